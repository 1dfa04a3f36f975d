import functools

import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings, strategies as st
from hypothesis.extra.numpy import arrays

from lib import model, symbolic
from lib.params import Body
from lib.simulate import open_loop_comparison, simulate_open_loop

finite = st.floats(-3.0, 3.0, allow_nan=False)
states = arrays(float, 6, elements=finite)
bodies = st.builds(Body, *(st.floats(0.05, 5.0) for _ in range(5)))


@given(body=bodies, q=states, F=st.floats(0.0, 5.0), beta=st.floats(-4.0, 4.0))
@settings(max_examples=200, deadline=None)
def test_body_frame_form_matches_configuration_form(body, q, F, beta):
    """d/dt of q(z, zdot), taken along the exact motion (2)-(4) by a Taylor step,
    equals the state-space right-hand side (5)."""
    z, dz = model.config_from_state(q)
    ddz = model.config_accel(body, z, dz, F, beta)
    h = 1e-5
    # z(t) to second order; the O(h^3) term does not affect the O(h^2) central difference of q
    q_plus = model.state_from_config(z + h * dz + 0.5 * h**2 * ddz, dz + h * ddz)
    q_minus = model.state_from_config(z - h * dz + 0.5 * h**2 * ddz, dz - h * ddz)
    fd = (q_plus - q_minus) / (2 * h)
    rhs = model.state_rhs(body, q, F, beta)
    np.testing.assert_allclose(fd, rhs, rtol=3e-6, atol=3e-6)  # measured 2.9e-7 (1 + |rhs|) over 6000 draws: O(h^2) difference


@functools.lru_cache(maxsize=1)
def _symbolic_fields():
    """The derived f, g1, g2 as numpy functions of (q, m, I, a, c, c_phi)."""
    sm = symbolic.derive_body_frame()
    p = sm.params
    args = [list(sm.q), p["m"], p["I"], p["a"], p["c"], p["c_phi"]]
    return tuple(sp.lambdify(args, field, "numpy") for field in (sm.f, sm.g1, sm.g2))


@given(body=bodies, q=states)
@settings(max_examples=100, deadline=None)
def test_numeric_drift_equals_symbolic_derivation(body, q):
    f_sym, g1_sym, g2_sym = _symbolic_fields()
    params = (body.m, body.I, body.a, body.c, body.c_phi)
    np.testing.assert_allclose(np.ravel(f_sym(q, *params)), model.f(body, q), rtol=1e-14, atol=1e-14)  # exact: the symbolic derivation against the numeric one; measured 7.1e-15 abs, 8.3e-16 rel
    np.testing.assert_allclose(np.ravel(g1_sym(q, *params)).astype(float), model.g1(body), rtol=1e-15)  # exact: the symbolic derivation against the numeric one; measured 0
    np.testing.assert_allclose(np.ravel(g2_sym(q, *params)).astype(float), model.g2(body), rtol=1e-15)  # exact: the symbolic derivation against the numeric one; measured 0


def test_printed_drift_differs_only_in_the_v2_row_by_twice_v1_omega():
    sm = symbolic.derive_body_frame()
    _, _, _, v1, _, w = sm.q
    diff = sp.simplify(symbolic.printed_drift(sm) - sm.f)
    assert list(diff) == [0, 0, 0, 0, 2 * v1 * w, 0]


def test_derived_drift_conserves_kinetic_energy_without_drag_and_printed_does_not():
    """With c = c_phi = 0 and no input, the derived drift conserves m(v1^2+v2^2)/2;
    the printed one makes it change at rate 2 m v1 v2 omega."""
    sm = symbolic.derive_body_frame()
    _, _, _, v1, v2, w = sm.q
    p = sm.params
    free = {p["c"]: 0, p["c_phi"]: 0}
    energy_rate = lambda f: sp.simplify(p["m"] * (v1 * f[3] + v2 * f[4]))  # noqa: E731
    assert energy_rate(sm.f.subs(free)) == 0
    assert sp.simplify(energy_rate(symbolic.printed_drift(sm).subs(free)) - 2 * p["m"] * v1 * v2 * w) == 0


@given(arrays(float, (4, 6), elements=finite))
def test_state_and_configuration_conversions_are_inverse(q):
    z, dz = model.config_from_state(q)
    np.testing.assert_allclose(model.state_from_config(z, dz), q, rtol=0, atol=1e-14)  # exact: two closed forms, inverse; measured 8.9e-16
    np.testing.assert_allclose(np.linalg.norm(dz[:, :2], axis=1), np.linalg.norm(q[:, 3:5], axis=1), rtol=0, atol=1e-14)  # exact: a rotation keeps the norm; measured 4.4e-16



def test_printed_drift_diverges_from_configuration_form():
    _, runs = open_loop_comparison(Body(), 20.0)
    assert np.abs(runs["state"] - runs["config"]).max() < 1e-8  # measured 9.7e-10, two integrations of one flow
    assert np.abs(runs["printed"] - runs["config"]).max() > 1.0


def test_model_rejects_wrong_shapes():
    with pytest.raises(ValueError, match="q must have a last axis of length 6"):
        model.f(Body(), np.zeros(5))
    with pytest.raises(ValueError, match="z must have a last axis of length 3"):
        model.config_accel(Body(), np.zeros(2), np.zeros(3), 1.0, 0.0)
    with pytest.raises(ValueError, match="unknown model form"):
        simulate_open_loop(Body(), np.sin, np.cos, np.zeros(6), 1.0, form="nope")
    with pytest.raises(ValueError, match=r"q0\[2\] must be finite"):
        simulate_open_loop(Body(), np.sin, np.cos, [0, 0, np.nan, 0, 0, 0], 1.0)
