"""The one decision procedure (lib.dynamics.verdicts): each step and each definition at
its boundary, on inputs whose answer is known without the procedure."""

import math

import numpy as np
import pandas as pd
import pytest

from lib.limits import verdicts as limits
from lib.weighting import verdicts as loop_verdicts
from lib.rotation import verdicts as rotation_verdicts
from lib import stability
from lib.angles import wrap_angle
from lib.dynamics import statistics
from lib.rotation.circle import circle_critical_radius, circle_eigenvalues
from lib.dynamics import verdicts as dv
from lib.dynamics.orbits import newton_orbit
from lib.params import Body
from lib.rotation.engine import RotationMap, _Engine
from lib.rotation.field import coefficients

BODY = Body()


# ---------------------------------------------------------------- the rule, at its boundaries

@pytest.mark.parametrize("factor, regime", [(1.001, "chaotic"), (0.999, "undecided")])
def test_chaotic_needs_the_exponent_three_standard_errors_above_zero(factor, regime):
    # lambda T = 0.05 clears the band (0.01); it is chaotic exactly when it clears 3 SE too
    lam = 0.05
    se = lam / (dv.SIGMAS * factor)
    got, reason = dv.classify([lam], [se], [np.inf], band=0.01, return_tol=0.05, max_period=8)
    assert got[0] == regime
    assert (reason[0] == "") == (regime == "chaotic")


def test_one_standard_error_is_not_enough_for_chaos():
    # 2.1 sigma (the point a 1-sigma rule would call chaotic) stays undecided
    got, _ = dv.classify([0.021], [0.01], [np.inf], band=0.01, return_tol=0.05, max_period=8)
    assert got[0] == "undecided"


@pytest.mark.parametrize("lam, regime", [(0.0101, "chaotic"), (0.0099, "quasiperiodic")])
def test_the_band_separates_chaos_from_a_zero_exponent(lam, regime):
    # a tiny standard error: only the band decides; a closed section makes the zero quasi-periodic
    got, _ = dv.classify([lam], [1e-5], [0.01], band=0.01, return_tol=0.05, max_period=8)
    assert got[0] == regime


@pytest.mark.parametrize("se, returns, regime", [
    (0.0033, 0.01, "quasiperiodic"),     # SE <= band / 3, section closed
    (0.0034, 0.01, "undecided"),         # SE just above band / 3
    (0.0010, 0.06, "undecided"),         # section does not return within 0.05
])
def test_quasiperiodic_needs_a_resolved_zero_and_a_closed_section(se, returns, regime):
    got, reason = dv.classify([0.0], [se], [returns], band=0.01, return_tol=0.05, max_period=8)
    assert got[0] == regime
    if regime == "undecided" and returns > 0.05:
        assert "does not return" in reason[0]


def test_a_contracting_run_without_an_orbit_is_undecided_and_says_so():
    got, reason = dv.classify([-0.2], [0.01], [np.inf], band=0.01, return_tol=0.05, max_period=8)
    assert got[0] == "undecided" and reason[0].startswith("contracting")


@pytest.mark.parametrize("drift, se, lost", [(0.0, 0.0, False), (0.0041, 0.001, True), (0.0039, 0.001, False),
                                             (-0.5, 0.01, True)])
def test_heading_lost_when_it_drifts_by_more_than_three_errors_plus_the_band(drift, se, lost):
    # no orbit, range within a turn: lost iff |drift| > 3 SE + slip_band (1e-3 turns per period)
    got = dv.heading_lost([False], [0], [drift], [se], slip_band=1e-3)
    assert bool(got[0]) is lost


def test_heading_lost_on_an_orbit_exactly_when_it_slips():
    got = dv.heading_lost([True, True], [0, -1], [np.nan, np.nan], [np.nan, np.nan], slip_band=1e-3)
    assert got.tolist() == [False, True]


def test_a_swing_over_a_turn_that_comes_back_is_not_lost_but_turns_round():
    # no drift, a range of 3 pi: held by the one definition, counted by the other reading
    assert not dv.heading_lost([False], [0], [0.0], [1e-4], slip_band=1e-3)[0]
    assert dv.turns_round([3 * np.pi, 6.28]).tolist() == [True, False]


def test_every_flow_names_the_regimes_of_the_one_procedure():
    assert rotation_verdicts.REGIMES is dv.REGIMES
    assert stability.REGIMES is dv.REGIMES
    assert loop_verdicts.dv is dv and limits.dv is dv


# ---------------------------------------------------------------- statistics

def test_block_statistics_are_the_mean_and_error_of_the_block_means():
    rng = np.random.default_rng(1)
    v = rng.normal(0.3, 1.0, size=(3, 50))          # 4 blocks of 12, the first 2 periods dropped
    mean, se = dv.block_statistics(v, 12)
    for i in range(3):
        means = [v[i, 2 + 12 * b: 2 + 12 * (b + 1)].mean() for b in range(4)]
        assert mean[i] == pytest.approx(np.mean(means), rel=1e-14, abs=0)  # exact: one formula on given numbers; measured 0
        assert se[i] == pytest.approx(np.std(means, ddof=1) / 2.0, rel=1e-14, abs=0)  # exact: one formula on given numbers; measured 0
    with pytest.raises(ValueError, match="two blocks"):
        dv.block_statistics(v[:, :20], 12)


def test_drift_of_a_steady_slip_is_its_rate_with_zero_error():
    # a heading gaining 0.25 turns per period, sampled at the ends of blocks of 6 periods
    ends = 2 * np.pi * 0.25 * 6 * np.arange(9.0)
    drift, se = dv.drift_statistics(ends[None], 6, 2 * np.pi)
    assert drift[0] == pytest.approx(0.25, rel=1e-14, abs=0) and se[0] == pytest.approx(0.0, abs=1e-14)  # exact: one formula on given numbers; measured 0 and 2.6e-17


# ---------------------------------------------------------------- orbits

def _two_cycle(n_periods, turns_per_period=0):
    """Sections of a period-2 motion: x alternates between 0.3 and -0.3, the heading gains
    ``turns_per_period`` whole turns a period."""
    j = np.arange(n_periods)
    x = 0.3 * (-1.0) ** j
    phi = 2 * np.pi * turns_per_period * j + 0.1
    return np.stack([phi, x], axis=-1)[:, None, :]


@pytest.mark.parametrize("turns", [0, 1])
def test_lag_candidates_find_the_period_and_its_turns(turns):
    ok, n, defect = dv.lag_candidates(_two_cycle(17, turns), 8, 1e-9, turn_axis=0)
    assert ok[:, 0].tolist() == [False, True, False, True, False, True, False, True]
    assert n[1, 0] == 2 * turns
    assert defect[0, 0] == pytest.approx(0.6, abs=1e-15)  # exact: a difference of given numbers; measured 0
    blocked, _, _ = dv.lag_candidates(_two_cycle(17, turns), 8, 1e-9, turn_axis=0, turns=False)
    assert blocked[1, 0] == (turns == 0)


def test_reached_asks_the_approach_to_be_as_fast_as_the_slowest_multiplier():
    rho, k, m = 0.5, 1, 16
    d_then = 1e-2
    on_time = d_then * rho ** m
    assert dv.reached([on_time], [d_then], [rho], m / k, tol=0.05, floor=1e-12)[0]
    # ten times too slow for |mu| = 0.5: not reached, however small the distance
    assert not dv.reached([10 * 3 * on_time], [d_then], [rho], m / k, tol=0.05, floor=1e-12)[0]
    assert not dv.reached([0.06], [0.07], [0.999], m / k, tol=0.05, floor=1e-12)[0]     # beyond tol
    assert dv.reached([1e-13], [1e-13], [0.999], m / k, tol=0.05, floor=1e-12)[0]       # on it


def test_least_period_reduces_a_fixed_point_found_through_its_second_power():
    x = np.array([[0.5, 0.0]])
    pts = np.stack([x + [2 * np.pi, 0.0], x + [4 * np.pi, 0.0]])          # P(x) = x + 2 pi e_0
    k, n = dv.least_period(x, pts, np.array([2]), np.array([2]), turn_axis=0, tol=1e-9)
    assert (k[0], n[0]) == (1, 1)
    k, n = dv.least_period(x, pts, np.array([2]), np.array([2]), turn_axis=0, turns=False, tol=1e-9)
    assert (k[0], n[0]) == (2, 2)


def test_newton_finds_the_fixed_point_of_a_contraction_and_its_turns():
    # P(x) = (x0 + 2 pi + 0.5 sin x0 ... ): a standard-map-like step with a known fixed point at x0 = 0
    def step(idx, x, k):
        y = np.column_stack([x[:, 0] + 2 * np.pi + 0.5 * np.sin(x[:, 0]) + 0.1 * x[:, 1], 0.5 * x[:, 1]])
        J = np.zeros((x.shape[0], 2, 2))
        J[:, 0, 0], J[:, 0, 1], J[:, 1, 1] = 1 + 0.5 * np.cos(x[:, 0]), 0.1, 0.5
        return y, J

    r = dv.newton(step, np.arange(2), np.array([[0.4, 0.2], [-0.3, -0.1]]), 1, turn_axis=0, tol=1e-13,
                  max_iter=30)
    assert np.all(r.residual <= 1e-13)  # exact: the stopping rule itself; reason: the stopping tolerance given to newton above
    # accuracy: residual <= tol = 1e-13 times |(J - I)^-1| at 0 (J - I = [[0.5, 0.1], [0, -0.5]]:
    # 2.2), 2.2e-13: the floor (measured 6.0e-16)
    assert np.allclose(r.x, 0.0, rtol=0, atol=1e-12) and r.turns.tolist() == [1, 1]
    assert np.all(r.iterations >= 2)


def test_difference_jacobian_is_the_exact_jacobian_of_the_rotation_map():
    eng = _Engine("eight", 128, "numba")
    A, B, C = coefficients(BODY, np.array([2.0, 1.0]), np.array([np.pi / 4, 1.2]))
    rmap = RotationMap(eng, A, B, C)
    x = np.array([[0.3, 1.1], [2.0, -0.4]])
    y_exact, J_exact = rmap.step(np.arange(2), x, 1)
    y_fd, J_fd = dv.difference_jacobian(rmap, np.arange(2), x, 1, 1e-7)
    assert np.array_equal(y_fd, y_exact)
    # forward differences: error ~ h |P''| (measured 1.8e-7 at h = 1e-7)
    assert np.abs(J_fd - J_exact).max() < 2e-6 * max(1.0, np.abs(J_exact).max())  # measured 1.8e-7


def test_the_circles_equilibrium_has_the_exponent_of_the_linearisation_34():
    # the verdict's exponent of an orbit, ln|mu_1| / (k T), in 1/s, against the largest real
    # part of the eigenvalues of (34): an independent route to the exponent and its scale
    theta = math.pi / 4
    R = 3.0 * circle_critical_radius(BODY, theta)
    frame = rotation_verdicts.rotation_verdicts(BODY, "circle", [R], [theta])
    assert frame.regime[0] == "periodic" and frame.period[0] == 1
    expected = circle_eigenvalues(BODY, R, theta).real.max()
    # accuracy: the verdict's multiplier comes from 128 steps of the 8th-order scheme a
    # period, whose error lies below the floor (measured 0)
    assert frame.lyapunov[0] == pytest.approx(expected, rel=1e-12)


def test_undecided_rows_are_decided_again_and_keep_their_place():
    import pandas as pd

    frame = pd.DataFrame({"regime": ["periodic", "undecided", "chaotic", "undecided"], "x": [1, 2, 3, 4]},
                         index=[10, 11, 12, 13])
    seen = {}

    def redo(rows, factor):
        seen.update(rows=rows.tolist(), factor=factor)
        return pd.DataFrame({"regime": ["periodic", "quasiperiodic"], "x": [20, 40]})

    out = dv.redecide_undecided(frame, 120, 8, redo)
    assert seen == {"rows": [1, 3], "factor": 8}
    assert out.regime.tolist() == ["periodic", "periodic", "chaotic", "quasiperiodic"]
    assert out.x.tolist() == [1, 20, 3, 40] and out.index.tolist() == [10, 11, 12, 13]
    assert out.horizon.tolist() == [120, 960, 120, 960]
    assert frame.regime.tolist()[1] == "undecided"            # the input is not changed


# ---------------------------------------------------------------- the boundaries of each definition
# (the mutation run of lib/dynamics/verdicts.py: mutation/REPORT.md). The numbers are exact in
# binary, so each comparison is tested at its boundary, where > and >= differ.

REASONS = {"zero": "Lyapunov exponent zero, but the section does not return near itself "
                   "(no closed curve: a slow transient or a bifurcation)",
           "unresolved": "Lyapunov exponent not resolved from zero"}


def test_classify_at_its_boundaries():
    band, tol = 0.75, 0.5
    # lambda T = 3 SE = band exactly: not chaotic (strictly above), and zero within the band
    # (|lambda T| <= band, SE = band / 3): quasi-periodic when the section returns within tol
    regime, reason = dv.classify([0.75, 0.75, 0.9, -0.75], [0.25, 0.25, 0.5, 0.25], [0.5, 0.6, 0.0, 1.0],
                                 band=band, return_tol=tol, max_period=4)
    assert list(regime) == ["quasiperiodic", "undecided", "undecided", "undecided"]
    # at -max(3 SE, band) exactly the run is not counted as contracting: it is a zero exponent
    assert list(reason) == ["", REASONS["zero"], REASONS["unresolved"], REASONS["zero"]]
    regime, reason = dv.classify([-0.7501], [0.25], [1.0], band=band, return_tol=tol, max_period=4)
    assert regime[0] == "undecided" and reason[0] == "contracting, but no attracting orbit of period <= 4 reached"


def test_heading_lost_at_three_errors_plus_the_band_exactly():
    # a drift of exactly 3 SE + band is not lost (strictly beyond), nor on an orbit without turns
    lost = dv.heading_lost([False, False, True], [0, 0, 0], [1.0, -1.0000001, 5.0], [0.25, 0.25, 0.0],
                           slip_band=0.25)
    assert lost.tolist() == [False, True, False]


def test_drift_and_its_error_are_those_of_the_block_increments():
    # increments 1, 2, 3, 4 per block of 2 periods, in units of 2: mean 2.5 / 4, and the
    # standard error std(ddof = 1) / sqrt(4) = 1.2910 / 2 / 4; a second row standing still
    ends = np.array([[0.0, 1.0, 3.0, 6.0, 10.0], [7.0] * 5])
    drift, se = dv.drift_statistics(ends, periods_per_block=2.0, unit=2.0)
    np.testing.assert_allclose(drift, [2.5 / 4, 0.0], rtol=1e-15, atol=0)  # exact: one formula on given numbers; measured 0
    np.testing.assert_allclose(se, [np.std([1, 2, 3, 4], ddof=1) / 2 / 4, 0.0], rtol=1e-15, atol=0)  # exact: one formula on given numbers; measured 0


def test_block_statistics_need_two_blocks_and_take_the_last_complete_ones():
    # 5 periods in blocks of 2: the last 4 form 2 blocks (means 2.5 and 4.5), the first is dropped
    mean, se = dv.block_statistics(np.array([[100.0, 2.0, 3.0, 4.0, 5.0]]), 2)
    assert mean[0] == 3.5 and se[0] == pytest.approx(np.std([2.5, 4.5], ddof=1) / np.sqrt(2), rel=1e-15)  # exact: one formula on given numbers; measured 0
    with pytest.raises(ValueError, match="two blocks"):
        dv.block_statistics(np.ones((1, 3)), 2)


def test_held_is_periodic_not_lost_and_tracked():
    regime = ["periodic", "periodic", "periodic", "slipping", "chaotic"]
    assert dv.held(regime, [False, True, False, False, False], [True, True, False, True, True]).tolist() == \
        [True, False, False, False, False]
    assert dv.held(regime, [False] * 5).tolist() == [True, True, True, False, False]  # no position: tracked


def test_a_single_undecided_row_is_decided_again():
    frame = pd.DataFrame({"regime": ["periodic", "undecided"], "x": [1.0, 2.0]}, index=[10, 11])
    seen = []

    def redo(rows, factor):
        seen.append((rows.tolist(), factor))
        return pd.DataFrame({"regime": ["chaotic"], "x": [-2.0]})

    out = dv.redecide_undecided(frame, 120, 8, redo)
    assert seen == [([1], 8)]
    assert out.regime.tolist() == ["periodic", "chaotic"] and out.x.tolist() == [1.0, -2.0]
    assert out.horizon.tolist() == [120, 960] and frame.regime.tolist() == ["periodic", "undecided"]


def test_section_returns_tell_a_closed_curve_from_a_slow_approach():
    L = 400
    k = np.arange(L)[:, None]
    rot = 2 * np.pi * (np.sqrt(5) - 1) / 2                           # an irrational rotation
    circle = np.stack([np.cos(k * rot), np.sin(k * rot)], axis=2)     # (L, 1, 2), fills a circle
    line = np.stack([0.97 ** k, 0.5 * 0.97 ** k], axis=2)             # slides along a line onto 0
    # the heading column wraps: a circle drawn across +-pi is still closed
    wrapped = np.stack([np.pi + 0.3 * np.cos(k * rot), 0.3 * np.sin(k * rot)], axis=2)
    r = dv.section_returns(np.concatenate([circle, line, wrapped], axis=1), angles=(0,))
    assert r[0] < 0.05 and r[2] < 0.05    # measured 5.7e-3 (both); 0.05 is the flows' return_tol
    assert r[1] == np.inf                 # reason: never comes back after leaving, by construction
    assert dv.section_returns(circle[:5]).tolist() == [np.inf]
    with pytest.raises(ValueError, match="shape"):
        dv.section_returns(np.zeros((10, 2)))


def test_enclosed_orbit_finds_an_attracting_or_repelling_fixed_point_inside_a_curve():
    # x -> c + A (x - c): a fixed point at c (heading column 0 at pi, reached across the
    # wrap) that attracts for A = 0.5 R and repels for A = 1.5 R, R a rotation
    c = np.array([np.pi, 0.2])
    rot = np.array([[np.cos(1.0), -np.sin(1.0)], [np.sin(1.0), np.cos(1.0)]])
    gains = np.array([0.5, 1.5])

    def step(idx, x, k):
        A = gains[np.asarray(idx)][:, None, None] * rot
        return c + np.einsum("mij,mj->mi", A, x - c), A

    t = np.linspace(0, 2 * np.pi, 40, endpoint=False)[:, None]
    curve = c + 0.3 * np.stack([np.cos(t), np.sin(t)], axis=2)       # (40, 1, 2) around c
    sec = np.concatenate([curve, curve], axis=1)
    sec[:, :, 0] = (sec[:, :, 0] + np.pi) % (2 * np.pi) - np.pi     # headings wrapped to (-pi, pi]
    attracting, mu = dv.enclosed_orbit(step, np.array([0, 1]), sec, turn_axis=0, newton_tol=1e-12,
                                       newton_options=dict(max_iter=10))
    assert attracting.tolist() == [True, False]
    # accuracy: the eigensolver's backward error, a few eps |A|, on a scaled rotation (normal:
    # condition 1): the floor (measured 0)
    np.testing.assert_allclose(mu, gains, rtol=1e-12)


# ---------------------------------------------------------------- find_orbits and its steps on a toy period map
# (the survivors of the first mutation run of lib/dynamics/verdicts.py, mutation/REPORT.md). The map's
# orbits, multipliers and turns are known in closed form, so every field find_orbits returns is
# checked against them; the heading is column 1, so that no step may assume it is column 0.

TWO_PI = 2 * np.pi


class ToyMap:
    """A period map with known orbits, one parameter set per row. Column 0: x; column 1: the
    heading phi (``turn_axis`` 1). phi' = phi + 2 pi s + (a - 1) g(phi - phi0), with g = sin
    (an angle: the map commutes with whole turns; phi0 attracts for |a| < 1, phi0 + pi repels)
    or g(u) = u (``angle`` False: a plain coordinate, one fixed point). x' = b x (mode 1: a fixed
    point at 0, multiplier b); x' = -h(x), h(x) = x - c (x^3 - q^2 x), c = (1 - b) / (2 q^2)
    (mode 2: a 2-cycle +-q, multiplier b^2 in x per two periods); x' = x + 1e-6 (2 + sin x)
    (mode 3: no fixed point, and DP - I singular only where cos x = 0 exactly). One period's
    multipliers are those of the diagonal Jacobian: b (or h', 1 + 1e-6 cos x) and 1 + (a - 1) g'."""

    turn_axis = 1

    def __init__(self, **rows):
        defaults = dict(s=0, a=0.5, b=0.25, mode=1, phi0=0.3, angle=True, q=0.3)
        self.p = {key: np.atleast_1d(rows.get(key, val)) for key, val in defaults.items()}

    def _one(self, idx, X):
        p = {key: v[idx] if v.size > 1 else np.repeat(v, len(idx)) for key, v in self.p.items()}
        x, phi = X[:, 0], X[:, 1]
        u = phi - p["phi0"]
        g, dg = np.where(p["angle"], np.sin(u), u), np.where(p["angle"], np.cos(u), 1.0)
        c = (1 - p["b"]) / (2 * p["q"] ** 2)
        xn = np.select([p["mode"] == 1, p["mode"] == 2], [p["b"] * x, -(x - c * (x ** 3 - p["q"] ** 2 * x))],
                       x + 1e-6 * (2 + np.sin(x)))
        dx = np.select([p["mode"] == 1, p["mode"] == 2], [p["b"] + 0 * x, -(1 - c * (3 * x ** 2 - p["q"] ** 2))],
                       1 + 1e-6 * np.cos(x))
        J = np.zeros((len(idx), 2, 2))
        J[:, 0, 0], J[:, 1, 1] = dx, 1 + (p["a"] - 1) * dg
        return np.column_stack([xn, phi + TWO_PI * p["s"] + (p["a"] - 1) * g]), J

    def step(self, idx, X, k):
        """P^k and DP^k (the chain rule), as newton wants them."""
        idx = np.asarray(idx)
        k = np.broadcast_to(np.asarray(k, dtype=int), (len(idx),))
        y, J = np.array(X, dtype=float), np.tile(np.eye(2), (len(idx), 1, 1))
        for j in range(int(k.max(initial=0))):
            act = k > j
            y[act], Jj = self._one(idx[act], y[act])
            J[act] = Jj @ J[act]
        return y, J

    def advance(self, idx, X, k):
        return self.step(idx, X, k)[0]

    def run(self, x0, L):
        """Sections (L, N, 2) of the runs of every row from the starts x0 (N, 2)."""
        out = [np.array(x0, dtype=float)]
        for _ in range(L - 1):
            out.append(self.advance(np.arange(len(out[0])), out[-1], 1))
        return np.stack(out)


OPTS = dict(max_period=4, candidate_tol=1e-3, newton_tol=1e-12, reach_tol=0.05, reach_floor=1e-9,
            newton_options=dict(max_iter=20))


def _find(pm, hist, **kw):
    return dv.find_orbits(pm.step, pm, np.arange(hist.shape[1]), hist, **{**OPTS, **kw})


def _standing(point, L):
    """A synthetic history: the same state at every section (L, 1, 2)."""
    return np.tile(np.asarray(point, dtype=float), (L, 1, 1))


def test_find_orbits_reports_the_orbits_runs_reach_with_their_period_turns_and_multipliers():
    # rows: 0 a fixed point (multipliers 0.5 heading, 0.25 x); 1 the same slipping a turn a period;
    # 2 a 2-cycle x = +-0.3 (multipliers of P^2: 0.6^2 heading, 0.5^2 x); 3 a slipping fixed point
    # the run alternates around (x' = -0.9 x): only lag 2 repeats, so it is found through P^2;
    # 4 an attracting fixed point the run stands 0.01 away from (not reached); 5 no repeat at all
    pm = ToyMap(s=[0, 1, 0, 1, 0, 0], a=[0.5, 0.5, 0.6, 0.5, 0.5, 0.5], b=[0.25, 0.25, 0.5, -0.9, 0.25, 0.25],
                mode=[1, 1, 2, 1, 1, 1], phi0=[0.3, 0.3, -0.4, 0.3, 0.3, 0.3])
    L = 13
    runs = pm.run([[0.01, 0.31], [0.01, 0.31], [0.31, -0.39], [2e-3 / 0.9 ** 11, 0.301], [0, 0], [0, 0]], L)
    runs[:, 4] = [0.01, 0.3]                                          # standing still, off the orbit
    runs[:, 5] = np.column_stack([0.1 * np.arange(L), np.full(L, 0.3)])   # drifting away
    before = runs.copy()
    out = _find(pm, runs)
    assert np.array_equal(runs, before)                              # the history is not changed
    assert out["found"].tolist() == [True, True, True, True, False, False]
    assert out["status"].tolist() == ["found"] * 4 + ["not reached", ""]
    assert out["k"].tolist() == [1, 1, 2, 1, 0, 0] and out["lag"].tolist() == [1, 1, 2, 2, 0, 0]
    assert out["n"].tolist() == [0, 1, 0, 1, 0, 0]
    assert all(out[f].dtype.kind == "i" for f in ("k", "lag", "n"))
    # exact: diagonal Jacobians, products of two numbers; rho: the largest |multiplier| of P^k for the least period k, |mu_1(P^lag)|^(k / lag)
    np.testing.assert_allclose(out["rho"][:4], [0.5, 0.5, 0.36, 0.9], rtol=1e-15, atol=0)  # measured 0
    np.testing.assert_allclose(out["floquet"][:5], [0.5, 0.5, 0.36, 0.81, 0.5], rtol=1e-15, atol=0)  # exact: diagonal Jacobians, products of two numbers; measured 0
    np.testing.assert_allclose(np.abs(out["mult"][:4]), [[0.5, 0.25], [0.5, 0.25], [0.36, 0.25], [0.81, 0.25]],
                               rtol=1e-15, atol=0)  # exact: diagonal Jacobians, products of two numbers; measured 0
    # the orbit point Newton found from the last state (the 2-cycle's point near it: +0.3)
    np.testing.assert_allclose(out["x"][:4, 0], [0, 0, 0.3, 0], rtol=0, atol=1e-16)  # exact: a linear map, Newton's step lands on the point to rounding; measured 1.1e-18
    np.testing.assert_allclose(wrap_angle(out["x"][:4, 1] - [0.3, 0.3, -0.4, 0.3]), 0, rtol=0,
                               atol=3e-13)  # exact: a linear map, to the rounding of a heading 24 pi out; measured 2.5e-14
    assert np.all(out["residual"][:4] <= 1e-12)   # reason: Newton's stopping tolerance (OPTS)
    # the distance of the last state to the orbit (the heading modulo whole turns), and the
    # orbit point it is nearest to
    orbit = np.array([[0, 0.3], [0, 0.3], [0.3, -0.4], [0, 0.3]])
    dd = runs[-1, :4] - orbit
    dd[:, 1] = wrap_angle(dd[:, 1])
    np.testing.assert_allclose(out["distance"][:4], np.abs(dd).max(axis=1), rtol=1e-8, atol=0)  # measured 1.5e-9
    assert out["distance"][3] > 1e-3              # reason: the alternating run is still 1.8e-3 away (0.9^12)
    np.testing.assert_allclose(out["near"][:4, 0], orbit[:, 0], rtol=0, atol=1e-16)  # exact: a given orbit point; measured 9.8e-19
    np.testing.assert_allclose(wrap_angle(out["near"][:4, 1] - orbit[:, 1]), 0, rtol=0,
                               atol=4e-14)  # exact: a given orbit point, to the rounding of the heading; measured 3.6e-15
    # rows without an orbit: every orbit field NaN, nothing left over from an attempt
    for f in ("rho", "x", "mult", "residual", "distance", "near"):
        assert np.isnan(out[f][4:]).all(), f
    assert np.isnan(out["floquet"][5])


def test_find_orbits_says_why_an_orbit_does_not_count_and_goes_on_to_longer_periods():
    # 0 a repelling fixed point (x' = 1.5 x) the run sits on; 1 a 2-cycle (found at lag 2 after
    # lag 1 gave nothing attracting); 2 no fixed point (Newton does not converge); 3 a neutral
    # heading (a = 1: |mu_1| = 1 exactly) is not attracting
    pm = ToyMap(a=[0.5, 0.6, 0.5, 1.0], b=[1.5, 0.5, 0.25, 0.25], mode=[1, 2, 3, 1], phi0=[0.3, -0.4, 0.3, 0.3])
    L = 13
    runs = pm.run([[0, 0.3], [0.31, -0.39], [1.0, 0.3], [0, 0.7]], L)
    out = _find(pm, runs)
    assert out["status"].tolist() == ["not attracting", "found", "not converged", "not attracting"]
    assert out["found"].tolist() == [False, True, False, False] and out["k"][1] == 2
    # floquet: the last attempt's, lag 4 for the repelling point (tried at every lag)
    np.testing.assert_allclose(out["floquet"][[0, 3]], [1.5 ** 4, 1.0], rtol=1e-15, atol=0)  # exact: diagonal Jacobians, products of numbers; measured 0
    assert np.isnan(out["floquet"][2])


def test_find_orbits_takes_the_earlier_distance_max_period_doubled_or_the_history_back():
    # the approach is judged from the state M = min(L - 1, 2 max_period) periods back (k = 1): the
    # runs stand 0.01 from the orbit, except one earlier state 2 pi away. Row 0: 2 pi in x (not an
    # angle); row 1: 2 pi in a heading that is a plain coordinate (turns False). Found exactly when
    # that state is the one M periods back.
    # Row 2: a whole turn in an angle heading is the same state: never found.
    pm = ToyMap(b=0.9, phi0=0.3, angle=[True, False, True])
    for L in (6, 12):
        M = min(L - 1, 2 * OPTS["max_period"])
        for shift in (0, 1, -1):
            if M + 1 - shift > L:
                continue
            runs = np.tile([[0.01, 0.3]] * 3, (L, 1, 1))
            runs[-1 - M + shift] += [[TWO_PI, 0], [0, TWO_PI], [0, TWO_PI]]
            out = _find(pm, runs, turns=[True, False, True])
            assert out["found"].tolist() == [shift == 0] * 2 + [False], (L, shift)
            assert out["status"].tolist() == ["found" if shift == 0 else "not reached"] * 2 + ["not reached"]


def test_find_orbits_on_a_short_history_and_max_period():
    # a 2-cycle from four sections: lag 2 at max_period 2, the earlier state two periods back
    pm = ToyMap(a=0.6, b=0.5, mode=2, phi0=-0.4)
    runs = pm.run([[0.3 + 1e-4, -0.4]], 4)
    out = _find(pm, runs, max_period=2)
    assert out["status"].tolist() == ["found"] and (out["k"][0], out["lag"][0]) == (2, 2)


def test_find_orbits_does_not_count_a_run_standing_off_its_orbit_by_a_whole_turn_in_a_plain_coordinate():
    # standing 2 pi from the orbit in x (row 0) or in a heading that is no angle (row 1, turns
    # False): far, not on it; row 2, the same in an angle heading, is on it
    pm = ToyMap(b=0.5, phi0=0.3, angle=[True, False, True])
    runs = np.tile([[TWO_PI, 0.3], [0, 0.3 + TWO_PI], [0, 0.3 + TWO_PI]], (8, 1, 1))
    out = _find(pm, runs, turns=[True, False, True], newton_options=dict(max_iter=20, max_step=10.0))
    assert out["status"].tolist() == ["not reached", "not reached", "found"]


def test_find_orbits_keeps_the_turns_the_history_shows_unless_told_otherwise():
    # the history gains a turn a period, the map does not slip: with the candidate's turns
    # (the default) there is no orbit; with free turns Newton finds the fixed point, n = 0
    pm = ToyMap(phi0=0.3)
    runs = np.stack([np.zeros(12), 0.3 + TWO_PI * np.arange(12)], axis=-1)[:, None]
    assert _find(pm, runs)["status"].tolist() == ["not converged"]
    out = _find(pm, runs, fixed_turns=False)
    assert out["status"].tolist() == ["found"] and (out["k"][0], out["n"][0]) == (1, 0)


def test_find_orbits_slips_only_where_turns_allow_it():
    pm = ToyMap(s=1)
    runs = pm.run([[0.01, 0.31], [0.01, 0.31]], 12)
    out = _find(pm, runs, turns=[True, False])
    assert out["status"].tolist() == ["found", ""] and out["n"][0] == 1


def test_find_orbits_needs_ends_repeating_states():
    # the section repeats exactly at the orbit but for the fourth state from the end: two
    # repeating ends (the default) find it; three do not (max_period 3: no lag avoids that state)
    pm = ToyMap()
    runs = _standing([0, 0.3], 8)
    runs[-4] = [0.5, 0.3]
    assert _find(pm, runs, max_period=3)["status"].tolist() == ["found"]
    assert _find(pm, runs, max_period=3, ends=3)["status"].tolist() == [""]


def test_find_orbits_counts_a_residual_at_newton_tol_as_converged():
    # x' = x / 2 from x = 2^-20, the heading on its fixed point, no Newton step: the residual is
    # 2^-21 exactly, equal to the tolerance
    pm = ToyMap(b=0.5)
    out = _find(pm, _standing([2.0 ** -20, 0.3], 8), newton_tol=2.0 ** -21, reach_floor=1e-6,
                newton_options=dict(max_iter=0))
    assert out["status"].tolist() == ["found"] and out["residual"][0] == 2.0 ** -21


def test_find_orbits_tries_a_lag_again_only_once_its_defect_has_halved():
    # 0 a run reaching a fixed point (found at lag 1), 1 a run standing off one (not reached: its
    # multiples wait), 2 a run that never repeats
    pm = ToyMap()
    L = 13
    runs = pm.run([[0.01, 0.31], [0, 0], [0, 0]], L)
    runs[:, 1] = [0.01, 0.3]
    runs[:, 2] = np.column_stack([0.1 * np.arange(L), np.full(L, 0.3)])
    tried = np.full((4, 3), np.inf)
    out = _find(pm, runs, tried=tried)
    assert out["status"].tolist() == ["found", "not reached", ""]
    d0 = max(np.abs(runs[-1, 0] - runs[-2, 0]).max(), np.abs(runs[-2, 0] - runs[-3, 0]).max())
    assert tried[0].tolist() == [d0, 0.0, np.inf]                    # the lag-1 defect Newton ran at
    assert np.isinf(tried[1:]).all()                                  # no other lag was tried
    # the same history again (lag 1 only): the defect has not halved, so nothing is tried
    again = _find(pm, runs, tried=tried[:1], max_period=1)
    assert again["status"].tolist() == ["", "", ""]
    tried[0, 0] = 2 * d0 * (1 + 1e-12)                              # just over twice the defect: tried again
    assert _find(pm, runs, tried=tried[:1], max_period=1)["status"].tolist() == ["found", "", ""]


def test_find_orbits_waits_on_the_multiples_of_an_orbit_not_yet_reached():
    # a 2-cycle the run stands off (0.01 from both points): tried at lag 2 only, not at 4 (its
    # multiple), so the multiplier reported is that of P^2
    pm = ToyMap(a=0.6, b=0.5, mode=2, phi0=-0.4)
    runs = np.array([[0.31, -0.4], [-0.31, -0.4]] * 6)[:, None]
    tried = np.full((4, 1), np.inf)
    out = _find(pm, runs, tried=tried)
    assert out["status"].tolist() == ["not reached"]
    np.testing.assert_allclose(out["floquet"], [0.36], rtol=1e-15, atol=0)  # exact: a diagonal Jacobian, a product of two numbers; measured 0
    assert tried[:, 0].tolist() == [np.inf, 0.0, np.inf, np.inf]


def test_lag_candidates_at_their_boundaries():
    # (L, N, d) = (6, 3, 2), heading column 1. Row 0 repeats but for the fourth state from the
    # end; row 1 but for the third (one return is not enough); row 2 gains a turn in its last
    # period and x alternates by 0.5 (= tol: a repeat)
    hist = np.zeros((6, 3, 2))
    hist[-4, 0, 0] = 1.0
    hist[-3, 1, 0] = 1.0
    hist[-1, 2, 1] = TWO_PI
    hist[::2, 2, 0] = 0.5
    ok, n, defect = dv.lag_candidates(hist, 6, 0.5, turn_axis=1)
    assert ok[0].tolist() == [True, False, True]
    assert defect[0].tolist() == [0.0, 1.0, 0.5]
    assert n[0].tolist() == [0, 0, 1] and n.dtype.kind == "i"        # turns between the last two
    assert not ok[4:].any() and np.isinf(defect[4:]).all()           # lags beyond L - ends
    ok3, _, _ = dv.lag_candidates(hist, 6, 0.5, turn_axis=1, ends=3)
    assert ok3[0].tolist() == [False, False, True]
    # whole numbers are states too
    ints = np.arange(24).reshape(6, 2, 2) % 3
    for a, b in zip(dv.lag_candidates(ints, 3, 0.5, turn_axis=1), dv.lag_candidates(ints * 1.0, 3, 0.5, turn_axis=1)):
        assert np.array_equal(a, b)


def test_least_period_at_its_boundaries():
    # row 0: a 2-cycle found at lag 4 is of period 2; row 1: period 4; row 2: P^2(x) - x = 0.25 =
    # tol exactly (a repeat), P(x) - x = 0.5 (not)
    x = np.array([[0.3, 0.0], [0.0, 0.0], [0.0, 0.0]])
    pts = np.array([[[-0.3, 0.0], [1.0, 0.0], [0.5, 0.0]], [[0.3, 0.0], [2.0, 0.0], [0.25, 0.0]],
                    [[-0.3, 0.0], [3.0, 0.0], [0.5, 0.0]], [[0.3, 0.0], [0.0, 0.0], [0.0, 0.0]]])
    k, n = dv.least_period(x, pts, np.array([4, 4, 4]), np.array([0, 0, 0]), turn_axis=1, tol=0.25)
    assert k.tolist() == [2, 4, 2] and n.tolist() == [0, 0, 0]
    k, n = dv.least_period(np.zeros((0, 2)), np.zeros((1, 0, 2)), np.zeros(0, int), np.zeros(0, int),
                           turn_axis=1, tol=0.25)
    assert k.size == 0 and n.size == 0


def test_distance_to_orbit_wraps_only_the_heading_and_only_where_turns_allow():
    # heading column 1; orbit points (K, M, d) = (3, 2, 2), row 0 has only two (NaN past k)
    pts = np.array([[[0.0, 0.5], [5.0, 0.0]], [[1.0, 0.0], [5.0, 1.0]], [[np.nan, np.nan], [0.5, 0.0]]])
    state = np.array([[1.0, TWO_PI + 0.125], [0.25, 0.0]])
    d, j = dv.distance_to_orbit(state, pts, turn_axis=1)                  # turns allowed by default
    np.testing.assert_allclose(d, [0.125, 0.25], rtol=1e-15, atol=0)  # exact: a difference of given numbers; measured 0 (2 pi + 0.125 wrapped)
    assert j.tolist() == [1, 2]
    d, j = dv.distance_to_orbit(state, pts, turn_axis=1, turns=[False, True])
    np.testing.assert_allclose(d, [TWO_PI - 0.375, 0.25], rtol=1e-15, atol=0)  # exact: a difference of given numbers; measured 0
    assert j.tolist() == [0, 2]


def test_reached_at_its_boundaries():
    # binary-exact numbers: 3 d_then rho^r + floor = 3 * 0.25 * 0.25 + 2^-10
    floor = 2.0 ** -10
    bound = 3 * 0.25 * 0.25 + floor
    got = dv.reached([bound, 0.01, floor, 0.125], [0.25, 0.01, floor, 1.0], [0.25, 0.999, 0.999, 0.25], 1,
                     tol=0.125, floor=floor)
    # beyond tol, however fast; standing still above the floor: not; standing on the floor:
    # reached; at tol exactly and shrinking: reached
    assert got.tolist() == [False, False, True, True]
    # on the rate bound: reached; above it (0.2: 3.2 d_then rho^r, within 4x): not
    got = dv.reached([bound, 0.2], [0.25, 0.25], [0.25, 0.25], 1, tol=0.5, floor=floor)
    assert got.tolist() == [True, False]


def test_orbit_points_stop_at_each_rows_period():
    # x' = x / 2, the heading on its fixed point 0 gaining s turns a period; a start in whole numbers
    pm = ToyMap(s=[0, 1], b=0.5, phi0=0.0)
    pts = dv.orbit_points(pm, np.arange(2), np.array([[3, 0], [3, 0]]), [1, 2])
    assert pts.shape == (2, 2, 2)
    np.testing.assert_array_equal(pts[0], [[1.5, 0.0], [1.5, TWO_PI]])
    assert np.isnan(pts[1, 0]).all()
    np.testing.assert_allclose(pts[1, 1], [0.75, 2 * TWO_PI], rtol=1e-15, atol=0)  # exact: given numbers; measured 0


def test_section_returns_of_a_standing_run_a_short_one_and_a_one_dimensional_one():
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")                             # no 0 / 0 warning either
        assert dv.section_returns(np.ones((10, 1, 2))).tolist() == [np.inf]
    # a 2-cycle over six sections (the shortest run judged) comes back exactly
    two = np.zeros((6, 1, 2))
    two[1::2, 0, 1] = 1.0
    assert dv.section_returns(two).tolist() == [0.0]
    assert dv.section_returns(two[:5]).tolist() == [np.inf]
    # a heading alone, rotating by an irrational angle: it fills the circle
    k = np.arange(400)[:, None, None]
    r = dv.section_returns(wrap_angle(k * 2 * np.pi * (np.sqrt(5) - 1) / 2), angles=(0,))
    assert r[0] < 0.05                         # reason: the flows' return_tol; measured 1.9e-3


def test_section_returns_are_per_run_invariant_under_scale_and_heading_shift():
    L = 400
    k = np.arange(L)[:, None]
    line = np.stack([-1 + 1.5 * 0.995 ** k, 0.5 * 0.995 ** k], axis=2)       # a slow approach (L, 1, 2)
    ring = np.stack([0.3 * np.cos(k * 2.4), 0.3 * np.sin(k * 2.4)], axis=2)  # a closed curve
    alone = [dv.section_returns(line)[0], dv.section_returns(ring)[0]]
    assert dv.section_returns(np.concatenate([line, 2 * ring], axis=1)).tolist() == alone
    assert 0.25 <= alone[0] < np.inf                           # reason: moves away for good (at least leave)
    # only the angle columns wrap: x steadily drifting over 20 (more than 2 pi) never comes back
    drift = np.stack([np.zeros((L, 1)), 0.05 * k], axis=2)
    assert dv.section_returns(drift, angles=(0,))[0] >= 0.25   # reason: moves away for good
    # the first state is a reference: a start off a closed curve that never comes back near it
    start = ring.copy()
    start[0] = [0.6, 0.0]                                      # 0.3 from the curve, D = 0.9
    assert 0.25 < dv.section_returns(start, angles=())[0] < np.inf   # reason: by construction; measured 0.33
    # a scale of all the (non-angle) columns, a shift of the heading (column 0): the same result
    assert dv.section_returns(4 * line, angles=())[0] == dv.section_returns(line, angles=())[0]
    for c in (1.0, np.pi / 2, -2.0, 3.0):
        np.testing.assert_allclose(dv.section_returns(line + [c, 0.0])[0], alone[0], rtol=1e-15,
                                   atol=0)  # exact: one code path, shifted by whole turns; measured 0
    # whole numbers are states too: a heading advancing 1 rad a period, given as integers
    ints = np.stack([np.arange(40), np.zeros(40, int)], axis=-1)[:, None]
    assert dv.section_returns(ints).tolist() == dv.section_returns(ints * 1.0).tolist()


def test_a_state_exactly_leave_times_the_diameter_away_has_not_left():
    # D = 1: the second state, 0.25 = leave D from the first, has not left; the first to leave
    # is 0.5 away, and nothing comes back nearer (the reference at L // 3 = 2 returns exactly)
    x = np.array([0.0, 0.25, 0.5, 1.0, 0.5, 0.5])[:, None, None]
    assert dv.section_returns(x, angles=()).tolist() == [0.5]


def test_enclosed_orbit_starts_newton_at_the_circular_mean_of_each_curve():
    # with no Newton step allowed, the curve's centre must already be the fixed point: row 0 a
    # slipping orbit with its heading at pi (the curve crosses the wrap), row 1 one at 0.5;
    # multipliers 0.5 (heading) and 0.25 (x), 0.5 and 0.8
    pm = ToyMap(s=[1, 0], b=[0.25, 0.8], phi0=[np.pi, 0.5])
    t = np.linspace(0, 2 * np.pi, 40, endpoint=False)[:, None]
    sec = np.stack([0.2 * np.cos(t) + [0.0, 0.0], 0.2 * np.sin(t) + [np.pi, 0.5]], axis=2)
    sec[:, :, 1] = wrap_angle(sec[:, :, 1])
    att, mu = dv.enclosed_orbit(pm.step, np.arange(2), sec, turn_axis=1, newton_tol=1e-12,
                                newton_options=dict(max_iter=0))
    assert att.tolist() == [True, True]
    np.testing.assert_allclose(mu, [0.5, 0.8], rtol=1e-15, atol=0)  # exact: diagonal Jacobians; measured 0
    # a neutral heading (a = 1), x symmetric about its fixed point: the residual is 0 = tol
    # exactly; |mu_1| = 1 is not attracting
    pm = ToyMap(a=1.0)
    sec = np.array([[0.25, 0.1], [-0.25, 0.2]] * 4)[:, None]
    att, mu = dv.enclosed_orbit(pm.step, np.arange(1), sec, turn_axis=1, newton_tol=0.0,
                                newton_options=dict(max_iter=0))
    assert att.tolist() == [False] and mu.tolist() == [1.0]


def test_held_orbit_regime_and_turns_round_on_their_own_terms():
    # held: flags given as 0 / 1 floats (a frame's column) read as booleans, the answer a bool array
    got = dv.held(["periodic", "periodic", "periodic"], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0])
    assert got.dtype == bool and got.tolist() == [True, False, False]
    assert dv.orbit_regime([0, 1, -2]).tolist() == ["periodic", "slipping", "slipping"]
    assert dv.turns_round([TWO_PI, np.nextafter(TWO_PI, 7)]).tolist() == [False, True]


def test_drift_is_per_period_in_the_units_of_the_samples_by_default():
    drift, se = dv.drift_statistics([[0.0, 3.0, 6.0, 9.0]], 3)
    assert drift.tolist() == [1.0] and se.tolist() == [0.0]


class SwappedToy(ToyMap):
    """The toy map with column 0 (x) taken as the heading."""

    turn_axis = 0


def test_a_two_cycle_a_whole_turn_apart_is_of_period_two_in_a_plain_coordinate():
    # x' = -h(x) has the 2-cycle +-pi (q = pi), its points 2 pi apart. Where the heading column is
    # a plain coordinate (turns False) it is a 2-cycle, not reduced to a fixed point by a whole turn
    pm = SwappedToy(b=0.5, mode=2, q=np.pi)
    runs = pm.run([[np.pi + 1e-3, 0.3]], 13)
    out = _find(pm, runs, turns=False)
    assert out["status"].tolist() == ["found"]
    assert (out["k"][0], out["n"][0], out["lag"][0]) == (2, 0, 2)


# ---------------------------------------------------------------- the two survivors of the 04:20 run (issue 22)


def test_find_orbits_tells_a_two_cycle_from_a_fixed_point_at_100_newton_tol():
    # a 2-cycle x = +-q (ToyMap mode 2) whose points lie 2 q apart: P(x) - x = -2 q. find_orbits
    # takes the least period as the smallest d with P^d(x) = x within 100 newton_tol (its
    # docstring): 2 q = 100.5 newton_tol is period 2, 2 q = 99.5 newton_tol period 1 (closer than
    # Newton's accuracy allows to tell). Newton converges on both (residual <= newton_tol = 1e-12)
    tol = OPTS["newton_tol"]
    ks = []
    for gap in (100.5, 99.5):
        q = 0.5 * gap * tol
        pm = ToyMap(a=0.6, b=0.5, mode=2, phi0=-0.4, q=q)
        out = _find(pm, pm.run([[q, -0.4]], 13))
        assert out["found"][0] and out["lag"][0] == 2, out["status"]
        ks.append(int(out["k"][0]))
    assert ks == [2, 1]


def test_section_returns_judge_the_state_at_a_third_of_the_run_too():
    # a circle filled by an irrational rotation, but the state at L // 3 is off it (radius 1.6)
    # and never come back to: seen from the first state the run returns as on a closed curve,
    # seen from the state at L // 3 it never comes within about 0.6 / 2.6 of it. The documented
    # references are the states at 0 and L // 3, and the worse one counts.
    L = 120
    k = np.arange(L)[:, None]
    rot = 2 * np.pi * (np.sqrt(5) - 1) / 2
    sec = np.stack([np.cos(k * rot), np.sin(k * rot)], axis=2)
    sec[L // 3] *= 1.6
    r = dv.section_returns(sec, angles=())
    assert r[0] > 0.2            # measured 0.223: about (1.6 - 1) / 2.6, the outlier's gap over D
    assert dv.section_returns(np.delete(sec, L // 3, axis=0), angles=())[0] < 0.05  # measured 0.021 without it


# ------------------------------------------- bug classes: chains of divisors, complex multipliers
# (issue 28: a least period trying its divisors in ascending order, and stability judged by
# the real part of a multiplier, both passed the suite)

def _images(x, period, lag, slip=(0.0, 0.0)):
    """pts (lag, 1, 2) of a point of least period ``period``: P^j(x) = x + (j / period) slip
    where period divides j, and 0.1 away (in x) elsewhere."""
    pts = np.empty((lag, 1, 2))
    for j in range(1, lag + 1):
        pts[j - 1, 0] = x[0] + (np.array(slip) * j / period if j % period == 0 else [0.1, 0.0])
    return pts


@pytest.mark.parametrize("lag, period", [(4, 1), (4, 2), (6, 1), (6, 2), (6, 3), (8, 1), (8, 2), (8, 4),
                                         (6, 6), (8, 8)])
def test_least_period_is_the_smallest_divisor_along_a_chain_of_divisors(lag, period):
    # lag 8 of a period-2 orbit: its divisors 2 and 4 both return, 1 does not; the least
    # period is 2 (trying the divisors in the other order would report 4)
    x = np.array([[0.5, 0.2]])
    pts = _images(x, period, lag)
    k, n = dv.least_period(x, pts, np.array([lag]), np.array([0]), turn_axis=1, tol=1e-9)
    assert (k[0], n[0]) == (period, 0)
    # slipping: one turn of the heading per period, so lag / period turns at the lag
    pts = _images(x, period, lag, slip=(0.0, TWO_PI))
    k, n = dv.least_period(x, pts, np.array([lag]), np.array([lag // period]), turn_axis=1, tol=1e-9)
    assert (k[0], n[0]) == (period, 1)
    k, n = dv.least_period(x, pts, np.array([lag]), np.array([lag // period]), turn_axis=1, turns=False,
                           tol=1e-9)
    assert (k[0], n[0]) == ((lag, lag // period) if period < lag else (period, 1))


def test_least_period_of_several_rows_takes_each_rows_own_divisors():
    # rows of lags 4, 6, 8 and 8 at once (NaN past a row's own lag), least periods 1, 3, 2, 8
    x = np.array([[0.5, 0.2], [0.1, -1.0], [2.0, 0.0], [0.0, 3.0]])
    rows = [(4, 1), (6, 3), (8, 2), (8, 8)]
    pts = np.full((8, 4, 2), np.nan)
    for i, (lag, period) in enumerate(rows):
        pts[:lag, i] = _images(x[i:i + 1], period, lag)[:, 0]
    k, _ = dv.least_period(x, pts, np.array([4, 6, 8, 8]), np.zeros(4, int), turn_axis=1, tol=1e-9)
    assert k.tolist() == [1, 3, 2, 8]


class FocusMap:
    """P(x) = c + r R(theta) (x - c), R a rotation: a focus at c with the complex multipliers
    r exp(+-i theta), one (r, theta) per row; column 1 the heading (``turn_axis`` 1)."""

    turn_axis = 1

    def __init__(self, r, theta, c=(0.0, 0.3)):
        self.r, self.theta, self.c = np.atleast_1d(r), np.atleast_1d(theta), np.asarray(c, dtype=float)

    def step(self, idx, X, k):
        idx = np.asarray(idx)
        k = np.broadcast_to(np.asarray(k, dtype=int), (len(idx),))
        a, s = self.r[idx] ** k, self.theta[idx] * k
        A = a[:, None, None] * np.stack([np.stack([np.cos(s), -np.sin(s)], -1),
                                         np.stack([np.sin(s), np.cos(s)], -1)], -2)
        return self.c + np.einsum("mij,mj->mi", A, np.asarray(X, dtype=float) - self.c), A

    def advance(self, idx, X, k):
        return self.step(idx, X, k)[0]

    def run(self, x0, L):
        out = [np.array(x0, dtype=float)]
        for _ in range(L - 1):
            out.append(self.advance(np.arange(len(out[0])), out[-1], 1))
        return np.stack(out)


@pytest.mark.parametrize("r, found", [(0.98, True), (0.995, True), (1.005, False), (1.02, False)])
@pytest.mark.parametrize("theta", [1.3, math.pi / 2, 2.9])
def test_a_focus_is_attracting_by_the_modulus_of_its_complex_multipliers(r, found, theta):
    # |mu| = r just below or above 1, mu complex: |Re mu| = r |cos theta| < 1 every time, so a
    # stability judged by the real part would take the repelling focus as attracting
    pm = FocusMap([r], [theta])
    out = _find(pm, _standing(pm.c, 13))
    assert out["status"].tolist() == ["found" if found else "not attracting"]
    assert out["found"].tolist() == [found] and out["k"].tolist() == [1 if found else 0]
    # the last attempt's |mu|: lag 1 for the attracting focus, lag 4 (max_period) for the
    # repelling one, tried at every lag
    want = r if found else r ** OPTS["max_period"]
    assert out["floquet"][0] == pytest.approx(want, rel=1e-12)  # accuracy: the eigensolver on a normal matrix: the floor
    # and an orbit's own verdict (lib.dynamics.orbits.Orbit.attracting)
    orb = newton_orbit(lambda x: pm.step(np.zeros(len(x), int), x, 1), pm.c + [[1e-3, -2e-3]], 1)
    assert orb.converged[0] and orb.attracting[0] == (r < 1)
    mu = orb.multipliers[0]
    assert abs(mu[0].imag) > 0.1 and abs(mu[0].real) < 1  # reason: the case that tells |mu| from |Re mu|


def test_a_focus_returning_at_lag_four_but_not_at_lag_one_is_a_fixed_point():
    # a quarter turn a period, slowly contracting: the run returns near itself at lag 4 (the
    # lag-4 defect 6e-4 is within candidate_tol 1e-3), not at lags 1-3 (1e-2 and more).
    # Newton on P^4 lands on the focus, whose P^1 and P^2 both return it: least period 1
    pm = FocusMap([0.98], [math.pi / 2])
    runs = pm.run([pm.c + [0.01, 0.0]], 13)
    cand, _, defect = dv.lag_candidates(runs, 4, OPTS["candidate_tol"], turn_axis=1, ends=2)
    assert cand[:, 0].tolist() == [False, False, False, True]
    out = _find(pm, runs)
    assert out["status"].tolist() == ["found"]
    assert (out["k"][0], out["lag"][0], out["n"][0]) == (1, 4, 0)
    # rho is the least period's: |mu(P^4)|^(1/4) = 0.98
    assert out["rho"][0] == pytest.approx(0.98, rel=1e-12)  # accuracy: the eigensolver on a normal matrix: the floor
    np.testing.assert_allclose(out["x"][0], pm.c, rtol=0, atol=1e-12)  # accuracy: Newton on a linear map, newton_tol 1e-12


def test_a_heading_within_one_turn_takes_its_drift_error_from_two_ends_of_a_bounded_quantity():
    # blocks of 2 periods; row 0 stays within a turn (span 1.5 rad): its error is
    # sqrt(2 var(q)) / (4 blocks x 2 periods) in turns; row 1 spans more than a turn and keeps
    # the batch means of its increments; without bounded_span both keep the batch means
    ends = np.array([[0.0, 1.0, -0.5, 0.5, 0.2], [0.0, 3.0, 6.0, 9.0, 13.0]])
    drift, se = dv.drift_statistics(ends, 2.0, 2 * np.pi, bounded_span=2 * np.pi)
    _, se_bm = dv.drift_statistics(ends, 2.0, 2 * np.pi)
    np.testing.assert_allclose(drift, [0.2 / 8 / (2 * np.pi), 13.0 / 8 / (2 * np.pi)], rtol=1e-15, atol=0)  # exact: one formula on given numbers; measured 0
    want0 = np.sqrt(2 * np.var(ends[0], ddof=1)) / (2 * np.pi * 8)
    np.testing.assert_allclose(se, [want0, se_bm[1]], rtol=1e-15, atol=0)  # exact: one formula on given numbers; measured 0
    assert se_bm[0] == pytest.approx(np.std(np.diff(ends[0]), ddof=1) / 2 / 2 / (2 * np.pi), rel=1e-15)  # exact: one formula on given numbers; measured 0
    with pytest.raises(ValueError, match="bounded_span"):
        dv.drift_statistics(ends, 2.0, 2 * np.pi, bounded_span=0.0)
    got = dv.heading_drift(ends, 2.0)                  # the heading's drift: in turns, bounded at one turn
    assert np.array_equal(got[0], drift) and np.array_equal(got[1], se)


def test_a_long_run_merges_its_blocks_into_batches_of_at_most_48_periods_and_at_least_six():
    # blocks of 12 periods: g = min(nb // 6, 48 // 12) blocks a batch, over the last (nb // g) g
    assert [statistics.batch_grouping(nb, 12.0) for nb in (6, 11, 12, 25, 100)] == [
        (1, 6), (1, 11), (2, 6), (4, 6), (4, 25)]
    assert statistics.batch_grouping(10, 96.0) == (1, 10)    # blocks already longer than 48 periods
    g, n = statistics.batch_grouping(np.array([6, 12, 25, 100]), 12.0)     # many runs at once
    assert g.tolist() == [1, 2, 4, 4] and n.tolist() == [6, 6, 6, 25]
    assert (statistics.MIN_BATCHES, statistics.BATCH_PERIODS) == (6, 48)
    rng = np.random.default_rng(3)
    q = np.cumsum(np.r_[0.0, rng.normal(size=25)])[None]   # 25 blocks: 6 increments of 48 periods
    drift, se = dv.drift_statistics(q, 12.0)
    inc = np.diff(q[0, 1::4]) / 48.0
    assert inc.size == 6
    assert drift[0] == pytest.approx(inc.mean(), rel=1e-12)  # accuracy: the same sums in another order
    assert se[0] == pytest.approx(inc.std(ddof=1) / np.sqrt(6), rel=1e-12)  # accuracy: the same sums in another order
    short = q[:, :12]                                        # 11 blocks: no merging
    d11, s11 = dv.drift_statistics(short, 12.0)
    inc11 = np.diff(short[0]) / 12.0
    assert s11[0] == pytest.approx(inc11.std(ddof=1) / np.sqrt(11), rel=1e-12)  # accuracy: the same sums in another order
    assert d11[0] == pytest.approx(inc11.mean(), rel=1e-12)  # accuracy: the same sums in another order
    _, s_all = dv.drift_statistics(q, 12.0, batches=25)     # asked for 25 batches: every block kept
    assert s_all[0] == pytest.approx(np.diff(q[0]).std(ddof=1) / 12.0 / 5.0, rel=1e-12)  # accuracy: the same sums in another order
    for bad in (1, 2.5, 0):
        with pytest.raises(ValueError, match="batches"):
            dv.drift_statistics(q, 12.0, batches=bad)
    with pytest.raises(ValueError, match="at_block_ends"):
        dv.drift_statistics(np.zeros(5), 12.0)
    # the same merging of block means (the exponent's), and the same refusals
    means = rng.normal(size=(2, 25))
    mean, err = dv.batch_means(means, 4)
    merged = means[:, 1:].reshape(2, 6, 4).mean(axis=2)
    np.testing.assert_allclose(mean, merged.mean(axis=1), rtol=1e-12, atol=0)  # accuracy: the same sums in another order
    np.testing.assert_allclose(err, merged.std(axis=1, ddof=1) / np.sqrt(6), rtol=1e-12, atol=0)  # accuracy: as above
    assert np.array_equal(dv.batch_means(means, 1)[1], dv.batch_means(means)[1])  # exact: merge 1 keeps every block
    long = statistics.long_run_means(means, 12.0)             # 25 blocks of 12 periods: merged 4 at a time
    assert np.array_equal(long[0], mean) and np.array_equal(long[1], err)  # exact: the same call
    with pytest.raises(ValueError, match="block_means"):
        statistics.long_run_means(means[0], 12.0)
    for bad in (0, 1.5):
        with pytest.raises(ValueError, match="merge"):
            dv.batch_means(means, bad)
    with pytest.raises(ValueError, match="block_periods"):
        statistics.batch_grouping(10, 0.0)