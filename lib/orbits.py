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

from .params import Body
from .stability import _check_grid, _coefficients, _forcing, _initial, _tableau, steps_per_period

__all__ = ["Orbit", "newton_orbit", "floquet_multipliers", "rotation_period_map", "rotation_orbit",
           "RotationLyapunov", "rotation_lyapunov"]

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


def rotation_period_map(body: Body, kind: str, R, Theta, *, steps: int | None = None,
                        h_lambda: float = 0.125) -> MapWithJacobian:
    """The period map of the reduced rotation equation (32) on the reference ``kind``
    (``"eight"`` or ``"circle"``) for the points (R_i (m), Theta_i (rad/s)), all with
    the same number of fixed steps per period (``steps``, or the largest that
    :func:`lib.stability.steps_per_period` asks for).

    The returned function maps states x = (phi, w) of shape (N, 2) at phase
    s = 0 (mod 2 pi) to the states one reference period later, with the Jacobian
    d x(2 pi) / d x(0) (N, 2, 2); phi is the heading (rad) and w = d phi / ds. Its
    attribute ``winding`` is the number of turns the reference heading makes per
    period (0 on the eight, 1 on the circle).
    """
    if kind not in ("eight", "circle"):
        raise ValueError(f"kind must be 'eight' or 'circle', got {kind!r}")
    if not isinstance(body, Body):
        raise TypeError(f"body must be a lib.params.Body, got {type(body).__name__}")
    R, Theta = _check_grid(R, Theta)
    n = int(steps) if steps is not None else int(steps_per_period(body, kind, R, Theta, h_lambda).max())
    if n < 1:
        raise ValueError(f"steps must be a positive integer, got {steps!r}")
    h, X1, Y1, X2, Y2, _, winding = _forcing(kind, n)
    A, B, C = _coefficients(body, R, Theta)
    Aa, Bb, _ = _tableau()
    hA, hB = Aa * h, Bb * h
    stages = X1.shape[1]

    def step(x):
        x = np.asarray(x, dtype=float)
        if x.shape != (R.size, 2):
            raise ValueError(f"states must have shape ({R.size}, 2), got {x.shape}")
        phi, w = x[:, 0].copy(), x[:, 1].copy()
        V = np.broadcast_to(np.eye(2)[:, :, None], (2, 2, R.size)).copy()  # V[component, column, point]
        KP = np.empty((stages, R.size))
        KW = np.empty_like(KP)
        KV = np.empty((stages, 2, 2, R.size))
        for j in range(n):
            for i in range(stages):
                ps = phi + np.tensordot(hA[i, :i], KP[:i], 1)
                ws = w + np.tensordot(hA[i, :i], KW[:i], 1)
                Vs = V + np.tensordot(hA[i, :i], KV[:i], 1)
                fy, fx = B * Y1[j, i] + C * Y2[j, i], B * X1[j, i] + C * X2[j, i]
                c, s = np.cos(ps), np.sin(ps)
                KP[i] = ws
                KW[i] = fy * c - fx * s - A * ws
                dfdphi = -fy * s - fx * c
                KV[i, 0] = Vs[1]
                KV[i, 1] = dfdphi * Vs[0] - A * Vs[1]
            phi = phi + hB @ KP
            w = w + hB @ KW
            V = V + np.tensordot(hB, KV, 1)
        return np.column_stack([phi, w]), np.moveaxis(V, -1, 0)

    step.winding = winding  # turns of the reference heading per period (eight 0, circle 1)
    return step


def rotation_orbit(body: Body, kind: str, R, Theta, *, k: int = 1, slip: int = 0, p0=0.0, v0=0.0,
                   transient: int = 10, steps: int | None = None, tol: float = 1e-11) -> Orbit:
    """Locate a period-``k`` orbit of the heading on the reference ``kind`` at each point
    (R_i (m), Theta_i (rad/s)), starting Newton from the state reached after
    ``transient`` periods from p(0) = ``p0`` (rad), dp/dt(0) = ``v0`` (rad/s) (the start
    on the reference by default). ``slip`` is the number of whole turns the heading
    error gains per k periods (0 for a repeating motion). The orbit's ``x`` are the
    states (phi, w = d phi / ds) at phase s = 0."""
    R, Theta = _check_grid(R, Theta)
    step = rotation_period_map(body, kind, R, Theta, steps=steps)
    phi, w = _initial(kind, Theta, np.broadcast_to(np.asarray(p0, float), R.shape),
                      np.broadcast_to(np.asarray(v0, float), R.shape))
    x = np.column_stack([phi, w])
    winding = step.winding
    for _ in range(transient):
        x, _ = step(x)
    x[:, 0] -= 2 * np.pi * winding * transient
    shift = np.array([2 * np.pi * (winding * k + slip), 0.0])
    return newton_orbit(step, x, k, shift, tol=tol)


@dataclass(frozen=True)
class RotationLyapunov:
    """Largest Lyapunov exponent of the reduced rotation equation at N points:
    ``value`` (N,) in 1/s, ``stderr`` (N,) its standard error over the periods
    averaged, and ``periods`` the number of periods averaged."""

    value: np.ndarray
    stderr: np.ndarray
    periods: int


def rotation_lyapunov(body: Body, kind: str, R, Theta, *, periods: int = 200, transient: int = 50,
                      p0=0.0, v0=0.0, steps: int | None = None) -> RotationLyapunov:
    """Largest Lyapunov exponent (1/s) of the heading on the reference ``kind`` at each point
    (R_i (m), Theta_i (rad/s)), from p(0) = ``p0``, dp/dt(0) = ``v0`` (the reference start
    by default): after ``transient`` periods a tangent vector is carried by the exact
    Jacobian of the period map (:func:`rotation_period_map`) and renormalised every
    period; the exponent is the mean of the ``periods`` logarithmic growth rates
    divided by the period 2 pi / Theta, and its standard error that of the mean (the
    rates of successive periods are treated as independent, which is what makes the
    error small only for long runs).
    """
    if not isinstance(periods, (int, np.integer)) or periods < 2:
        raise ValueError(f"periods must be an integer >= 2, got {periods!r}")
    if not isinstance(transient, (int, np.integer)) or transient < 0:
        raise ValueError(f"transient must be a non-negative integer, got {transient!r}")
    R, Theta = _check_grid(R, Theta)
    step = rotation_period_map(body, kind, R, Theta, steps=steps)
    phi, w = _initial(kind, Theta, np.broadcast_to(np.asarray(p0, float), R.shape),
                      np.broadcast_to(np.asarray(v0, float), R.shape))
    x = np.column_stack([phi, w])
    for _ in range(transient):
        x, _ = step(x)
    u = np.tile(np.array([1.0, 1.0]) / np.sqrt(2.0), (R.size, 1))
    logs = np.empty((periods, R.size))
    for i in range(periods):
        x, J = step(x)
        u = np.einsum("nij,nj->ni", J, u)
        norm = np.linalg.norm(u, axis=1)
        logs[i] = np.log(norm)
        u = u / norm[:, None]
    rates = logs * (Theta / (2 * np.pi))
    return RotationLyapunov(value=rates.mean(axis=0), stderr=rates.std(axis=0, ddof=1) / np.sqrt(periods),
                            periods=int(periods))
