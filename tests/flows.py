"""Flows with known Lyapunov exponents, for testing the estimator of :mod:`lib.limits`."""

from __future__ import annotations

import math
from typing import Callable

import numpy as np
from scipy.integrate import solve_ivp
from scipy.linalg import expm


def damped_oscillator_flow(zeta: float = 0.1, omega: float = 1.0) -> Callable:
    """Flow of x'' + 2 zeta omega x' + omega^2 x = 0 (exact, via the matrix exponential);
    its Lyapunov exponents are -zeta omega (twice, for zeta < 1)."""
    A = np.array([[0.0, 1.0], [-omega**2, -2 * zeta * omega]])

    def flow(x, t0, t1):
        return expm(A * (t1 - t0)) @ np.asarray(x, dtype=float)
    return flow


def driven_pendulum_flow(q: float = 2.0, g: float = 1.5, omega_d: float = 2.0 / 3.0,
                         rtol: float = 1e-10, atol: float = 1e-10) -> Callable:
    """Flow of the driven damped pendulum of Baker & Gollub (Chaotic Dynamics, 1996),
    theta'' + theta'/q + sin(theta) = g cos(omega_d t), state (theta, theta').
    Their q = 2, g = 1.5, omega_d = 2/3 is chaotic."""

    def rhs(t, x):
        return [x[1], -x[1] / q - math.sin(x[0]) + g * math.cos(omega_d * t)]

    def flow(x, t0, t1):
        return solve_ivp(rhs, (t0, t1), x, method="DOP853", rtol=rtol, atol=atol).y[:, -1]
    return flow
