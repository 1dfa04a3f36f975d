"""Every row of the reproduction report: its check runs and decides the status the book reports."""

import pytest

from lib.paper import errata, report
from lib.paper.outcomes import STATUSES, legend_status

ITEMS = report.items()


@pytest.mark.parametrize("item", ITEMS, ids=[i.key for i in ITEMS])
def test_report_row_status_is_decided_by_its_check(item):
    out = report.outcome(item.key)   # the check, run once per library state when the book is built beside
    assert out.status == item.expected, f"{item.key}: computed {out.status!r}, book reports {item.expected!r} ({out.note})"
    if out.status in ("corrected", "refuted"):
        assert out.erratum, f"{item.key}: a {out.status} row must link its errata row"
    # the status is the legend's (lib.paper.outcomes.legend_status): a confirmed errata row on the
    # row's equations, or the one it links, makes it "corrected", a counterexample "refuted"
    linked = report.errata_on(item) + ([out.erratum] if out.erratum else [])
    printed_fails = any(errata.verdict(k).confirmed for k in linked)
    legend = legend_status(out.status != "not reproducible", printed_fails=printed_fails,
                           counterexample=out.counterexample, extension=item.expected == "extended")
    assert out.status == legend, f"{item.key}: status {out.status!r}, the legend gives {legend!r} (errata {linked})"


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


def test_legend_status_is_the_reports_legend():
    assert legend_status(False, printed_fails=True, counterexample=True) == "not reproducible"
    assert legend_status(True) == "reproduced"
    assert legend_status(True, printed_fails=True) == "corrected"
    assert legend_status(True, printed_fails=True, counterexample=True) == "refuted"
    assert legend_status(True, extension=True) == "extended"
    assert {legend_status(e, printed_fails=p, counterexample=c, extension=x)
            for e in (True, False) for p in (True, False) for c in (True, False) for x in (True, False)} == set(STATUSES)


def test_equation_numbers_are_read_from_the_rows_head():
    assert report.equation_numbers("Eqs. (5), (7)-(10): state form") == {5, 7, 8, 9, 10}
    assert report.equation_numbers("Sec. 6: globally stable under (36)") == set()


def test_rows_with_a_failing_printed_equation_are_not_reproduced():
    """(24) and the principal Arg of (28) fail as printed (errata rows): their rows are corrected;
    a slip of notation alone (the order of N's arguments in (23)) does not count."""
    by_key = {i.key: i for i in ITEMS}
    assert "eq24-rows" in report.errata_on(by_key["eq23-24"])
    assert "eq28-arg-branch" in report.errata_on(by_key["eq27-28"])
    assert "eq22-23-N-order" not in report.errata_on(by_key["eq23-24"])
    for i in ITEMS:
        if report.errata_on(i):
            assert i.expected != "reproduced", i.key
    assert by_key["gas"].expected == by_key["thm7"].expected == "refuted"
