"""Sampled signals: the steady state of a signal sampled over its last periods
(:func:`classify_samples`), and the range and extremes of a sampled signal refined
between the samples (:func:`sampled_range`, :func:`sampled_extremes`: parabolas through
three samples, or cubic Hermite pieces where the derivative is sampled too). Used by
the rotation sweeps (:mod:`lib.rotation`, which re-exports them) and the closed loop
under limits (:mod:`lib.limits`).
"""

from __future__ import annotations

import numpy as np

__all__ = ["classify_samples", "sampled_range", "sampled_extremes"]


def classify_samples(P: np.ndarray, tol: float = 1e-9, dP: np.ndarray | None = None) -> dict:
    """Classify the steady state from the rotation error sampled over the last periods.

    ``P`` has shape (L_max + 1, N, n): for N points, the last L_max + 1 reference
    periods of p (rad) at n equally spaced phases each (oldest first). For each lag
    L = 1..L_max the defect is d_L = max_j |p_j - p_{j-L periods} - 2 pi k_L|, with
    k_L the whole number of turns slipped in L periods. The smallest L with
    d_L <= ``tol`` is the period (in reference periods); k_L = 0 makes the point
    ``periodic``, k_L != 0 ``slipping``; if no lag qualifies it is ``irregular``
    (the smallest defect is reported). Returns arrays: regime, period, slip
    (turns per reference period), defect, range (max - min of p over the last
    ``period`` periods; with the phase derivatives ``dP`` = dp/ds at the same
    samples, the extremes are refined by cubic Hermite interpolation, see
    :func:`sampled_range`).

    Parameters
    ----------
    P : numpy.ndarray
        Samples of p (rad), (L_max + 1, N, n).
    tol : float
        Defect tolerance (rad).
    dP : numpy.ndarray, optional
        dp/ds at the same samples.

    Returns
    -------
    dict
        Arrays (N,): regime, period, slip (turns per period), defect (rad), range (rad).
    """
    P = np.asarray(P, dtype=float)
    if P.ndim != 3 or P.shape[0] < 2 or P.shape[2] < 1:
        raise ValueError(f"P must have shape (L_max + 1 >= 2, N, n >= 1), got {P.shape}")
    Lmax, N = P.shape[0] - 1, P.shape[1]
    last = P[-1]
    defects = np.empty((Lmax, N))
    turns = np.empty((Lmax, N))
    for L in range(1, Lmax + 1):
        d = last - P[-1 - L]
        k = np.round(d[:, -1] / (2 * np.pi))
        turns[L - 1] = k
        defects[L - 1] = np.abs(d - 2 * np.pi * k[:, None]).max(axis=1)
    ok = defects <= tol
    any_ok = ok.any(axis=0)
    Lidx = np.where(any_ok, ok.argmax(axis=0), defects.argmin(axis=0))
    cols = np.arange(N)
    k = turns[Lidx, cols]
    period = Lidx + 1
    regime = np.where(~any_ok, "irregular", np.where(k == 0, "periodic", "slipping"))
    rng = np.empty(N)
    for L in np.unique(period):
        sel = period == L
        window = P[-L:, sel, :].transpose(1, 0, 2).reshape(sel.sum(), -1)
        dwin = None if dP is None else dP[-L:, sel, :].transpose(1, 0, 2).reshape(sel.sum(), -1)
        rng[sel] = sampled_range(window, cyclic=(k[sel] == 0), dy=dwin, h=2 * np.pi / P.shape[2])
    return dict(regime=regime, period=period, slip=k / period, defect=defects[Lidx, cols], range=rng)


def sampled_range(y, cyclic=True, dy=None, h: float = 1.0) -> np.ndarray:
    """max - min of each row of ``y`` (samples at equal phase steps ``h``), the extremes
    refined as :func:`sampled_extremes` refines them.

    Parameters
    ----------
    y : array_like
        Samples, one row per signal.
    cyclic : bool or array_like
        Whether each row wraps around.
    dy : array_like, optional
        Derivatives per unit phase at the samples.
    h : float
        The phase step.

    Returns
    -------
    numpy.ndarray
        max - min per row, in the units of y.
    """
    lo, hi = sampled_extremes(y, cyclic, dy, h)
    return hi - lo


def sampled_extremes(y, cyclic=True, dy=None, h: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """(min, max) of each row of ``y`` (samples at equal phase steps ``h``).

    Without ``dy`` the extreme samples are refined by the parabola through them
    and their neighbours (error O(h^3)); with the derivatives ``dy`` (per unit
    phase) at the samples, by the cubic Hermite interpolant on the two
    intervals beside each extreme sample (error O(h^4)), so that the range is
    that of the continuous signal, not of its sampling. ``cyclic`` (per row) lets
    neighbours wrap around, as for whole periods of a periodic signal;
    otherwise extremes at the ends are not refined.

    Parameters
    ----------
    y : array_like
        Samples, one row per signal.
    cyclic : bool or array_like
        Whether each row wraps around.
    dy : array_like, optional
        Derivatives per unit phase at the samples.
    h : float
        The phase step.

    Returns
    -------
    lo, hi : numpy.ndarray
        Minimum and maximum per row, in the units of y.
    """
    y = np.atleast_2d(np.asarray(y, dtype=float))
    n = y.shape[1]
    if n < 3:
        return y.min(axis=1), y.max(axis=1)
    cyclic = np.broadcast_to(np.asarray(cyclic, bool), y.shape[:1])
    rows = np.arange(y.shape[0])

    def parabola(j, sign):
        ym, y0, yp = y[rows, (j - 1) % n], y[rows, j], y[rows, (j + 1) % n]
        curv = ym - 2 * y0 + yp
        ok = (cyclic | ((j > 0) & (j < n - 1))) & (sign * curv < 0)
        with np.errstate(divide="ignore", invalid="ignore"):
            val = y0 - (ym - yp) ** 2 / (8 * curv)
        return np.where(ok, val, y0)

    def hermite(j, sign):
        best = y[rows, j] * sign
        for a in (j - 1, j):
            b = a + 1
            ok = cyclic | ((a >= 0) & (b <= n - 1))
            a, b = a % n, b % n
            y0, y1 = y[rows, a] * sign, y[rows, b] * sign
            d0, d1 = dy[rows, a] * h * sign, dy[rows, b] * h * sign
            c1, c2, c3 = d0, 3 * (y1 - y0) - 2 * d0 - d1, 2 * (y0 - y1) + d0 + d1
            disc = np.maximum(c2**2 - 3 * c1 * c3, 0.0)
            for root in ((-c2 + np.sqrt(disc)), (-c2 - np.sqrt(disc))):
                with np.errstate(divide="ignore", invalid="ignore"):
                    t = np.where(np.abs(c3) > 1e-300, root / (3 * c3), -c1 / (2 * c2))
                inside = ok & np.isfinite(t) & (t > 0) & (t < 1)
                t = np.where(inside, t, 0.0)
                val = y0 + t * (c1 + t * (c2 + t * c3))
                best = np.where(inside, np.maximum(best, val), best)
        return best * sign

    if dy is None:
        return parabola(y.argmin(axis=1), -1), parabola(y.argmax(axis=1), 1)
    dy = np.atleast_2d(np.asarray(dy, dtype=float))
    return hermite(y.argmin(axis=1), -1), hermite(y.argmax(axis=1), 1)
