"""Every erratum row: the printed form fails its check and the corrected form passes."""

import pytest

from lib.paper import errata

ROWS = errata.rows()


@pytest.mark.parametrize("row", ROWS, ids=[r.key for r in ROWS])
def test_erratum_printed_form_fails_and_corrected_form_holds(row):
    verdict = errata.verdict(row.key)   # the check, run once per library state when the book is built beside
    assert not verdict.printed_holds, f"{row.key}: the printed form passed its check ({verdict.detail})"
    assert verdict.corrected_holds, f"{row.key}: the corrected form failed its check ({verdict.detail})"


def test_errata_rows_are_complete():
    for r in ROWS:
        assert r.where and r.printed and r.corrected and r.verified_by and r.section
    assert len({r.key for r in ROWS}) == len(ROWS)


def test_table_number_check_reads_its_evidence_from_the_repository():
    from lib.paper.tracking_errata import PAPER_TABLE_LINES, _check_table_number

    v = _check_table_number()
    assert not v.printed_holds and v.corrected_holds
    # the verdict follows the data: a paper with five captioned tables would make "Table 5" right
    five = tuple(f"Table {k}. Something" for k in range(1, 6)) + PAPER_TABLE_LINES[:1]
    assert _check_table_number(five).printed_holds


def test_library_refers_to_no_path_outside_the_repository():
    import re
    from pathlib import Path

    lib = Path(__file__).resolve().parents[1] / "lib"
    bad = re.compile(r"parents\[[1-9]\]|\.\./|[\"']shared[\"/]")
    hits = [f"{p.name}:{i}" for p in sorted(lib.glob("*.py"))
            for i, line in enumerate(p.read_text().splitlines(), 1) if bad.search(line)]
    assert not hits, hits
