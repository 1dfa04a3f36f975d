"""The batch integrator: explicit Runge-Kutta with a fixed step, vectorised over many
parameter points at once.

Every point takes the same steps, so the states of N points are one array and each
stage is one vectorised evaluation of the field. Used for the closed loop over a
map of (R, Theta) (Chapter 6, :func:`lib.weighting.batch.closed_loop_batch`, classical
RK4) and for the reduced rotation equation over the Fig. 5 grid
(:mod:`lib.rotation`, 8th-order Dormand-Prince), whose compiled engine runs this
same scheme in numba loops.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Callable, Iterator

import numpy as np

__all__ = ["Tableau", "RK4", "dop853", "steps", "integrate", "fixed_steps", "nonfinite_message"]


@dataclass(frozen=True)
class Tableau:
    """Butcher tableau of an explicit method: stage coefficients ``A`` (s, s), nodes ``c``
    (s,) and weights ``b`` / ``b_den`` (``b`` may hold whole numbers over a common
    denominator, as the classical RK4's (1, 2, 2, 1) / 6)."""

    name: str
    A: np.ndarray
    c: np.ndarray
    b: np.ndarray
    b_den: float = 1.0


#: the classical Runge-Kutta method of order 4
RK4 = Tableau("RK4", A=np.array([[0, 0, 0, 0], [0.5, 0, 0, 0], [0, 0.5, 0, 0], [0, 0, 1.0, 0]]),
              c=np.array([0, 0.5, 0.5, 1.0]), b=np.array([1.0, 2.0, 2.0, 1.0]), b_den=6.0)


@lru_cache(maxsize=None)
def dop853() -> Tableau:
    """The 8th-order Dormand-Prince method of scipy's ``DOP853``, used with a fixed step."""
    from scipy.integrate import DOP853

    n = DOP853.n_stages
    return Tableau("DOP853", A=np.array(DOP853.A[:n, :n]), c=np.array(DOP853.C[:n]), b=np.array(DOP853.B))


Rates = Callable[[float, np.ndarray], np.ndarray]


def steps(rates: Rates, y0, t0: float, h: float, n_steps: int, tableau: Tableau = RK4) -> Iterator:
    """Yield (t, y) after each of ``n_steps`` steps of size ``h`` from (t0, y0), for
    y' = rates(t, y); y may have any shape (e.g. (N points, d)), rates returns the same.
    Stage sums are taken term by term in order, zero coefficients skipped.

    Parameters
    ----------
    rates : callable
        (t, y) -> y'.
    y0 : array_like
        Start, any shape.
    t0 : float
        Start time.
    h : float
        Step.
    n_steps : int
        Steps.
    tableau : Tableau
        The explicit Runge-Kutta method.

    Yields
    ------
    tuple
        (t, y) after each step.
    """
    A, b, c = tableau.A, tableau.b, tableau.c
    hA, hb = h * A, h / tableau.b_den
    n_st = len(c)
    y = np.asarray(y0, dtype=np.result_type(np.asarray(y0), float))
    for k in range(n_steps):
        t = t0 + k * h
        K = []
        for i in range(n_st):
            yi = y
            for j in range(i):
                if A[i, j] != 0:
                    yi = yi + hA[i, j] * K[j]
            K.append(rates(t + c[i] * h, yi))
        acc = b[0] * K[0]
        for j in range(1, n_st):
            if b[j] != 0:
                acc = acc + b[j] * K[j]
        y = y + hb * acc
        yield t0 + (k + 1) * h, y


def integrate(rates: Rates, y0, t0: float, t_end: float, dt: float, tableau: Tableau = RK4, *,
              record_every: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """Integrate from t0 to ``t_end`` with the largest step h <= ``dt`` that divides the
    interval, recording (t, y) at the start, every ``record_every`` steps and at the end.
    A state that becomes non-finite raises ``FloatingPointError`` naming the time and the
    first point (index along the first axis) affected.

    Parameters
    ----------
    rates : callable
        (t, y) -> y'.
    y0 : array_like
        Start, any shape.
    t0, t_end : float
        Start and end times.
    dt : float
        Largest step.
    tableau : Tableau
        The explicit Runge-Kutta method.
    record_every : int
        Steps between records.

    Returns
    -------
    t : numpy.ndarray
        Recorded times, (n,).
    y : numpy.ndarray
        Recorded states, (n,) + y0.shape.
    """
    n_steps, h = fixed_steps(t0, t_end, dt)
    ts, ys = [t0], [np.array(y0, dtype=np.result_type(np.asarray(y0), float))]
    for k, (t, y) in enumerate(steps(rates, y0, t0, h, n_steps, tableau), start=1):
        if not np.all(np.isfinite(y)):
            bad = np.flatnonzero(~np.all(np.isfinite(y.reshape(y.shape[0], -1)), axis=1)) if y.ndim else [0]
            raise FloatingPointError(nonfinite_message(t, int(bad[0])))
        if k % record_every == 0 or k == n_steps:
            ts.append(t)
            ys.append(y)
    return np.array(ts), np.array(ys)


def fixed_steps(t0: float, t_end: float, dt: float) -> tuple[int, float]:
    """The steps :func:`integrate` takes from t0 to ``t_end``: their number n and size h, the
    largest h <= ``dt`` that divides the interval.

    Parameters
    ----------
    t0, t_end : float
        Start and end times.
    dt : float
        Largest step.

    Returns
    -------
    tuple
        (n, h).
    """
    n_steps = int(np.ceil((t_end - t0) / dt))
    return n_steps, (t_end - t0) / n_steps


def nonfinite_message(t: float, point: int) -> str:
    """What :func:`integrate` says of a state that became non-finite at time t at ``point``.

    Parameters
    ----------
    t : float
        The time (s).
    point : int
        The point's index along the first axis.

    Returns
    -------
    str
        The message.
    """
    return f"batch integration became non-finite at t = {t:.6g} s for point {point}"
