"""Errata of the paper's Secs. 2-3: the drift (6), the brackets printed under (21), the
bracket count, Theorem 6, the rank condition and the conclusion; each row with the
computation that proves it."""

from __future__ import annotations

from typing import Callable

import sympy as sp

from ..controllability import (free_lie_rank, paper_bracket_count, rest_report, right_nested,
                               strong_accessibility_det, sussmann_check, witt_dimension)
from ..symbolic import (Bracket, _slug, _symbols_only, accessibility_matrix, bracket_latex,
                        compare_printed_brackets, derive_body_frame, evaluate_bracket, lie_bracket,
                        model_fields, printed_brackets, printed_drift, rank_determinants)
from ..machinery.cache import cached
from ..params import Body
from .verdicts import Erratum, Verdict

__all__ = ["ROWS"]


def _check_drift_row(printed=None, corrected=None) -> Verdict:
    """The drift (6): ``printed`` the drift as printed (a 6-vector; default
    :func:`lib.symbolic.printed_drift`), ``corrected`` its fifth row as corrected
    (default -c/m v2 - v1 omega); each holds if it equals the derivation."""
    model = derive_body_frame()
    X, Y, PHI, V1, V2, W = model.q
    p = model.params
    printed = printed_drift(model) if printed is None else sp.Matrix(printed)
    corrected = -p["c"] / p["m"] * V2 - V1 * W if corrected is None else corrected
    diff = sp.simplify(printed - model.f)
    wrong_rows = [i + 1 for i in range(6) if diff[i] != 0]
    return Verdict(
        printed_holds=not wrong_rows,
        corrected_holds=sp.simplify(model.f[4] - corrected) == 0,
        detail=f"printed minus derived drift is nonzero in row(s) {wrong_rows}: {sp.sstr(diff[4])}",
    )


def _entry_check(expr: Bracket, row: int, corrected_entry) -> Callable[..., Verdict]:
    def check(printed=None, corrected=None):
        """Entry ``row`` of bracket ``expr`` under (21): ``printed`` the entry as printed
        (default from :func:`lib.symbolic.printed_brackets`), ``corrected`` as corrected
        (default the row's typed value); each holds if it equals the derived entry."""
        model = derive_body_frame()
        rec = next(r for r in compare_printed_brackets(model) if r["bracket"] == expr and r["row"] == row)
        printed = rec["printed"] if printed is None else printed
        fixed = corrected_entry(model) if corrected is None else corrected
        why = {"drift typo": "follows from the sign typo of (6): the printed drift gives exactly the printed entry",
               "independent": f"independent of (6): the printed drift gives {sp.sstr(rec['printed_drift'])}",
               "correct": "entry is correct"}[rec["verdict"]]
        if rec["opposite_convention"]:
            why += " (the sign of the opposite convention [g, f])"
        return Verdict(
            printed_holds=sp.simplify(printed - rec["derived"]) == 0,
            corrected_holds=sp.simplify(fixed - rec["derived"]) == 0,
            detail=f"derived {sp.sstr(rec['derived'])}; {why}",
        )
    return check


def _witt_count(w: int, r: int) -> int:
    """Independent r-th order brackets of the drift and w inputs: Witt's formula."""
    return witt_dimension(w + 1, r + 1)


def _check_count(printed=None, corrected=None) -> Verdict:
    """The number of r-th order brackets of the drift and w inputs (w <= 2, r <= 3):
    ``printed`` and ``corrected`` are functions (w, r) -> count of independent brackets
    (defaults :func:`lib.controllability.paper_bracket_count`, Witt's formula), each
    holding if it gives the rank of the brackets in the free algebra; the corrected row
    also keeps w(w+1)^r/2 as the number of bracket expressions."""
    printed = paper_bracket_count if printed is None else printed
    corrected = _witt_count if corrected is None else corrected
    cases = [(w, r) for w in (1, 2) for r in (1, 2, 3)]
    names = lambda w: ["f"] + [f"g{i + 1}" for i in range(w)]  # noqa: E731
    indep = {(w, r): free_lie_rank(names(w), r) for w, r in cases}
    wrong = [(w, r, printed(w, r), indep[w, r]) for w, r in cases if printed(w, r) != indep[w, r]]
    exprs_ok = all(len(right_nested(names(w), r)) == paper_bracket_count(w, r) for w, r in cases)
    indep_ok = all(indep[w, r] == corrected(w, r) for w, r in cases)
    return Verdict(
        printed_holds=not wrong,
        corrected_holds=exprs_ok and indep_ok,
        detail="(w, r, printed, independent): " + ", ".join(map(str, wrong)),
    )


def _counterexample():
    """The textbook system x1' = u, x2' = x1^2: accessible at 0, not STLC."""
    x1, x2 = sp.symbols("x_1 x_2", real=True)
    return [x1, x2], {"f": sp.Matrix([0, x1**2]), "g": sp.Matrix([1, 0])}


#: the brackets that show the counterexample accessible at 0
_COUNTER_BRACKETS = ["g", ("f", "g"), ("g", ("f", "g"))]


def _theorem6_printed(fields, q, at) -> bool:
    """Theorem 6 as printed: STLC at ``at`` if locally accessible there."""
    return accessibility_matrix(fields, _COUNTER_BRACKETS, q).subs(at).rank() == len(q)


def _theorem6_corrected(fields, q, at) -> bool:
    """Theorem 6 corrected (Sussmann 1987, Thm. 7.3): STLC at the equilibrium ``at`` if
    accessible there and every bad bracket is neutralised by good ones of lower degree."""
    return _theorem6_printed(fields, q, at) and sussmann_check(fields, q, at, drift="f",
                                                               max_order=2).all_bad_neutralised


def _check_theorem6(printed=None, corrected=None) -> Verdict:
    """``printed`` and ``corrected`` are theorems: functions (fields, q, point) -> whether
    they conclude STLC at the point (defaults :func:`_theorem6_printed`,
    :func:`_theorem6_corrected`). A theorem fails if it concludes STLC for the
    counterexample x1' = u, x2' = x1^2 at 0, which is not STLC."""
    printed = _theorem6_printed if printed is None else printed
    corrected = _theorem6_corrected if corrected is None else corrected
    q, fields = _counterexample()
    at0 = {q[0]: 0, q[1]: 0}
    C = accessibility_matrix(fields, _COUNTER_BRACKETS, q).subs(at0)
    # x2' = x1^2 + 0*u >= 0 for every state and input: x2 never decreases, so
    # (0, -eps) is never reached and 0 is not interior to the reachable set
    rate = fields["f"][1] + fields["g"][1] * sp.Symbol("u", real=True)
    not_stlc = bool(rate.is_nonnegative)
    counter = sussmann_check(fields, q, at0, drift="f", max_order=2)
    return Verdict(
        printed_holds=not (printed(fields, q, at0) and not_stlc),
        corrected_holds=not (corrected(fields, q, at0) and not_stlc) and rest_report().complete,
        detail=f"x1'=u, x2'=x1^2: rank {C.rank()} at 0, x2' >= 0 always; "
               f"bad [g,[f,g]] neutralised: {counter.all_bad_neutralised}; "
               f"this body at rest: Sussmann condition proven {rest_report().complete}",
    )


def _theorem7_as_used(fields, q, at, brackets) -> bool:
    """Theorem 7 as the conclusion of Sec. 3 uses it: controllable if locally accessible at
    ``at`` (the brackets ``brackets`` span), whether or not the system has a drift."""
    return accessibility_matrix(fields, brackets, q).subs(at).rank() == len(q)


def _theorem7(fields, q, at, brackets) -> bool:
    """Theorem 7 within its hypothesis (Chow-Rashevskii): a system *without drift* that is
    locally accessible is (globally) controllable; it says nothing about one with a drift."""
    driftless = "f" not in fields or all(e == 0 for e in fields["f"])
    return driftless and _theorem7_as_used(fields, q, at, brackets)


def _check_theorem7(printed=None, corrected=None) -> Verdict:
    """Theorem 7 as applied in Sec. 3: ``printed`` and ``corrected`` are inferences
    (fields, q, point, brackets) -> whether they conclude the system controllable
    (defaults :func:`_theorem7_as_used`, :func:`_theorem7`). An inference fails if it
    concludes it for the system with drift x1' = u, x2' = x1^2, which is accessible at 0
    and never lowers x2; the corrected one must still conclude it for the driftless
    x1' = u1, x2' = x1 u2 (accessible through [g1, g2], Chow). The body's drift is not zero
    at a moving state, so the theorem does not apply to (5)."""
    printed = _theorem7_as_used if printed is None else printed
    corrected = _theorem7 if corrected is None else corrected
    q, fields = _counterexample()
    at0 = {q[0]: 0, q[1]: 0}
    rate = fields["f"][1] + fields["g"][1] * sp.Symbol("u", real=True)
    never_lowers = bool(rate.is_nonnegative)        # (0, -eps) is never reached: not controllable
    x1, x2 = q
    driftless = {"g1": sp.Matrix([1, 0]), "g2": sp.Matrix([0, x1])}
    concludes_driftless = corrected(driftless, q, at0, ["g1", "g2", ("g1", "g2")])
    model = derive_body_frame()
    moving = {v: 1 for v in model.q[3:]}
    drift_moving = sp.simplify(model.f.subs(moving).subs({model.q[2]: 0}))
    return Verdict(
        printed_holds=not (printed(fields, q, at0, _COUNTER_BRACKETS) and never_lowers),
        corrected_holds=not (corrected(fields, q, at0, _COUNTER_BRACKETS) and never_lowers) and concludes_driftless,
        detail=f"x1'=u, x2'=x1^2: accessible at 0, x2' >= 0 always; the driftless x1'=u1, x2'=x1 u2 accessible: "
               f"{concludes_driftless}; the body's drift at v1 = v2 = omega = 1, phi = 0 is nonzero: "
               f"{not drift_moving.is_zero_matrix}",
    )


def _stlc_claims(model):
    """The sets of states where the conclusion claims STLC, as sympy conditions on
    (v1, v2, omega): as printed (omega != a m v2 / I_C) and as corrected (at rest)."""
    _, _, _, V1, V2, W = model.q
    p = model.params
    return (sp.Ne(W, p["a"] * p["m"] / p["I"] * V2),
            sp.And(sp.Eq(V1, 0), sp.Eq(V2, 0), sp.Eq(W, 0)))


def _claims_moving_state(claim, model) -> bool:
    """Whether ``claim`` includes a state where the body moves: tried at the unit
    velocities along each axis, both signs, and on the printed excluded line, with the
    Table's parameters."""
    _, _, _, V1, V2, W = model.q
    p = model.params
    b = Body()
    vals = {p["m"]: b.m, p["I"]: b.I, p["a"]: b.a, p["c"]: b.c, p["c_phi"]: b.c_phi}
    points = [(s * e[0], s * e[1], s * e[2]) for e in ((1, 0, 0), (0, 1, 0), (0, 0, 1)) for s in (1, -1)]
    points.append((0, 1, b.a * b.m / b.I))
    return any(bool(sp.sympify(claim).subs(vals).subs({V1: v1, V2: v2, W: w})) for v1, v2, w in points)


def _check_conclusion(printed=None, corrected=None) -> Verdict:
    """``printed`` and ``corrected`` are the sets of states where STLC is claimed, as sympy
    conditions on (v1, v2, omega) (defaults :func:`_stlc_claims`). A claim fails if it
    includes a moving state (there the configuration moves whatever the bounded inputs);
    the corrected one must also include the rest state (Sussmann's condition proven
    there) and come with strong accessibility at every state."""
    model = derive_body_frame()
    _, _, _, V1, V2, W = model.q
    p = model.params
    printed_claim, corrected_claim = _stlc_claims(model)
    printed = printed_claim if printed is None else printed
    corrected = corrected_claim if corrected is None else corrected
    # configuration rates (rows 1-3) are free of the inputs and vanish only at rest
    inputs_free = all(e == 0 for e in list(model.g1[:3]) + list(model.g2[:3]))
    rest = sp.solve(list(model.f[:3]), [V1, V2, W], dict=True)
    only_rest = rest == [{V1: 0, V2: 0, W: 0}]
    moving_not_stlc = inputs_free and only_rest
    det = strong_accessibility_det()
    everywhere = det.free_symbols <= set(p.values()) and det != 0
    corrected_at_rest = bool(sp.sympify(corrected).subs({V1: 0, V2: 0, W: 0}))
    return Verdict(
        printed_holds=not (moving_not_stlc and _claims_moving_state(printed, model)),
        corrected_holds=(bool(everywhere) and rest_report().complete and corrected_at_rest
                         and not (moving_not_stlc and _claims_moving_state(corrected, model))),
        detail=f"off the printed set the configuration always moves (rest only at {rest}); "
               f"det of strong-accessibility brackets = {sp.sstr(det)}; "
               f"Sussmann at rest proven: {rest_report().complete}",
    )


def _check_f1_name(printed=None, corrected=None) -> Verdict:
    """The line "Also: [X, [g1, g2]] = 0": ``printed`` and ``corrected`` are the field X
    (defaults f_1 of eq. (1), a 3-vector of accelerations, and the drift f of (5)); each
    holds if the bracket is defined on the 6-dimensional state and vanishes."""
    model = derive_body_frame()
    p = model.params
    fields = model_fields(model)
    if printed is None:
        xd, yd, pd = sp.symbols("xdot ydot varphidot", real=True)
        printed = sp.Matrix([-p["c"] / p["m"] * xd, -p["c"] / p["m"] * yd, -p["c_phi"] / p["I"] * pd])  # eq. (1)
    corrected = fields["f"] if corrected is None else corrected
    g1g2 = evaluate_bracket(("g1", "g2"), fields, model.q)

    def vanishes(X) -> bool:
        try:
            return all(sp.simplify(e) == 0 for e in lie_bracket(X, g1g2, model.q))
        except ValueError:  # not a field on the state: the bracket is undefined
            return False

    return Verdict(
        printed_holds=vanishes(printed),
        corrected_holds=vanishes(corrected),
        detail="f_1 of eq. (1) is a 3-vector (accelerations): [f_1, .] on the 6-dim state is undefined; "
               "[f, [g1, g2]] = 0",
    )


#: wrong entries of the brackets printed under (21), with the corrected value (typed here,
#: checked against the derivation)
_ENTRY_ROWS = [
    (("f", "g1"), 2, lambda M: -sp.sin(M.q[2]) / M.params["m"]),
    (("f", "g1"), 4, lambda M: M.params["c"] / M.params["m"] ** 2),
    (("f", "g1"), 5, lambda M: M.q[5] / M.params["m"]),
    (("f", "g2"), 5, lambda M: M.params["c"] / M.params["m"] ** 2 + M.q[3] * M.params["a"] / M.params["I"]),
    (("g1", ("f", "g2")), 5, lambda M: M.params["a"] / (M.params["m"] * M.params["I"])),
]


def _entry_rows():
    model = _symbols_only()  # the LaTeX of the rows needs symbols only, not the derivation
    printed = printed_brackets(model)
    out = []
    for expr, row, corrected in _ENTRY_ROWS:
        out.append(Erratum(
            key=f"eq21-{_slug(expr)}-row{row}",
            where=f"Eq. (21), ${bracket_latex(expr)}$, row {row}",
            printed=f"${sp.latex(printed[expr][row - 1])}$",
            corrected=f"${sp.latex(corrected(model))}$",
            verified_by="sympy bracket (16) of the derived fields, recomputed with the printed drift "
                        "to classify (`lib.symbolic.compare_printed_brackets`); finite-difference "
                        "brackets (`tests/test_symbolic.py::test_symbolic_brackets_match_finite_differences`)",
            section="chapters/02_controllability",
            check=_entry_check(expr, row, corrected),
            equations=(21,),
        ))
    return out


def _check_rank_condition(printed=None, corrected=None):
    """The paper's exceptional set omega = a m v2 / I_C against the zero set of det C:
    ``printed`` and ``corrected`` are det C (defaults from
    :func:`lib.symbolic.rank_determinants`: with the printed columns of (21), with the
    derived ones); each holds if it is the claim times a nonzero constant."""
    model = derive_body_frame()
    p = model.params
    _, _, _, _, v2, w = model.q
    claim = p["a"] * p["m"] * v2 - p["I"] * w
    if printed is None or corrected is None:
        dets = cached(rank_determinants)        # of that model; shared with Chapter 2 and the report
        printed = dets["printed"] if printed is None else printed
        corrected = dets["derived"] if corrected is None else corrected

    def matches(det):  # det C = const * claim with a nonzero constant free of the state
        ratio = sp.simplify(det / claim)
        return not ratio.free_symbols & set(model.q) and ratio != 0

    return Verdict(printed_holds=matches(printed), corrected_holds=matches(corrected),
                   detail=f"det C with the printed columns: {sp.sstr(printed)}; "
                          f"with the derived ones: {sp.sstr(corrected)}")


def _errata():
    return [
        Erratum(
            key="eq6-v2-row",
            where="Eq. (6), fifth row (the rate of $v_2$)",
            printed=r"$-\frac{c}{m}v_2 + v_1\omega$",
            corrected=r"$-\frac{c}{m}v_2 - v_1\omega$",
            verified_by="sympy derivation of (5) from (2)-(4) (`lib.symbolic.derive_body_frame`); "
                        "open-loop integration of both forms against (2)-(4) "
                        "(`tests/test_model.py::test_printed_drift_diverges_from_configuration_form`)",
            section="chapters/01_model",
            check=_check_drift_row,
            equations=(6,),
        ),
        *_entry_rows(),
        Erratum(
            key="sec3-also-f1",
            where="Sec. 3, line after (21) (\"Also: ...\")",
            printed=r"$[f_1, [g_1, g_2]] = 0$",
            corrected=r"$[f, [g_1, g_2]] = 0$ ($f_1$ is the drift of the second-order form (1))",
            verified_by="`lie_bracket` refuses the 3-dimensional $f_1$ on the 6-dimensional state; "
                        "$[f,[g_1,g_2]]$ computed",
            section="chapters/02_controllability",
            check=_check_f1_name,
            equations=(21,),
        ),
        Erratum(
            key="sec3-bracket-count",
            where="Sec. 3, after (20): number of $r$-th order brackets",
            printed=r"$w(w+1)^r/2$",
            corrected=r"$w(w+1)^r/2$ bracket expressions $[X_{a_1},[\dots,[X_i,X_j]]]$, $i<j$; "
                      r"at most $\frac{1}{r+1}\sum_{d\mid r+1}\mu(d)(w+1)^{(r+1)/d}$ independent (Witt)",
            verified_by="rank of the brackets expanded in the free associative algebra "
                        "(`lib.controllability.free_lie_rank`) against Witt's formula, $w\\le 2$, $r\\le 3$",
            section="chapters/02_controllability",
            check=_check_count,
            notation=True,        # a reading of what is counted: no computation of the paper uses the count
        ),
        Erratum(
            key="thm6-accessibility-stlc",
            where="Theorem 6 (attributed to Sussmann 1987)",
            printed="a locally accessible system with drift is small-time locally controllable",
            corrected="false in general ($\\dot x_1 = u$, $\\dot x_2 = x_1^2$ is accessible at 0, not STLC); "
                      "sufficient at an equilibrium: accessibility and every bad bracket neutralised "
                      "by good brackets of lower degree (Sussmann 1987, Thm. 7.3)",
            verified_by="counterexample computed with `lie_bracket`; `lib.controllability.sussmann_check`",
            section="chapters/02_controllability",
            check=_check_theorem6,
        ),
        Erratum(
            key="thm7-drift",
            where="Sec. 3, the last sentence's \"theory 7\"",
            printed="\"theory 7\" (a system *without drift* that is locally accessible is globally "
                    "controllable), cited to conclude that (5), a system *with* drift, is small-time locally "
                    "controllable",
            corrected="Theorem 7 (Chow) holds for systems without drift only; (5) has a drift, nonzero at "
                      "every moving state, so Theorem 7 cannot give the conclusion, and accessibility with a "
                      "drift does not give STLC ($\\dot x_1 = u$, $\\dot x_2 = x_1^2$ has a drift, is accessible "
                      "at 0 and never lowers $x_2$). Read as a slip for Theorem 6, the inference is Theorem 6's, "
                      "refuted in its row",
            verified_by="the counterexample and a driftless system checked with `accessibility_matrix`; "
                        "the body's drift at a moving state (`lib.paper.model_errata._check_theorem7`)",
            section="chapters/02_controllability",
            check=_check_theorem7,     # a theorem cited outside its hypothesis: the report's row is misapplied
        ),
        Erratum(
            key="sec3-stlc-conclusion",
            where="Sec. 3, last sentence (conclusion from Def. 4 and \"theory 7\")",
            printed=r"accessible and STLC for $q_0$ with $\omega \ne \frac{am}{I_C}v_2$",
            corrected=r"strongly accessible at every state; STLC at every rest state "
                      r"($v_1=v_2=\omega=0$, inside the excluded set); with bounded inputs not STLC "
                      r"at any state where the body moves, which includes every state the claim names",
            verified_by="constant determinant of six brackets without $f$; Sussmann's condition at rest "
                        "(`lib.controllability.rest_report`); configuration rates free of inputs",
            section="chapters/02_controllability",
            check=_check_conclusion,
        ),
        Erratum(
            key="sec3-rank-condition",
            where="Sec. 3, the rank condition stated after (21)",
            printed=r"$\mathrm{rank}\,C = 6$ for $\omega \ne \frac{am}{I_C}v_2$, from the columns of (21) as printed",
            corrected=r"the condition holds for the derived columns; with the printed ones "
                      r"$\det C \propto a m v_2\cos 2\varphi + a m v_1 \sin 2\varphi - I_C\omega\cos 2\varphi$",
            verified_by="sympy determinants of $C$ with the printed and the derived bracket columns "
                        "(`lib.symbolic.rank_determinants`)",
            section="chapters/02_controllability",
            check=_check_rank_condition,
        ),
    ]


ROWS = _errata()
