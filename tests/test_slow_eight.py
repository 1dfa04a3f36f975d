"""Slow eights (lib.rotation.slow_eight, Chapter 5): the frozen equilibrium of the osculating
circle, the boundary r_follow where it ceases to exist, and the overdamped heading's
periodic solution with its first inertia correction, against the decided orbits of
the reduced rotation (37) (lib.rotation.verdicts, lib.dynamics.verdicts).

The decided orbits compared here are period-1 orbits with Floquet multipliers below
1e-10 in modulus, located by Newton to 1e-10 rad with ranges good to about 1e-7 rad:
nothing rides on the last bits of a trajectory."""

import math

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from lib.rotation.circle import circle_equilibria
from lib.params import Body
from lib.rotation.slow_eight import slow_eight_prediction
from lib.rotation.verdicts import rotation_verdicts
from lib.rotation.slow_eight import follow_radius, frozen_heading, series_peak_curvature, unit_eight_geometry
from lib.trajectories import eight_kinematics

BODY = Body()


def _decided(R, Theta):
    """The decided verdicts of (37) from the reference at the pairs (R_i, Theta_i)."""
    return rotation_verdicts(BODY, "eight", np.asarray(R, float), np.asarray(Theta, float))


def _peak_curvature() -> float:
    """The unit eight's largest |curvature| (1/m), by a bounded scalar search on the
    tangent angle's rate over the speed (eight_kinematics), near s = 0.9 rad."""
    def neg(s):
        _, dz, _ = eight_kinematics(1.0, 1.0, s)
        return -abs(dz[2] / math.hypot(dz[0], dz[1]))
    return -minimize_scalar(neg, bounds=(0.5, 1.3), method="bounded", options=dict(xatol=1e-12)).fun


def test_frozen_heading_is_the_circles_stable_equilibrium_on_the_osculating_circle():
    R, Theta = 2.5, 0.2
    s = np.array([0.3, 0.9, 1.4, 2.0, 2.6, 3.5, 4.4, 5.9])
    sig, kap = unit_eight_geometry(s)
    p, k = frozen_heading(BODY, R, Theta, s)
    assert np.any(kap > 0) and np.any(kap < 0)
    for si, sg, kp, pi, ki in zip(s, sig, kap, p, k):
        R_loc, th_loc = R / abs(kp), Theta * sg * abs(kp)   # radius (m), rate v / R_loc (rad/s)
        p_circle = circle_equilibria(BODY, R_loc, th_loc)[0]
        # exact: one closed form, two routes; the same closed form by two routes: measured 3.3e-16 rad at most (p* of 0.27-0.78)
        assert pi == pytest.approx(math.copysign(1.0, kp) * p_circle, rel=0, abs=3e-15), si
        r_crit = BODY.c_phi / (BODY.a * math.hypot(BODY.m * th_loc, BODY.c))
        assert ki == pytest.approx(r_crit / R_loc, rel=2e-15, abs=0)   # exact: one closed form, two routes; measured 2.2e-16 relative


def test_frozen_heading_is_absent_where_the_osculating_circle_is_below_its_critical_radius():
    p, k = frozen_heading(BODY, 1.0, 0.05, np.linspace(0, 2 * np.pi, 400))
    assert np.any(k > 1) and np.all(np.isnan(p[k > 1])) and np.all(np.isfinite(p[k <= 1]))


def test_follow_radius_at_a_slow_rate_is_the_critical_radius_times_the_peak_curvature():
    kmax = _peak_curvature()
    # measured 3.3e-6 relative: the max sampled at 4096 phases lies below the searched peak
    assert kmax == pytest.approx(series_peak_curvature()[0], rel=2e-5, abs=0)
    r0 = BODY.c_phi / (BODY.a * BODY.c) * kmax         # R_crit(0) kappa_max
    assert follow_radius(BODY, 1e-9) == pytest.approx(r0, rel=1e-7)   # measured 4.6e-9
    # faster, the centripetal force helps: r_follow falls with Theta
    r = follow_radius(BODY, [0.05, 0.1, 0.2, 0.4])
    assert np.all(np.diff(r) < 0) and r[0] < r0


def test_follows_exactly_when_the_frozen_equilibrium_exists_along_the_path():
    Theta = 0.1
    r = float(follow_radius(BODY, Theta))
    pr = slow_eight_prediction(BODY, [0.98 * r, 1.02 * r], Theta)
    assert list(pr.follows) == [False, True]
    assert pr.k_max == pytest.approx([1 / 0.98, 1 / 1.02], rel=1e-15, abs=0)   # exact: a ratio of two closed forms; measured 0.0 (rounding floor)
    assert np.isnan(pr.frozen_range[0]) and pr.frozen_range[1] > 0
    # exact: max - min; measured 0.0: the range is max - min (rounding floor)
    assert pr.frozen_range[1] == pytest.approx(pr.frozen_max[1] - pr.frozen_min[1], rel=1e-15, abs=0)


def test_the_series_misses_the_peak_curvature():
    exact, series = series_peak_curvature()
    # measured 2.6e-5 (exact = 4.790274); reason: 4.7903 is the value rounded to four
    # decimals, so the tolerance is half a unit in its last place
    assert exact == pytest.approx(4.7903, rel=0, abs=5e-5)
    assert abs(series / exact - 1) > 0.05                # measured 9.7 % low


def test_corrected_range_matches_the_decided_orbit_with_an_error_of_order_theta_squared():
    """The overdamped heading neglects I_C phi'' (relative size I_C Theta / c_phi): its
    range errs by O(Theta), halving with Theta; with the first inertia correction the
    error is O(Theta^2), falling by about four. Measured at R = 0.5, 1, 2 m (both sides of
    r_follow ~ 1.9 m): corrected 1.6e-4, 2.5e-3, 2.0e-3 rad at Theta = 0.025 and 1.4e-3,
    1.0e-2, 1.3e-2 at 0.05; overdamped 4.5e-2, 3.9e-2, 4.2e-2 and about twice that. The
    prediction's own discretisation error is below 1e-4 rad (steps x 4: measured 2.3e-6 for
    the overdamped range, 6.0e-5 for the corrected one, over the book's slow band)."""
    R = np.array([0.5, 1.0, 2.0])
    err = {}
    for Theta in (0.025, 0.05):
        d = _decided(R, np.full(3, Theta))
        assert (d.regime == "periodic").all() and (d.period == 1).all()
        pr = slow_eight_prediction(BODY, R, Theta)
        err[Theta] = (np.abs(pr.corrected_range - d["range"].to_numpy()),
                      np.abs(pr.overdamped_range - d["range"].to_numpy()))
    assert np.all(err[0.025][0] < 0.02)                  # measured at most 2.5e-3
    assert np.all(err[0.05][0] < 0.13)                   # measured at most 1.3e-2
    assert np.all(err[0.05][0] / err[0.025][0] > 2.5)    # measured 8.3, 4.2, 6.3: second order
    ratio = err[0.05][1] / err[0.025][1]
    assert np.all((ratio > 1.7) & (ratio < 2.6))         # measured 2.2, 2.1, 2.1: first order
    assert np.all(err[0.025][0] < err[0.025][1])         # the correction helps


def test_frozen_range_matches_the_decided_orbit_for_large_eights():
    """The frozen equilibrium drops the heading's lag, of relative size k_max = r_follow / R,
    so it is the limit of large eights, not of slow ones. At Theta = 0.0125 rad/s the
    error is 0.064, 3.9e-3, 1.1e-3 rad at R = 5, 10, 20 m (k_max 0.40, 0.20, 0.10)."""
    R = np.array([5.0, 10.0, 20.0])
    d = _decided(R, np.full(3, 0.0125))
    assert (d.regime == "periodic").all()
    pr = slow_eight_prediction(BODY, R, 0.0125)
    assert pr.follows.all()
    err = np.abs(pr.frozen_range - d["range"].to_numpy())
    assert np.all(np.diff(err) < 0)                      # shrinks as R grows
    assert err[-1] < 0.011                               # measured 1.1e-3
    assert err[-1] < 0.1 * pr.frozen_range[-1]


def test_slow_band_of_the_map_is_periodic_on_both_sides_of_the_follow_radius():
    """Where the slow analysis applies the heading cannot slip or turn chaotic: the
    overdamped heading is a scalar first-order equation, its period map a circle
    homeomorphism whose attracting orbits, at rotation number 0, are fixed points.
    The decided map agrees, and shows no boundary at r_follow: the heading that cannot
    follow the sharpest bends lags through them and catches up."""
    R, Th = np.meshgrid([0.3, 1.0, 2.0, 3.5], [0.05, 0.15, 0.25])
    R, Th = R.ravel(), Th.ravel()
    d = _decided(R, Th)
    pr = slow_eight_prediction(BODY, R, Th)
    assert not pr.overdamped_slips.any() and not pr.corrected_slips.any()
    assert (d.regime == "periodic").all() and (d.period == 1).all() and not d.lost.any()
    for th in (0.05, 0.15, 0.25):                        # both sides of r_follow sampled
        sel = Th == th
        assert pr.follows[sel].any() and not pr.follows[sel].all()
    # on the smallest eights the heading barely turns: p swings by more than pi, short
    # of the tangent angle's own swing of 3 pi / 2 (measured 4.46, 3.96, 3.38 rad)
    small = d["range"].to_numpy()[R == 0.3]
    assert np.all((small > math.pi) & (small < 1.5 * math.pi))


def test_prediction_is_vectorised_over_a_grid():
    R, Th = np.array([[0.5], [2.0]]), np.array([0.05, 0.2])
    g = slow_eight_prediction(BODY, R, Th)
    assert g.corrected_range.shape == (2, 2) and g.r_follow.shape == (2, 2)
    one = slow_eight_prediction(BODY, 2.0, 0.2)
    assert one.corrected_range.shape == ()
    # exact: one code path, a grid and one point; measured 0.0 for both: the same closed form, and (corrected) the same 512 RK4 steps and
    # Illinois iterates; 1e-14 for the second admits the libm's last bits over those steps
    assert g.frozen_range[1, 1] == pytest.approx(float(one.frozen_range), rel=1e-15, abs=0)
    # exact: one code path, a grid and one point; measured 0.0 (see above)
    assert g.corrected_range[1, 1] == pytest.approx(float(one.corrected_range), rel=1e-14, abs=0)


@pytest.mark.parametrize("args, exc, words", [
    (("body", 1.0, 0.1), TypeError, "body"),
    ((BODY, [1.0, -1.0], 0.1), ValueError, "R[1]"),
    ((BODY, 1.0, [0.1, float("nan")]), ValueError, "Theta[1]"),
    ((BODY, "1", 0.1), TypeError, "R"),
    ((BODY, [1.0, 2.0], [0.1, 0.2, 0.3]), ValueError, "broadcast"),
    ((BODY, 1.0, 0.0), ValueError, "Theta"),
])
def test_bad_input_raises(args, exc, words):
    with pytest.raises(exc, match=None) as info:
        slow_eight_prediction(*args)
    assert words in str(info.value)


def test_n_phase_must_be_an_integer_of_at_least_64():
    with pytest.raises(TypeError, match="n_phase"):
        slow_eight_prediction(BODY, 1.0, 0.1, n_phase=100.0)
    with pytest.raises(ValueError, match="n_phase"):
        slow_eight_prediction(BODY, 1.0, 0.1, n_phase=8)


def test_helpers_check_their_arguments():
    with pytest.raises(ValueError, match=r"R\[0\]"):
        frozen_heading(BODY, [-1.0], 0.1, 0.0)
    with pytest.raises(TypeError, match="body"):
        follow_radius(None, 0.1)
    with pytest.raises(ValueError, match="Theta"):
        follow_radius(BODY, -0.1)


@pytest.mark.parametrize("corrected", [False, True])
def test_compiled_overdamped_period_is_the_vectorised_one(corrected):
    """The compiled engine's period of the first-order heading against the vectorised numpy
    steps (``record=True`` keeps that path) from the same starts: the same RK4 steps in the
    same order, so they differ only by the stages' cos and sin (libm's, or the compiled engine's
    from its step's, lib.integrators.trig) over 256 steps."""
    from lib.rotation.field import coefficients
    from lib.rotation.slow_eight import _forcing, _period

    rng = np.random.default_rng(28)
    R, Th, phi = rng.uniform(0.2, 4.0, 40), rng.uniform(0.05, 0.3, 40), rng.uniform(-math.pi, math.pi, 40)
    A, B, C = coefficients(BODY, R, Th)
    f, _ = _forcing(256)
    fast = _period(phi, A, B, C, f, 256, corrected)
    slow, rec = _period(phi, A, B, C, f, 256, corrected, record=True)
    assert rec.shape == (257, 40)
    # measured 2.9e-15; reason: the two ways to cos and sin differ by an ulp or two per stage
    # (lib.integrators.trig), and 1024 stage evaluations of a contracting flow keep that far below 1e-12 rad
    assert fast == pytest.approx(slow, rel=0, abs=1e-12)
