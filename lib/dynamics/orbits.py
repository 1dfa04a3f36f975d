"""Periodic orbits located, not waited for: Newton on a period map, and Floquet multipliers.

A periodic motion of a T-periodic system is a fixed point of the k-th power of
its period (stroboscopic) map P, up to a shift: P^k(x) = x + shift, where the
shift is zero for a motion that repeats and (2 pi n, 0, ...) for one whose angle
advances by n whole turns every k periods (a slipping motion). Newton's method
on G(x) = P^k(x) - x - shift, with the Jacobian DP^k from the variational
equations, finds such an orbit in a few iterations from a rough start, where
waiting for a transient to die out may take hundreds of periods (the slowest
Floquet multiplier of the paper's own eight is close to one). The eigenvalues of
DP^k at the orbit are its Floquet multipliers: the orbit attracts when all lie
inside the unit circle.

:func:`newton_orbit` works on any map given with its Jacobian, vectorised over
points; :func:`lib.rotation.reduced.rotation_period_map` is the period map of the reduced rotation
equation (32) on the eight (28) or the circle (27), integrated with the same
fixed-step 8th-order Dormand-Prince scheme as the Fig. 5 sweep
(:func:`lib.stability.rotation_sweep`), its Jacobian by integrating the
variational equation with the same stages (so it is the exact derivative of the
discrete map, and Newton converges quadratically on it).

Units: angles in rad, the phase s = Theta t in rad; w = d phi / ds is
dimensionless (the rate d phi / dt divided by Theta).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, NamedTuple

import numpy as np


__all__ = ["Orbit", "newton", "NewtonResult", "newton_orbit", "floquet_multipliers", "MapWithJacobian"]

MapWithJacobian = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]


@dataclass(frozen=True)
class Orbit:
    """Result of :func:`newton_orbit` for N starting points in d dimensions.

    ``x`` (N, d): a point of each orbit; ``jacobian`` (N, d, d): DP^k there;
    ``residual`` (N,): max-norm of P^k(x) - x - shift; ``converged`` (N,) bool:
    residual <= tol; ``iterations`` (N,): Newton steps taken.
    """

    x: np.ndarray
    jacobian: np.ndarray
    residual: np.ndarray
    converged: np.ndarray
    iterations: np.ndarray

    @property
    def multipliers(self) -> np.ndarray:
        """Floquet multipliers (N, d), complex, sorted by decreasing modulus."""
        return floquet_multipliers(self.jacobian)

    @property
    def attracting(self) -> np.ndarray:
        """Converged and every multiplier inside the unit circle, one bool per row (N,)."""
        return self.converged & (np.abs(self.multipliers[:, 0]) < 1.0)


def floquet_multipliers(jacobian) -> np.ndarray:
    """Eigenvalues of DP^k (shape (..., d, d)), sorted by decreasing modulus.

    Parameters
    ----------
    jacobian : array_like
        DP^k, shape (..., d, d).

    Returns
    -------
    numpy.ndarray
        The multipliers (complex, dimensionless), (..., d).
    """
    J = np.asarray(jacobian, dtype=float)
    if J.ndim < 2 or J.shape[-1] != J.shape[-2]:
        raise ValueError(f"jacobian must have shape (..., d, d), got {J.shape}")
    if not np.all(np.isfinite(J)):
        raise ValueError("jacobian must be finite")
    lam = np.linalg.eigvals(J)
    order = np.argsort(-np.abs(lam), axis=-1, kind="stable")
    return np.take_along_axis(lam, order, axis=-1)


class NewtonResult(NamedTuple):
    """What :func:`newton` returns for M rows: the iterate ``x`` (M, d), ``jacobian`` DP^k
    there (M, d, d), ``residual`` (M,), ``turns`` n (M,), ``iterations`` (M,)."""

    x: np.ndarray
    jacobian: np.ndarray
    residual: np.ndarray
    turns: np.ndarray
    iterations: np.ndarray


def newton(step: Callable, idx, x0, k, *, turn_axis: int = 0, turns=None, tol: float, max_iter: int,
           max_step: float = 1.0, stall_after: int | None = None, polish: float | None = None):
    """Orbits of period k: Newton on G(x) = P^k(x) - x - 2 pi n e_turn for many rows.

    ``step(idx, x, k) -> (P^k(x), DP^k)`` for the rows ``idx`` (the map's exact
    Jacobian, or :func:`lib.dynamics.verdicts.difference_jacobian`). ``turns``: the whole turns n per row
    (M,), or None to take n afresh at every iterate as the turns P^k(x) - x is nearest
    to. Steps longer than ``max_step`` (max-norm) are cut back to it. A row goes on
    while its residual exceeds ``tol`` (after ``stall_after`` iterations, only while
    it at least halves) and, below ``tol``, while it is above ``polish`` and still
    halves; at most ``max_iter`` steps. Returns a :class:`NewtonResult`: x (M, d), DP^k
    (M, d, d) at the last iterate, the residual (M,) (max-norm; NaN where a step was not
    finite), the turns n (M,) and the steps taken (M,).

    Parameters
    ----------
    step : callable
        (idx, x, k) -> (P^k(x), DP^k).
    idx : array_like
        Rows of the map (M,).
    x0 : array_like
        Starting points (M, d).
    k : int or array_like
        Periods (one or one per row).
    turn_axis : int
        The heading's column.
    turns : array_like, optional
        Whole turns per row.
    tol : float
        Residual tolerance (the state's units).
    max_iter : int
        Iterations.
    max_step : float
        Longest step (max-norm).
    stall_after : int, optional
        Iterations after which a row goes on only while its residual halves.
    polish : float, optional
        Residual below which a row is polished.

    Returns
    -------
    NewtonResult
        The points x, the Jacobian there, the residuals, the turns and the iterations.
    """
    x = np.array(x0, dtype=float)
    M, d = x.shape
    idx = np.asarray(idx)
    k = np.broadcast_to(np.asarray(k, dtype=int), (M,))
    fixed = turns is not None
    n = np.broadcast_to(np.asarray(turns if fixed else 0), (M,)).astype(int)
    polish = tol if polish is None else polish
    stall = np.inf if stall_after is None else stall_after
    J = np.tile(np.eye(d), (M, 1, 1))
    res, prev = np.full(M, np.inf), np.full(M, np.inf)
    its = np.zeros(M, int)
    eye = np.eye(d)
    todo = np.arange(M)
    for it in range(max_iter + 1):
        y, Jt = step(idx[todo], x[todo], k[todo])
        G = y - x[todo]
        if not fixed:
            n[todo] = np.rint(G[:, turn_axis] / (2 * np.pi)).astype(int)
        G[:, turn_axis] -= (2 * np.pi) * n[todo]
        r = np.abs(G).max(axis=1)
        J[todo], res[todo] = Jt, r
        halving = r < 0.5 * prev[todo]
        go = np.isfinite(r) & (((r > tol) & ((it < stall) | halving)) | ((r > polish) & halving))
        prev[todo] = r
        if it == max_iter or not go.any():
            break
        with np.errstate(all="ignore"):
            dx = np.linalg.solve(Jt[go] - eye, -G[go][..., None])[..., 0]
        dx /= np.maximum(1.0, np.abs(dx).max(axis=1) / max_step)[:, None]
        bad = ~np.all(np.isfinite(dx), axis=1)
        t = todo[go]
        x[t] += np.where(bad[:, None], 0.0, dx)
        its[t] += 1
        res[t[bad]] = np.nan
        todo = t[~bad]
        if todo.size == 0:
            break
    return NewtonResult(x, J, res, n, its)


def _power(step: MapWithJacobian, x: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """P^k(x) and its Jacobian by the chain rule, for points x of shape (N, d)."""
    J = np.broadcast_to(np.eye(x.shape[1]), (x.shape[0],) + (x.shape[1],) * 2).copy()
    for _ in range(k):
        x, Jk = step(x)
        J = Jk @ J
    return x, J


def newton_orbit(step: MapWithJacobian, x0, k: int = 1, shift=0.0, *, tol: float = 1e-11,
                 max_iter: int = 40, max_step: float = 1.0) -> Orbit:
    """Orbits of period ``k`` of the map ``step``: points with P^k(x) = x + ``shift``.

    ``step(x)`` maps points x of shape (N, d) to (P(x) (N, d), DP(x) (N, d, d)).
    ``x0`` (N, d) are the starting guesses (e.g. the state after a short
    transient); ``shift`` (d,) or (N, d) is the advance per k periods (zero for
    a repeating motion). Newton steps longer than ``max_step`` (max-norm) are
    cut back to it, which keeps a far start from jumping across the phase
    space. Points whose residual falls to ``tol`` stop; the rest stop after
    ``max_iter`` steps with ``converged`` False. (:func:`newton` on the map less its shift.)

    Parameters
    ----------
    step : callable
        x (N, d) -> (P(x), DP(x)).
    x0 : array_like
        Starting guesses (N, d).
    k : int
        Period (>= 1).
    shift : float or array_like
        Advance per k periods, (d,) or (N, d).
    tol : float
        Residual tolerance.
    max_iter : int
        Iterations.
    max_step : float
        Longest step (max-norm).

    Returns
    -------
    Orbit
        The orbit points x, the Jacobian there, the residuals, convergence and iterations.
    """
    if not isinstance(k, (int, np.integer)) or k < 1:
        raise ValueError(f"period k must be a positive integer, got {k!r}")
    x = np.array(x0, dtype=float, ndmin=2)
    if x.ndim != 2 or not np.all(np.isfinite(x)):
        raise ValueError(f"x0 must be a finite array of shape (N, d), got shape {x.shape}")
    if not (np.isfinite(tol) and tol > 0 and max_step > 0):
        raise ValueError("tol and max_step must be positive")
    N, d = x.shape
    shift = np.broadcast_to(np.asarray(shift, dtype=float), (N, d))

    def shifted(idx, y, kk):
        Pk, J = _power(step, y, int(kk[0]))
        return Pk - shift[idx], J

    r = newton(shifted, np.arange(N), x, k, turns=np.zeros(N, int), tol=tol, max_iter=max_iter, max_step=max_step)
    with np.errstate(invalid="ignore"):
        converged = r.residual <= tol
    return Orbit(x=r.x, jacobian=r.jacobian, residual=r.residual, converged=converged, iterations=r.iterations)
