"""Chapter 7: the centre of percussion, its zero dynamics and the law for P (lib.percussion)."""

import math

import numpy as np
import pytest
import sympy as sp
from scipy.linalg import expm

from lib.rotation import circle as circle_equilibria
from lib import model, percussion as pc, trajectories as tr
from lib.angles import wrap_angle
from lib.params import Body, Gains
from lib.simulate import simulate as paper_simulate

BODY, GAINS = Body(), Gains()
RNG = np.random.default_rng(30)


def _random_states(n=50):
    z = RNG.normal(size=(n, 3)) * [1.0, 1.0, 3.0]
    dz = RNG.normal(size=(n, 3))
    return z, dz, RNG.uniform(0.1, 5.0, n), RNG.uniform(-3, 3, n)


def test_sympy_point_is_minus_inertia_over_m_a_and_matches_numbers():
    d = pc.derive_point()
    S = d.sym
    assert sp.simplify(d.s_P + S["I"] / (S["m"] * S["a"])) == 0
    assert pc.centre_of_percussion(BODY) == pytest.approx(-BODY.I / (BODY.m * BODY.a), rel=1e-15)  # exact: the same closed form, one division
    assert sp.simplify(d.lateral_u2.subs(S["s"], d.s_P)) == 0


def test_point_acceleration_is_free_of_the_lateral_force_in_lib_model():
    z, dz, F, beta = _random_states()
    s = pc.centre_of_percussion(BODY)
    for db in (0.0, 0.7):
        # the same u1 = F cos beta, a different u2
        u1, u2 = F * np.cos(beta), F * np.sin(beta) + db
        Fb, bb = np.hypot(u1, u2), np.arctan2(u2, u1)
        ddz = model.config_accel(BODY, z, dz, Fb, bb)
        e1 = np.stack([np.cos(z[:, 2]), np.sin(z[:, 2])], -1)
        e2 = np.stack([-e1[:, 1], e1[:, 0]], -1)
        aP = ddz[:, :2] + s * ddz[:, 2:3] * e2 - s * dz[:, 2:3] ** 2 * e1
        _, dP = pc.point_state(BODY, z, dz)
        np.testing.assert_allclose(pc.point_accel(BODY, z[:, 2], dz[:, 2], dP, u1), aP, rtol=1e-12, atol=1e-12)  # exact: two algebraic forms of one expression, O(1) terms


def test_sympy_equation_of_P_matches_the_numeric_form():
    d = pc.derive_point()
    S = d.sym
    vals = {S["m"]: BODY.m, S["I"]: BODY.I, S["a"]: BODY.a, S["c"]: BODY.c, S["c_phi"]: BODY.c_phi}
    f = sp.lambdify([S["phi"], S["omega"], S["vx"], S["vy"], S["u1"]], d.accel.subs(vals), "numpy")
    z, dz, F, beta = _random_states(10)
    _, dP = pc.point_state(BODY, z, dz)
    for i in range(10):
        got = np.array(f(z[i, 2], dz[i, 2], dz[i, 0], dz[i, 1], F[i] * np.cos(beta[i])), float).ravel()
        want = pc.point_accel(BODY, z[i, 2], dz[i, 2], dP[i], F[i] * np.cos(beta[i]))
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12)  # exact: sympy's expression against numpy's


def test_lateral_drag_vanishes_exactly_when_the_drag_rates_agree():
    d = pc.derive_point()
    S = d.sym
    equal = {S["c"]: S["m"] * S["c_phi"] / S["I"]}
    assert sp.simplify(d.drag_lateral.subs(equal)) == 0
    assert sp.simplify(d.drag_lateral - d.s_P * d.mismatch * S["omega"]) == 0
    assert pc.drag_mismatch(BODY) == pytest.approx(0.3 - 1.0)  # exact: c/m - c_phi/I_C of the Table
    assert pc.lateral_drag_speed(BODY) == pytest.approx((BODY.c_phi * BODY.m - BODY.c * BODY.I) / (BODY.m**2 * BODY.a))  # exact: closed form


def test_static_feedback_is_singular_and_the_extension_regular_iff_drag_rates_differ():
    d = pc.derive_point()
    S = d.sym
    assert d.static.rank() == 1
    assert sp.simplify(d.extended_det + d.mismatch / S["m"] ** 2) == 0
    assert sp.simplify(d.extended_det.subs(S["c"], S["m"] * S["c_phi"] / S["I"])) == 0


def test_circle_steady_motion_matches_the_full_closed_loop():
    R, Th = 2.0, math.pi / 4
    ref = tr.circle(R, Th)
    res = pc.simulate(BODY, GAINS, ref, 60.0, t_eval=np.linspace(50, 60, 11))
    st = pc.circle_steady_motion(BODY, R, Th)
    # integration at rtol 1e-10 over 60 s; the transient has decayed by exp(-0.8 * 50)
    p = wrap_angle(res.z[:, 2] - ref.z(res.t)[:, 2])
    np.testing.assert_allclose(p, st.p, atol=1e-7)  # accuracy: 1000 x rtol 1e-10 over 60 s
    np.testing.assert_allclose(res.F, st.F, rtol=1e-7)  # accuracy: 1000 x rtol 1e-10
    np.testing.assert_allclose(np.hypot(res.z[:, 0], res.z[:, 1]), st.radius_C, rtol=1e-7)  # accuracy: 1000 x rtol 1e-10
    np.testing.assert_allclose(res.beta, st.beta, atol=1e-7)  # accuracy: 1000 x rtol 1e-10


def test_circle_rate_is_the_decay_of_the_zero_dynamics():
    R, Th = 1.0, 0.6
    st = pc.circle_steady_motion(BODY, R, Th)
    ref = tr.circle(R, Th)
    d0 = 1e-5
    t = np.array([0.0, 3.0 / abs(st.rate)])
    phi = pc.zero_dynamics_run(BODY, ref, t, math.pi / 2 + st.p + d0)
    d1 = phi[-1] - (Th * t[-1] + math.pi / 2 + st.p)
    # linearisation error O(d0) relative; integration at rtol 1e-11
    assert math.log(d1 / d0) / t[-1] == pytest.approx(st.rate, rel=1e-3)  # reason: the linearisation's error, O(d0 = 1e-5) relative, and 1e-11 integration


def test_below_the_lock_radius_the_heading_slips():
    Th = 0.3
    R_lock = pc.circle_lock_radius(BODY, Th)
    with pytest.raises(ValueError, match="R must be at least"):
        pc.circle_steady_motion(BODY, 0.5 * R_lock, Th)
    ref = tr.circle(0.5 * R_lock, Th)
    T = 2 * math.pi / Th
    phi = pc.zero_dynamics_run(BODY, ref, np.linspace(0, 10 * T, 11), math.pi / 2)
    p = phi - (Th * np.linspace(0, 10 * T, 11) + math.pi / 2)
    assert abs(p[-1] - p[0]) > 2 * math.pi
    st = pc.circle_steady_motion(BODY, 1.001 * R_lock, Th)
    assert st.rate < 0


def test_lock_radius_is_below_the_papers_critical_radius():
    for Th in (0.1, 0.5, 1.5):
        ours, paper = pc.circle_lock_radius(BODY, Th), circle_equilibria.circle_critical_radius(BODY, Th)
        factor = BODY.c_phi / (BODY.c_phi - BODY.c * BODY.I / BODY.m)
        assert paper == pytest.approx(ours * factor, rel=1e-12)  # exact: two closed forms


def test_point_error_follows_the_designed_third_order_equation():
    ref = tr.eight(2.0, math.pi / 4)
    res = pc.simulate(BODY, GAINS, ref, 12.0, thrust0=0.5, t_eval=np.linspace(0, 12, 49))
    e, de, dde = pc.point_error(BODY, res)
    k = pc.error_polynomial(BODY, GAINS)
    for j in range(2):
        A = np.array([[0, 1, 0], [0, 0, 1], [-k[j, 2], -k[j, 1], -k[j, 0]]])
        x0 = np.array([e[0, j], de[0, j], dde[0, j]])
        want = np.array([expm(A * t) @ x0 for t in res.t])
        # DOP853 at rtol = atol = 1e-10 on errors of order 1 m
        np.testing.assert_allclose(e[:, j], want[:, 0], atol=1e-7)  # accuracy: 1000 x the integration's 1e-10
        np.testing.assert_allclose(de[:, j], want[:, 1], atol=1e-7)  # accuracy: 1000 x the integration's 1e-10


def test_error_polynomial_is_the_papers_24_times_one_pole():
    k = pc.error_polynomial(BODY, GAINS, pole=3.0)
    roots = np.sort_complex(np.roots([1, *k[0]]))
    paper = np.roots([BODY.m, GAINS.kv[0], GAINS.kp[0]])
    np.testing.assert_allclose(np.sort_complex(np.r_[paper, -3.0]), roots, rtol=1e-10)  # accuracy: np.roots on a cubic, well-separated roots


def test_law_meets_the_papers_steady_circle_when_P_is_given_the_papers_P_circle():
    R, Th = 2.0, math.pi / 4
    p0 = circle_equilibria.circle_equilibria(BODY, R, Th)[0]
    s = pc.centre_of_percussion(BODY)
    # under the paper's law C runs on R with heading p0: P runs on this circle
    R_P = math.sqrt(R**2 - 2 * R * s * math.sin(p0) + s**2)
    st = pc.circle_steady_motion(BODY, R_P, Th)
    assert st.radius_C == pytest.approx(R, rel=1e-12)  # exact: closed forms composed
    assert st.F == pytest.approx(R * Th * math.hypot(BODY.m * Th, BODY.c), rel=1e-12)  # exact: closed forms
    # and the paper's law, simulated, puts P on that circle
    res = paper_simulate(BODY, GAINS, tr.circle(R, Th), 80.0, t_eval=np.linspace(70, 80, 5))
    P, _ = pc.point_state(BODY, res.z, res.dz)
    np.testing.assert_allclose(np.hypot(P[:, 0], P[:, 1]), R_P, rtol=1e-7)  # accuracy: 1000 x rtol 1e-10 over 80 s


@pytest.mark.parametrize("call, name", [
    (lambda: pc.simulate(BODY, GAINS, tr.circle(), float("nan")), "t_end"),
    (lambda: pc.simulate(BODY, GAINS, tr.circle(), 1.0, thrust0="x"), "thrust0"),
    (lambda: pc.simulate(BODY, GAINS, tr.circle(), 1.0, pole=-1.0), "pole"),
    (lambda: pc.simulate("body", GAINS, tr.circle(), 1.0), "body"),
    (lambda: pc.circle_steady_motion(BODY, -1.0, 0.5), "R"),
    (lambda: pc.circle_steady_motion(BODY, 1.0, float("inf")), "Theta"),
    (lambda: pc.centre_of_percussion(None), "body"),
])
def test_bad_input_is_named(call, name):
    with pytest.raises((TypeError, ValueError), match=name):
        call()
