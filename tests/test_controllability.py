"""Bracket counts, Sussmann's condition and the no-STLC bound away from rest."""

import numpy as np
import pytest
import sympy as sp
from hypothesis import example, given, settings, strategies as st

from lib import controllability as ctrl
from lib import symbolic
from lib.params import Body
from lib.simulate import simulate_open_loop


@pytest.mark.parametrize("w", [1, 2, 3])
@pytest.mark.parametrize("r", [1, 2, 3])
def test_paper_count_is_the_number_of_right_nested_expressions(w, r):
    gens = ["f"] + [f"g{i}" for i in range(1, w + 1)]
    assert len(ctrl.right_nested(gens, r)) == ctrl.paper_bracket_count(w, r)


@pytest.mark.parametrize("n,r", [(2, 1), (2, 2), (2, 3), (2, 4), (3, 1), (3, 2), (3, 3), (4, 2)])
def test_free_lie_rank_equals_witt_formula(n, r):
    """Two routes to the number of independent brackets: expansion in the free
    associative algebra, and Witt's necklace formula."""
    gens = [f"X{i}" for i in range(n)]
    assert ctrl.free_lie_rank(gens, r) == ctrl.witt_dimension(n, r + 1)


def test_paper_count_overcounts_from_second_order_on():
    """For w = 2 (f, g1, g2): 3 = 3 at r = 1, but 9 > 8 at r = 2 (the Jacobi identity)."""
    assert ctrl.paper_bracket_count(2, 1) == ctrl.witt_dimension(3, 2) == 3
    assert (ctrl.paper_bracket_count(2, 2), ctrl.witt_dimension(3, 3)) == (9, 8)


def test_bad_brackets_follow_sussmann():
    assert ctrl.is_bad("f") and not ctrl.is_bad("g1")
    assert ctrl.is_bad(("g1", ("f", "g1"))) and not ctrl.is_bad(("g1", ("f", "g2")))
    assert not ctrl.is_bad(("f", ("f", "g1")))
    assert ctrl.theta_degree(("g1", ("f", "g1")), theta=0.5) == 2.5
    with pytest.raises(ValueError, match="theta"):
        ctrl.theta_degree("f", theta=2.0)


def test_counterexample_to_theorem6_fails_sussmann():
    """x1' = u, x2' = x1^2 is accessible at 0, but its bad bracket [g, [f, g]] = (0, -2)
    is not a combination of lower good brackets."""
    x1, x2 = sp.symbols("x_1 x_2", real=True)
    fields = {"f": sp.Matrix([0, x1**2]), "g": sp.Matrix([1, 0])}
    rep = ctrl.sussmann_check(fields, [x1, x2], {x1: 0, x2: 0}, max_order=2)
    assert rep.good_rank == 1 and not rep.all_bad_neutralised and not rep.complete
    bad = {b.expr: b for b in rep.bad}
    assert list(bad[("g", ("f", "g"))].value) == [0, -2]


def test_sussmann_check_refuses_non_equilibria():
    sm = symbolic.derive_body_frame()
    _, _, _, v1, v2, w = sm.q
    with pytest.raises(ValueError, match="equilibri"):
        ctrl.sussmann_check(symbolic.model_fields(sm), sm.q, {v1: 1, v2: 0, w: 0})


def test_body_satisfies_sussmann_at_rest():
    """At rest the only nonzero bad bracket is [g2, [f, g2]] = -(2a/I_C) g1, and good
    brackets up to order 3 span R^6: the condition holds for every bracket."""
    rep = ctrl.rest_report()
    nonzero_bad = [b for b in rep.bad if any(x != 0 for x in b.value)]
    assert [b.expr for b in nonzero_bad] == [("g2", ("f", "g2"))]
    assert rep.good_rank == 6 and rep.all_bad_neutralised and rep.complete


@pytest.mark.parametrize("params", [(2.0, 0.1, 0.4, 0.6, 0.1), (1.0, 1.0, 0.5, 1.0, 1.0)],
                         ids=["paper", "equal-damping-rates"])
def test_sussmann_at_rest_for_numeric_bodies(params):
    """Also with numbers, including c/m = c_phi/I_C where [f,[f,g2]] is not enough."""
    sm = symbolic.derive_body_frame()
    _, _, _, v1, v2, w = sm.q
    point = {v1: 0, v2: 0, w: 0, **dict(zip((sm.params[k] for k in ("m", "I", "a", "c", "c_phi")), params))}
    assert ctrl.sussmann_check(symbolic.model_fields(sm), sm.q, point, max_order=3).complete


@given(omega0=st.floats(0.05, 3.0), u_max=st.floats(0.5, 10.0))
@example(omega0=0.1875, u_max=0.5)          # small omega0 T: the integration's absolute tolerance dominates
@settings(max_examples=10, deadline=None)
def test_heading_cannot_return_before_the_time_bound(omega0, u_max):
    """Full braking torque from omega0 brings phi back to phi0 exactly at the bound
    (simulated with the open-loop model, F = u_max, beta = -pi/2)."""
    body = Body()
    T = ctrl.rest_time_bound(body, omega0, u_max)
    q0 = np.array([0.0, 0.0, 0.0, 0.0, 0.0, omega0])
    t, q = simulate_open_loop(body, lambda t: u_max, lambda t: -np.pi / 2, q0, 1.5 * T, form="state",
                              t_eval=np.linspace(0.0, 1.5 * T, 601))
    dphi = q[:, 2]
    assert np.all(dphi[(t > 0) & (t < 0.98 * T)] > 0)
    # accuracy: DOP853 at rtol = atol = 1e-10 holds each step's error below atol + rtol |y|, so the
    # heading's global error is of order 1e-10 (1 + omega0 T) (T is a grid point); measured up to
    # 8.4e-12 omega0 T, and 4.8e-12 rad where omega0 T = 0.034 (the example above)
    assert np.interp(T, t, dphi) == pytest.approx(0.0, abs=1e-10 * (1.0 + omega0 * T))


def test_time_bound_refuses_bad_input():
    with pytest.raises(ValueError, match="omega0"):
        ctrl.rest_time_bound(Body(), 0.0, 1.0)
    with pytest.raises(ValueError, match="u_max"):
        ctrl.rest_time_bound(Body(), 1.0, -1.0)
