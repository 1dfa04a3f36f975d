"""Symbolic (sympy) form of the model: the body-frame state equations (5)-(10)
derived from the configuration-space equations (2)-(4), not retyped.

:func:`derive_body_frame` is the single source of the symbolic model; the
paper's printed drift (6) is kept beside it in :func:`printed_drift` so that
the two can be compared row by row.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import lru_cache
from types import SimpleNamespace
from typing import Union

import sympy as sp

__all__ = [
    "SymbolicModel", "derive_body_frame", "printed_drift", "parameter_symbols",
    "Bracket", "lie_bracket", "evaluate_bracket", "bracket_latex", "bracket_degree",
    "accessibility_matrix", "model_fields", "printed_brackets", "compare_printed_brackets", "rank_determinants",
    "RANK_BRACKETS",
]


def parameter_symbols() -> dict[str, sp.Symbol]:
    """Positive sympy symbols for the body parameters m, I_C, a, c, c_phi.

    Returns
    -------
    dict
        Name -> sympy Symbol (m in kg, I_C in kg m^2, a in m, c in N s/m, c_phi in N m s).
    """
    return dict(
        m=sp.Symbol("m", positive=True),
        I=sp.Symbol("I_C", positive=True),
        a=sp.Symbol("a", positive=True),
        c=sp.Symbol("c", positive=True),
        c_phi=sp.Symbol("c_varphi", positive=True),
    )


@dataclass(frozen=True)
class SymbolicModel:
    """The control-affine model qdot = f(q) + g1 u1 + g2 u2 of eq. (5).

    ``q`` is the state column [x, y, phi, v1, v2, omega]; ``f``, ``g1``, ``g2``
    are 6x1 sympy matrices; ``params`` maps field names of
    :class:`lib.params.Body` to their symbols; ``u`` holds (u1, u2) of
    eqs. (7)-(8).
    """

    q: sp.Matrix
    f: sp.Matrix
    g1: sp.Matrix
    g2: sp.Matrix
    params: dict
    u: tuple

    @property
    def rhs(self) -> sp.Matrix:
        """Right-hand side f + g1 u1 + g2 u2 of eq. (5)."""
        return self.f + self.g1 * self.u[0] + self.g2 * self.u[1]


@lru_cache(maxsize=None)
def derive_body_frame() -> SymbolicModel:
    """Derive eqs. (5)-(10) from eqs. (2)-(4).

    The body-frame velocities are v1 = xdot cos(phi) + ydot sin(phi) and
    v2 = -xdot sin(phi) + ydot cos(phi) (the inertial velocity rotated by
    -phi). Differentiating them, substituting the accelerations of (2)-(4)
    and writing F cos(beta) = u1, F sin(beta) = u2 gives the drift f and the
    input fields g1, g2.
    """
    p = parameter_symbols()
    m, I, a, c, c_phi = p["m"], p["I"], p["a"], p["c"], p["c_phi"]
    t = sp.Symbol("t", real=True)
    F, beta = sp.symbols("F beta", real=True)
    x, y, phi = (sp.Function(n, real=True)(t) for n in ("x", "y", "varphi"))

    # configuration-space equations (2)-(4), solved for the accelerations
    acc = {
        x.diff(t, 2): (F * sp.cos(phi + beta) - c * x.diff(t)) / m,
        y.diff(t, 2): (F * sp.sin(phi + beta) - c * y.diff(t)) / m,
        phi.diff(t, 2): (F * a * sp.sin(beta) - c_phi * phi.diff(t)) / I,
    }
    v1_def = x.diff(t) * sp.cos(phi) + y.diff(t) * sp.sin(phi)
    v2_def = -x.diff(t) * sp.sin(phi) + y.diff(t) * sp.cos(phi)

    X, Y, PHI, V1, V2, W = sp.symbols("x y varphi v_1 v_2 omega", real=True)
    u1, u2 = sp.symbols("u_1 u_2", real=True)
    back = {  # inertial velocities in terms of body-frame ones, and phi' = omega
        x.diff(t): V1 * sp.cos(phi) - V2 * sp.sin(phi),
        y.diff(t): V1 * sp.sin(phi) + V2 * sp.cos(phi),
        phi.diff(t): W,
    }

    def to_state(expr: sp.Expr) -> sp.Expr:
        expr = sp.expand_trig(expr.subs(acc).subs(back))
        expr = expr.subs({F * sp.cos(beta): u1, F * sp.sin(beta): u2})
        expr = sp.expand(expr).subs({F * sp.cos(beta): u1, F * sp.sin(beta): u2})
        expr = expr.subs({phi: PHI})
        return sp.simplify(expr)

    rhs = sp.Matrix([
        to_state(x.diff(t)),
        to_state(y.diff(t)),
        to_state(phi.diff(t)),
        to_state(v1_def.diff(t)),
        to_state(v2_def.diff(t)),
        to_state(phi.diff(t, 2)),
    ])
    if rhs.free_symbols & {F, beta}:
        raise RuntimeError("derivation failed to express the inputs as u1, u2")
    f = sp.simplify(rhs.subs({u1: 0, u2: 0}))
    g1 = sp.simplify(rhs.diff(u1))
    g2 = sp.simplify(rhs.diff(u2))
    q = sp.Matrix([X, Y, PHI, V1, V2, W])
    return SymbolicModel(q=q, f=f, g1=g1, g2=g2, params=p, u=(u1, u2))


def printed_drift(model: SymbolicModel | None = None) -> sp.Matrix:
    """The drift f exactly as printed in eq. (6) of the paper.

    Its fifth row reads -c/m v2 + v1 omega; the derivation gives -v1 omega
    (see :func:`derive_body_frame` and the errata).

    Parameters
    ----------
    model : SymbolicModel, optional
        The derived model (default :func:`derive_body_frame`).

    Returns
    -------
    sympy.Matrix
        f as printed, 6 x 1.
    """
    model = model or derive_body_frame()
    X, Y, PHI, V1, V2, W = model.q
    p = model.params
    return sp.Matrix([
        V1 * sp.cos(PHI) - V2 * sp.sin(PHI),
        V1 * sp.sin(PHI) + V2 * sp.cos(PHI),
        W,
        -p["c"] / p["m"] * V1 + V2 * W,
        -p["c"] / p["m"] * V2 + V1 * W,
        -p["c_phi"] / p["I"] * W,
    ])


# ---------------------------------------------------------------- Lie brackets (Sec. 3)

Bracket = Union[str, tuple]
"""A bracket expression, a field name (``"f"``, ``"g1"``) or a pair ``(X, Y)``
standing for [X, Y]; e.g. ``("g1", ("f", "g2"))`` is [g1, [f, g2]]."""


def _column(v, name: str) -> sp.Matrix:
    if not isinstance(v, sp.MatrixBase):
        raise TypeError(f"{name} must be a sympy column Matrix, got {type(v).__name__}")
    if v.shape[1] != 1:
        raise ValueError(f"{name} must be a column vector (n x 1), got shape {v.shape}")
    return sp.Matrix(v)


def _coordinates(q) -> list[sp.Symbol]:
    if isinstance(q, sp.MatrixBase):
        coords = list(q)
    elif isinstance(q, Sequence) and not isinstance(q, str):
        coords = list(q)
    else:
        raise TypeError(f"q must be a sympy Matrix or a sequence of sympy Symbols, got {type(q).__name__}")
    if not coords:
        raise ValueError("q is empty: a vector field needs at least one coordinate")
    bad = [c for c in coords if not isinstance(c, sp.Symbol)]
    if bad:
        raise TypeError(f"q must contain sympy Symbols only, got {bad[0]!r} ({type(bad[0]).__name__})")
    if len(set(coords)) != len(coords):
        raise ValueError(f"q has repeated coordinates: {coords}")
    return coords


def _tidy(expr: sp.Expr) -> sp.Expr:
    """Cheap canonical form: expand, then put over a common denominator.

    Enough to expose zeros in this model, whose fields are linear in
    (cos phi, sin phi); trigonometric identities are left to the caller.
    """
    return sp.expand(sp.cancel(sp.expand(expr)))


def lie_bracket(f: sp.MatrixBase, g: sp.MatrixBase, q) -> sp.Matrix:
    """Lie (Jacobi) bracket of eq. (16): [f, g] = (dg/dq) f - (df/dq) g.

    ``f`` and ``g`` are n x 1 sympy matrices, ``q`` the n coordinates (sympy
    Symbols). Works for any pair of vector fields, not only this model. Each
    entry is expanded and put over a common denominator.

    Parameters
    ----------
    f, g : sympy.Matrix
        Vector fields, n x 1 columns in the coordinates ``q`` (their units those of dq/dt).
    q : sequence of sympy.Symbol
        The n coordinates.

    Returns
    -------
    sympy.Matrix
        [f, g], n x 1, each entry expanded over a common denominator.

    Raises
    ------
    TypeError
        For non-sympy input (e.g. numpy arrays, or expressions in place of
        coordinate symbols).
    ValueError
        When the dimensions of f, g and q disagree.
    """
    f = _column(f, "f")
    g = _column(g, "g")
    coords = _coordinates(q)
    if not (f.shape[0] == g.shape[0] == len(coords)):
        raise ValueError(f"dimension mismatch: f has {f.shape[0]} rows, g has {g.shape[0]}, "
                         f"q has {len(coords)} coordinates")
    return (g.jacobian(coords) * f - f.jacobian(coords) * g).applyfunc(_tidy)


def _check_bracket(expr: Bracket) -> None:
    if isinstance(expr, str):
        return
    if not (isinstance(expr, tuple) and len(expr) == 2):
        raise TypeError(f"a bracket is a field name or a pair (X, Y), got {expr!r}")
    _check_bracket(expr[0])
    _check_bracket(expr[1])


def evaluate_bracket(expr: Bracket, fields: Mapping[str, sp.MatrixBase], q,
                     cache: dict | None = None) -> sp.Matrix:
    """The vector field of a bracket expression, built with :func:`lie_bracket`.

    ``fields`` maps names to sympy columns (e.g. :func:`model_fields`);
    ``cache`` (a dict) may be shared between calls to reuse inner brackets.

    Parameters
    ----------
    expr : Bracket
        A field name or a pair.
    fields : mapping
        Name -> sympy column.
    q : sequence of sympy.Symbol
        The coordinates.
    cache : dict, optional
        Shared between calls.

    Returns
    -------
    sympy.Matrix
        The bracket's field, n x 1.
    """
    _check_bracket(expr)
    cache = {} if cache is None else cache
    if expr in cache:
        return cache[expr]
    if isinstance(expr, str):
        if expr not in fields:
            raise KeyError(f"unknown field {expr!r}; known: {sorted(fields)}")
        out = _column(fields[expr], expr)
    else:
        out = lie_bracket(evaluate_bracket(expr[0], fields, q, cache),
                          evaluate_bracket(expr[1], fields, q, cache), q)
    cache[expr] = out
    return out


def bracket_latex(expr: Bracket) -> str:
    """LaTeX of a bracket expression: ``("g1", ("f", "g2"))`` -> ``[g_1, [f, g_2]]``.

    Parameters
    ----------
    expr : Bracket
        A field name or a pair.

    Returns
    -------
    str
        LaTeX.
    """
    _check_bracket(expr)
    if isinstance(expr, str):
        name = expr.rstrip("0123456789")
        idx = expr[len(name):]
        return f"{name}_{{{idx}}}" if idx else name
    return f"[{bracket_latex(expr[0])}, {bracket_latex(expr[1])}]"


def bracket_degree(expr: Bracket) -> Counter:
    """How many times each field enters the bracket (Sussmann's degrees delta^i).

    Parameters
    ----------
    expr : Bracket
        A field name or a pair.

    Returns
    -------
    collections.Counter
        Field name -> degree.
    """
    _check_bracket(expr)
    if isinstance(expr, str):
        return Counter({expr: 1})
    return bracket_degree(expr[0]) + bracket_degree(expr[1])


def accessibility_matrix(fields: Mapping[str, sp.MatrixBase], brackets: Sequence[Bracket], q,
                         cache: dict | None = None) -> sp.Matrix:
    """The matrix of eq. (18): the listed brackets side by side, C = [B_1 | B_2 | ...].

    Its rank at a state is the dimension of the span of those brackets there;
    rank n everywhere proves the Lie algebra rank condition (Definition 4).

    Parameters
    ----------
    fields : mapping
        Name -> sympy column.
    brackets : sequence of Bracket
        The columns.
    q : sequence of sympy.Symbol
        The coordinates.
    cache : dict, optional
        Shared between calls.

    Returns
    -------
    sympy.Matrix
        C, n x len(brackets).
    """
    if len(brackets) == 0:
        raise ValueError("brackets is empty")
    cache = {} if cache is None else cache
    return sp.Matrix.hstack(*(evaluate_bracket(b, fields, q, cache) for b in brackets))


def _symbols_only():
    """State and parameter symbols of :func:`derive_body_frame` without deriving
    (sympy symbols are equal when name and assumptions are)."""
    q = sp.Matrix(sp.symbols("x y varphi v_1 v_2 omega", real=True))
    return SimpleNamespace(q=q, params=parameter_symbols())


def model_fields(model: SymbolicModel | None = None, *, printed: bool = False) -> dict[str, sp.Matrix]:
    """``{"f": f, "g1": g1, "g2": g2}`` of eqs. (6), (9), (10); ``printed=True``
    uses the drift as printed in (6) instead of the derived one.

    Parameters
    ----------
    model : SymbolicModel, optional
        The derived model (default :func:`derive_body_frame`).
    printed : bool
        Use the drift as printed in (6).

    Returns
    -------
    dict
        ``{"f": f, "g1": g1, "g2": g2}``, sympy columns 6 x 1.
    """
    model = model or derive_body_frame()
    f = printed_drift(model) if printed else model.f
    return {"f": f, "g1": model.g1, "g2": model.g2}


def printed_brackets(model: SymbolicModel | None = None) -> dict[Bracket, sp.Matrix]:
    """The three brackets exactly as printed under eq. (21) of the paper.

    (The fifth entry of [f, g2] is printed with ``I`` for ``I_C``.)

    Parameters
    ----------
    model : SymbolicModel, optional
        The derived model (default :func:`derive_body_frame`).

    Returns
    -------
    dict
        Bracket -> sympy column as printed.
    """
    model = model or _symbols_only()
    _, _, PHI, V1, V2, W = model.q
    m, I, a, c, c_phi = (model.params[k] for k in ("m", "I", "a", "c", "c_phi"))
    cos, sin = sp.cos(PHI), sp.sin(PHI)
    return {
        ("f", "g1"): sp.Matrix([-cos / m, sin / m, 0, -c / m**2, -W / m, 0]),
        ("f", "g2"): sp.Matrix([sin / m, -cos / m, -a / I, -V2 * a / I - W / m,
                                c / m**2 - V1 * a / I, a * c_phi / I**2]),
        ("g1", ("f", "g2")): sp.Matrix([0, 0, 0, 0, -a / (m * I), 0]),
    }


def _slug(expr: Bracket) -> str:
    if isinstance(expr, str):
        return expr
    return f"{_slug(expr[0])}-{_slug(expr[1])}"


def compare_printed_brackets(model: SymbolicModel | None = None) -> list[dict]:
    """Entry-by-entry comparison of the brackets printed under eq. (21).

    For every entry: the printed value, the value from the derived drift, the
    value from the printed drift (6), and a verdict: ``"correct"``,
    ``"drift typo"`` (wrong, but exactly what the printed drift gives) or
    ``"independent"`` (wrong even with the printed drift). ``"opposite sign
    convention"`` flags entries equal to the bracket [g, f] of the printed drift.

    Parameters
    ----------
    model : SymbolicModel, optional
        The derived model (default :func:`derive_body_frame`).

    Returns
    -------
    list of dict
        One per entry: bracket, row, key, printed, derived, printed_drift, verdict,
    opposite_convention.
    """
    model = model or derive_body_frame()
    true_fields, printed_fields = model_fields(model), model_fields(model, printed=True)
    out = []
    for expr, printed in printed_brackets(model).items():
        true = evaluate_bracket(expr, true_fields, model.q)
        from_printed = evaluate_bracket(expr, printed_fields, model.q)
        for i in range(printed.shape[0]):
            ok = sp.simplify(printed[i] - true[i]) == 0
            typo = sp.simplify(printed[i] - from_printed[i]) == 0
            opposite = sp.simplify(printed[i] + from_printed[i]) == 0 and printed[i] != 0
            out.append(dict(
                bracket=expr, row=i + 1, key=f"eq21-{_slug(expr)}-row{i + 1}",
                printed=printed[i], derived=true[i], printed_drift=from_printed[i],
                verdict="correct" if ok else ("drift typo" if typo else "independent"),
                opposite_convention=bool(opposite and not ok),
            ))
    return out


RANK_BRACKETS = ["f", "g1", "g2", ("f", "g1"), ("f", "g2"), ("g1", ("f", "g2"))]


def rank_determinants(model: SymbolicModel | None = None) -> dict[str, sp.Expr]:
    """det C of the distribution (21), factored: ``"printed"`` with the drift (6) and the
    three bracket columns exactly as printed under (21), ``"derived"`` with every column
    computed from the derived model.

    Parameters
    ----------
    model : SymbolicModel, optional
        The derived model (default :func:`derive_body_frame`).

    Returns
    -------
    dict
        ``"printed"`` and ``"derived"`` -> det C, factored.
    """
    model = model or derive_body_frame()
    fields = model_fields(model)
    pb = printed_brackets(model)
    printed = sp.Matrix.hstack(printed_drift(model), fields["g1"], fields["g2"],
                               *(pb[b] for b in RANK_BRACKETS[3:]))
    derived = accessibility_matrix(fields, RANK_BRACKETS, model.q)
    return {"printed": sp.factor(sp.simplify(printed.det())), "derived": sp.factor(sp.simplify(derived.det()))}
