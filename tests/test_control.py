import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from hypothesis.extra.numpy import arrays

from lib import control, model, trajectories as T
from lib.params import Body, Gains

vec3 = arrays(float, 3, elements=st.floats(-50, 50, allow_nan=False))
angle = st.floats(-10.0, 10.0)


@given(tau=vec3, phi=angle)
def test_allocate_reproduces_tau_x_and_tau_y_exactly_when_unlimited(tau, phi):
    F, beta = control.allocate(tau, phi)
    Q = model.generalized_force(F, beta, phi)
    np.testing.assert_allclose(Q[:2], tau[:2], rtol=0, atol=2e-14 * (1 + np.abs(tau[:2]).max()))  # measured 1.9e-15 (1 + |tau|)
    assert F >= 0 and -np.pi < beta <= np.pi


@given(tau=arrays(float, (20, 3), elements=st.floats(-50, 50)), phi=angle,
       fmax=st.floats(0.1, 20.0), bmax=st.floats(0.05, np.pi))
def test_allocate_limits_hold(tau, phi, fmax, bmax):
    F, beta = control.allocate(tau, phi, force_limit=fmax, angle_limit=bmax)
    assert np.all(F <= fmax) and np.all(np.abs(beta) <= bmax)
    F0, beta0 = control.allocate(tau, phi)
    # exact: a clip; the force cap keeps the direction and the angle limit keeps admissible directions
    np.testing.assert_allclose(F, np.minimum(F0, fmax), rtol=1e-15)  # measured 0: a clip
    inside = np.abs(beta0) <= bmax
    np.testing.assert_allclose(beta[inside], beta0[inside], rtol=1e-15)  # exact: a copy; measured 0: a copy
    np.testing.assert_allclose(np.abs(beta[~inside]), bmax, rtol=1e-15)  # exact: a clip; measured 0: a clip


def test_allocate_angle_limit_jumps_sides_when_demand_passes_behind_the_body():
    phi = 0.0
    just_left = [np.cos(np.pi - 1e-3), np.sin(np.pi - 1e-3)]
    just_right = [np.cos(np.pi + 1e-3), np.sin(np.pi + 1e-3)]
    _, b1 = control.allocate(just_left, phi, angle_limit=1.0)
    _, b2 = control.allocate(just_right, phi, angle_limit=1.0)
    assert b1 == 1.0 and b2 == -1.0


def test_allocate_zero_demand_is_zero_force_at_zero_angle():
    F, beta = control.allocate(np.zeros((3, 3)), np.array([0.3, -2.0, 5.0]))
    np.testing.assert_array_equal(F, 0.0)
    np.testing.assert_array_equal(beta, 0.0)


@pytest.mark.parametrize("kw,msg", [({"force_limit": 0.0}, "force_limit"), ({"force_limit": np.nan}, "force_limit"),
                                    ({"angle_limit": 4.0}, "angle_limit"), ({"angle_limit": -0.1}, "angle_limit")])
def test_allocate_rejects_bad_limits(kw, msg):
    with pytest.raises(ValueError, match=msg):
        control.allocate([1.0, 0.0, 0.0], 0.0, **kw)


def test_allocate_rejects_wrong_shape():
    with pytest.raises(ValueError, match="tau must have a last axis of length 2 or 3"):
        control.allocate(np.zeros(4), 0.0)


@given(st.floats(-100, 100))
def test_wrap_angle_lands_in_half_open_interval(a):
    w = control.wrap_angle(a)
    assert -np.pi < w <= np.pi
    assert np.isclose(np.cos(w), np.cos(a), rtol=0, atol=1e-13) and np.isclose(np.sin(w), np.sin(a), rtol=0, atol=1e-13)  # exact: a closed form; measured 7.5e-15


@pytest.mark.parametrize("ref", [T.circle(2.0, 0.8), T.eight(1.5, 0.6)])
def test_computed_torque_on_the_reference_is_inverse_dynamics(ref):
    """On the reference (e = 0), tau = M ddz_d + N(dz_d) (eq. 23), so an input realising
    tau exactly on all three axes would reproduce ddz_d through (2)-(4)."""
    body, gains = Body(), Gains()
    t = np.linspace(0, 10, 50)
    tau = control.computed_torque(body, gains, ref, t, ref.z(t), ref.dz(t))
    ddz = (tau - body.drag * ref.dz(t)) / np.array([body.m, body.m, body.I])
    np.testing.assert_allclose(ddz, ref.ddz(t), rtol=0, atol=5e-15)  # exact: (23) against the reference's closed form; measured 4.4e-16


def test_error_dynamics_solution_solves_eq24():
    body, gains = Body(), Gains(kp=[5.2, 3.0, 1.0], kv=[1.0, 2.0, 0.5])
    t = np.linspace(0, 5, 2001)
    e = control.error_dynamics_solution(body, gains, [1.0, -0.5, 0.2], [0.0, 1.5, -1.0], t)
    h = t[1] - t[0]
    de = np.gradient(e, h, axis=0, edge_order=2)
    dde = np.gradient(de, h, axis=0, edge_order=2)
    m = np.array([body.m, body.m, body.I])
    resid = m * dde + gains.kv * de + gains.kp * e
    assert np.abs(resid[5:-5]).max() < 1e-4  # measured 2.7e-5: the O(h^2) error of np.gradient's second difference
    np.testing.assert_allclose(e[0], [1.0, -0.5, 0.2], atol=1e-14)  # exact: the closed form's initial value; measured 0


@settings(max_examples=60, deadline=None)
@given(t=st.floats(0.0, 30.0), z=vec3, dz=vec3, kind=st.sampled_from(["circle", "eight"]))
def test_computed_torque_off_the_reference_gives_the_error_equation_24(t, z, dz, kind):
    """Off the reference (e != 0, de != 0), the plant M ddz + N(dz) = tau driven by (23) has
    M e'' + Kv e' + Kp e = 0 (24), e = z_d - z: (23)'s drag term must cancel the plant's drag
    at the actual rate dz. The drag of the reference rate dz_d would leave N(dz - dz_d) in (24),
    which no test on the reference (e = 0) sees (issue 28)."""
    body, gains = Body(), Gains(kp=[5.2, 3.0, 1.0], kv=[1.0, 2.0, 0.5])
    ref = T.make(kind, 1.7, 0.6)
    z, dz = np.asarray(z) / 10, np.asarray(dz) / 10
    tau = control.computed_torque(body, gains, ref, t, z, dz)
    m = np.array([body.m, body.m, body.I])
    ddz = (tau - body.drag * dz) / m                     # the plant (2)-(4) in configuration form
    e, de, dde = ref.z(t) - z, ref.dz(t) - dz, ref.ddz(t) - ddz
    resid = m * dde + gains.kv * de + gains.kp * e
    scale = 1 + np.abs(m * ref.ddz(t)).max() + np.abs(body.drag * dz).max() + np.abs(gains.kv * de).max() \
        + np.abs(gains.kp * e).max()
    # exact: a closed form, to the rounding of its terms
    np.testing.assert_allclose(resid, 0.0, rtol=0, atol=1e-14 * scale)
