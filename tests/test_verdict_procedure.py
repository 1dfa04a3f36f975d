"""The one decision procedure (lib.dynamics.verdicts): each step and each definition at
its boundary, on inputs whose answer is known without the procedure."""

import math

import numpy as np
import pandas as pd
import pytest

from lib import limits, loop_verdicts, rotation_verdicts, stability
from lib.circle_rotation import circle_critical_radius, circle_eigenvalues
from lib.dynamics import verdicts as dv
from lib.params import Body
from lib.rotation_engine import RotationMap, _Engine
from lib.rotation_field import coefficients

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
        assert mean[i] == pytest.approx(np.mean(means), rel=1e-14, abs=0)  # measured 0
        assert se[i] == pytest.approx(np.std(means, ddof=1) / 2.0, rel=1e-14, abs=0)  # measured 0
    with pytest.raises(ValueError, match="two blocks"):
        dv.block_statistics(v[:, :20], 12)


def test_drift_of_a_steady_slip_is_its_rate_with_zero_error():
    # a heading gaining 0.25 turns per period, sampled at the ends of blocks of 6 periods
    ends = 2 * np.pi * 0.25 * 6 * np.arange(9.0)
    drift, se = dv.drift_statistics(ends[None], 6, 2 * np.pi)
    assert drift[0] == pytest.approx(0.25, rel=1e-14, abs=0) and se[0] == pytest.approx(0.0, abs=1e-14)  # measured 0 and 2.6e-17


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
    assert defect[0, 0] == pytest.approx(0.6, abs=1e-15)  # measured 0
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
    assert np.all(r.residual <= 1e-13)  # reason: the stopping tolerance given to newton above
    assert np.allclose(r.x, 0.0, rtol=0, atol=1e-14) and r.turns.tolist() == [1, 1]  # measured 6.0e-16
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
    assert frame.lyapunov[0] == pytest.approx(expected, rel=1e-13)  # measured 0


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
    np.testing.assert_allclose(drift, [2.5 / 4, 0.0], rtol=1e-15, atol=0)  # measured 0
    np.testing.assert_allclose(se, [np.std([1, 2, 3, 4], ddof=1) / 2 / 4, 0.0], rtol=1e-15, atol=0)  # measured 0


def test_block_statistics_need_two_blocks_and_take_the_last_complete_ones():
    # 5 periods in blocks of 2: the last 4 form 2 blocks (means 2.5 and 4.5), the first is dropped
    mean, se = dv.block_statistics(np.array([[100.0, 2.0, 3.0, 4.0, 5.0]]), 2)
    assert mean[0] == 3.5 and se[0] == pytest.approx(np.std([2.5, 4.5], ddof=1) / np.sqrt(2), rel=1e-15)  # measured 0
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
    np.testing.assert_allclose(mu, gains, rtol=1e-13)  # measured 0
