"""The statistics behind the book's verdicts (:mod:`lib.dynamics.verdicts`, which re-exports
them): a per-period series' mean with its batch-means standard error
(:func:`block_statistics`, :func:`batch_means`), the drift per period of a quantity sampled
at block ends (:func:`drift_statistics`), the integrated autocorrelation time that sets the
blocks (:func:`integrated_time`), and how a section fails to come back near itself
(:func:`section_returns`, the test for a closed invariant curve).

Every standard error the book quotes, and every 3-standard-error verdict, is a batch-means
error (:func:`batch_means`): the spread of the means of consecutive blocks, over the square
root of their number, with one exception: the drift of a heading that never moves a whole turn
(:func:`drift_statistics`'s bounded rule). It is honest when the blocks are long against the
series' memory, its integrated autocorrelation time tau_int; :func:`block_statistics` therefore
makes each series' blocks at least :data:`BLOCK_TAUS` times its own tau_int (Sokal's automatic
window), whatever shorter block a caller asks for; :func:`drift_statistics` merges a long run's
blocks into batches of up to :data:`BATCH_PERIODS` periods, :data:`MIN_BATCHES` of them at least
(:func:`batch_grouping`). The Methods page shows the calibration
(:mod:`lib.methods.calibration`): the spread of an estimate over independent starts against
the mean standard error reported.
"""

from __future__ import annotations

import math

import numpy as np

from ..angles import wrap_angle

__all__ = ["block_statistics", "batch_means", "drift_statistics", "heading_drift", "integrated_time", "block_length",
           "section_returns", "BLOCK_TAUS", "SOKAL_WINDOW", "MIN_BATCHES", "BATCH_PERIODS",
           "batch_grouping", "long_run_means"]

#: a block is at least this many integrated autocorrelation times long, so that the batch-means
#: variance of an AR(1) series is then biased low by less than 1 / BLOCK_TAUS (its standard
#: error by less than half that), see :func:`block_length`
BLOCK_TAUS = 6

#: a long run's batch means merge consecutive blocks into longer batches (:func:`batch_grouping`), so
#: that a longer run buys longer batches against a memory of tens of periods, rather than more
#: blocks of the same length (the Methods page measures both); this many batches at least (B.
#: Schmeiser, Oper. Res. 30, 1982, on the number of batches), fewer than twice as many while the
#: batches are shorter than :data:`BATCH_PERIODS`
MIN_BATCHES = 6

#: the longest batch (periods) of :func:`batch_grouping`, since the heading's displacement variance
#: V(tau) / tau levels off by about 48 periods at Fig. 5's slipping points (Methods), and a longer
#: run then buys more batches, which a test at 3 standard errors needs
BATCH_PERIODS = 48

#: Sokal's automatic window c, the autocorrelations summed up to the first lag M >= c tau_int(M)
SOKAL_WINDOW = 5.0


def integrated_time(series, window: float = SOKAL_WINDOW) -> np.ndarray:
    """Integrated autocorrelation time tau_int = 1/2 + sum_{k>=1} rho_k of each row of a
    series (N, L), in samples, by Sokal's automatic windowing: the sum runs up to the first
    lag M with M >= ``window`` tau_int(M) (A. Sokal, Monte Carlo methods in statistical
    mechanics, 1997, Sec. 3). The standard error of the mean of L samples is
    sqrt(2 tau_int var / L): tau_int = 1/2 for independent samples. A constant row gets 1/2.

    Parameters
    ----------
    series : array_like
        (N, L), L >= 2.
    window : float
        Sokal's c (> 0).

    Returns
    -------
    numpy.ndarray
        tau_int (N,), in samples.
    """
    x = np.asarray(series, dtype=float)
    if x.ndim != 2 or x.shape[1] < 2:
        raise ValueError(f"series must have shape (N, L) with L >= 2, got {x.shape}")
    if not window > 0:
        raise ValueError(f"window must be positive, got {window}")
    N, L = x.shape
    x = x - x.mean(axis=1, keepdims=True)
    f = np.fft.rfft(x, 2 * L, axis=1)
    acov = np.fft.irfft(f * np.conj(f), 2 * L, axis=1)[:, :L]
    tau = np.full(N, 0.5)
    live = acov[:, 0] > 0
    if not live.any():
        return tau
    taus = 2 * np.cumsum(acov[live] / acov[live, :1], axis=1) - 1        # 2 tau_int(M), M = 0 .. L-1
    ok = np.arange(L) >= window * 0.5 * taus
    ok[:, -1] = True
    m = ok.argmax(axis=1)
    tau[live] = 0.5 * taus[np.arange(m.size), m]
    return tau


def block_length(per_period, block: int) -> np.ndarray:
    """The block (periods) of each row of a per-period series (N, L) for its batch means: at
    least ``block`` and at least :data:`BLOCK_TAUS` times the row's :func:`integrated_time`,
    at most L // 2 (two blocks). With b >= 6 tau_int the block means of an AR(1) series (lag
    correlation phi, 2 tau_int = (1 + phi) / (1 - phi)) have the variance 2 tau_int var / b
    times 1 - 2 phi (1 - phi^b) / (b (1 - phi^2)), and 2 phi / (1 - phi^2) < tau_int: the
    error is low by less than 1 / (2 BLOCK_TAUS). Returns (N,) int.

    Parameters
    ----------
    per_period : array_like
        A series per period (N, L).
    block : int
        The shortest block (periods, >= 1).

    Returns
    -------
    numpy.ndarray
        Periods per block (N,).
    """
    v = np.asarray(per_period, dtype=float)
    if block < 1:
        raise ValueError(f"block must be at least 1 period, got {block}")
    L = v.shape[1]
    if L // block < 2:
        raise ValueError(f"need at least two blocks of {block} periods, got {L} periods")
    b = np.maximum(block, np.ceil(BLOCK_TAUS * integrated_time(v) - 1e-9).astype(int))
    return np.minimum(b, L // 2)


def block_statistics(per_period, block: int) -> tuple[np.ndarray, np.ndarray]:
    """Mean and batch-means standard error (:func:`batch_means`) of a per-period series (N, L)
    over its last complete blocks: each row's blocks are :func:`block_length` periods, at
    least ``block`` and at least :data:`BLOCK_TAUS` times the row's integrated
    autocorrelation time, so that correlated periods do not shrink the error. Returns
    (mean (N,), stderr (N,)).

    Parameters
    ----------
    per_period : array_like
        A series per period (N, L).
    block : int
        The shortest block (periods).

    Returns
    -------
    mean, stderr : numpy.ndarray
        (N,) each, in the series' units.
    """
    v = np.asarray(per_period, dtype=float)
    if v.ndim != 2:
        raise ValueError(f"per_period must have shape (N, L), got {v.shape}")
    N, L = v.shape
    b = block_length(v, block)
    mean, se = np.empty(N), np.empty(N)
    for bb in np.unique(b):
        rows = np.flatnonzero(b == bb)
        nb = L // bb
        mean[rows], se[rows] = batch_means(v[rows, L - nb * bb:].reshape(rows.size, nb, bb).mean(axis=2))
    return mean, se


def batch_grouping(n_blocks, block_periods: float, batches: int = MIN_BATCHES,
                   longest: float = BATCH_PERIODS) -> tuple:
    """How :func:`batch_means` merges a run of ``n_blocks`` blocks of ``block_periods`` periods:
    g consecutive blocks a batch, g = nb // ``batches`` but no batch longer than ``longest``
    periods (and g >= 1), over the last (nb // g) g blocks. Returns (g, number of batches):
    ints for one run, arrays for an array of runs.

    Parameters
    ----------
    n_blocks : int or array_like
        Blocks in the run (>= 1), or in each run.
    block_periods : float
        Periods a block (> 0).
    batches : int
        The fewest batches (>= 2), :data:`MIN_BATCHES`.
    longest : float
        The longest batch (periods), :data:`BATCH_PERIODS`.

    Returns
    -------
    tuple
        (blocks a batch, batches).
    """
    if not batches >= 2 or int(batches) != batches:
        raise ValueError(f"batches must be a whole number >= 2, got {batches!r}")
    if not block_periods > 0:
        raise ValueError(f"block_periods must be positive, got {block_periods!r}")
    nb = np.asarray(n_blocks).astype(int)
    g = np.maximum(1, np.minimum(nb // int(batches), int(longest // block_periods)))
    return (int(g), int(nb // g)) if nb.ndim == 0 else (g, nb // g)


def long_run_means(block_means, block_periods: float) -> tuple[np.ndarray, np.ndarray]:
    """:func:`batch_means` of a run's block means (N, nb), blocks of ``block_periods`` periods,
    merged into longer batches as a long run is (:func:`batch_grouping`). Returns (mean (N,),
    stderr (N,)).

    Parameters
    ----------
    block_means : array_like
        Block means (N, nb).
    block_periods : float
        Periods a block (> 0).

    Returns
    -------
    mean, stderr : numpy.ndarray
        (N,) each.
    """
    m = np.asarray(block_means, dtype=float)
    if m.ndim != 2:
        raise ValueError(f"block_means must have shape (N, nb), got {m.shape}")
    return batch_means(m, batch_grouping(m.shape[1], block_periods)[0])


def batch_means(block_means, merge: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """Mean and standard error of the means of consecutive blocks (N, nb) of equal length: the
    standard deviation of the block means over sqrt(nb) (NaN for nb = 1). The one estimator of
    every error the book quotes; honest when the blocks are long against the series' memory
    (:func:`block_length`). With ``merge`` = g > 1 the last (nb // g) g blocks are first merged g
    at a time into longer batches (:func:`batch_grouping` chooses g for a long run).

    Parameters
    ----------
    block_means : array_like
        Block means (N, nb).
    merge : int
        Blocks merged into one batch (>= 1).

    Returns
    -------
    mean, stderr : numpy.ndarray
        (N,) each.
    """
    m = np.asarray(block_means, dtype=float)
    if m.ndim != 2:
        raise ValueError(f"block_means must have shape (N, nb), got {m.shape}")
    if not merge >= 1 or int(merge) != merge:
        raise ValueError(f"merge must be a whole number >= 1, got {merge!r}")
    g, nb = int(merge), m.shape[1]
    if g > 1:
        m = m[:, nb - (nb // g) * g:].reshape(m.shape[0], nb // g, g).mean(axis=2)
    if m.shape[1] < 2:                      # one block: no spread to read an error from
        return m.mean(axis=1), np.full(m.shape[0], np.nan)
    return m.mean(axis=1), m.std(axis=1, ddof=1) / math.sqrt(m.shape[1])


def drift_statistics(at_block_ends, periods_per_block: float, unit: float = 1.0, *,
                     bounded_span: float | None = None, batches: int = MIN_BATCHES,
                     longest: float = BATCH_PERIODS) -> tuple[np.ndarray, np.ndarray]:
    """Drift per period of a quantity sampled at block ends (N, m + 1), in ``unit``
    (2 pi: turns of an angle), with the standard error of its block increments
    (:func:`batch_means`, m >= 2). Returns (drift (N,), stderr (N,)).

    A long run merges g consecutive blocks into one increment and uses its last (m // g) g
    blocks (:func:`batch_grouping`: at least ``batches`` increments, none longer than
    ``longest`` periods). Batch means
    is honest only with blocks long against the increments' memory; a heading whose slips
    come in runs of tens of periods needs blocks that long (at Fig. 5's slipping points,
    blocks of 12 periods understated the error by a fifth, Methods).

    Batch means takes the increments as independent. That fails for a quantity that stays
    bounded: its increments cancel over the run, the displacement q_m - q_0 does not grow with
    m, and batch means overstates its error about sqrt(m) times (the Methods page measures it).
    With ``bounded_span`` (in the samples' units; 2 pi for a heading), a row whose samples
    span less than it (a heading that never moved a whole turn) is taken as bounded, and its
    drift's error is that of the difference of two samples far apart against the quantity's
    memory: sqrt(2 var(q)) over the run's periods, var(q) the samples' variance.

    Parameters
    ----------
    at_block_ends : array_like
        The quantity at block ends (N, m + 1).
    periods_per_block : float
        Periods per block.
    unit : float
        The unit of the result (2 pi: turns).
    bounded_span : float, optional
        A row spanning less is bounded (samples' units, > 0); None: every row by batch means.
    batches, longest : int, float
        The fewest increments, and the longest (periods), of :func:`batch_grouping`.

    Returns
    -------
    drift, stderr : numpy.ndarray
        Per period, (N,) each.
    """
    q = np.asarray(at_block_ends, dtype=float)
    if q.ndim != 2 or q.shape[1] < 2:
        raise ValueError(f"at_block_ends must have shape (N, m + 1) with m >= 1 blocks, got {q.shape}")
    g, _ = batch_grouping(q.shape[1] - 1, periods_per_block, batches, longest)
    drift, se = batch_means(np.diff(q, axis=1) / (unit * periods_per_block), g)
    if bounded_span is None:
        return drift, se
    if not bounded_span > 0:
        raise ValueError(f"bounded_span must be positive, got {bounded_span}")
    m = q.shape[1] - 1
    q = q[:, m - (m // g) * g:]                         # the span the merged increments cover
    bounded = np.ptp(q, axis=1) < bounded_span
    periods = (q.shape[1] - 1) * periods_per_block
    with np.errstate(invalid="ignore"):
        se_bounded = np.sqrt(2 * q.var(axis=1, ddof=1)) / (unit * periods)
    return drift, np.where(bounded, se_bounded, se)


def heading_drift(at_block_ends, periods_per_block: float) -> tuple[np.ndarray, np.ndarray]:
    """The heading's drift in turns per period, with its error, from the heading (rad) at block
    ends (N, m + 1): :func:`drift_statistics` in turns with its bounded rule at one turn (a
    heading that never moved a whole turn takes its error from its spread). The one drift of a
    heading the book decides "lost" by (:func:`lib.dynamics.verdicts.heading_lost`).

    Parameters
    ----------
    at_block_ends : array_like
        The heading (rad) at block ends (N, m + 1).
    periods_per_block : float
        Periods per block.

    Returns
    -------
    drift, stderr : numpy.ndarray
        Turns per period, (N,) each.
    """
    return drift_statistics(at_block_ends, periods_per_block, 2 * np.pi, bounded_span=2 * np.pi)


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
