"""Stroboscopic (Poincaré) sections of a periodically driven motion: how many distinct
points a section has, its period, and by how much that verdict clears its tolerance."""

from __future__ import annotations

import math

import numpy as np

__all__ = ["distinct_points", "section_period", "section_margin"]


def distinct_points(points, tol: float) -> int:
    """Number of clusters of ``points`` (n, d) whose members lie within ``tol`` of
    the cluster's first point (max-norm); a period-k orbit of the map gives k.

    Parameters
    ----------
    points : array_like
        Section points (n, d).
    tol : float
        Cluster radius (max-norm, the points' units).

    Returns
    -------
    int
        The number of clusters.
    """
    pts = np.atleast_2d(np.asarray(points, dtype=float))
    if pts.shape[0] == 0:
        raise ValueError("points must not be empty")
    reps: list[np.ndarray] = []
    for p in pts:
        if not any(np.max(np.abs(p - r)) <= tol for r in reps):
            reps.append(p)
    return len(reps)


def section_period(points, tol: float, max_period: int = 8) -> tuple[int, bool]:
    """Smallest period k <= ``max_period`` of a stroboscopic sequence, and whether it is
    still converging: (k, False) if the last points repeat every k periods within
    ``tol`` (max-norm); (k, True) if d_j = |P_(j+k) - P_j| shrinks strictly at every
    step over the second half of the sequence (at least 8 steps; fewer could shrink
    by chance) *towards zero*: the Aitken extrapolation of its limit,
    d_n - (d_n - d_(n-1))^2 / (d_n - 2 d_(n-1) + d_(n-2)), is below ``tol`` or
    below half the last distance d_n. (A period-2k orbit approached from one side
    makes the lag-k distances shrink strictly too, but towards the orbit's non-zero
    spread, and the extrapolated limit is then close to d_n itself; a slow geometric
    approach to an orbit, whose ratio still creeps up towards the slowest
    multiplier, extrapolates to a small fraction of d_n.) (0, False) if neither
    holds for any k.

    Parameters
    ----------
    points : array_like
        Section points (n, d), oldest first.
    tol : float
        Tolerance (max-norm, the points' units).
    max_period : int
        Longest period tried.

    Returns
    -------
    k : int
        The period (0: none found).
    converging : bool
        Whether the sequence is still converging to it.
    """
    pts = np.atleast_2d(np.asarray(points, dtype=float))
    n = pts.shape[0]
    if n < 4:
        raise ValueError("need at least 4 section points")
    if not (np.isfinite(tol) and tol > 0):
        raise ValueError(f"tol must be a positive distance, got {tol!r}")
    for k in range(1, min(max_period, n // 2) + 1):
        tail = _lag_distances(pts, k)
        if np.all(tail[-k:] <= tol):
            return k, False
        if tail.size >= 8 and np.all(np.diff(tail) < 0) and _aitken_limit(tail) <= max(tol, 0.5 * tail[-1]):
            return k, True
    return 0, False


def section_margin(points, tol: float, max_period: int = 8) -> float:
    """How decisively :func:`section_period` decides a sequence, as a factor on ``tol``:
    for a period k found (not converging), ``tol`` over the distance at which the last
    points repeat every k periods; for none found, the smallest distance |P_(j+k) - P_j|
    over the second half at any lag k <= ``max_period``, over ``tol``; NaN for a
    sequence still converging (decided by :func:`section_period`'s extrapolation).
    A margin of 30 means the verdict would survive errors 30 times the tolerance.

    Parameters
    ----------
    points : array_like
        Section points (n, d), oldest first.
    tol : float
        Tolerance (max-norm).
    max_period : int
        Longest period tried.

    Returns
    -------
    float
        The margin (dimensionless), NaN while converging.
    """
    pts = np.atleast_2d(np.asarray(points, dtype=float))
    k, converging = section_period(pts, tol, max_period)
    if converging:
        return math.nan
    if k:
        return float(tol / max(_lag_distances(pts, k)[-k:].max(), 1e-300))
    lags = range(1, min(max_period, pts.shape[0] // 2) + 1)
    return float(min(_lag_distances(pts, j).min() for j in lags) / tol)


def _lag_distances(pts: np.ndarray, k: int) -> np.ndarray:
    """|P_(j+k) - P_j| (max-norm) over the second half of a section sequence."""
    d = np.max(np.abs(pts[k:] - pts[:-k]), axis=1)
    return d[len(d) // 2:]


def _aitken_limit(d: np.ndarray) -> float:
    """Aitken's delta-squared estimate of the limit of a sequence from its last three terms."""
    d2, d1, d0 = d[-3], d[-2], d[-1]
    den = d0 - 2 * d1 + d2
    if den == 0:
        return float(d0)
    return float(d0 - (d0 - d1) ** 2 / den)
