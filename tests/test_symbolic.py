"""Lie brackets (16), the accessibility matrix and the bracket errata of Sec. 3."""

import functools

import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings, strategies as st

from lib import controllability as ctrl
from lib import symbolic
from lib.paper import model_errata
from lib.params import Body

X1, X2, X3 = sp.symbols("x1 x2 x3", real=True)
Q3 = [X1, X2, X3]


# ------------------------------------------------------------ textbook systems

def test_unicycle_brackets_are_the_textbook_ones():
    """Kinematic unicycle q = (x, y, theta), g1 = (cos, sin, 0) (drive), g2 = (0, 0, 1) (steer):
    [g1, g2] = (sin theta, -cos theta, 0) with the convention (16), and the three fields span R^3 (det = 1)."""
    x, y, th = sp.symbols("x y theta", real=True)
    g1 = sp.Matrix([sp.cos(th), sp.sin(th), 0])
    g2 = sp.Matrix([0, 0, 1])
    b = symbolic.lie_bracket(g1, g2, [x, y, th])
    assert sp.simplify(b - sp.Matrix([sp.sin(th), -sp.cos(th), 0])) == sp.zeros(3, 1)
    assert sp.simplify(sp.Matrix.hstack(g1, g2, b).det()) == 1


def test_kinematic_car_needs_a_third_order_bracket():
    """Kinematic car (x, y, phi, theta): drive g1 = (cos th, sin th, tan(phi)/l, 0), steer g2 = e_phi.
    [g1, g2] points along theta, [g1, [g1, g2]] sideways; the four span R^4 (det = -1/(l^2 cos^4 phi))."""
    x, y, phi, th = sp.symbols("x y phi theta", real=True)
    L = sp.Symbol("l", positive=True)
    q = [x, y, phi, th]
    g1 = sp.Matrix([sp.cos(th), sp.sin(th), 0, sp.tan(phi) / L])
    g2 = sp.Matrix([0, 0, 1, 0])
    b12 = symbolic.lie_bracket(g1, g2, q)
    b112 = symbolic.lie_bracket(g1, b12, q)
    assert sp.simplify(b12 - sp.Matrix([0, 0, 0, -1 / (L * sp.cos(phi) ** 2)])) == sp.zeros(4, 1)
    det = sp.simplify(sp.Matrix.hstack(g1, g2, b12, b112).det())
    assert sp.simplify(det + 1 / (L**2 * sp.cos(phi) ** 4)) == 0


def test_bracket_of_linear_fields_is_the_commutator():
    """For linear fields Ax and Bx, (16) gives [Ax, Bx] = (BA - AB) x."""
    A = sp.Matrix([[0, 1, 0], [-2, 0, 3], [1, 1, 1]])
    B = sp.Matrix([[1, 0, 2], [0, 0, 1], [4, -1, 0]])
    x = sp.Matrix(Q3)
    assert symbolic.lie_bracket(A * x, B * x, Q3) == (B * A - A * B) * x


coeffs = st.integers(-3, 3)


@st.composite
def poly_fields(draw):
    """Random polynomial vector fields on R^3 of degree <= 2."""
    monomials = [sp.Integer(1), X1, X2, X3, X1 * X2, X3**2]
    return sp.Matrix([sum(draw(coeffs) * mono for mono in monomials) for _ in range(3)])


@given(f=poly_fields(), g=poly_fields())
@settings(max_examples=20, deadline=None)
def test_bracket_is_antisymmetric(f, g):
    assert symbolic.lie_bracket(f, g, Q3) + symbolic.lie_bracket(g, f, Q3) == sp.zeros(3, 1)
    assert symbolic.lie_bracket(f, f, Q3) == sp.zeros(3, 1)


@given(f=poly_fields(), g=poly_fields(), h=poly_fields())
@settings(max_examples=10, deadline=None)
def test_bracket_satisfies_the_jacobi_identity(f, g, h):
    lb = lambda a, b: symbolic.lie_bracket(a, b, Q3)  # noqa: E731
    total = lb(f, lb(g, h)) + lb(g, lb(h, f)) + lb(h, lb(f, g))
    assert total.applyfunc(sp.expand) == sp.zeros(3, 1)


# ------------------------------------------------------------ bad input

def test_bracket_refuses_mismatched_dimensions():
    with pytest.raises(ValueError, match="dimension mismatch"):
        symbolic.lie_bracket(sp.Matrix([X1, X2]), sp.Matrix([X1, X2, X3]), Q3)
    with pytest.raises(ValueError, match="dimension mismatch"):
        symbolic.lie_bracket(sp.Matrix([X1, X2]), sp.Matrix([X2, X1]), Q3)
    with pytest.raises(ValueError, match="column vector"):
        symbolic.lie_bracket(sp.Matrix([[X1, X2, X3]]), sp.Matrix(Q3), Q3)


def test_bracket_refuses_non_symbolic_input():
    with pytest.raises(TypeError, match="sympy column Matrix"):
        symbolic.lie_bracket(np.array([1.0, 2.0, 3.0]), sp.Matrix(Q3), Q3)
    with pytest.raises(TypeError, match="Symbols"):
        symbolic.lie_bracket(sp.Matrix(Q3), sp.Matrix(Q3), [X1, X2, X1 + X3])
    with pytest.raises(TypeError, match="sympy Matrix or a sequence"):
        symbolic.lie_bracket(sp.Matrix(Q3), sp.Matrix(Q3), 3)
    with pytest.raises(ValueError, match="repeated"):
        symbolic.lie_bracket(sp.Matrix(Q3), sp.Matrix(Q3), [X1, X1, X2])
    with pytest.raises(TypeError, match="pair"):
        symbolic.evaluate_bracket(("f", "g1", "g2"), symbolic.model_fields(), symbolic.derive_body_frame().q)
    with pytest.raises(ValueError, match="empty"):
        symbolic.accessibility_matrix(symbolic.model_fields(), [], symbolic.derive_body_frame().q)


# ------------------------------------------------------------ the body's brackets

def test_bracket_latex_and_degree():
    e = (("f", "g1"), ("f", "g2"))
    assert symbolic.bracket_latex(e) == "[[f, g_{1}], [f, g_{2}]]"
    assert symbolic.bracket_degree(e) == {"f": 2, "g1": 1, "g2": 1}


def test_brackets_of_the_body_by_hand():
    """The brackets of (21) from the derived drift, written out by hand from (16)."""
    sm = symbolic.derive_body_frame()
    fields = symbolic.model_fields(sm)
    _, _, phi, v1, v2, w = sm.q
    m, I, a, c, cp = (sm.params[k] for k in ("m", "I", "a", "c", "c_phi"))
    expected = {
        ("f", "g1"): sp.Matrix([-sp.cos(phi) / m, -sp.sin(phi) / m, 0, c / m**2, w / m, 0]),
        ("f", "g2"): sp.Matrix([sp.sin(phi) / m, -sp.cos(phi) / m, -a / I, -w / m - a * v2 / I,
                                c / m**2 + a * v1 / I, a * cp / I**2]),
        ("g1", ("f", "g2")): sp.Matrix([0, 0, 0, 0, a / (m * I), 0]),
        ("g2", ("f", "g2")): -2 * a / I * sm.g1,
    }
    for expr, value in expected.items():
        assert sp.simplify(symbolic.evaluate_bracket(expr, fields, sm.q) - value) == sp.zeros(6, 1), expr


def test_also_line_after_eq21_holds_for_the_derived_drift():
    """[g1,g2] = [g1,[g1,g2]] = [f,[g1,g2]] = [g1,[f,g1]] = 0 and [g2,[f,g1]] = [g1,[f,g2]]."""
    sm = symbolic.derive_body_frame()
    fields = symbolic.model_fields(sm)
    ev = lambda e: symbolic.evaluate_bracket(e, fields, sm.q)  # noqa: E731
    for e in [("g1", "g2"), ("g1", ("g1", "g2")), ("f", ("g1", "g2")), ("g1", ("f", "g1"))]:
        assert ev(e) == sp.zeros(6, 1), e
    assert ev(("g2", ("f", "g1"))) == ev(("g1", ("f", "g2")))


def test_rank_of_eq21_drops_exactly_where_the_paper_says():
    """det C of (21) = a^2 (a m v2 - I_C omega) / (I_C^3 m^4): zero iff omega = a m v2 / I_C."""
    sm = symbolic.derive_body_frame()
    C = symbolic.accessibility_matrix(symbolic.model_fields(sm),
                                      ["f", "g1", "g2", ("f", "g1"), ("f", "g2"), ("g1", ("f", "g2"))], sm.q)
    _, _, _, v1, v2, w = sm.q
    m, I, a = (sm.params[k] for k in ("m", "I", "a"))
    assert sp.simplify(C.det() - a**2 * (a * m * v2 - I * w) / (I**3 * m**4)) == 0


def test_six_brackets_without_f_have_a_constant_determinant():
    """Strong accessibility at every state: det = a^4 / (I_C^4 m^4), whatever the state."""
    sm = symbolic.derive_body_frame()
    m, I, a = (sm.params[k] for k in ("m", "I", "a"))
    assert sp.simplify(ctrl.strong_accessibility_det() - a**4 / (I**4 * m**4)) == 0
    assert "f" not in ctrl.full_rank_brackets()


def test_every_wrong_entry_of_eq21_has_an_erratum_row():
    """The set of mismatching printed entries equals the set of eq21-* errata keys."""
    mismatched = {r["key"] for r in symbolic.compare_printed_brackets() if r["verdict"] != "correct"}
    rows = {r.key for r in model_errata.ROWS if r.key.startswith("eq21-")}
    assert mismatched == rows
    assert len(mismatched) == 5


def test_drift_typo_explains_exactly_three_wrong_entries():
    """Recomputed with the printed drift (6), three wrong entries reappear verbatim; the
    other two (rows 2 and 4 of [f, g1]) are wrong either way and carry the opposite sign convention."""
    recs = [r for r in symbolic.compare_printed_brackets() if r["verdict"] != "correct"]
    typo = {r["key"] for r in recs if r["verdict"] == "drift typo"}
    indep = {r["key"] for r in recs if r["verdict"] == "independent"}
    assert typo == {"eq21-f-g1-row5", "eq21-f-g2-row5", "eq21-g1-f-g2-row5"}
    assert indep == {"eq21-f-g1-row2", "eq21-f-g1-row4"}
    assert all(r["opposite_convention"] for r in recs if r["verdict"] == "independent")


# ------------------------------------------------------------ numeric cross-check

#: every bracket the chapter uses, with the FD step suited to its nesting depth
CHAPTER_BRACKETS = [
    (("f", "g1"), 1e-4), (("f", "g2"), 1e-4), (("g1", "g2"), 1e-4),
    (("g1", ("f", "g2")), 1e-4), (("g2", ("f", "g1")), 1e-4), (("g2", ("f", "g2")), 1e-4),
    (("g1", ("f", "g1")), 1e-4), (("f", ("g1", "g2")), 1e-4), (("f", ("f", "g1")), 1e-4),
    (("f", ("f", "g2")), 1e-4), ((("f", "g1"), ("f", "g2")), 1e-4),
    (("g1", ("g1", "g2")), 1e-4), (("f", ("f", ("f", "g2"))), 1e-3),
]


@functools.lru_cache(maxsize=None)
def _lambdified(expr, printed):
    sm = symbolic.derive_body_frame()
    fields = symbolic.model_fields(sm, printed=printed)
    p = sm.params
    value = symbolic.evaluate_bracket(expr, fields, sm.q)
    return sp.lambdify([list(sm.q), p["m"], p["I"], p["a"], p["c"], p["c_phi"]], value, "numpy")


@pytest.mark.parametrize("printed", [False, True], ids=["derived", "printed-drift"])
@pytest.mark.parametrize("expr,h", CHAPTER_BRACKETS, ids=[symbolic.bracket_latex(e) for e, _ in CHAPTER_BRACKETS])
def test_symbolic_brackets_match_finite_differences(expr, h, printed):
    """sympy bracket vs nested central-difference Jacobians of lib.model's numpy fields,
    at random states and bodies."""
    rng = np.random.default_rng(abs(hash((symbolic.bracket_latex(expr), printed))) % 2**32)
    fn = _lambdified(expr, printed)
    for _ in range(4):
        body = Body(*rng.uniform(0.3, 3.0, size=5))
        q = rng.uniform(-2.0, 2.0, size=6)
        sym = np.ravel(np.asarray(fn(q, body.m, body.I, body.a, body.c, body.c_phi), dtype=float))
        sym = np.broadcast_to(sym, (6,)) if sym.size == 1 else sym
        num = ctrl.numeric_bracket(expr, ctrl.numeric_fields(body, printed=printed), q, h=h)
        scale = 1.0 + np.max(np.abs(sym))
        np.testing.assert_allclose(num, sym, rtol=0, atol=5e-6 * scale)  # measured 4.3e-7 scale: the O(h^2) difference error, h per bracket


def test_numeric_bracket_refuses_bad_input():
    with pytest.raises(ValueError, match="1-D"):
        ctrl.fd_jacobian(lambda q: q, np.zeros((2, 2)))
    with pytest.raises(ValueError, match="positive"):
        ctrl.fd_jacobian(lambda q: q, np.zeros(3), h=0.0)
