"""The periodic LQR tracker of :mod:`lib.optimal.tracker`, proved on an exact periodic motion:
the paper's circle (27) run at the stable equilibrium p0 of (33), where F and beta are constant.

Its linearisation is time-invariant in a frame turning with the path, so the periodic Riccati
solution and the loop's Floquet multipliers have an independent route through the algebraic
Riccati equation (scipy) and a matrix exponential.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg import expm, solve_continuous_are

from lib.allocation import Limits
from lib.integrators.smooth import SimulationError
from lib.angles import wrap_angle
from lib.model import config_accel, generalized_force
from lib.optimal import tracker
from lib.optimal.tracker import RICCATI_SETTLE, RTOL, jacobians, periodic_lqr, track_motion
from lib.optimal.verdict import motion_verdict
from lib.params import PAPER_DZ0, PAPER_Z0, Body
from lib.rotation.circle import circle_equilibria

R_PATH, THETA = 2.0, math.pi / 4


class _CircleMotion:
    """The circle's steady motion: C on C_d = R (cos Th t, sin Th t), phi = Th t + pi/2 + p0,
    F = |m C_d'' + c C_d'| = R Th sqrt(m^2 Th^2 + c^2), beta = arg(m C_d'' + c C_d') - phi."""

    kind, turns = "circle", 1

    def __init__(self, body: Body, F_max=None, beta_max=None):
        self.R, self.Theta, self.F_max, self.beta_max = R_PATH, THETA, F_max, beta_max
        self.period = 2 * math.pi / THETA
        self.p0 = circle_equilibria(body, R_PATH, THETA)[0]
        self.F = R_PATH * THETA * math.hypot(body.m * THETA, body.c)
        self.beta = math.atan2(body.c, -body.m * THETA) - math.pi / 2 - self.p0
        self.calls = 0
        self.poison = False

    def state(self, t):
        self.calls += 1
        t = np.asarray(t, dtype=float)
        c, s = np.cos(THETA * t), np.sin(THETA * t)
        z = np.stack([R_PATH * c, R_PATH * s, THETA * t + math.pi / 2 + self.p0], -1)
        dz = np.stack([-R_PATH * THETA * s, R_PATH * THETA * c, np.full(t.shape, THETA)], -1)
        return z, dz

    def inputs(self, t):
        t = np.asarray(t, dtype=float)
        F = np.full(t.shape, self.F)
        if self.poison:
            F = np.where(t > 0.5, np.nan, F)
        return F, np.full(t.shape, self.beta)


@pytest.fixture(scope="module")
def body():
    return Body()


@pytest.fixture(scope="module")
def motion(body):
    return _CircleMotion(body)


@pytest.fixture(scope="module")
def lqr(body, motion):
    return periodic_lqr(body, motion)


def _x(motion, t):
    z, dz = motion.state(t)
    return np.concatenate([z, dz], -1)


def _rotating_frame(body, motion, lqr, t):
    """G(t) (turning the position and velocity blocks by Theta t) and the constant
    A_r = G'(A G - G_dot), B_r = G' B of the linearisation in the turning frame."""
    c, s = math.cos(THETA * t), math.sin(THETA * t)
    G = np.eye(6)
    G[:2, :2] = G[3:5, 3:5] = [[c, -s], [s, c]]
    J = np.zeros((6, 6))
    J[0, 1] = J[3, 4] = -1.0
    J[1, 0] = J[4, 3] = 1.0
    F, beta = motion.inputs(np.asarray(t))
    A, B = jacobians(body, _x(motion, np.asarray(t)), np.stack([F, beta], -1))
    return G, G.T @ (A @ G - THETA * G @ J), G.T @ B


def test_the_test_motion_solves_the_open_loop_model(body, motion):
    # the motion's own accelerations are those of (2)-(4) under its inputs (closed form vs model)
    t = np.linspace(0.0, motion.period, 7)
    z, dz = motion.state(t)
    ddz = np.stack([-R_PATH * THETA**2 * np.cos(THETA * t), -R_PATH * THETA**2 * np.sin(THETA * t),
                    np.zeros_like(t)], -1)
    F, beta = motion.inputs(t)
    # exact: a closed form against the model's few flops, rounding only (measured 2.5e-15)
    np.testing.assert_allclose(config_accel(body, z, dz, F, beta), ddz, rtol=0, atol=1e-12)


def test_analytic_jacobians_match_central_differences_of_config_accel(body):
    # truncation O(h^2) ~ 1e-12 and rounding ~ eps |f| / h ~ 1e-10 for h = 1e-6: 1e-7 bounds both
    rng = np.random.default_rng(7)
    h = 1e-6
    for _ in range(5):
        x = rng.uniform(-3, 3, 6)
        u = np.array([rng.uniform(-1, 5), rng.uniform(-np.pi, np.pi)])
        A, B = jacobians(body, x, u)

        def f(x, u):
            return np.concatenate([x[3:], config_accel(body, x[:3], x[3:], u[0], u[1])])

        A_num = np.stack([(f(x + h * e, u) - f(x - h * e, u)) / (2 * h) for e in np.eye(6)], -1)
        B_num = np.stack([(f(x, u + h * e) - f(x, u - h * e)) / (2 * h) for e in np.eye(2)], -1)
        # accuracy: central differences at h = 1e-6, truncation ~1e-12 and rounding ~1e-10, times
        # 1000 (measured 1.9e-9)
        np.testing.assert_allclose(A, A_num, rtol=0, atol=1e-7)
        np.testing.assert_allclose(B, B_num, rtol=0, atol=1e-7)  # accuracy: as A's above


def test_jacobians_broadcast_over_leading_axes(body):
    x = np.zeros((4, 6))
    A, B = jacobians(body, x, [2.0, 0.1])
    assert A.shape == (4, 6, 6) and B.shape == (4, 6, 2)
    np.testing.assert_array_equal(A[0], jacobians(body, x[0], [2.0, 0.1])[0])


def test_periodic_riccati_solution_repeats_and_matches_the_turning_frame_are(body, motion, lqr):
    # P(T) = P(0) to the settling tolerance it was integrated to
    assert lqr.repeat < RICCATI_SETTLE
    assert np.linalg.norm(lqr.P[-1] - lqr.P[0]) / np.linalg.norm(lqr.P[0]) < RICCATI_SETTLE
    # in the turning frame the problem is time-invariant (the default Q is invariant under the
    # turn), so P(t) = G(t) P_are G(t)'; agreement to 10 settling tolerances plus 100 RTOL
    _, A_r, B_r = _rotating_frame(body, motion, lqr, 0.0)
    P_are = solve_continuous_are(A_r, B_r, lqr.Q, lqr.R)
    for t in (0.0, 1.3, 5.0, 7.9, 8.0 * 3 + 2.2):
        G, A_t, B_t = _rotating_frame(body, motion, lqr, t)
        # exact: an identity, the frame makes it constant; rounding only (measured 5.4e-15)
        np.testing.assert_allclose(A_t, A_r, rtol=0, atol=1e-12)      # the frame makes it constant
        np.testing.assert_allclose(B_t, B_r, rtol=0, atol=1e-12)  # exact: as A's above
        err = np.abs(lqr.riccati(t) - G @ P_are @ G.T).max() / np.abs(P_are).max()
        assert err < 10 * RICCATI_SETTLE + 100 * RTOL, (t, err)


def test_linearised_closed_loop_multipliers_lie_inside_the_unit_circle_as_the_are_predicts(body, motion, lqr):
    assert np.all(np.abs(lqr.multipliers) < 1.0)
    _, A_r, B_r = _rotating_frame(body, motion, lqr, 0.0)
    K_r = np.linalg.solve(lqr.R, B_r.T @ solve_continuous_are(A_r, B_r, lqr.Q, lqr.R))
    # G(T) = G(0): the monodromy matrix is exp((A_r - B_r K_r) T), up to the frame
    expected = np.sort(np.abs(np.linalg.eigvals(expm((A_r - B_r @ K_r) * motion.period))))
    # accuracy: the monodromy is integrated at atol = RTOL: entries good to ~1e-9, so 100 RTOL
    # (measured 1.4e-11)
    np.testing.assert_allclose(np.sort(np.abs(lqr.multipliers)), expected, rtol=0, atol=100 * RTOL)


def test_gain_is_periodic_and_is_r_inverse_b_transpose_p(body, motion, lqr):
    t = np.array([0.3, 4.1])
    # exact: one code path, t + 2 T reduced modulo the period (its rounding only; measured 4.8e-15)
    np.testing.assert_allclose(lqr.gain(t + 2 * motion.period), lqr.gain(t), rtol=0, atol=1e-12)
    F, beta = motion.inputs(t)
    _, B = jacobians(body, _x(motion, t), np.stack([F, beta], -1))
    # exact: the formula the gain evaluates (a solve against an inverse: rounding only; measured 0)
    np.testing.assert_allclose(lqr.gain(t), np.linalg.inv(lqr.R) @ np.swapaxes(B, -1, -2) @ lqr.riccati(t),
                               rtol=1e-12, atol=1e-12)


def test_loop_started_on_the_motion_stays_on_it(body, motion, lqr):
    z0, dz0 = motion.state(np.asarray(0.0))
    res = track_motion(body, motion, 2 * motion.period, z0=z0, dz0=dz0, lqr=lqr)
    z, dz = motion.state(res.t)
    # accuracy: the integrator's error at rtol = atol = RTOL over two periods of an attracting loop:
    # 1e3 RTOL (measured 2.6e-11)
    assert np.abs(res.z - z).max() < 1e3 * RTOL
    assert np.abs(res.dz - dz).max() < 1e3 * RTOL  # accuracy: 1e3 x RTOL, as above
    # accuracy: 1e3 x RTOL, as above
    assert np.abs(res.F - motion.F).max() < 1e3 * RTOL and np.abs(res.beta - motion.beta).max() < 1e3 * RTOL
    # the reference in the result is the path's, and tau is the force applied
    # exact: the same closed form R (cos Th t, sin Th t), rounding only (measured 0)
    np.testing.assert_allclose(res.z_d[:, :2], z[:, :2], rtol=0, atol=1e-12)
    # exact: one code path, the same generalized_force of the same F, beta and phi
    np.testing.assert_allclose(res.tau, generalized_force(res.F, res.beta, res.z[:, 2]) * [1, 1, body.a],
                               rtol=0, atol=1e-15)


def test_loop_from_the_paper_start_converges_at_the_rate_of_the_largest_multiplier(body, motion, lqr):
    T = motion.period
    res = track_motion(body, motion, 4 * T, lqr=lqr, t_eval=np.arange(5) * T)
    x = np.concatenate([res.z, res.dz], 1)
    d = np.abs(x - _x(motion, res.t)).max(axis=1)
    assert d[0] > 1.0                                             # 1 m and 1.13 rad off at t = 0
    # reason: a property, four periods contract by about |mu_1|^4 (measured 4.2e-9)
    assert d[-1] < 1e-6 * d[0]
    # independent route: the nonlinear run contracts per period as the linearised loop's |mu_1|
    ratio = d[3] / d[2]
    rho = np.abs(lqr.multipliers[0])
    assert 0.5 * rho < ratio < 1.5 * rho, (ratio, rho)


def test_motion_verdict_finds_the_motion_as_an_attracting_orbit_reached_from_the_paper_start(
        body, motion, lqr):
    v = motion_verdict(body, motion, lqr=lqr, periods=4)
    assert v.regime == "periodic" and v.reason == ""
    assert np.all(np.abs(v.multipliers) < 1.0)
    # the motion is an exact orbit of the unclipped loop: Newton's point is the motion's state
    assert np.abs(v.offset).max() < 100 * tracker.NEWTON_TOL
    # the multipliers of the nonlinear period map (difference Jacobian) are the linearised loop's
    # (variational route); accuracy: the differences of step 1e-5 are good to ~1e-6, times 10
    # (measured 1.4e-9)
    np.testing.assert_allclose(np.sort(np.abs(v.multipliers)), np.sort(np.abs(lqr.multipliers)), rtol=0, atol=1e-5)
    assert v.reached.shape == (7,) and v.reached[0]
    assert v.distance[0] < tracker.REACH_FLOOR


def test_the_fixed_step_period_map_decides_alike(body, motion, lqr):
    # RK4 with 256 steps a period (h = 0.03 s): its map's orbit and multipliers differ from the
    # adaptive map's by the method's O(h^4) error, ~1e-6 on these states and multipliers
    v = motion_verdict(body, motion, lqr=lqr, periods=4, steps=256)
    assert v.regime == "periodic" and v.reached[0]
    # accuracy: 100 x RK4's O(h^4) ~1e-6 (measured 1.7e-6)
    assert np.abs(v.offset).max() < 1e-4
    # accuracy: 100 x RK4's O(h^4) ~1e-6 (measured 3.3e-9)
    np.testing.assert_allclose(np.sort(np.abs(v.multipliers)), np.sort(np.abs(lqr.multipliers)), rtol=0, atol=1e-4)


def test_angle_limit_tighter_than_the_motion_s_beta_holds_in_the_result(body, motion, lqr):
    cap, limit = 4.0, 0.05
    assert abs(motion.beta) > limit                               # the limit bites on the motion
    res = track_motion(body, motion, motion.period, lqr=lqr, limits=Limits(force=cap, angle=limit))
    assert np.all(np.isfinite(res.z))
    assert np.all(np.abs(res.beta) <= limit) and np.all((res.F >= 0) & (res.F <= cap))
    # exact: the clip returns the limit itself
    assert np.isclose(np.abs(res.beta).max(), limit, rtol=0, atol=0)   # active, not just satisfied


def test_the_motion_s_own_limits_apply_when_no_limits_are_given(body):
    m = _CircleMotion(body, F_max=2.7, beta_max=0.05)
    res = track_motion(body, m, 2.0, t_eval=np.linspace(0, 2.0, 41))
    assert np.all(np.abs(res.beta) <= 0.05) and np.all(res.F <= 2.7)
    assert np.abs(res.beta).max() == 0.05 and res.F.max() == 2.7


def test_without_an_angle_limit_a_negative_force_turns_round_and_applies_the_same_force():
    F, beta = np.array([-2.0, 1.5, -0.3]), np.array([0.3, -2.0, 3.0])
    F2, beta2 = tracker._saturate(F, beta, math.inf, None)
    assert np.all(F2 >= 0) and np.all(np.abs(beta2) <= np.pi)
    phi = np.array([0.1, 2.0, -1.0])
    # exact: the generalised force (22), torque included, is unchanged: the flip is exact (an
    # identity, up to the rounding of beta +- pi; measured 5.6e-17)
    np.testing.assert_allclose(generalized_force(F2, beta2, phi), generalized_force(F, beta, phi), rtol=0, atol=1e-14)


def test_a_non_finite_loop_raises_a_simulation_error_naming_the_time(body):
    m = _CircleMotion(body)
    gain = periodic_lqr(body, m, samples=64)
    m.poison = True                                               # F* is NaN after t = 0.5 s
    with pytest.raises(SimulationError, match=r"t = 0\.5"):
        track_motion(body, m, 2.0, lqr=gain)


BAD = [
    (dict(body="body"), TypeError, "body"),
    (dict(motion=object()), TypeError, "motion must have"),
    (dict(t_end=-1.0), ValueError, "t_end"),
    (dict(limits=(4.0, 0.5)), TypeError, "limits"),
    (dict(z0=[1.0, 0.0]), ValueError, "z0"),
    (dict(dz0=[0.0, np.nan, 0.0]), ValueError, "dz0"),
    (dict(Q=np.ones((6, 6)) - 2 * np.eye(6)), ValueError, "Q must be positive semi-definite"),
    (dict(Q=np.triu(np.ones((6, 6)))), ValueError, "Q must be symmetric"),
    (dict(Q=[1, 1, 1, -1, 1, 1]), ValueError, r"Q\[3\]"),
    (dict(R_weight=[1.0, 0.0]), ValueError, r"R_weight\[1\]"),
    (dict(R_weight=np.eye(3)), ValueError, "R_weight must have shape"),
    (dict(t_eval=[0.0, 3.0, 2.0]), ValueError, "t_eval"),
]


@pytest.mark.parametrize("bad, error, match", BAD)
def test_track_motion_rejects_a_bad_argument_by_name_before_any_work(body, bad, error, match):
    m = _CircleMotion(body)
    args = dict(body=body, motion=m, t_end=4.0) | bad
    with pytest.raises(error, match=match):
        track_motion(args.pop("body"), args.pop("motion"), args.pop("t_end"), **args)
    assert m.calls <= 1                                           # one sample to check the motion


def test_a_bad_motion_attribute_is_named(body):
    for attr, value, match in (("kind", "square", "motion.kind"), ("period", 0.0, "motion.period"),
                               ("turns", 1.0, "motion.turns"), ("beta_max", 4.0, "motion.beta_max")):
        m = _CircleMotion(body)
        setattr(m, attr, value)
        with pytest.raises((TypeError, ValueError), match=match):
            periodic_lqr(body, m)


def test_motion_verdict_and_periodic_lqr_reject_bad_arguments_by_name(body, motion, lqr):
    other = _CircleMotion(body)
    cases = [(lambda: motion_verdict(body, motion, starts=np.zeros((2, 5))), ValueError, "starts"),
             (lambda: motion_verdict(body, motion, periods=1), ValueError, "periods"),
             (lambda: motion_verdict(body, motion, lqr="gain"), TypeError, "lqr"),
             (lambda: motion_verdict(body, other, lqr=lqr), ValueError, "lqr must be"),
             (lambda: motion_verdict(body, motion, h=0.0), ValueError, "h must be"),
             (lambda: track_motion(body, motion, 1.0, lqr=lqr, Q=np.eye(6)), ValueError, "either lqr"),
             (lambda: periodic_lqr(body, other, samples=4), ValueError, "samples"),
             (lambda: periodic_lqr(Body(m=3.0), other, R_weight=[[1, 2], [2, 1]]), ValueError, "R_weight")]
    for call, error, match in cases:
        with pytest.raises(error, match=match):
            call()
    assert other.calls <= 3                                       # validation samples only


def test_default_starts_are_the_paper_start_and_its_shifts():
    s = tracker.DEFAULT_STARTS
    base = np.concatenate([PAPER_Z0, PAPER_DZ0])
    assert s.shape == (7, 6) and np.array_equal(s[0], base)
    # exact: shifts of 0.5 and pi/2, up to the rounding of base + shift - base (default rtol 1e-7)
    np.testing.assert_allclose(np.abs(s[1:] - base).max(axis=1), [0.5, 0.5, 0.5, 0.5, np.pi / 2, np.pi / 2])


def _random_collocated_lqr(body, seed):
    """A collocated motion with random polynomials and inputs, and an LQR with a random grid of P
    (the rates need no solution)."""
    from lib.optimal.motion import PeriodicMotion
    rng = np.random.default_rng(seed)
    nodes, degree, T = 8, 3, 5.0
    motion = PeriodicMotion(t=np.arange(nodes) * T / nodes, z=np.zeros((nodes, 3)), dz=np.zeros((nodes, 3)),
                            F=rng.uniform(0.5, 3, nodes), beta=rng.uniform(-1, 1, nodes), max_error=0.0,
                            rms_error=0.0, period=T, kind="circle", R=2.0, Theta=2 * np.pi / T, F_max=None,
                            beta_max=None, nodes=nodes, degree=degree, turns=1, starts=(),
                            collocation=rng.normal(size=(nodes, degree + 1, 6)))
    grid = np.union1d(np.linspace(0, T, 33), motion.t)
    P = rng.normal(size=(grid.size, 6, 6))
    return tracker.PeriodicLQR(body, motion, tracker.DEFAULT_Q, tracker.DEFAULT_R, grid, P + np.swapaxes(P, 1, 2),
                               rng.normal(size=(grid.size - 1, 2, 6, 6)), 1, 0.0, np.zeros(6))


def test_the_compiled_riccati_rhs_is_the_numpy_one_on_a_collocated_motion(body):
    """lib.optimal.riccati against the numpy right-hand sides it compiles (the Riccati equation's,
    the linearised closed loop's), on a motion with collocation polynomials and piecewise-constant
    inputs and an LQR with a random grid of P (random: the rhs needs no solution), at times
    inside, on and beyond the nodes, with heading turns."""
    from lib.optimal.riccati import closed_loop_rhs, riccati_rhs
    lqr = _random_collocated_lqr(body, 8)
    motion, nodes, T = lqr.motion, lqr.motion.nodes, lqr.motion.period
    rng = np.random.default_rng(9)
    Q, R_inv = tracker.DEFAULT_Q, np.linalg.inv(tracker.DEFAULT_R)
    fast = riccati_rhs(body, motion, Q, R_inv)
    for t in np.r_[rng.uniform(-7, 13, 40), np.arange(-2, 18) * T / nodes]:
        P = rng.normal(size=(6, 6))
        P = P + P.T
        t_in = T / nodes * (np.floor(t * nodes / T) + 0.5)           # inside t's input piece
        A, B = tracker._jacobians(body, *tracker._reference(motion, t, t_in))
        want = tracker._riccati_rate(A, B, P, R_inv, Q).ravel()
        # accuracy: the same formulas in their order, compiled (the polynomial's sum over the basis
        # written out where numpy's einsum may sum otherwise, the products summed in order where BLAS
        # may pair or fuse terms): measured within 3.5e-13 on values up to 8e2 over 60 times here;
        # the bound allows rounding of terms up to 3e3
        np.testing.assert_allclose(fast(t, P.ravel(), t_in), want, rtol=1e-12, atol=1e-11)
    assert riccati_rhs(body, _CircleMotion(body), Q, R_inv) is None   # no polynomials: the numpy rhs
    loop = closed_loop_rhs(lqr)
    for t in np.r_[rng.uniform(-7, 13, 40), lqr.t[:-1], lqr.t[1:] + 2 * T]:
        Y = rng.normal(size=(6, 6))
        t_in = T / nodes * (np.floor(t * nodes / T) + 0.5)
        x, u = tracker._reference(motion, t, t_in)
        A, B = tracker._jacobians(body, x, u)
        want = ((A - B @ lqr._gain(t, x, u)) @ Y).ravel()
        # accuracy: as above (the gain's 2 x 2 solve by LU with partial pivoting, as LAPACK's, written
        # out): measured within 2.3e-13 on values up to 1.3e3 here
        np.testing.assert_allclose(loop(t, Y.ravel(), t_in), want, rtol=1e-12, atol=1e-11)
    assert closed_loop_rhs(tracker.periodic_lqr(body, _CircleMotion(body))) is None



@pytest.mark.parametrize("F_max, beta_max", [(math.inf, None), (2.5, None), (math.inf, 0.5), (2.0, 0.3)])
def test_the_compiled_loop_is_the_numpy_one_on_a_collocated_motion(body, F_max, beta_max, monkeypatch):
    """lib.optimal.riccati.loop_rhs against the numpy rates of the clipped closed loop it compiles
    (tracker._loop with the compiled path switched off), rows of states far from the motion, at
    times inside, on and beyond the nodes, with and without each limit; the demands met include
    negative forces (flipped without an angle limit), forces above the cap and angles beyond
    the limit, so every branch of the clip is compared."""
    lqr = _random_collocated_lqr(body, 11)
    T, nodes = lqr.motion.period, lqr.motion.nodes
    fast = tracker._loop(lqr, F_max, beta_max, 5)
    monkeypatch.setattr(tracker, "loop_rhs", lambda *args: None)           # the numpy rates
    slow = tracker._loop(lqr, F_max, beta_max, 5)
    rng = np.random.default_rng(12)
    demands = []
    for t in np.r_[rng.uniform(-7, 13, 30), lqr.t[1:-1], lqr.t[1:-1] + 2 * T]:
        lo = T / nodes * np.floor(t * nodes / T)
        hi = lo + T / nodes
        X = rng.normal(scale=2.0, size=(5, 6))
        want = slow(lo, hi)(t, X.ravel())
        # accuracy: the same formulas in their order, compiled, except u* - K (x - x*), summed in
        # order where numpy's einsum may pair its terms: rounding of terms up to 1e3 N, through a
        # clip that is continuous (a kink, not a jump), then cos and sin of the force's angle
        np.testing.assert_allclose(fast(lo, hi)(t, X.ravel()), want, rtol=1e-11, atol=1e-10)
        xs, us, K = tracker._loop_reference(lqr, t, tracker._inside(t, lo, hi))
        demands.append(us - np.einsum("ij,rj->ri", K, X - xs))
    U = np.concatenate(demands)
    beta = np.where(U[:, 0] < 0, U[:, 1] + np.pi, U[:, 1])
    assert (U[:, 0] < 0).sum() > 10 and (np.abs(U[:, 0]) > 2.5).sum() > 10
    assert (np.abs(wrap_angle(beta)) > 0.5).sum() > 10


def test_the_compiled_loop_raises_on_a_non_finite_rate(body):
    """A state that makes the rates non-finite is refused, naming the time."""
    lqr = _random_collocated_lqr(body, 13)
    X = np.zeros((2, 6))
    X[1, 0] = np.nan
    with pytest.raises(SimulationError, match="non-finite at t = 0.3"):
        tracker._loop(lqr, 2.0, 0.5, 2)(0.0, 0.625)(0.3, X.ravel())


@pytest.mark.parametrize("F_max, beta_max, match", [(0.0, None, "F_max"), (float("nan"), None, "F_max"),
                                                    (2.0, -0.1, "beta_max"), (2.0, 4.0, "beta_max")])
def test_the_compiled_loop_refuses_bad_limits(body, F_max, beta_max, match):
    from lib.optimal import riccati
    with pytest.raises(ValueError, match=match):
        riccati.loop_rhs(_random_collocated_lqr(body, 14), F_max, beta_max)



_RICCATI_CALLS = """
import sys
import numpy as np
sys.path.insert(0, "tests")
from test_optimal_tracker import _random_collocated_lqr
from lib.optimal import riccati, tracker
from lib.params import Body
lqr = _random_collocated_lqr(Body(), 8)
rhs = riccati.riccati_rhs(Body(), lqr.motion, tracker.DEFAULT_Q, np.linalg.inv(tracker.DEFAULT_R))
rhs(0.3, np.eye(6).ravel(), 0.3)
riccati.closed_loop_rhs(lqr)(0.3, np.eye(6).ravel(), 0.3)
riccati.loop_rhs(lqr, 2.0, 0.5)(0.3, np.zeros((2, 6)), 0.3)
riccati.loop_steps(lqr, 2.0, 0.5, [0.0, 0.1], [1], [0.1], [[0.0, 0.1]])(np.zeros((2, 6)), 1e8)
"""


def test_the_riccati_kernels_compile_once_each_on_a_fresh_clone(fresh_signatures):
    """On an empty numba cache every compiled function of lib.optimal.riccati is compiled for one
    signature: the small products' transposes are passed as typed flags, not literals, so their
    one helper is compiled once."""
    counts = fresh_signatures(_RICCATI_CALLS, ("lib.optimal.riccati",))
    assert counts["lib.optimal.riccati _mul"] == 1 and counts["lib.optimal.riccati _rhs"] == 1
    assert {k: n for k, n in counts.items() if n > 1} == {}
