"""Every row of the reproduction report: its check runs and decides the status the book reports."""

import pytest

from lib.paper import report

ITEMS = report.items()


@pytest.mark.parametrize("item", ITEMS, ids=[i.key for i in ITEMS])
def test_report_row_status_is_decided_by_its_check(item):
    out = report.outcome(item.key)   # the check, run once per library state when the book is built beside
    assert out.status == item.expected, f"{item.key}: computed {out.status!r}, book reports {item.expected!r} ({out.note})"
    if out.status in ("corrected", "refuted"):
        assert out.erratum, f"{item.key}: a {out.status} row must link its errata row"


def test_report_rows_are_unique_and_link_existing_pages():
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    assert len({i.key for i in ITEMS}) == len(ITEMS)
    for i in ITEMS:
        assert (root / f"{i.section}.md").exists(), f"{i.key}: no page {i.section}"
        assert i.expected in report.STATUSES


def test_outcome_rejects_unknown_status_and_non_finite_merit():
    with pytest.raises(ValueError, match="unknown status"):
        report.Outcome("fine", 0.0, "x")
    with pytest.raises(ValueError, match="finite"):
        report.Outcome("reproduced", float("nan"), "x")


def test_the_front_page_states_report_rows_with_the_status_each_row_claims():
    # intro.md's findings read these rows (lib.paper.findings); a finding cannot claim another
    # status than the row's check is required to decide
    from lib.paper.findings import FINDINGS
    expected = {it.key: it.expected for it in report.items()}
    assert set(FINDINGS) <= set(expected)
    assert {k: expected[k] for k in FINDINGS} == FINDINGS
