"""Every row of the reproduction report: its check runs and decides the status the book reports."""

import pytest

from lib.paper import errata, report
from lib.paper.outcomes import STATUSES, legend_status

ITEMS = report.items()


@pytest.mark.parametrize("item", ITEMS, ids=[i.key for i in ITEMS])
def test_report_row_status_is_decided_by_its_check(item):
    out = report.outcome(item.key)   # the check, run once per library state when the book is built beside
    assert out.status == item.expected, f"{item.key}: computed {out.status!r}, book reports {item.expected!r} ({out.note})"
    if out.status in ("corrected", "refuted", "misapplied"):
        assert out.erratum, f"{item.key}: a {out.status} row must link its errata row"
    # the status is the legend's (lib.paper.outcomes.legend_status): a confirmed errata row on the
    # row's equations, or the one it links (a slip of notation aside), makes it "corrected", a
    # counterexample "refuted", a theorem outside its hypotheses "misapplied", ...
    notation = {r.key for r in errata.rows() if r.notation}
    linked = report.errata_on(item) + ([out.erratum] if out.erratum and out.erratum not in notation else [])
    printed_fails = any(errata.verdict(k).confirmed for k in linked)
    legend = legend_status(out.status != "not reproducible", printed_fails=printed_fails,
                           counterexample=out.counterexample, extension=item.expected == "extended",
                           misapplied=out.misapplied, added_condition=out.added_condition, unstated=out.unstated)
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
    assert legend_status(False, printed_fails=True, counterexample=True, misapplied=True, added_condition=True,
                         unstated=True) == "not reproducible"
    assert legend_status(True) == "reproduced"
    assert legend_status(True, printed_fails=True) == "corrected"
    assert legend_status(True, printed_fails=True, counterexample=True) == "refuted"
    assert legend_status(True, extension=True, unstated=True) == "extended"


def test_legend_gives_each_new_word_for_its_own_finding_only():
    # a confirmation that needs a condition the paper does not state: not plain "reproduced",
    # and a correction still outranks it
    assert legend_status(True, added_condition=True) == "reproduced under an added condition"
    assert legend_status(True, added_condition=True, printed_fails=True) == "corrected"
    # a true theorem outside its hypotheses: "misapplied", not "refuted", even with the
    # counterexample that shows the conclusion does not follow
    assert legend_status(True, misapplied=True, counterexample=True) == "misapplied"
    assert legend_status(True, counterexample=True) == "refuted"
    # a figure whose unstated grid and criterion decide it
    assert legend_status(True, unstated=True, misapplied=True, counterexample=True) == "not reproducible as stated"
    flags = ("printed_fails", "counterexample", "extension", "misapplied", "added_condition", "unstated")
    seen = set()
    for e in (True, False):
        for bits in range(2 ** len(flags)):
            seen.add(legend_status(e, **{f: bool(bits >> i & 1) for i, f in enumerate(flags)}))
    assert seen == set(STATUSES)


def test_equation_numbers_are_read_from_the_rows_head():
    assert report.equation_numbers("Eqs. (5), (7)-(10): state form") == {5, 7, 8, 9, 10}
    assert report.equation_numbers("Sec. 6: globally stable under (36)") == set()


def test_rows_with_a_failing_printed_equation_are_not_reproduced():
    """A row whose equations have an errata row in which a printed form fails is not "reproduced"."""
    for i in ITEMS:
        if report.errata_on(i):
            assert i.expected != "reproduced", i.key


def test_slips_of_notation_and_readings_make_no_row_corrected():
    """(24) holds as printed (for Q = tau; its x and y rows under (25)-(26), all (29)-(30) use), and
    the principal Arg of (28) names the tangent direction, which the law never reads: their errata
    rows change no computation, and the rows are reproduced, like the order of N's arguments."""
    by_key = {i.key: i for i in ITEMS}
    notation = {r.key for r in errata.rows() if r.notation}
    assert {"eq24-rows", "eq28-arg-branch", "eq22-23-N-order"} <= notation
    assert report.errata_on(by_key["eq23-24"]) == report.errata_on(by_key["eq27-28"]) == []
    assert by_key["eq23-24"].expected == by_key["eq27-28"].expected == "reproduced"


def test_each_word_of_the_legend_names_the_rows_the_referee_named():
    by_key = {i.key: i for i in ITEMS}
    # "theory 7" read as printed: Chow's theorem (true, for systems without drift) cited for (5),
    # which has a drift; read as a slip for Theorem 6, the inference is refuted in Theorem 6's row
    assert by_key["thm7"].expected == "misapplied"
    assert by_key["thm6"].expected == by_key["gas"].expected == "refuted"
    assert by_key["quasi"].expected == "reproduced under an added condition"   # only with a force cap
    assert by_key["fig5"].expected == "not reproducible as stated"          # grid and criterion unstated
    assert by_key["fig5-map"].expected == "extended"                        # and the book's map beside it
    assert by_key["fourier"].expected == "corrected"       # a wrong printed digit is not a slip of notation
    assert by_key["count"].expected == "reproduced"        # the count of expressions: a reading
    assert {i.expected for i in ITEMS} == set(STATUSES) - {"not reproducible"}


def test_the_errata_rows_say_what_the_report_rows_say():
    """The errata agree with the report's words: Theorem 7's row says that it holds for systems
    without drift only and is not a reading (the report's row is misapplied), a3's is a wrong value,
    and the rows behind the reproduced (23)-(24) and (27)-(28) say that they change no computation."""
    by_key = {r.key: r for r in errata.rows()}
    assert by_key["thm7-drift"].corrected.startswith("Theorem 7 (Chow) holds for systems without drift only")
    assert not by_key["thm7-drift"].notation and not by_key["fourier-a3"].notation
    assert by_key["sec3-bracket-count"].notation
    assert "No printed form fails" in by_key["eq24-rows"].corrected
    assert "slip of notation" in by_key["eq28-arg-branch"].corrected
    kinds = errata.table(run_checks=False).set_index("key")["kind"]
    assert kinds["eq24-rows"] == kinds["eq28-arg-branch"] == "notation or reading"
    assert kinds["sec3-bracket-count"] == "notation or reading"
    assert kinds["thm7-drift"] == kinds["fourier-a3"] != "notation or reading"
