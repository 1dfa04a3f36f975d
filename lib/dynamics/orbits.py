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
points; :func:`rotation_period_map` is the period map of the reduced rotation
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
from typing import Callable

import numpy as np


__all__ = ["Orbit", "newton_orbit", "floquet_multipliers", "MapWithJacobian"]

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
        """(N,) bool: converged and every multiplier inside the unit circle."""
        return self.converged & (np.abs(self.multipliers[:, 0]) < 1.0)


def floquet_multipliers(jacobian) -> np.ndarray:
    """Eigenvalues of DP^k (shape (..., d, d)), sorted by decreasing modulus."""
    J = np.asarray(jacobian, dtype=float)
    if J.ndim < 2 or J.shape[-1] != J.shape[-2]:
        raise ValueError(f"jacobian must have shape (..., d, d), got {J.shape}")
    if not np.all(np.isfinite(J)):
        raise ValueError("jacobian must be finite")
    lam = np.linalg.eigvals(J)
    order = np.argsort(-np.abs(lam), axis=-1, kind="stable")
    return np.take_along_axis(lam, order, axis=-1)


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
    ``max_iter`` steps with ``converged`` False.
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
    J = np.empty((N, d, d))
    res = np.full(N, np.inf)
    its = np.zeros(N, dtype=int)
    todo = np.arange(N)
    for it in range(max_iter + 1):
        y, Jt = _power(step, x[todo], k)
        G = y - x[todo] - shift[todo]
        J[todo] = Jt
        res[todo] = np.max(np.abs(G), axis=1)
        done = ~(res[todo] > tol)  # NaN residuals count as done (and not converged)
        todo_next = todo[~done]
        if it == max_iter or todo_next.size == 0:
            break
        Gk, Jk = G[~done], Jt[~done]
        dx = np.linalg.solve(Jk - np.eye(d), -Gk[..., None])[..., 0]
        scale = np.maximum(1.0, np.max(np.abs(dx), axis=1) / max_step)
        x[todo_next] += dx / scale[:, None]
        its[todo_next] += 1
        todo = todo_next
    return Orbit(x=x, jacobian=J, residual=res, converged=res <= tol, iterations=its)
