"""The largest Lyapunov exponent of a flow, with its standard error, by two nearby
trajectories renormalised at fixed intervals (Benettin et al. {cite}`benettin1980`)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from .statistics import block_statistics

__all__ = ["LyapunovEstimate", "largest_lyapunov"]


@dataclass(frozen=True)
class LyapunovEstimate:
    """Largest Lyapunov exponent (1/s) with its standard error over the renormalisation
    intervals, and the running estimate after each interval."""

    value: float
    stderr: float
    running: np.ndarray


def largest_lyapunov(flow: Callable, x0, dt: float, n_steps: int, *, d0: float = 1e-8,
                     n_transient: int = 0, difference: Callable | None = None,
                     direction=None) -> LyapunovEstimate:
    """Largest Lyapunov exponent by two nearby trajectories renormalised every ``dt`` (Benettin).

    ``flow(x, t0, t1)`` maps a state at t0 to t1 (it may carry extra state, e.g.
    a switching mode, as the second item of a tuple ``(x, extra)``: then
    ``x0`` is such a tuple too). After ``n_transient`` intervals the companion
    starts at distance ``d0`` along ``direction`` (default: all components
    equal); after each interval its separation d is measured with
    ``difference`` (default a - b), log(d / d0) recorded, and the companion
    pulled back to distance d0 along the separation.
    Returns the mean of log(d/d0)/dt and its standard error: the batch-means error of
    :func:`lib.dynamics.statistics.block_statistics`, its blocks set from the intervals'
    integrated autocorrelation time (the book's one estimator of an error).

    Parameters
    ----------
    flow : callable
        (x, t0, t1) -> the state at t1.
    x0 : array_like or tuple
        The start (with its extra state, if the flow carries one).
    dt : float
        Renormalisation interval (s).
    n_steps : int
        Intervals averaged.
    d0 : float
        Initial separation (the state's units).
    n_transient : int
        Intervals before the companion starts.
    difference : callable, optional
        (a, b) -> a - b (e.g. with an angle wrapped).
    direction : array_like, optional
        The companion's initial direction.

    Returns
    -------
    LyapunovEstimate
        value (1/s), its standard error and the running estimate.
    """
    if dt <= 0 or n_steps < 2 or d0 <= 0:
        raise ValueError("need dt > 0, n_steps >= 2 and d0 > 0")
    diff = difference or (lambda a, b: np.asarray(a, float) - np.asarray(b, float))
    carry = isinstance(x0, tuple)
    state = x0
    t = 0.0
    for _ in range(n_transient):
        state = flow(state[0], t, t + dt, state[1]) if carry else flow(state, t, t + dt)
        t += dt
    x = np.asarray(state[0] if carry else state, dtype=float)
    u = np.ones_like(x) if direction is None else np.asarray(direction, dtype=float)
    u = u / np.linalg.norm(u)
    y = x + d0 * u
    extra_x = state[1] if carry else None
    extra_y = None
    logs = np.empty(n_steps)
    for i in range(n_steps):
        if carry:
            x, extra_x = flow(x, t, t + dt, extra_x)
            y, extra_y = flow(y, t, t + dt, None)
        else:
            x, y = flow(x, t, t + dt), flow(y, t, t + dt)
        t += dt
        d = diff(y, x)
        dn = float(np.linalg.norm(d))
        if not np.isfinite(dn) or dn == 0:
            raise RuntimeError(f"separation became {dn} at t = {t:.6g}")
        logs[i] = math.log(dn / d0)
        y = np.asarray(x, dtype=float) + d * (d0 / dn)
    rates = logs / dt
    _, se = block_statistics(rates[None], 1)
    return LyapunovEstimate(value=float(rates.mean()), stderr=float(se[0]),
                            running=np.cumsum(logs) / (dt * np.arange(1, n_steps + 1)))
