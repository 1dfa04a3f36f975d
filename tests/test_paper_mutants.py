"""Properties of :mod:`lib.paper` and :mod:`lib.weighting.circle` that mutation testing
(``make mutation``, mutation/REPORT.md) found unchecked: each test here kills mutants that
survived the rest of the fast suite.

The circle's limit search is tested twice: on the real loop (its arguments, the fields of the
result) and on a loop whose spectrum or branch is replaced by a synthetic one with a known
answer (a real eigenvalue or a complex pair crossing at a chosen weight, a branch that ends at a
chosen weight), so that each way the search can end is reached; the real loop reaches only one
(a complex pair at w_phi = 3.13).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from lib.params import Body, Gains
from lib.weighting import circle as C

BODY, GAINS, R, THETA = Body(), Gains(), 2.0, math.pi / 4


# ------------------------------------------------------------------ weighting.circle: arguments

def _limit(**kw):
    return lambda: C.circle_weight_limit(BODY, GAINS, R, THETA, **kw)


def _error_weight(level=0.2, **kw):
    return lambda: C.circle_error_weight(BODY, GAINS, R, THETA, level, **kw)


def _field(y=np.zeros(6), t=0.0):
    return lambda: C.rotating_field(BODY, GAINS, R, THETA, (1.0, 1.0, 0.5), y, t)


def _sweep(w_phi):
    return lambda: C.circle_weight_sweep(BODY, GAINS, R, THETA, w_phi)


def _steady(weights=(1.0, 1.0, 0.5), t=0.0):
    return lambda: C.circle_steady_state(BODY, GAINS, R, THETA, weights, t)


@pytest.mark.parametrize("call, match", [
    # each bad value breaks one clause of its check only, and the message starts with the name
    (_field(t=True), r"^t must be a finite time"),
    (_field(t=np.array([0.0, 1.0])), r"^t must be a finite time"),
    (_field(t=float("nan")), r"^t must be a finite time"),
    (_field(y=np.float64(1.0)), r"^y must have a last axis of length 6"),
    (_field(y=np.zeros((6, 5))), r"^y must have a last axis of length 6"),
    (_steady(t=True), r"^t must be a finite time"),
    (_steady(t=np.array([1.0])), r"^t must be a finite time"),
    (_steady(weights=(1.0, 1.0, np.nan)), r"^weights must be three finite non-negative numbers \(w_x, w_y, w_phi\)"),
    (_steady(weights=(1.0, 1.0, -1.0)), r"^weights must be three finite non-negative numbers \(w_x, w_y, w_phi\)"),
    (_sweep([]), r"^w_phi must be a non-empty 1-D array"),
    (_sweep([[0.1, 0.2]]), r"^w_phi must be a non-empty 1-D array"),
    (_sweep([np.nan]), r"^w_phi must be a non-empty 1-D array"),
    (_sweep([-1.0]), r"^w_phi must be a non-empty 1-D array"),
    (_limit(w_max=True), r"^w_max must be a finite number above 0.0001"),
    (_limit(w_max=np.array([10.0])), r"^w_max must be a finite number above 0.0001"),
    (_limit(w_max=float("inf")), r"^w_max must be a finite number above 0.0001"),
    (_limit(w_max=1e-4), r"^w_max must be a finite number above 0.0001"),   # the first step: not above
    (_limit(rtol=0.0), r"^rtol must be a finite number above 0"),
    (_limit(rtol=True), r"^rtol must be a finite number above 0"),
    (_limit(rtol=0.1), r"^rtol must be below 0.1"),
    (_error_weight(level=0.0), r"^level must be a positive finite number"),
    (_error_weight(level=True), r"^level must be a positive finite number"),
    (_error_weight(level=np.array([0.2])), r"^level must be a positive finite number"),
    (_error_weight(level=float("inf")), r"^level must be a positive finite number"),
    (_error_weight(w_max=0.0), r"^w_max must be a positive finite number"),
    (_error_weight(rtol=-1e-6), r"^rtol must be a positive finite number"),
], ids=["t-bool", "t-array", "t-nan", "y-0d", "y-5", "steady-t-bool", "steady-t-array", "weights-nan",
        "weights-neg", "w_phi-empty", "w_phi-2d", "w_phi-nan", "w_phi-neg",
        "w_max-bool", "w_max-array", "w_max-inf", "w_max-first-step", "rtol-0", "rtol-bool", "rtol-0.1",
        "level-0", "level-bool", "level-array", "level-inf", "ew-w_max", "ew-rtol"])
def test_circle_functions_name_a_bad_argument(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_rotating_field_takes_one_state_or_any_batch_of_them():
    st = C.circle_steady_state(BODY, GAINS, R, THETA, (1.0, 1.0, 0.5))
    one = C.rotating_field(BODY, GAINS, R, THETA, (1.0, 1.0, 0.5), st.state)
    assert one.shape == (6,)
    # accuracy: the steady state is Newton's to a residual of 1e-13 (measured 2e-16)
    assert np.max(np.abs(one)) < 1e-12
    batch = C.rotating_field(BODY, GAINS, R, THETA, (1.0, 1.0, 0.5), np.broadcast_to(st.state, (3, 2, 6)))
    assert batch.shape == (3, 2, 6)
    np.testing.assert_allclose(batch, np.broadcast_to(one, (3, 2, 6)), rtol=0, atol=1e-12)  # measured 0: the same formulas on each state


# ------------------------------------------------------------------ weighting.circle: the real limit

def test_weight_limit_called_directly_returns_its_steady_state_tolerance_and_eigenvalue():
    # the module's own tests read the limit through a module-scoped fixture, which mutmut
    # credits to the first test only; this one calls it and checks every field
    lim = C.circle_weight_limit(BODY, GAINS, R, THETA)
    assert lim.kind == "complex pair" and round(lim.w_phi, 3) == 3.130       # Chapter 6's value
    assert lim.rtol == 1e-6  # exact: the default, returned as given
    assert lim.steady.weights == (1.0, 1.0, lim.w_phi)
    assert lim.eigenvalue == lim.steady.eigenvalues[0]
    # accuracy: brentq to xtol rtol / 4 in log w_phi, where Re lambda changes by 1.05 per unit
    # (measured), so |Re lambda| <= 2.6e-7; reason: Im > 0.05 is a property (measured 0.19)
    assert abs(lim.eigenvalue.real) < 1e-6 and abs(lim.eigenvalue.imag) > 0.05
    again = C.circle_steady_state(BODY, GAINS, R, THETA, (1.0, 1.0, lim.w_phi))
    # accuracy: both are Newton's to a residual of 1e-13 times |J^-1| = 19 (measured 1e-15)
    assert np.max(np.abs(again.state - lim.steady.state)) < 1e-10
    below = C.circle_steady_state(BODY, GAINS, R, THETA, (1.0, 1.0, lim.w_phi * (1 - 1e-5)))
    above = C.circle_steady_state(BODY, GAINS, R, THETA, (1.0, 1.0, lim.w_phi * (1 + 1e-5)))
    assert below.max_real < 0 < above.max_real


# ------------------------------------------------------------------ weighting.circle: synthetic spectra and branches

def _spectrum(monkeypatch, eigenvalues):
    """Replace the linearisation's eigenvalues at weight w_phi by ``eigenvalues(w_phi)`` (the
    equilibria stay the real loop's)."""
    real = C._state

    def state(loop, Theta, R_, x, weights, t=0.0):
        st = real(loop, Theta, R_, x, weights, t)
        lam = np.asarray(eigenvalues(weights[2]), dtype=complex)
        return dataclasses.replace(st, eigenvalues=lam[np.lexsort((-lam.imag, -lam.real))])

    monkeypatch.setattr(C, "_state", state)


def _branch_ends(monkeypatch, w_end):
    """No equilibrium on the branch above w_phi = ``w_end`` (a fold there)."""
    real_loop, real_solve, weight = C._loop, C._solve, {}

    def loop(body, gains, R_, Theta, weights):
        lp = real_loop(body, gains, R_, Theta, weights)
        weight[id(lp)] = (lp, weights[2])            # the loop kept alive: its id is not reused
        return lp

    def solve(lp, Theta, guess, t=0.0):
        return None if weight[id(lp)][1] > w_end else real_solve(lp, Theta, guess, t)

    monkeypatch.setattr(C, "_loop", loop)
    monkeypatch.setattr(C, "_solve", solve)


def _real_crossing(w_c):
    return lambda w: [w - w_c, -1.0, -2.0, -3.0, -4.0, -5.0]


def _pair_crossing(w_c, imag):
    return lambda w: [complex(w - w_c, imag), complex(w - w_c, -imag), -1.0, -2.0, -3.0, -4.0]


@pytest.mark.parametrize("w_c", [1.7, 3e-5])
def test_weight_limit_finds_a_real_eigenvalue_crossing_where_it_is(monkeypatch, w_c):
    # 3e-5 lies below the first step of the continuation (1e-4): brentq's bracket then reaches
    # 50 units of log w_phi below it
    _spectrum(monkeypatch, _real_crossing(w_c))
    lim = C.circle_weight_limit(BODY, GAINS, R, THETA)
    assert lim.kind == "real eigenvalue crossing"
    assert abs(math.log(lim.w_phi / w_c)) < lim.rtol  # accuracy: brentq's xtol rtol / 4 in log w_phi
    assert lim.eigenvalue == lim.steady.eigenvalues[0] and lim.eigenvalue.imag == 0
    assert abs(lim.eigenvalue.real) < 1e-5  # accuracy: Re lambda = w - w_c, w to rtol 1e-6 relative
    assert lim.steady.weights == (1.0, 1.0, lim.w_phi) and lim.rtol == 1e-6  # exact: the default


@pytest.mark.parametrize("imag", [0.3, 1e-7])
def test_weight_limit_calls_a_crossing_with_an_imaginary_part_a_complex_pair(monkeypatch, imag):
    # the docstring's rule: complex when |Im| > 1e-6 |lambda| + 1e-9 (1/s); 1e-7 is above it
    _spectrum(monkeypatch, _pair_crossing(1.7, imag))
    lim = C.circle_weight_limit(BODY, GAINS, R, THETA)
    assert lim.kind == "complex pair"
    assert abs(math.log(lim.w_phi / 1.7)) < lim.rtol  # accuracy: brentq's xtol rtol / 4 in log w_phi
    assert abs(lim.eigenvalue.imag) == imag  # exact: the synthetic spectrum's value


def test_weight_limit_searches_no_further_than_w_max(monkeypatch):
    # the continuation's steps from 1e-4 by 1.25 pass 0.752 then 0.940; with w_max = 0.9 the
    # last step is cut to 0.9 and a crossing at 0.92 lies beyond the search
    _spectrum(monkeypatch, _real_crossing(0.92))
    with pytest.raises(RuntimeError, match=r"stays stable up to w_max = 0\.9$"):
        C.circle_weight_limit(BODY, GAINS, R, THETA, w_max=0.9)
    assert C.circle_weight_limit(BODY, GAINS, R, THETA, w_max=0.95).kind == "real eigenvalue crossing"


def test_weight_limit_refuses_a_motion_unstable_at_zero_weight(monkeypatch):
    _spectrum(monkeypatch, lambda w: [0.5, -1.0, -2.0, -3.0, -4.0, -5.0])
    with pytest.raises(ValueError, match=r"not stable at w_phi = 0 \(max Re = 0\.5 1/s\)"):
        C.circle_weight_limit(BODY, GAINS, R, THETA)


@pytest.mark.parametrize("w_end", [0.5, 2e-5])
def test_weight_limit_reports_a_fold_at_the_last_weight_with_an_equilibrium(monkeypatch, w_end):
    # 2e-5 lies below the first step (1e-4): the step is halved from there
    _branch_ends(monkeypatch, w_end)
    lim = C.circle_weight_limit(BODY, GAINS, R, THETA)
    assert lim.kind == "fold" and lim.w_phi <= w_end
    assert w_end / lim.w_phi - 1 < lim.rtol  # exact: the step is halved until it is below rtol
    assert lim.rtol == 1e-6 and lim.steady.weights == (1.0, 1.0, lim.w_phi)  # exact: as given
    assert isinstance(lim.eigenvalue, complex) and lim.eigenvalue == lim.steady.eigenvalues[0]
    assert lim.steady.stable


# ------------------------------------------------------------------ weighting.circle: the error weight and the sweep

def test_error_weight_below_the_first_step_of_the_continuation():
    # the level reached at w_phi = 5e-5, below the first step (1e-4): the bracket then reaches 50
    # units of log w_phi below the first step
    level = C.circle_steady_state(BODY, GAINS, R, THETA, (1.0, 1.0, 5e-5)).position_error
    w = C.circle_error_weight(BODY, GAINS, R, THETA, level)
    assert abs(math.log(w / 5e-5)) < 2e-6  # accuracy: brentq's xtol rtol / 4 in log w_phi, and the level's own error


def test_error_weight_searches_no_further_than_w_max():
    level = C.circle_steady_state(BODY, GAINS, R, THETA, (1.0, 1.0, 1.5)).position_error
    with pytest.raises(RuntimeError, match=r"stays below .* up to w_max = 1$"):
        C.circle_error_weight(BODY, GAINS, R, THETA, level, w_max=1.0)
    w = C.circle_error_weight(BODY, GAINS, R, THETA, level, w_max=2.0)
    assert abs(math.log(w / 1.5)) < 2e-6  # accuracy: brentq's xtol rtol / 4 in log w_phi, and the level's own error


def test_error_weight_stops_where_the_branch_ends(monkeypatch):
    _branch_ends(monkeypatch, 0.5)
    with pytest.raises(RuntimeError, match=r"branch ends near w_phi = .* before its position error reaches 1 m"):
        C.circle_error_weight(BODY, GAINS, R, THETA, 1.0)


def test_steady_state_past_the_end_of_the_branch_says_so(monkeypatch):
    _branch_ends(monkeypatch, 0.5)
    with pytest.raises(RuntimeError, match=r"^no steady state on the branch from w_phi = 0 at weights "
                                           r"\(1\.0, 1\.0, 0\.7\): the continuation in w_phi failed before it \(a fold\)$"):
        C.circle_steady_state(BODY, GAINS, R, THETA, (1.0, 1.0, 0.7))


def test_sweep_rows_are_the_steady_states_and_nan_past_the_end_of_the_branch(monkeypatch):
    columns = ["w_phi", "radial", "tangential", "position_error", "heading", "max_real", "max_imag", "stable"]
    one = C.circle_weight_sweep(BODY, GAINS, R, THETA, [0.5])          # a single weight is a sweep too
    assert one.columns.tolist() == columns and len(one) == 1
    _branch_ends(monkeypatch, 0.5)
    d = C.circle_weight_sweep(BODY, GAINS, R, THETA, [0.2, 0.7, 0.0, 0.9])
    assert d.columns.tolist() == columns
    assert d.w_phi.tolist() == [0.2, 0.7, 0.0, 0.9] and d.stable.tolist() == [True, False, True, False]
    for i in (1, 3):                                   # past the end: every value NaN, not stable
        assert d.iloc[i].drop(["w_phi", "stable"]).isna().all() and d.stable[i] is np.False_
    for i, w in ((0, 0.2), (2, 0.0)):
        st = C.circle_steady_state(BODY, GAINS, R, THETA, (1.0, 1.0, w))
        got = d.iloc[i]
        # exact: one code path, the same continuation to the same weight
        assert (got.radial, got.tangential, got.position_error, got.heading, got.max_real) == \
            (st.radial, st.tangential, st.position_error, st.heading, st.max_real)
        assert got.max_imag == abs(st.eigenvalues[0].imag) and got.stable == st.stable


# ------------------------------------------------------------------ paper.report: the rows' format

def test_report_rows_are_written_in_the_reports_format():
    # the key names the row in the notebooks' calls (report.outcome("fig5")), the paper's item
    # opens with the item's kind and number as the paper prints it (equation_numbers reads the
    # numbers from there), the section is a chapter page
    import re

    from lib.paper import report
    from lib.paper.outcomes import STATUSES

    rows = report.items()
    assert len({r.key for r in rows}) == len(rows) == 46   # Fig. 5's map beside its row; Ch. 8's margins, entry
    for r in rows:
        assert re.fullmatch(r"[a-z0-9]+(-[a-z0-9]+)*", r.key), r.key
        assert re.match(r"(Eqs?\. \(\d+\)|Secs?\. \d|Fig\. \d|Theorem \d|Table of parameters)", r.paper), r.paper
        assert re.fullmatch(r"chapters/0[1-8]_[a-z]+", r.section), r.section
        assert r.expected in STATUSES and callable(r.check)


# ------------------------------------------------------------------ paper errata: the rows' format

def test_errata_rows_are_written_in_the_errata_format():
    # built here by each module's _errata(), not read from its ROWS (made once at import): the
    # key names the row in errata.verdict(key) and in the report's links, `where` opens with the
    # paper's item as printed, the section is a chapter page, and the equations a row corrects
    # are among those its `where` names (the report's legend reads them: errata_on)
    import re

    from lib.paper import errata, report

    rows = [r for module in errata.SOURCES for r in module._errata()]
    assert [r.key for r in rows] == [r.key for r in errata.rows()] and len({r.key for r in rows}) == len(rows)
    for r in rows:
        assert re.fullmatch(r"[a-z][a-z0-9]*(-[a-zA-Z0-9]+)*", r.key), r.key      # one has an N: N's arguments
        assert re.match(r"(Eqs?\. \(\d+\)|Secs?\. \d|Theorem \d)", r.where), r.where
        assert re.fullmatch(r"chapters/0[1-8]_[a-z]+", r.section), r.section
        assert all(isinstance(k, int) for k in r.equations) and set(r.equations) <= report.equation_numbers(r.where), r.key
        assert r.printed.strip() and r.corrected.strip() and r.verified_by.strip() and callable(r.check)
        assert isinstance(r.notation, bool)


# ------------------------------------------------------------------ paper.extensions: the weight-limit row

@pytest.mark.parametrize("below, above, status", [
    (-1e-3, 1e-3, "extended"),
    (0.0, 1e-3, "not reproducible"),          # not strictly stable below the limit
    (-1e-3, 0.0, "not reproducible"),         # not unstable above it
])
def test_weight_limit_row_asks_for_the_papers_circle_just_either_side_of_the_limit(monkeypatch, below, above, status):
    # the row is about the paper's circle (Table body and gains, R = 2 m, Theta = pi/4) with
    # w_x = w_y = 1, and its clauses are strict: stable (Re < 0) within 1 % below the limit,
    # unstable (Re > 0) within 1 % above
    from types import SimpleNamespace

    from lib.paper import extensions as ext

    w, asked = 3.13, []

    def limit(body, gains, R_, Theta):
        asked.append(("limit", body, gains, R_, Theta))
        return SimpleNamespace(w_phi=w, kind="complex pair")

    def steady(body, gains, R_, Theta, weights):
        asked.append(("steady", body, gains, R_, Theta, tuple(weights[:2])))
        growth = below if weights[2] < w else above
        assert 0.98 * w <= weights[2] <= 1.02 * w, weights      # just either side of the limit
        return SimpleNamespace(eigenvalues=np.array([growth, -1.0]))

    monkeypatch.setattr(ext, "circle_weight_limit", limit)
    monkeypatch.setattr(ext, "circle_steady_state", steady)
    out = [i for i in ext.items() if i.key == "weight-limit"][0].check()
    assert out.status == status and out.merit == w and out.merit_label and out.note
    assert asked[0] == ("limit", Body(), Gains(), 2.0, math.pi / 4)
    assert asked[1:] == [("steady", Body(), Gains(), 2.0, math.pi / 4, (1.0, 1.0))] * 2


# ------------------------------------------------------------------ weighting.circle: the solver's Newton polish

def _rough_root(shift, success):
    """scipy's root, then its answer moved by ``shift`` (m, m, rad) and its success flag set."""
    from scipy.optimize import root as real_root

    def rough(g, x0, method, tol):
        sol = real_root(g, x0, method=method, tol=tol)
        sol.x, sol.success = sol.x + shift, success
        return sol
    return rough


def test_solver_polishes_a_rough_root_by_newton_and_refuses_a_failed_one(monkeypatch):
    # hybr at tol 1e-14 always lands below the polish's 1e-13 on the real loop, so the Newton
    # polish never runs there; here the root comes back 1e-6 off
    loop = C._loop(BODY, GAINS, R, THETA, (1.0, 1.0, 1.0))
    guess = C._start(BODY, R, THETA)
    exact = C._solve(loop, THETA, guess)
    monkeypatch.setattr(C, "root", _rough_root(1e-6, True))
    x = C._solve(loop, THETA, guess)
    # accuracy: Newton from 1e-6 converges quadratically in 3 steps (difference Jacobian, step
    # 1e-6) to the polish's residual 1e-13 times |J^-1| = 19 (measured 2e-16)
    assert x is not None and np.max(np.abs(x - exact)) < 1e-11
    monkeypatch.setattr(C, "root", _rough_root(1e-6, False))
    assert C._solve(loop, THETA, guess) is None          # failed, and its residual above 1e-11
    monkeypatch.setattr(C, "root", _rough_root(0.0, False))
    x = C._solve(loop, THETA, guess)                      # "failed", but its residual below 1e-11
    assert x is not None and np.max(np.abs(x - exact)) < 1e-11  # accuracy: as above


def test_sweep_columns_do_not_depend_on_which_row_comes_first(monkeypatch):
    # a weight past the end of the branch given first: its row still has every column, in order
    _branch_ends(monkeypatch, 0.5)
    d = C.circle_weight_sweep(BODY, GAINS, R, THETA, [0.7, 0.2])
    assert d.columns.tolist() == ["w_phi", "radial", "tangential", "position_error", "heading", "max_real",
                                  "max_imag", "stable"]


def test_sweep_max_imag_is_that_of_the_leading_eigenvalue(monkeypatch):
    # a real leading eigenvalue with a complex pair behind it: max_imag is 0, not the pair's
    _spectrum(monkeypatch, lambda w: [w - 0.8, complex(-1.0, 0.5), complex(-1.0, -0.5), -2.0, -3.0, -4.0])
    d = C.circle_weight_sweep(BODY, GAINS, R, THETA, [0.5])
    assert d.max_imag[0] == 0.0 and d.max_real[0] == 0.5 - 0.8  # exact: the synthetic spectrum's values


def test_circle_checks_name_the_bad_type_and_each_gain_and_size():
    with pytest.raises(TypeError, match=r"^body must be a lib.params.Body, got str$"):
        C.circle_steady_state("body", GAINS, R, THETA)
    with pytest.raises(TypeError, match=r"^gains must be a lib.params.Gains, got str$"):
        C.circle_steady_state(BODY, "gains", R, THETA)
    equal = r"^the circle's steady motion needs equal gains on x and y .* not autonomous in the rotating frame$"
    for bad in (Gains(kp=(5.2, 5.0, 5.2)), Gains(kv=(3.2, 3.0, 3.2))):     # x and y unequal: kp, then kv
        with pytest.raises(ValueError, match=equal):
            C.circle_steady_state(BODY, bad, R, THETA)
    # the heading's gains (third components) may differ: (23)'s phi row is not allocated
    free = C.circle_steady_state(BODY, Gains(kp=(5.2, 5.2, 1.0), kv=(GAINS.kv[0],) * 2 + (1.0,)), R, THETA)
    assert free.eigenvalues.shape == (6,)
    for v in (True, np.array([1.0, 2.0])):                  # a bool, an array: each clause of the size check
        with pytest.raises(ValueError, match=r"^R must be a positive finite number"):
            C.circle_steady_state(BODY, GAINS, v, THETA)
        with pytest.raises(ValueError, match=r"^Theta must be a positive finite number"):
            C.circle_steady_state(BODY, GAINS, R, v)


def test_steady_state_eigenvalues_put_a_pairs_positive_imaginary_part_first():
    # at w_phi = 3, just below the limit, the two leading pairs are complex
    lam = C.circle_steady_state(BODY, GAINS, R, THETA, (1.0, 1.0, 3.0)).eigenvalues
    assert np.all(np.diff(lam.real) <= 0)
    for k in (0, 2):
        assert lam[k].imag > 0.1 and lam[k + 1] == np.conj(lam[k])   # exact: eigvals returns exact conjugates


def test_solver_refuses_a_point_the_polish_cannot_bring_to_a_root(monkeypatch):
    # scipy's root "succeeds" 1e-6 off, and a Jacobian ten times too steep makes Newton's three
    # steps shrink the residual by 0.9 each: about 7e-7, above the final refusal's 1e-9
    loop = C._loop(BODY, GAINS, R, THETA, (1.0, 1.0, 1.0))
    guess = C._start(BODY, R, THETA)
    monkeypatch.setattr(C, "root", _rough_root(1e-6, True))
    real_jacobian = C._jacobian
    monkeypatch.setattr(C, "_jacobian", lambda *a, **kw: 10.0 * real_jacobian(*a, **kw))
    assert C._solve(loop, THETA, guess) is None
