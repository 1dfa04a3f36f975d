"""Every erratum's check can fail: fed a right "printed" form and a wrong "corrected" one,
its verdict flips.

``tests/test_errata.py`` shows that each row's printed form fails its check and its
corrected form passes. That alone cannot tell a check from one that ignores its forms
(a check comparing the corrected form with itself passes too). Each row's check takes
its two forms as arguments (``printed=``, ``corrected=``, defaulting to the row's own);
here each row gets a printed form that is right (the derivation, or the row's own
correction) and a corrected form that is wrong (the paper's printed form, or another
wrong one), and its verdict must say so: the printed form holds, the corrected one does
not. A row added without a case here fails :func:`test_every_erratum_has_a_falsifying_case`.
"""

from __future__ import annotations

import pytest
import sympy as sp

from lib.controllability import paper_bracket_count, witt_dimension
from lib.paper import errata, model_errata, reading_errata as rd, rotation_errata as ro
from lib.paper.rotation_errata import CORRECTED_HEADING_SERIES
from lib.rotation.equations import (corrected_p0, derive_eight_equation, derive_rotation_equation,
                                    printed_eq33, printed_eq37, printed_p0)
from lib.symbolic import (derive_body_frame, evaluate_bracket, model_fields, printed_brackets, printed_drift,
                          rank_determinants)
from lib.trajectories import PAPER_HEADING_SERIES

ROWS = errata.rows()


def _f1():
    """f_1 of eq. (1): the 3-vector of accelerations, no field on the 6-dimensional state."""
    p = derive_body_frame().params
    xd, yd, pd = sp.symbols("xdot ydot varphidot", real=True)
    return sp.Matrix([-p["c"] / p["m"] * xd, -p["c"] / p["m"] * yd, -p["c_phi"] / p["I"] * pd])


def _entry_case(expr, row):
    def case():
        M = derive_body_frame()
        derived = evaluate_bracket(expr, model_fields(M), M.q)[row - 1]
        return [dict(printed=derived, corrected=printed_brackets(M)[expr][row - 1]),
                dict(printed=derived, corrected=derived + M.params["a"])]
    return case


def _claims():
    _, _, _, V1, V2, W = derive_body_frame().q
    p = derive_body_frame().params
    printed = sp.Ne(W, p["a"] * p["m"] / p["I"] * V2)
    rest = sp.And(sp.Eq(V1, 0), sp.Eq(V2, 0), sp.Eq(W, 0))
    # a claim with a moving state in it, and one that leaves out the rest state
    return [dict(printed=rest, corrected=printed), dict(printed=rest, corrected=sp.Eq(V1, 1))]


def _rank_cases():
    d = rank_determinants()
    return [dict(printed=d["derived"], corrected=d["printed"])]


def _eq33_cases():
    eq = derive_rotation_equation()
    return [dict(printed=eq.rhs, corrected=printed_eq33()),
            dict(printed=eq.rhs, corrected=eq.rhs + sp.cos(eq.p) / 1000)]


def _eq37_cases():
    torque = derive_eight_equation()[1]
    return [dict(printed=printed_eq37(False), corrected=printed_eq37(True)),
            dict(printed=torque, corrected=2 * torque)]


def _always_stlc(fields, q, at):
    return True


#: per row key: a function returning the cases, each the keyword arguments of a right
#: printed form and a wrong corrected form
CASES = {
    "eq6-v2-row": lambda: [dict(printed=derive_body_frame().f, corrected=printed_drift(derive_body_frame())[4])],
    **{f"eq21-{k}": _entry_case(expr, row) for k, expr, row in [
        ("f-g1-row2", ("f", "g1"), 2), ("f-g1-row4", ("f", "g1"), 4), ("f-g1-row5", ("f", "g1"), 5),
        ("f-g2-row5", ("f", "g2"), 5), ("g1-f-g2-row5", ("g1", ("f", "g2")), 5)]},
    # the field in [X, [g1, g2]] = 0: f_1 is a 3-vector, no field on the 6-dimensional state.
    # [g1, g2] = 0, so the bracket vanishes for every field on the state: only the
    # dimension can make X wrong
    "sec3-also-f1": lambda: [dict(printed=model_fields(derive_body_frame())["f"], corrected=_f1())],
    "sec3-bracket-count": lambda: [dict(printed=lambda w, r: witt_dimension(w + 1, r + 1),
                                        corrected=paper_bracket_count),
                                   dict(printed=lambda w, r: witt_dimension(w + 1, r + 1),
                                        corrected=lambda w, r: witt_dimension(w + 1, r + 1) + 1)],
    "thm6-accessibility-stlc": lambda: [dict(printed=model_errata._theorem6_corrected,
                                             corrected=model_errata._theorem6_printed),
                                        dict(printed=model_errata._theorem6_corrected, corrected=_always_stlc)],
    "sec3-stlc-conclusion": _claims,
    "sec3-rank-condition": _rank_cases,
    "thm7-drift": lambda: [dict(printed=model_errata._theorem7, corrected=model_errata._theorem7_as_used),
                           dict(printed=model_errata._theorem7, corrected=lambda *a: False)],
    "table-number": lambda: [dict(printed=1, corrected=5), dict(printed=1, corrected=2)],
    "eq33-cos-sign": _eq33_cases,
    "eq33-p0": lambda: [dict(printed=corrected_p0, corrected=printed_p0),
                        dict(printed=corrected_p0, corrected=lambda k: corrected_p0(k) + sp.Rational(1, 100))],
    "eq37-bracket": _eq37_cases,
    "sec6-global-stability": lambda: [dict(printed=ro._global_outside_window, corrected=ro._global_as_printed),
                                      dict(printed=ro._global_outside_window, corrected=lambda b, R, th: True)],
    "fourier-a3": lambda: [dict(printed=CORRECTED_HEADING_SERIES, corrected=PAPER_HEADING_SERIES),
                           dict(printed=CORRECTED_HEADING_SERIES, corrected={**CORRECTED_HEADING_SERIES, 5: 0.17})],
    # the line-by-line audit (lib.paper.reading_errata)
    "def2-stlc": lambda: [dict(printed=rd._interior, corrected=rd._membership),
                          dict(printed=rd._interior, corrected=lambda lo, hi, q: True)],
    "eq19-20-symbols": lambda: [dict(printed="g", corrected="q"), dict(printed="g", corrected="f")],
    "eq22-23-N-order": lambda: [dict(printed=(("z'", "z"), ("z'", "z")), corrected=(("z'", "z"), ("z", "z'")))],
    "eq24-rows": lambda: [dict(printed=(0, 1), corrected=(0, 1, 2)), dict(printed=(0,), corrected=(2,))],
    "eq28-arg-branch": lambda: [dict(printed=rd._continuous_heading, corrected=rd.printed_eight_heading),
                                dict(printed=rd._continuous_heading,
                                     corrected=lambda s: rd._continuous_heading(s) + 0.01)],
    "theta-symbol": lambda: [dict(printed=("theta",), corrected=("Theta", "theta"))],
}


def test_every_erratum_has_a_falsifying_case():
    missing = [r.key for r in ROWS if r.key not in CASES]
    assert not missing, f"errata rows without a falsifying case in this file: {missing}"
    stale = sorted(set(CASES) - {r.key for r in ROWS})
    assert not stale, f"cases for rows that no longer exist: {stale}"


@pytest.mark.parametrize("row", ROWS, ids=[r.key for r in ROWS])
def test_erratum_verdict_flips_with_a_right_printed_and_a_wrong_corrected_form(row):
    if row.key not in CASES:
        pytest.fail(f"{row.key}: no falsifying case")
    for kw in CASES[row.key]():
        v = row.check(**kw)
        assert v.printed_holds, f"{row.key}: a right printed form failed its check ({v.detail})"
        assert not v.corrected_holds, f"{row.key}: a wrong corrected form passed its check ({v.detail})"
        assert not v.confirmed


# ------------------------------------------------ sub-cases: a form wrong in one case only
# (issue 28: an errata check that held when one of its cases held, max(|r|) turned into
# min(|r|), passed every test above, whose wrong forms are wrong as a whole)

def _p0_wrong_for(bad):
    """p0^(k), right for every k but ``bad``, where it is the printed form."""
    return lambda k: printed_p0(k) if k == bad else corrected_p0(k)


def _p0_off_for(bad):
    return lambda k: corrected_p0(k) + (sp.Rational(1, 100) if k == bad else 0)


def _series_wrong_at(k):
    return {**CORRECTED_HEADING_SERIES, k: CORRECTED_HEADING_SERIES[k] + 0.01}


#: per row key: cases whose printed and corrected forms are both wrong in exactly one sub-case
SUB_CASES = {
    "eq33-p0": [dict(printed=_p0_wrong_for(k), corrected=_p0_off_for(k)) for k in (0, 1)],
    "fourier-a3": [dict(printed=_series_wrong_at(k), corrected=_series_wrong_at(k)) for k in (1, 3, 5)],
}


@pytest.mark.parametrize("key, i", [(key, i) for key, cases in SUB_CASES.items() for i in range(len(cases))])
def test_erratum_form_wrong_in_one_sub_case_fails_its_check(key, i):
    row = next(r for r in ROWS if r.key == key)
    v = row.check(**SUB_CASES[key][i])
    assert not v.printed_holds, f"{key}: a printed form wrong in one case passed its check ({v.detail})"
    assert not v.corrected_holds, f"{key}: a corrected form wrong in one case passed its check ({v.detail})"


def test_table_number_needs_every_text_reference_to_cite_the_corrected_number():
    from lib.paper.tracking_errata import PAPER_TABLE_LINES

    row = next(r for r in ROWS if r.key == "table-number")
    assert row.check().corrected_holds
    # one more reference, citing another number: the corrected number no longer holds
    lines = [*PAPER_TABLE_LINES, "as in Tab. 2 above"]
    assert not row.check(lines=lines).corrected_holds
    # a second caption: the paper would then have two tables, and "1" is not their count
    assert not row.check(lines=[*PAPER_TABLE_LINES, "Table 2 Other values"]).corrected_holds
