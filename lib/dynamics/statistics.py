"""The statistics behind the book's verdicts (:mod:`lib.dynamics.verdicts`, which re-exports
them): a per-period series' mean with its batch-means standard error
(:func:`block_statistics`, :func:`batch_means`), the drift per period of a quantity sampled
at block ends (:func:`drift_statistics`), and how a section fails to come back near itself
(:func:`section_returns`, the test for a closed invariant curve).
"""

from __future__ import annotations

import numpy as np

from ..angles import wrap_angle

__all__ = ["block_statistics", "batch_means", "drift_statistics", "section_returns"]


def block_statistics(per_period, block: int) -> tuple[np.ndarray, np.ndarray]:
    """Mean and batch-means standard error of a per-period series (N, L) over its last
    complete blocks of ``block`` periods: the standard error is that of the block means,
    so that correlated periods do not shrink it. Returns (mean (N,), stderr (N,)).

    Parameters
    ----------
    per_period : array_like
        A series per period (N, L).
    block : int
        Periods per block.

    Returns
    -------
    mean, stderr : numpy.ndarray
        (N,) each, in the series' units.
    """
    v = np.asarray(per_period, dtype=float)
    N, L = v.shape
    nb = L // block
    if nb < 2:
        raise ValueError(f"need at least two blocks of {block} periods, got {L} periods")
    return batch_means(v[:, L - nb * block:].reshape(N, nb, block).mean(axis=2))


def batch_means(block_means) -> tuple[np.ndarray, np.ndarray]:
    """Mean and standard error of the means of consecutive blocks (N, nb), nb >= 2.

    Parameters
    ----------
    block_means : array_like
        Block means (N, nb), nb >= 2.

    Returns
    -------
    mean, stderr : numpy.ndarray
        (N,) each.
    """
    m = np.asarray(block_means, dtype=float)
    return m.mean(axis=1), m.std(axis=1, ddof=1) / np.sqrt(m.shape[1])


def drift_statistics(at_block_ends, periods_per_block: float, unit: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Drift per period of a quantity sampled at block ends (N, m + 1), in ``unit``
    (2 pi: turns of an angle), with the standard error of its m block increments.
    Returns (drift (N,), stderr (N,)).

    Parameters
    ----------
    at_block_ends : array_like
        The quantity at block ends (N, m + 1).
    periods_per_block : float
        Periods per block.
    unit : float
        The unit of the result (2 pi: turns).

    Returns
    -------
    drift, stderr : numpy.ndarray
        Per period, (N,) each.
    """
    inc = np.diff(np.asarray(at_block_ends, dtype=float), axis=1) / (unit * periods_per_block)
    return inc.mean(axis=1), inc.std(axis=1, ddof=1) / np.sqrt(inc.shape[1])


def section_returns(sec: np.ndarray, leave: float = 0.25, angles=(0,)) -> np.ndarray:
    """How a sequence of section states fails to come back: for states ``sec`` (L, N, d)
    of N runs (the columns ``angles`` compared modulo 2 pi), and reference states at 0
    and L/3, the closest return of a later state to the reference state after the run
    has first moved more than ``leave`` times the set's diameter D away from it, divided
    by D (max-norm); the worse of the two references. Small (-> 0 as L grows) on a
    closed invariant curve filled by a quasi-periodic motion, which comes back near
    every point; at least ``leave`` for a motion that moves away for good (inf if it
    never moves that far), e.g. a slow approach to an orbit along a line, which a zero
    Lyapunov exponent alone would not tell apart. Returns (N,).

    Parameters
    ----------
    sec : numpy.ndarray
        Section states (L, N, d).
    leave : float
        How far (in diameters) a run must first move away.
    angles : tuple of int
        Columns compared modulo 2 pi.

    Returns
    -------
    numpy.ndarray
        The closest return over the diameter (dimensionless), (N,).
    """
    sec = np.array(sec, dtype=float)
    if sec.ndim != 3 or sec.shape[2] < 1:
        raise ValueError(f"sec must have shape (L, N, d), got {sec.shape}")
    L, N, _ = sec.shape
    if L < 6:
        return np.full(N, np.inf)
    ang = list(angles)
    sec[:, :, ang] = wrap_angle(sec[:, :, ang] - sec[:1, :, ang])
    D = np.ptp(sec, axis=0).max(axis=1)
    worst = np.zeros(N)
    for r in (0, L // 3):
        dd = sec[r + 1:] - sec[r]
        dd[:, :, ang] = wrap_angle(dd[:, :, ang])
        d = np.abs(dd).max(axis=2)                                   # (L - r - 1, N)
        left = np.maximum.accumulate(d > leave * D, axis=0)          # has moved away by then
        back = np.where(left, d, np.inf).min(axis=0)
        with np.errstate(invalid="ignore", divide="ignore"):
            worst = np.maximum(worst, np.where(D > 0, back / D, np.inf))
    return worst
