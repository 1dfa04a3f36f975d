"""Controllability of eq. (5) beyond the rank test of Sec. 3.

* Counting brackets: the paper's count w(w+1)^r/2 of r-th order brackets
  against the dimension of the free Lie algebra (Witt's formula), computed two
  ways.
* Sussmann's sufficient condition for small-time local controllability (STLC)
  at an equilibrium (Sussmann 1987): every *bad* bracket (odd number of
  drifts, even number of each input field) must be a linear combination of
  *good* brackets of lower (theta-weighted) degree.
* A numeric route to any bracket: nested central-difference Jacobians of
  numpy vector fields, independent of the sympy code in :mod:`lib.symbolic`.

Bracket expressions are those of :mod:`lib.symbolic` (``("g1", ("f", "g2"))``
is [g1, [f, g2]]).
"""

from __future__ import annotations

import itertools
from functools import lru_cache
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import sympy as sp

from scipy.optimize import brentq

from . import model
from .params import Body
from .symbolic import (Bracket, accessibility_matrix, bracket_degree, bracket_latex, derive_body_frame,
                       evaluate_bracket, model_fields)

__all__ = [
    "right_nested", "paper_bracket_count", "witt_dimension", "free_lie_rank",
    "is_bad", "theta_degree", "BracketAtPoint", "SussmannReport", "sussmann_check",
    "fd_jacobian", "numeric_bracket", "numeric_fields", "rest_time_bound",
    "full_rank_brackets", "strong_accessibility_det", "rest_report",
]


# ------------------------------------------------------------------ counting

def right_nested(generators: Sequence[str], order: int) -> list[Bracket]:
    """All brackets [X_a1, [X_a2, ..., [X_i, X_j]]] of the given order with i < j.

    ``order`` r counts the brackets (r = 1: [X_i, X_j]); the expressions have
    r + 1 fields. There are N^(r-1) N (N-1)/2 of them for N generators, and
    they span the order-r part of the Lie algebra (every bracket is a
    combination of right-nested ones).

    Parameters
    ----------
    generators : sequence of str
        Field names.
    order : int
        Bracket order r (>= 1).

    Returns
    -------
    list of Bracket
        The brackets.
    """
    if order < 1:
        raise ValueError(f"order must be >= 1, got {order}")
    gens = list(generators)
    if len(set(gens)) != len(gens) or len(gens) < 2:
        raise ValueError(f"need at least two distinct generators, got {gens}")
    inner = [(gens[i], gens[j]) for i in range(len(gens)) for j in range(i + 1, len(gens))]
    out = inner
    for _ in range(order - 1):
        out = [(x, b) for x in gens for b in out]
    return out


def paper_bracket_count(w: int, r: int) -> int:
    """The paper's count of r-th order brackets for w inputs plus a drift: w (w+1)^r / 2.

    Parameters
    ----------
    w : int
        Inputs.
    r : int
        Order.

    Returns
    -------
    int
        The count as printed.
    """
    if w < 1 or r < 1:
        raise ValueError(f"need w >= 1 and r >= 1, got w={w}, r={r}")
    return w * (w + 1) ** r // 2


def witt_dimension(n_generators: int, length: int) -> int:
    """Dimension of the length-k part of the free Lie algebra on N generators (Witt):
    (1/k) sum_{d | k} mu(d) N^(k/d).

    Parameters
    ----------
    n_generators : int
        N.
    length : int
        k.

    Returns
    -------
    int
        The dimension.
    """
    if n_generators < 1 or length < 1:
        raise ValueError(f"need N >= 1 and k >= 1, got N={n_generators}, k={length}")
    total = sum(sp.mobius(d) * n_generators ** (length // d) for d in sp.divisors(length))
    return int(total) // length


def _expand_free(expr: Bracket) -> dict[tuple, int]:
    """A bracket as a noncommutative polynomial: [A, B] = AB - BA, words -> coefficients."""
    if isinstance(expr, str):
        return {(expr,): 1}
    a, b = _expand_free(expr[0]), _expand_free(expr[1])
    out: dict[tuple, int] = {}
    for (u, cu), (v, cv) in itertools.product(a.items(), b.items()):
        out[u + v] = out.get(u + v, 0) + cu * cv
        out[v + u] = out.get(v + u, 0) - cu * cv
    return {k: c for k, c in out.items() if c}


def free_lie_rank(generators: Sequence[str], order: int) -> int:
    """Number of linearly independent order-r brackets in the free Lie algebra,
    by expanding the right-nested brackets in the free associative algebra.

    An independent route to :func:`witt_dimension` (with length = order + 1).

    Parameters
    ----------
    generators : sequence of str
        Field names.
    order : int
        Bracket order r.

    Returns
    -------
    int
        The rank.
    """
    exprs = right_nested(generators, order)
    polys = [_expand_free(e) for e in exprs]
    words = sorted({w for p in polys for w in p})
    mat = sp.Matrix([[p.get(w, 0) for w in words] for p in polys])
    return int(mat.rank())


# ------------------------------------------------------------------ Sussmann

def is_bad(expr: Bracket, drift: str = "f") -> bool:
    """Sussmann's bad bracket: the drift enters an odd number of times and every
    other field an even number of times (zero included).

    Parameters
    ----------
    expr : Bracket
        A bracket expression.
    drift : str
        The drift's name.

    Returns
    -------
    bool
        Whether the bracket is bad.
    """
    deg = bracket_degree(expr)
    return deg[drift] % 2 == 1 and all(n % 2 == 0 for k, n in deg.items() if k != drift)


def theta_degree(expr: Bracket, theta: float = 1.0, drift: str = "f") -> float:
    """Sussmann's weighted degree theta * delta^0 + sum_i delta^i, theta in [0, 1].

    Parameters
    ----------
    expr : Bracket
        A bracket expression.
    theta : float
        The weight, in [0, 1].
    drift : str
        The drift's name.

    Returns
    -------
    float
        The weighted degree.
    """
    if not 0.0 <= theta <= 1.0:
        raise ValueError(f"theta must lie in [0, 1], got {theta}")
    deg = bracket_degree(expr)
    return theta * deg[drift] + sum(n for k, n in deg.items() if k != drift)


@dataclass(frozen=True)
class BracketAtPoint:
    """One bracket evaluated at the point: its value, whether it is bad, and for a
    bad one whether it is neutralised (None for good brackets)."""

    expr: Bracket
    latex: str
    degree: float
    bad: bool
    value: sp.Matrix
    neutralised: bool | None


@dataclass(frozen=True)
class SussmannReport:
    """Outcome of :func:`sussmann_check` at one point.

    ``good_rank`` is the rank of the good brackets found (of degree up to the
    maximum); ``complete`` is True when this finite check proves Sussmann's
    condition for *all* brackets: theta = 1, the good brackets span the whole
    space and every bad bracket up to the maximum degree is neutralised (a bad
    bracket of higher degree is then a combination of good ones of lower degree).
    """

    brackets: tuple[BracketAtPoint, ...]
    n: int
    good_rank: int
    theta: float
    max_order: int

    @property
    def bad(self) -> list[BracketAtPoint]:
        return [b for b in self.brackets if b.bad]

    @property
    def all_bad_neutralised(self) -> bool:
        return all(b.neutralised for b in self.bad)

    @property
    def complete(self) -> bool:
        return self.theta == 1.0 and self.good_rank == self.n and self.all_bad_neutralised


def _rank(cols: list[sp.Matrix]) -> int:
    if not cols:
        return 0
    return int(sp.Matrix.hstack(*cols).rank(simplify=True))


def sussmann_check(fields: Mapping[str, sp.MatrixBase], q, point: Mapping, *, drift: str = "f",
                   max_order: int = 3, theta: float = 1.0) -> SussmannReport:
    """Check Sussmann's sufficient condition for STLC (Sussmann 1987) (Thm. 7.3)
    at ``point`` (a substitution dict for some or all symbols of q and the parameters).

    Every right-nested bracket of order <= ``max_order`` (plus the fields
    themselves) is evaluated at the point. The drift must vanish there (an
    equilibrium with zero input). A bad bracket B is *neutralised* when B(point)
    lies in the span of the good brackets of smaller theta-degree. Ranks are
    exact sympy ranks; with symbolic parameters they hold for generic values.

    Parameters
    ----------
    fields : mapping
        Name -> sympy column.
    q : sequence of sympy.Symbol
        The coordinates.
    point : mapping
        Substitutions for the state and parameters.
    drift : str
        The drift's name.
    max_order : int
        Highest bracket order.
    theta : float
        The weight of the drift's degree, in [0, 1].

    Returns
    -------
    SussmannReport
        The brackets at the point, the dimension n, the good brackets' rank and whether the
        check is complete.
    """
    if max_order < 1:
        raise ValueError(f"max_order must be >= 1, got {max_order}")
    if drift not in fields:
        raise KeyError(f"drift {drift!r} is not among the fields {sorted(fields)}")
    cache: dict = {}
    at = lambda v: v.subs(dict(point)).applyfunc(sp.simplify)  # noqa: E731
    if any(e != 0 for e in at(sp.Matrix(fields[drift]))):
        raise ValueError("the drift does not vanish at the point: Sussmann's theorem is about equilibria")
    exprs: list[Bracket] = list(fields)
    for r in range(1, max_order + 1):
        exprs += right_nested(list(fields), r)
    values = [at(evaluate_bracket(e, fields, q, cache)) for e in exprs]
    degrees = [theta_degree(e, theta, drift) for e in exprs]
    rows = []
    for e, v, d in zip(exprs, values, degrees):
        bad = is_bad(e, drift)
        neutral = None
        if bad:
            lower = [w for e2, w, d2 in zip(exprs, values, degrees) if not is_bad(e2, drift) and d2 < d]
            neutral = all(x == 0 for x in v) or _rank(lower) == _rank(lower + [v])
        rows.append(BracketAtPoint(e, bracket_latex(e), d, bad, v, neutral))
    good_rank = _rank([v for e, v in zip(exprs, values) if not is_bad(e, drift)])
    return SussmannReport(tuple(rows), len(values[0]), good_rank, float(theta), max_order)


def full_rank_brackets() -> list[Bracket]:
    """Six brackets whose matrix has a constant nonzero determinant for the body:
    g1, g2, [f, g1], [f, g2], [g1, [f, g2]], [[f, g1], [f, g2]].

    None of them is f itself, so they prove strong accessibility at every state.

    Returns
    -------
    list of Bracket
        The six brackets.
    """
    return ["g1", "g2", ("f", "g1"), ("f", "g2"), ("g1", ("f", "g2")), (("f", "g1"), ("f", "g2"))]


def strong_accessibility_det() -> sp.Expr:
    """det of :func:`full_rank_brackets` for the derived model, factored (symbolic parameters).

    Returns
    -------
    sympy.Expr
        The determinant, factored.
    """

    model = derive_body_frame()
    det = accessibility_matrix(model_fields(model), full_rank_brackets(), model.q).det()
    return sp.factor(sp.simplify(det))


@lru_cache(maxsize=None)
def rest_report(max_order: int = 3) -> SussmannReport:
    """:func:`sussmann_check` for the derived model at a rest state (v1 = v2 = omega = 0,
    any x, y, phi), with symbolic parameters, brackets up to ``max_order``."""

    model = derive_body_frame()
    _, _, _, V1, V2, W = model.q
    return sussmann_check(model_fields(model), model.q, {V1: 0, V2: 0, W: 0}, max_order=max_order)


def rest_time_bound(body: Body, omega0: float, u_max: float) -> float:
    """Shortest time in which the heading can come back to its start, from turning
    rate ``omega0`` (rad/s, nonzero) with |u2| <= ``u_max`` (N).

    The heading obeys I_C phi'' + c_phi phi' = a u2 (eqs. (4), (8)); the fastest
    return uses u2 = -sign(omega0) u_max throughout. Before this time every
    reachable state has phi on the side of phi0 that omega0 points to, so the
    start is not an interior point of the reachable set: no STLC there.

    Parameters
    ----------
    body : Body
        The body.
    omega0 : float
        Turning rate (rad/s), non-zero.
    u_max : float
        Bound on |u2| (N), > 0.

    Returns
    -------
    float
        The time (s).
    """

    if not np.isfinite(omega0) or omega0 == 0.0:
        raise ValueError(f"omega0 must be finite and nonzero, got {omega0}")
    if not np.isfinite(u_max) or u_max <= 0.0:
        raise ValueError(f"u_max must be positive and finite, got {u_max}")
    k = body.c_phi / body.I
    b = body.a * u_max / body.I
    w0 = abs(omega0)

    def dphi(t: float) -> float:  # phi(t) - phi0 under full braking, times sign(omega0)
        e = -np.expm1(-k * t)
        return w0 * e / k - b / k * (t - e / k)

    hi = 1.0
    while dphi(hi) > 0.0:
        hi *= 2.0
    return float(brentq(dphi, 1e-12 * hi, hi, xtol=1e-14))


# ------------------------------------------------------------------ numeric brackets

Field = Callable[[np.ndarray], np.ndarray]


def fd_jacobian(field: Field, q: np.ndarray, h: float = 1e-4) -> np.ndarray:
    """Central-difference Jacobian d field / dq (n x n), step ``h`` per coordinate.

    Parameters
    ----------
    field : callable
        q -> field(q), (n,).
    q : numpy.ndarray
        The state (n,).
    h : float
        Step per coordinate.

    Returns
    -------
    numpy.ndarray
        The Jacobian (n, n).
    """
    q = np.asarray(q, dtype=float)
    if q.ndim != 1 or q.size == 0:
        raise ValueError(f"q must be a non-empty 1-D array, got shape {q.shape}")
    if not h > 0:
        raise ValueError(f"h must be positive, got {h}")
    cols = []
    for i in range(q.size):
        dq = np.zeros_like(q)
        dq[i] = h
        cols.append((np.asarray(field(q + dq), float) - np.asarray(field(q - dq), float)) / (2 * h))
    return np.stack(cols, axis=-1)


def numeric_bracket(expr: Bracket, fields: Mapping[str, Field], q, h: float = 1e-4) -> np.ndarray:
    """A bracket at the state q by finite differences: [X, Y] = DY X - DX Y with
    central-difference Jacobians, recursively for nested brackets.

    Independent of the sympy route; the error grows with nesting depth (about
    h^2 truncation and eps/h^depth round-off).

    Parameters
    ----------
    expr : Bracket
        A bracket expression.
    fields : mapping
        Name -> numpy field.
    q : array_like
        The state (n,).
    h : float
        Difference step.

    Returns
    -------
    numpy.ndarray
        The bracket at q (n,).
    """
    q = np.asarray(q, dtype=float)
    if isinstance(expr, str):
        return np.asarray(fields[expr](q), dtype=float)
    X = lambda p: numeric_bracket(expr[0], fields, p, h)  # noqa: E731
    Y = lambda p: numeric_bracket(expr[1], fields, p, h)  # noqa: E731
    return fd_jacobian(Y, q, h) @ X(q) - fd_jacobian(X, q, h) @ Y(q)


def numeric_fields(body: Body, *, printed: bool = False) -> dict[str, Field]:
    """The numpy fields of :mod:`lib.model` ({"f", "g1", "g2"}) for ``body``;
    ``printed=True`` uses the printed drift (6).

    Parameters
    ----------
    body : Body
        The body.
    printed : bool
        Use the printed drift (6).

    Returns
    -------
    dict
        Name -> q (6,) -> field (6,).
    """
    drift = model.f_printed if printed else model.f
    return {"f": lambda q: drift(body, q), "g1": lambda q: model.g1(body),
            "g2": lambda q: model.g2(body)}
