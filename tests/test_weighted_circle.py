"""The circle's steady motion under the weighted allocation (lib.weighting.circle), each
property checked by an independent route: Chapter 5's closed form, a linearisation by
simulation, simulations on both sides of the limit, and frames taken at other times."""

import math

import numpy as np
import pytest

from lib import trajectories
from lib.weighting import comparison as weighting
from lib.allocation import Allocation
from lib.rotation.circle import circle_critical_radius, circle_eigenvalues, circle_equilibria
from lib.integrators.smooth import Integration
from lib.params import Body, Gains
from lib.simulate import simulate
from lib.weighting.circle import (LIMIT_KINDS, circle_error_weight, circle_steady_state, circle_weight_limit,
                                  circle_weight_sweep, rotating_field, _jacobian, _loop)
from lib.weighting.rotating_frame import inertial_to_rotating, rotating_to_inertial

BODY, GAINS, R, THETA = Body(), Gains(), 2.0, math.pi / 4


@pytest.fixture(scope="module")
def limit():
    return circle_weight_limit(BODY, GAINS, R, THETA)


def _flow(w_phi, y0, t_end, t_eval=None, tol=1e-12):
    """Simulate the inertial closed loop (lib.simulate) from the rotating-frame state y0 at
    t = 0 and return the rotating-frame states at t_eval."""
    s0 = rotating_to_inertial(y0, THETA, 0.0)
    res = simulate(BODY, GAINS, trajectories.circle(R, THETA), t_end, s0[:3], s0[3:],
                   allocation=Allocation("least_squares", (1.0, 1.0, w_phi)),
                   t_eval=[t_end] if t_eval is None else t_eval,
                   integration=Integration(rtol=tol, atol=tol))
    return inertial_to_rotating(np.c_[res.z, res.dz], THETA, res.t)


@pytest.mark.parametrize("R_, theta", [(2.0, math.pi / 4), (0.7, 1.3), (3.5, 0.3)])
def test_with_no_heading_weight_the_steady_state_is_chapter_5s_equilibrium(R_, theta):
    st = circle_steady_state(BODY, GAINS, R_, theta, (1.0, 1.0, 0.0))
    assert abs(st.heading - circle_equilibria(BODY, R_, theta)[0]) < 1e-13  # exact: w_phi = 0 starts the continuation on Chapter 5's closed form, and Newton is not run; measured 0
    assert abs(st.radial) < 1e-13 and abs(st.tangential) < 1e-13  # exact: w_phi = 0 starts the continuation on Chapter 5's closed form, and Newton is not run; measured 0
    # the spectrum: (34)'s pair and the four roots of (24), m s^2 + kv s + kp, seen from the
    # frame rotating at theta (shifted by +-i theta)
    s24 = np.roots([BODY.m, GAINS.kv[0], GAINS.kp[0]])
    expected = np.r_[circle_eigenvalues(BODY, R_, theta), s24 + 1j * theta, s24 - 1j * theta]
    got = st.eigenvalues
    assert len(got) == 6
    for lam in expected:
        assert np.min(np.abs(got - lam)) < 5e-9  # measured 5.5e-10


@pytest.mark.parametrize("w_phi", [0.3, 1.0, 2.5])
def test_eigenvalues_match_a_linearisation_by_simulating_perturbations(w_phi):
    # independent route: the flow map over tau seconds of the inertial closed loop
    # (lib.simulate, DOP853 at 1e-12), differentiated by central differences of step 1e-4 in the
    # rotating frame; its eigenvalues are exp(lambda tau). Differencing error ~ step^2 and
    # tolerance / step ~ 1e-8: the multipliers agree to 1e-8 (measured 9.6e-10).
    st = circle_steady_state(BODY, GAINS, R, THETA, (1.0, 1.0, w_phi))
    tau, d = 1.0, 1e-4
    Phi = np.empty((6, 6))
    for i in range(6):
        e = np.zeros(6)
        e[i] = d
        Phi[:, i] = (_flow(w_phi, st.state + e, tau)[-1] - _flow(w_phi, st.state - e, tau)[-1]) / (2 * d)
    mu = np.linalg.eigvals(Phi)
    for m in np.exp(st.eigenvalues * tau):
        assert np.min(np.abs(mu - m)) < 1e-8  # measured 9.6e-10
    # and a different difference step of the field itself
    # the same field's Jacobian with a 100 times larger step: agree to 3.5e-8 (measured 3.6e-9)
    lam = np.linalg.eigvals(_jacobian(_loop(BODY, GAINS, R, THETA, (1.0, 1.0, w_phi)), THETA, st.state, h=1e-4))
    for m in st.eigenvalues:
        assert np.min(np.abs(lam - m)) < 3.5e-8  # measured 3.6e-9


def test_steady_state_is_an_equilibrium_of_the_simulated_loop():
    st = circle_steady_state(BODY, GAINS, R, THETA, (1.0, 1.0, 1.0))
    y = _flow(1.0, st.state, 20.0)[-1]
    # accuracy: 100 x the simulation's rtol = atol = 1e-12 over 20 s, plus the steady state's
    # Newton residual 1e-13 times |J^-1| = 19: 1e-10 (measured 3.1e-14)
    assert np.max(np.abs(y - st.state)) < 1e-10


def test_limit_is_a_hopf_point_just_before_the_fold(limit):
    assert limit.kind in LIMIT_KINDS
    assert limit.kind == "complex pair" and 2.0 < limit.w_phi < 4.0
    # accuracy: brentq brackets log w_phi to xtol = rtol / 4 = 2.5e-7, and there Re lambda
    # changes by 1.05 per unit of log w_phi (measured), so |Re lambda| <= 2.6e-7; 1e-6 bounds it
    # on any machine (measured 7.8e-12 here, 3.5e-10 on another);
    # reason: Im > 0.05 is a property (measured 0.19)
    assert abs(limit.eigenvalue.real) < 1e-6 and abs(limit.eigenvalue.imag) > 0.05
    # the crossing itself: 40 x xtol either side, the largest real part changes sign
    below = circle_steady_state(BODY, GAINS, R, THETA, (1.0, 1.0, limit.w_phi * (1 - 1e-5)))
    above = circle_steady_state(BODY, GAINS, R, THETA, (1.0, 1.0, limit.w_phi * (1 + 1e-5)))
    assert below.max_real < 0 < above.max_real


def _max_real_by_another_jacobian(w_phi, h=1e-4):
    """The largest real part of the eigenvalues at the steady state for w_phi, from a
    Jacobian with 100 times the library's difference step, unsorted: no eigenvalue order."""
    st = circle_steady_state(BODY, GAINS, R, THETA, (1.0, 1.0, w_phi))
    lam = np.linalg.eigvals(_jacobian(_loop(BODY, GAINS, R, THETA, (1.0, 1.0, w_phi)), THETA, st.state, h=h))
    return lam[np.argmax(lam.real)]


def test_limit_and_its_eigenvalues_agree_with_an_independent_root_of_the_largest_real_part(limit):
    # Chapter 6's exact limit, on every machine: the root of max Re lambda(w_phi) found again by
    # brentq (xtol 1e-9 in log w_phi) on eigenvalues taken from another Jacobian (step 1e-4, not
    # 1e-6; its error moves the root by about 1e-8) with no sorting of the eigenvalues. A sort by
    # modulus instead of by real part would put the limit at 3.185, "fold" (issue 28).
    from scipy.optimize import brentq

    w = limit.w_phi
    logw = brentq(lambda x: _max_real_by_another_jacobian(math.exp(x)).real,
                  math.log(w) - 1e-4, math.log(w) + 1e-4, xtol=1e-9)
    # accuracy: the limit's own rtol (1e-6) plus the independent root's (1e-9) and its
    # Jacobian's shift (1e-8): 2 x rtol (measured 8.8e-10)
    assert limit.w_phi == pytest.approx(math.exp(logw), rel=2 * limit.rtol, abs=0)
    assert round(limit.w_phi, 3) == 3.130 and limit.kind == "complex pair"   # Chapter 6's value
    # the critical eigenvalue: Im lambda moves by |dIm/dlog w| (< 1) times the roots' distance
    # (< 2e-6) plus the two Jacobians' difference (measured 4.3e-9); accuracy: 1e-5
    lam = _max_real_by_another_jacobian(w)
    assert abs(limit.eigenvalue.imag) == pytest.approx(abs(lam.imag), abs=1e-5)  # accuracy: as above
    assert abs(lam.real) < 1e-5 and limit.eigenvalue == limit.steady.eigenvalues[0]  # accuracy: as above
    # and the whole spectrum at the limit, eigenvalue by eigenvalue (accuracy: the two
    # Jacobians differ by 1e-8 relative in the entries; measured 4.3e-9)
    other = np.linalg.eigvals(_jacobian(_loop(BODY, GAINS, R, THETA, (1.0, 1.0, w)), THETA, limit.steady.state, h=1e-4))
    for m in limit.steady.eigenvalues:
        assert np.min(np.abs(other - m)) < 1e-6  # accuracy: as above
    # sorted by decreasing real part, the critical pair first
    assert np.all(np.diff(limit.steady.eigenvalues.real) <= 0)


def test_simulation_decays_below_the_limit_and_leaves_above(limit):
    # from the steady state plus 1e-3 (m, m, rad) on the position and the heading, in the
    # rotating frame. Measure: the largest deviation of (xi, eta, p) from the steady state.
    # At 0.97 of the limit the slowest pair has max Re = -0.024 1/s and Im = 0.25 rad/s (a
    # period of 25 s): over the window [75, 100] s the deviation must be below half of that over
    # [0, 25] s (expected exp(-0.024 * 75) = 0.16; measured 0.16). At 1.03 there is no steady
    # state on the branch (it folds just above the limit) and the body drifts away from the
    # limit's steady state: after 30 s the deviation exceeds 100 times the start (measured
    # 7.9 m).
    d0 = np.array([1e-3, 1e-3, 1e-3, 0.0, 0.0, 0.0])
    lo = circle_steady_state(BODY, GAINS, R, THETA, (1.0, 1.0, 0.97 * limit.w_phi))
    t_eval = np.linspace(0.0, 100.0, 201)
    dev = np.abs(_flow(0.97 * limit.w_phi, lo.state + d0, 100.0, t_eval, tol=1e-9) - lo.state)[:, :3].max(1)
    assert dev[t_eval >= 75].max() < 0.5 * dev[t_eval <= 25].max()
    with pytest.raises(RuntimeError):
        circle_steady_state(BODY, GAINS, R, THETA, (1.0, 1.0, 1.03 * limit.w_phi))
    ref = limit.steady.state
    dev = np.abs(_flow(1.03 * limit.w_phi, ref + d0, 30.0, tol=1e-9) - ref)[:, :3].max()
    assert dev > 100 * 1e-3  # reason: a property (measured 7.9)


@pytest.mark.parametrize("w_phi", [0.0, 1.0, 3.0])
def test_steady_state_does_not_depend_on_the_time_of_the_frame(w_phi):
    st = [circle_steady_state(BODY, GAINS, R, THETA, (1.0, 1.0, w_phi), t=t) for t in (0.0, 1.7, 123.4)]
    for s in st[1:]:
        # accuracy: each is Newton's, polished to a residual of 1e-13 (_solve), times |J^-1|
        # (19 at the limit): 1e-11 (measured 8.9e-15)
        assert np.max(np.abs(s.state - st[0].state)) < 1e-11
        assert np.max(np.abs(s.eigenvalues - st[0].eigenvalues)) < 2.5e-7  # measured 2.3e-8
    rng = np.random.default_rng(3)
    y = st[0].state + rng.normal(scale=0.3, size=(20, 6))
    f = [rotating_field(BODY, GAINS, R, THETA, (1.0, 1.0, w_phi), y, t) for t in (0.0, 2.9, -41.0)]
    assert np.max(np.abs(f[1] - f[0])) < 1e-12 and np.max(np.abs(f[2] - f[0])) < 1e-12  # measured 3.2e-14 and 9.5e-14


def test_the_frames_are_inverse():
    rng = np.random.default_rng(0)
    y = rng.normal(size=(10, 6))
    assert np.allclose(inertial_to_rotating(rotating_to_inertial(y, THETA, 3.3), THETA, 3.3), y, rtol=0, atol=5e-15)  # exact: two closed forms, inverse; measured 4.4e-16


def test_steady_error_crosses_the_tolerance_of_held_inside_the_simulated_bracket():
    # the chapter's grid brackets "held" between 0.365 and 0.383 (refined); the exact crossing of
    # the steady error through 0.1 R must lie near it, and the error must be monotone below it
    w = circle_error_weight(BODY, GAINS, R, THETA, 0.1 * R)
    assert abs(circle_steady_state(BODY, GAINS, R, THETA, (1, 1, w)).position_error - 0.1 * R) < 2.5e-10  # measured 2.3e-11
    sweep = circle_weight_sweep(BODY, GAINS, R, THETA, np.linspace(0, w, 12))
    assert np.all(np.diff(sweep.position_error) > 0) and sweep.stable.all()


def test_sweep_is_the_steady_state_at_each_weight_and_marks_the_end_of_the_branch(limit):
    wp = np.array([1.0, 0.0, 10.0, 0.5])
    d = circle_weight_sweep(BODY, GAINS, R, THETA, wp)
    assert list(d.w_phi) == list(wp)
    st = circle_steady_state(BODY, GAINS, R, THETA, (1, 1, 0.5))
    assert abs(d.position_error[3] - st.position_error) < 1e-14 and abs(d.max_real[3] - st.max_real) < 1e-14  # exact: one code path, a sweep and one point; measured 0
    assert np.isnan(d.heading[2]) and not d.stable[2]


def test_weighting_re_exports_the_exact_circle():
    assert weighting.circle_weight_limit is circle_weight_limit
    assert weighting.circle_steady_state is circle_steady_state


@pytest.mark.parametrize("kwargs, error, match", [
    (dict(weights=(1.0, 2.0, 0.1)), ValueError, "w_x = w_y"),
    (dict(weights=(0.0, 0.0, 1.0)), ValueError, "w_x = w_y > 0"),
    (dict(weights=(1.0, 1.0, -1.0)), ValueError, "non-negative"),
    (dict(weights=(1.0, 1.0)), ValueError, "three"),
    (dict(weights="abc"), ValueError, "three"),
    (dict(R=-1.0), ValueError, "R must be"),
    (dict(R=float("nan")), ValueError, "R must be"),
    (dict(Theta=0.0), ValueError, "Theta must be"),
    (dict(R=0.5 * circle_critical_radius(BODY, THETA)), ValueError, "critical radius"),
    (dict(gains=Gains(kp=(5.2, 4.0, 5.2))), ValueError, "equal gains"),
    (dict(gains=(5.2, 3.2)), TypeError, "Gains"),
    (dict(body="body"), TypeError, "Body"),
    (dict(t=float("inf")), ValueError, "finite time"),
])
def test_bad_inputs_are_refused_with_a_clear_error(kwargs, error, match):
    args = dict(body=BODY, gains=GAINS, R=R, Theta=THETA, weights=(1.0, 1.0, 0.5))
    args.update(kwargs)
    with pytest.raises(error, match=match):
        circle_steady_state(**args)


def test_limit_arguments_are_checked():
    with pytest.raises(ValueError, match="rtol"):
        circle_weight_limit(BODY, GAINS, R, THETA, rtol=0.5)
    with pytest.raises(ValueError, match="w_max"):
        circle_weight_limit(BODY, GAINS, R, THETA, w_max=-1)
    with pytest.raises(RuntimeError, match="stays stable"):
        circle_weight_limit(BODY, GAINS, R, THETA, w_max=1.0)
    with pytest.raises(ValueError, match="w_phi"):
        circle_weight_sweep(BODY, GAINS, R, THETA, [-1.0])
