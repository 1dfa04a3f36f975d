"""Every erratum row: the printed form fails its check and the corrected form passes."""

import pytest

from lib import errata

ROWS = errata.rows()


@pytest.mark.parametrize("row", ROWS, ids=[r.key for r in ROWS])
def test_erratum_printed_form_fails_and_corrected_form_holds(row):
    verdict = row.check()
    assert not verdict.printed_holds, f"{row.key}: the printed form passed its check ({verdict.detail})"
    assert verdict.corrected_holds, f"{row.key}: the corrected form failed its check ({verdict.detail})"


def test_errata_rows_are_complete():
    for r in ROWS:
        assert r.where and r.printed and r.corrected and r.verified_by and r.section
    assert len({r.key for r in ROWS}) == len(ROWS)
