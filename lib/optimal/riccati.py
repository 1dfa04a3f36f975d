"""The right-hand sides of :func:`lib.optimal.tracker.periodic_lqr` compiled, for a motion of
:func:`lib.optimal.motion.periodic_motion` (its collocation polynomials and piecewise-constant
inputs): the periodic Riccati equation's (:func:`riccati_rhs`) and the linearised closed loop's,
whose monodromy matrix gives the multipliers (:func:`closed_loop_rhs`); and the clipped closed
loop of :func:`lib.optimal.tracker.track_motion` itself (:func:`loop_rhs`), and that loop stepped
by the classical RK4 over whole input pieces (:func:`loop_steps`, the period map of
:func:`lib.optimal.verdict.motion_verdict`).

``solve_ivp`` calls them on one matrix at a time, about 12 000 times a Riccati solution, so the
numpy versions' cost was their calls' overhead: the motion's state read from its polynomials
(:meth:`lib.optimal.motion.PeriodicMotion.state`, :meth:`~lib.optimal.motion.PeriodicMotion.inputs`),
the Jacobians of (2)-(4) (:func:`lib.optimal.tracker.jacobians`), -P' = A'P + PA - P B R^-1 B' P + Q,
the gain K = R^-1 B' P(t) from P's cubic Hermite interpolant. Here the same formulas in their
order, the small products summed in order and the 2 x 2 solve by LU with partial pivoting
written out (numba's BLAS and LAPACK calls took about 8 s to compile on a fresh clone): equal
to the numpy right-hand sides to rounding (``tests/test_optimal_tracker.py``).

Units: SI (s, m, rad, N).
"""

from __future__ import annotations

import math
from pathlib import Path

import numba
import numpy as np

from .. import closed_loop
from ..closed_loop import _accel, _wrap
from ..machinery import checks
from ..machinery.cache import source_stamp
from ..params import Body
from .collocation import tableau
from .motion import NODE_SNAP

__all__ = ["riccati_rhs", "closed_loop_rhs", "loop_rhs", "loop_steps"]



@numba.njit(cache=True)
def _locate(t, period, nodes, snap):  # pragma: no cover (compiled)
    """(interval, local time in [0, 1], whole periods) of t (s), as ``PeriodicMotion._locate``."""
    laps = math.floor(t / period)
    x = (t - laps * period) * (nodes / period)
    k = min(max(int(math.floor(x + snap)), 0), nodes - 1)
    return k, min(max(x - k, 0.0), 1.0), laps


@numba.njit(cache=True)
def _state(t, t_in, period, nodes, snap, turns, F, beta, basis, colloc):  # pragma: no cover (compiled)
    """The motion's state x* (6,) at t and its inputs (F*, beta*) at t_in, as
    ``lib.optimal.tracker._reference`` computes them."""
    k, s, laps = _locate(t, period, nodes, snap)
    d1 = basis.shape[0]
    x = np.zeros(6)
    for r in range(d1):                        # the Lagrange basis at s by Horner, then the state
        w = 0.0
        for j in range(d1):
            w = w * s + basis[r, j]
        for i in range(6):
            x[i] += w * colloc[k, r, i]
    x[2] += 2 * np.pi * turns * laps
    ti = t_in - math.floor(t_in / period) * period
    ki = _locate(ti, period, nodes, snap)[0]
    return x, F[ki], beta[ki]


@numba.njit(cache=True)
def _jac(t, t_in, period, nodes, snap, turns, F, beta, basis, colloc, body):  # pragma: no cover (compiled)
    """A (6, 6) and B (6, 2) of (2)-(4) about the motion's state at t and its inputs at t_in, as
    ``lib.optimal.tracker._reference`` and ``_jacobians`` compute them."""
    x, f, b = _state(t, t_in, period, nodes, snap, turns, F, beta, basis, colloc)
    return _jacobians(x, f, b, body)


@numba.njit(cache=True)
def _jacobians(x, f, b, body):  # pragma: no cover (compiled)
    """A (6, 6) and B (6, 2) of (2)-(4) at the state x (6,) and the inputs (f, b), as
    ``lib.optimal.tracker._jacobians``."""
    m, I, a, c, cphi = body[0], body[1], body[2], body[3], body[4]
    co, si = math.cos(x[2] + b), math.sin(x[2] + b)
    ia = a / I
    A = np.zeros((6, 6))
    A[0, 3] = A[1, 4] = A[2, 5] = 1.0
    A[3, 2], A[4, 2] = -f * si / m, f * co / m
    A[3, 3] = A[4, 4] = -c / m
    A[5, 5] = -cphi / I
    B = np.zeros((6, 2))
    B[3, 0], B[3, 1] = co / m, -f * si / m
    B[4, 0], B[4, 1] = si / m, f * co / m
    B[5, 0], B[5, 1] = ia * math.sin(b), ia * f * math.cos(b)
    return A, B


@numba.njit(cache=True)
def _square(p):  # pragma: no cover (compiled)
    """The (6, 6) matrix of a flat (36,) one, row by row (a copy, where ``reshape`` would make
    numba compile its shape checks and their messages)."""
    P = np.empty((6, 6))
    for i in range(6):
        for j in range(6):
            P[i, j] = p[6 * i + j]
    return P


@numba.njit(cache=True)
def _mul(X, Y, tx, ty):  # pragma: no cover (compiled)
    """X @ Y of small matrices, X transposed if ``tx``, Y if ``ty``: each entry summed over k in
    order (BLAS calls would cost more to compile than the products take)."""
    n, m = (X.shape[1], X.shape[0]) if tx else (X.shape[0], X.shape[1])
    p = Y.shape[0] if ty else Y.shape[1]
    Z = np.empty((n, p))
    for i in range(n):
        for j in range(p):
            acc = 0.0
            for k in range(m):
                acc += (X[k, i] if tx else X[i, k]) * (Y[j, k] if ty else Y[k, j])
            Z[i, j] = acc
    return Z


@numba.njit(cache=True)
def _rhs(t, t_in, p, period, nodes, snap, turns, F, beta, basis, colloc, body, Rinv, Q, out):  # pragma: no cover
    """-P' at t for P = p (36,) into out (36,): the motion's state at t, its inputs at t_in."""
    A, B = _jac(t, t_in, period, nodes, snap, turns, F, beta, basis, colloc, body)
    P = _square(p)
    no, yes = np.bool_(False), np.bool_(True)  # typed, not literals: one compiled _mul
    AtP, PA = _mul(A, P, yes, no), _mul(P, A, no, no)
    S = _mul(_mul(_mul(P, B, no, no), Rinv, no, no), B, no, yes)     # ((P B) R^-1) B'
    S = _mul(S, P, no, no)                                              # then P, as numpy associates
    for i in range(6):
        for j in range(6):
            out[6 * i + j] = -((AtP[i, j] + PA[i, j]) - S[i, j] + Q[i, j])


@numba.njit(cache=True)
def _closed_rhs(t, t_in, y, period, nodes, snap, turns, F, beta, basis, colloc, body, R, grid, PG, dPG,
                out):  # pragma: no cover (compiled)
    """(A - B K) Y at t for Y = y (36,) into out (36,), K = R^-1 B' P(t) with P(t) the cubic Hermite
    interpolant of the grid's P, dP (``PeriodicLQR.riccati``, ``PeriodicLQR._gain``)."""
    A, B = _jac(t, t_in, period, nodes, snap, turns, F, beta, basis, colloc, body)
    K = _gain(t, period, B, R, grid, PG, dPG)
    no = np.bool_(False)
    BK = _mul(B, K, no, no)
    for i in range(6):
        for j in range(6):
            BK[i, j] = A[i, j] - BK[i, j]
    M = _mul(BK, _square(y), no, no)
    for i in range(6):
        for j in range(6):
            out[6 * i + j] = M[i, j]


@numba.njit(cache=True)
def _gain(t, period, B, R, grid, PG, dPG):  # pragma: no cover (compiled)
    """K = R^-1 B' P(t) (2, 6), P(t) the cubic Hermite interpolant of the grid's P and dP
    (``PeriodicLQR.riccati``, ``PeriodicLQR._gain``); the 2 x 2 solve by LU with partial pivoting,
    as LAPACK's."""
    s = np.mod(t, period)
    n = grid.size
    k = min(max(np.searchsorted(grid, s, side="right") - 1, 0), n - 2)
    h = grid[k + 1] - grid[k]
    r = (s - grid[k]) / h
    c0, c1 = (1 + 2 * r) * (1 - r) ** 2, r * (1 - r) ** 2 * h
    c2, c3 = r * r * (3 - 2 * r), r * r * (1 - r) * h
    P = np.empty((6, 6))
    for i in range(6):
        for j in range(6):
            P[i, j] = c0 * PG[k, i, j] + c1 * dPG[k, 0, i, j] + c2 * PG[k + 1, i, j] - c3 * dPG[k, 1, i, j]
    Y = _mul(B, P, np.bool_(True), np.bool_(False))
    i0, i1 = (1, 0) if abs(R[1, 0]) > abs(R[0, 0]) else (0, 1)          # the pivot row first
    mult = R[i1, 0] / R[i0, 0]
    u = R[i1, 1] - mult * R[i0, 1]
    K = np.empty((2, 6))
    for j in range(6):
        K[1, j] = (Y[i1, j] - mult * Y[i0, j]) / u
        K[0, j] = (Y[i0, j] - R[i0, 1] * K[1, j]) / R[i0, 0]
    return K


def _make_loop_rows(stamp: int):
    """The clipped loop's kernel, cached on disk by numba. It calls the plant (2)-(4) and the
    wrap of the angle from :mod:`lib.closed_loop` (``_accel``, ``_wrap``), so it closes over
    ``stamp``, the hash of that module (:func:`lib.machinery.cache.source_stamp`): numba keys
    a cached kernel on its own file only, and on its closure's cells."""

    @numba.njit(cache=True)
    def _loop_rows(t, t_in, X, period, nodes, snap, turns, F, beta, basis, colloc, body, R, grid, PG, dPG,
                   F_max, beta_max, out):  # pragma: no cover (compiled)
        """The clipped closed loop's rates (M, 6) into out for the states X (M, 6) at t, the
        motion's inputs read at t_in, as ``lib.optimal.tracker._loop`` computes them:
        u = u* - K (x - x*), the limits of ``_saturate`` (beta_max < 0: no angle limit), then
        (2)-(4)."""
        if stamp < 0:
            return
        xs, fs, bs = _state(t, t_in, period, nodes, snap, turns, F, beta, basis, colloc)
        K = _gain(t, period, _jacobians(xs, fs, bs, body)[1], R, grid, PG, dPG)
        m, I, a, c, cphi = body[0], body[1], body[2], body[3], body[4]
        for r in range(X.shape[0]):
            u0, u1 = 0.0, 0.0
            for j in range(6):
                e = X[r, j] - xs[j]
                u0 += K[0, j] * e
                u1 += K[1, j] * e
            f, b = fs - u0, bs - u1
            if math.isnan(f) or math.isnan(b):
                for j in range(6):
                    out[r, j] = math.nan
                continue
            if beta_max < 0.0:
                if f < 0.0:
                    b = b + np.pi
                f = abs(f)
            f = min(max(f, 0.0), F_max)
            b = _wrap(b)
            if beta_max >= 0.0:
                b = min(max(b, -beta_max), beta_max)
            out[r, 0], out[r, 1], out[r, 2] = X[r, 3], X[r, 4], X[r, 5]
            out[r, 3], out[r, 4], out[r, 5] = _accel(f, b, X[r, 2], X[r, 3], X[r, 4], X[r, 5], m, I, c, cphi, a)

    @numba.njit(cache=True)
    def _loop_steps(Y, edges, n, h, lo_in, hi_in, period, nodes, snap, turns, F, beta, basis, colloc, body, R,
                    grid, PG, dPG, F_max, beta_max, blowup):  # pragma: no cover (compiled)
        """Classical RK4 on the rows Y (M, 6), in place, over the input pieces [edges[p], edges[p + 1]]
        with n[p] fixed steps of h[p] (s) each, the inputs of a piece read at a stage time clamped
        to [lo_in[p], hi_in[p]]: the stage sums of :func:`lib.integrators.batch.steps` in their
        order. Returns (0, 0, 0), or (1, t, row) where a stage's state exceeds ``blowup`` or its
        rate is not finite, or (2, t, row) where a step ends non-finite."""
        M = Y.shape[0]
        K = np.empty((4, M, 6))
        yi = np.empty((M, 6))
        for p in range(edges.size - 1 if stamp >= 0 else 0):
            for k in range(n[p]):
                t = edges[p] + k * h[p]
                for i in range(4):
                    ts = t + (0.0, 0.5, 0.5, 1.0)[i] * h[p]
                    w = (0.0, 0.5, 0.5, 1.0)[i] * h[p]
                    for r in range(M):
                        for col in range(6):
                            v = Y[r, col] if i == 0 else Y[r, col] + w * K[i - 1, r, col]
                            if abs(v) > blowup:
                                return 1, ts, r
                            yi[r, col] = v
                    _loop_rows(ts, min(max(ts, lo_in[p]), hi_in[p]), yi, period, nodes, snap, turns, F, beta,
                               basis, colloc, body, R, grid, PG, dPG, F_max, beta_max, K[i])
                    for r in range(M):
                        for col in range(6):
                            if not np.isfinite(K[i, r, col]):
                                return 1, ts, r
                hb = h[p] / 6.0
                for r in range(M):
                    for col in range(6):
                        acc = ((K[0, r, col] + 2.0 * K[1, r, col]) + 2.0 * K[2, r, col]) + K[3, r, col]
                        Y[r, col] = Y[r, col] + hb * acc
                        if not np.isfinite(Y[r, col]):
                            return 2, edges[p] + (k + 1) * h[p], r
        return 0, 0.0, 0

    return _loop_rows, _loop_steps


_loop_rows, _loop_steps = _make_loop_rows(source_stamp(Path(closed_loop.__file__)))


def loop_rhs(lqr, F_max: float, beta_max: float | None):
    """The compiled rates of the clipped closed loop of :func:`lib.optimal.tracker.track_motion`
    (u = u*(t) - K(t) (x - x*(t)), clipped to ``F_max`` (N, inf for none) and ``beta_max`` (rad,
    None for none), then (2)-(4)), or None for a motion without collocation polynomials (the
    tracker keeps its numpy rates).

    Parameters
    ----------
    lqr : PeriodicLQR
        The periodic LQR.
    F_max : float
        Force limit (N), inf for none.
    beta_max : float or None
        Angle limit (rad), None for none.

    Returns
    -------
    callable or None
        ``rhs(t, X, t_in)``: the rates (M, 6) of the states X (M, 6) (m, m, rad, m/s, m/s, rad/s)
        at t (s), the inputs read at ``t_in`` (s).
    """
    fmax, bmax, arrays = _limited_lqr(lqr, F_max, beta_max)
    if arrays is None:
        return None

    def rhs(t, X, t_in):
        X = np.ascontiguousarray(X, dtype=float)
        out = np.empty_like(X)
        _loop_rows(float(t), float(t_in), X, *arrays, fmax, bmax, out)
        return out
    return rhs


def loop_steps(lqr, F_max: float, beta_max: float | None, edges, n, h, inside):
    """The clipped closed loop of :func:`loop_rhs` stepped by the classical RK4 compiled, or None
    for a motion without collocation polynomials: equal to :func:`lib.integrators.batch.integrate`
    with :data:`lib.integrators.batch.RK4` on :func:`loop_rhs`'s rates piece by piece, to rounding
    (``tests/test_optimal_convergence.py``), without a Python call a stage.

    Parameters
    ----------
    lqr : PeriodicLQR
        The periodic LQR.
    F_max, beta_max : float, float or None
        As in :func:`loop_rhs`.
    edges : array_like
        The input pieces' ends (s), increasing (P + 1,).
    n, h : array_like
        Steps (P,) and their size (s) (P,) on each piece.
    inside : array_like
        (P, 2): the clamp of the stage times at which each piece's inputs are read (s).

    Returns
    -------
    callable or None
        ``run(X, blowup)``: the rows X (M, 6) at the last edge, and a status (code, t (s), row):
        code 1 where a stage's state exceeds ``blowup`` or its rate is not finite, 2 where a step
        ends non-finite, 0 otherwise.
    """
    fmax, bmax, arrays = _limited_lqr(lqr, F_max, beta_max)
    if arrays is None:
        return None
    e, hh = np.ascontiguousarray(edges, dtype=float), np.ascontiguousarray(h, dtype=float)
    nn, ins = np.ascontiguousarray(n, dtype=np.int64), np.ascontiguousarray(inside, dtype=float)

    def run(X, blowup: float):
        Y = np.array(X, dtype=float, order="C")
        status = _loop_steps(Y, e, nn, hh, ins[:, 0].copy(), ins[:, 1].copy(), *arrays, fmax, bmax, float(blowup))
        return (Y, *status)
    return run


def riccati_rhs(body: Body, motion, Q: np.ndarray, R_inv: np.ndarray):
    """The compiled right-hand side of the periodic Riccati equation about ``motion``, or None for
    a motion that is not one of :func:`lib.optimal.motion.periodic_motion` (no collocation
    polynomials): then :func:`lib.optimal.tracker.periodic_lqr` keeps its numpy one.

    Parameters
    ----------
    body : Body
        The body.
    motion : PeriodicMotion
        The motion.
    Q, R_inv : numpy.ndarray
        The state weight (6, 6) and the inverse of the input weight (2, 2).

    Returns
    -------
    callable or None
        ``rhs(t, p, t_in)``: -P'(t) (36,) for P = p (36,), the inputs read at ``t_in`` (s).
    """
    if not all(hasattr(motion, a) for a in ("collocation", "nodes", "degree", "F", "beta")):
        return None
    args = _motion_arrays(body, motion)
    Rinv, Qc = np.ascontiguousarray(R_inv, dtype=float), np.ascontiguousarray(Q, dtype=float)

    def rhs(t, p, t_in):
        out = np.empty(36)
        _rhs(float(t), float(t_in), np.ascontiguousarray(p, dtype=float), *args, Rinv, Qc, out)
        return out
    return rhs


def closed_loop_rhs(lqr):
    """The compiled right-hand side of the linearised closed loop Y' = (A - B K(t)) Y of a periodic
    LQR (:func:`lib.optimal.tracker.periodic_lqr`, for its monodromy matrix), or None for a motion
    without collocation polynomials.

    Parameters
    ----------
    lqr : PeriodicLQR
        The periodic LQR.

    Returns
    -------
    callable or None
        ``rhs(t, y, t_in)``: Y' (36,) for Y = y (36,), the inputs read at ``t_in`` (s).
    """
    arrays = _lqr_arrays(lqr)
    if arrays is None:
        return None

    def rhs(t, y, t_in):
        out = np.empty(36)
        _closed_rhs(float(t), float(t_in), np.ascontiguousarray(y, dtype=float), *arrays, out)
        return out
    return rhs


def _limited_lqr(lqr, F_max, beta_max) -> tuple:
    """The limits checked (the angle limit -1 for none, as the kernels read it) and the LQR's
    arrays (None where it is not one the kernels run): (F_max, beta_max, arrays)."""
    fmax = checks.number("F_max", F_max, positive=True, finite=False, unit="N")
    bmax = -1.0 if beta_max is None else checks.number("beta_max", beta_max, positive=True, maximum=math.pi,
                                                       unit="rad")
    return fmax, bmax, _lqr_arrays(lqr)


def _lqr_arrays(lqr) -> tuple | None:
    """The motion's arrays (:func:`_motion_arrays`), then R, the grid, P and dP of a periodic
    LQR, for the kernels; None for a motion without collocation polynomials."""
    if not all(hasattr(lqr.motion, a) for a in ("collocation", "nodes", "degree", "F", "beta")):
        return None
    return (*_motion_arrays(lqr.body, lqr.motion), *(np.ascontiguousarray(a, dtype=float)
                                                     for a in (lqr.R, lqr.t, lqr.P, lqr.dP)))


def _motion_arrays(body: Body, motion) -> tuple:
    """(period, nodes, the node snap, turns, F, beta, basis, collocation, body) for the kernels."""
    return (float(motion.period), int(motion.nodes), float(NODE_SNAP), int(motion.turns),
            np.ascontiguousarray(motion.F, dtype=float), np.ascontiguousarray(motion.beta, dtype=float),
            np.ascontiguousarray(tableau(int(motion.degree)).basis, dtype=float),
            np.ascontiguousarray(motion.collocation, dtype=float),
            np.array([body.m, body.I, body.a, body.c, body.c_phi], dtype=float))
