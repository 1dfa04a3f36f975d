"""The right-hand side of the periodic Riccati equation of :func:`lib.optimal.tracker.periodic_lqr`,
compiled, for a motion of :func:`lib.optimal.motion.periodic_motion` (its collocation polynomials
and piecewise-constant inputs).

``solve_ivp`` calls it on one matrix P at a time, about 12 000 times a Riccati solution, so the
numpy version's cost was its calls' overhead: the motion's state read from its polynomials
(:meth:`lib.optimal.motion.PeriodicMotion.state`, :meth:`~lib.optimal.motion.PeriodicMotion.inputs`),
the Jacobians of (2)-(4) (:func:`lib.optimal.tracker.jacobians`) and -P' = A'P + PA - P B R^-1 B' P + Q.
Here the same formulas, in their order (the products by numba's BLAS calls): equal to the numpy right-hand side to rounding (``tests/test_optimal_tracker.py``).

Units: SI (s, m, rad, N).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from ..params import Body
from .collocation import tableau

__all__ = ["riccati_rhs"]

#: a node time computed in floating point belongs to the interval it starts (as :mod:`lib.optimal.motion`)
_SNAP = 1e-9


@numba.njit(cache=True)
def _locate(t, period, nodes):  # pragma: no cover (compiled)
    """(interval, local time in [0, 1], whole periods) of t (s), as ``PeriodicMotion._locate``."""
    laps = math.floor(t / period)
    x = (t - laps * period) * (nodes / period)
    k = min(max(int(math.floor(x + _SNAP)), 0), nodes - 1)
    return k, min(max(x - k, 0.0), 1.0), laps


@numba.njit(cache=True)
def _rhs(t, t_in, p, period, nodes, turns, F, beta, basis, colloc, body, Rinv, Q, out):  # pragma: no cover
    """-P' at t for P = p (36,) into out (36,): the motion's state at t, its inputs at t_in."""
    k, s, laps = _locate(t, period, nodes)
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
    ki = _locate(ti, period, nodes)[0]
    f, b = F[ki], beta[ki]
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
    P = p.reshape(6, 6)
    M = A.T @ P + P @ A - P @ B @ Rinv @ np.ascontiguousarray(B.T) @ P + Q
    for i in range(6):
        for j in range(6):
            out[6 * i + j] = -M[i, j]


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
    basis = np.ascontiguousarray(tableau(int(motion.degree)).basis, dtype=float)
    colloc = np.ascontiguousarray(motion.collocation, dtype=float)
    F, beta = np.ascontiguousarray(motion.F, dtype=float), np.ascontiguousarray(motion.beta, dtype=float)
    bv = np.array([body.m, body.I, body.a, body.c, body.c_phi], dtype=float)
    Rinv = np.ascontiguousarray(R_inv, dtype=float)
    Qc = np.ascontiguousarray(Q, dtype=float)
    period, nodes, turns = float(motion.period), int(motion.nodes), int(motion.turns)

    def rhs(t, p, t_in):
        out = np.empty(36)
        _rhs(float(t), float(t_in), np.ascontiguousarray(p, dtype=float), period, nodes, turns, F, beta, basis,
             colloc, bv, Rinv, Qc, out)
        return out
    return rhs
