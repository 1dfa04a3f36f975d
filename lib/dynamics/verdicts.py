"""The one decision procedure behind every long-run verdict of the book.

A periodically driven motion is observed at its stroboscopic section (t = j T, T the
period of the forcing) through a *period map* P: the state after one period. Every
flow of the book (the reduced rotation (32), the switched closed loop under limits,
the full closed loop under any allocation) supplies only that map and which of its
coordinates is the heading, which may advance by whole turns; the steps below, and
the words they decide, are written here once.

The words (the book's definition ``def-regimes``, Chapter 5):

``periodic``
    Newton on P^k(x) = x (k <= ``max_period``) converges, every Floquet multiplier
    (eigenvalue of DP^k) lies inside the unit circle, and the run *reaches* the orbit
    (:func:`reached`).
``slipping``
    the same, with P^k(x) = x + 2 pi n e_heading, n != 0: the heading gains n whole
    turns against the reference every k periods.
``chaotic``
    no orbit is reached and the largest Lyapunov exponent per period, lambda T,
    exceeds both ``sigmas`` (3) standard errors and the band (:func:`classify`).
``quasiperiodic``
    no orbit, lambda T within the band of zero with SE <= band / 3, and the section
    closes on itself (:func:`section_returns`).
``undecided``
    anything else, with the reason.
``lost`` (the heading)
    the heading slips: a slipping orbit, or, without an orbit, a net drift of the
    heading of more than 3 standard errors plus ``slip_band`` turns per period
    (:func:`heading_lost`). A range over a full turn is reported beside it, not in it
    (:func:`turns_round`).
``held``
    periodic, the heading not lost, and the position tracked where there is one
    (:func:`held`).

The steps: :func:`lag_candidates` (where the section nearly repeats),
:func:`newton` (exact Jacobian or :func:`difference_jacobian`), Floquet multipliers
(:func:`lib.dynamics.orbits.floquet_multipliers`), :func:`least_period`,
:func:`distance_to_orbit` and :func:`reached`, :func:`block_statistics` (an exponent or
a drift with its batch-means standard error), :func:`section_returns`, and the rule
:func:`classify`.
"""

from __future__ import annotations

from typing import Callable, Protocol

import numpy as np

from ..angles import wrap_angle
from .orbits import NewtonResult, floquet_multipliers, newton

__all__ = ["REGIMES", "SIGMAS", "PeriodMap", "lag_candidates", "difference_jacobian", "newton", "NewtonResult", "least_period",
           "distance_to_orbit", "reached", "block_statistics", "batch_means", "drift_statistics", "section_returns", "classify",
           "heading_lost", "turns_round", "held", "redecide_undecided", "orbit_regime", "orbit_points", "find_orbits", "enclosed_orbit"]

#: the verdicts, in the order the book lists them
REGIMES = ("periodic", "slipping", "chaotic", "quasiperiodic", "undecided")

#: standard errors by which a positive exponent must clear zero to be called chaotic
SIGMAS = 3.0

TWO_PI = 2 * np.pi


class PeriodMap(Protocol):
    """What a flow provides: its period map over many rows at once.

    ``advance(idx, x, k)`` maps states ``x`` (M, d) of the rows ``idx`` (M,) (each row
    has its own parameters) by ``k`` periods (an integer, or one per row) and returns
    P^k(x) (M, d), with the heading (column ``turn_axis``) continuous, not wrapped."""

    turn_axis: int

    def advance(self, idx: np.ndarray, x: np.ndarray, k) -> np.ndarray: ...


def _less_whole_turns(d, turn_axis: int, allow):
    """Differences of states ``d`` (M, d) with the heading's whole turns taken out where ``allow``
    ((M,) bool) says so (in place); returns the turns n (M,) removed."""
    n = np.where(allow, np.round(d[:, turn_axis] / TWO_PI), 0.0)
    d[:, turn_axis] -= TWO_PI * n
    return n


def lag_candidates(hist, max_period: int, tol: float, *, turn_axis: int, turns=True, ends: int = 2):
    """Lags k <= ``max_period`` at which the section nearly repeats.

    ``hist`` (L, N, d): the last L section states of N runs. At lag k the last ``ends``
    states are each compared with the state k periods before them (max-norm), the
    heading (column ``turn_axis``) up to n whole turns where ``turns`` ((N,) bool, or
    one bool) allows it; a single chance return is not enough, so ``ends`` >= 2.
    Returns (ok, n, defect), each (max_period, N), row k - 1 for lag k: ok = defect <=
    ``tol``, n the whole turns between the last state and the one k periods before.

    Parameters
    ----------
    hist : array_like
        Section states (L, N, d), oldest first.
    max_period : int
        Longest lag.
    tol : float
        Tolerance (max-norm, the state's units).
    turn_axis : int
        The heading's column.
    turns : bool or array_like
        Whether whole turns are allowed, one or per run.
    ends : int
        States compared at each lag (>= 2).

    Returns
    -------
    ok : numpy.ndarray
        (max_period, N) bool.
    n : numpy.ndarray
        Whole turns (max_period, N).
    defect : numpy.ndarray
        The largest distance (max_period, N).
    """
    hist = np.asarray(hist, dtype=float)
    L, N, _ = hist.shape
    allow = np.broadcast_to(np.asarray(turns, dtype=bool), (N,))
    dd = np.full((max_period, N), np.inf)
    nn = np.zeros((max_period, N), int)
    for k in range(1, min(max_period, L - ends) + 1):
        worst = np.zeros(N)
        for end in range(-1, -ends - 1, -1):
            d = hist[end] - hist[end - k]
            n = _less_whole_turns(d, turn_axis, allow)
            worst = np.maximum(worst, np.abs(d).max(axis=1))
            if end == -1:
                nn[k - 1] = n.astype(int)
        dd[k - 1] = worst
    return dd <= tol, nn, dd


def difference_jacobian(pmap: PeriodMap, idx, x, k, h: float) -> tuple[np.ndarray, np.ndarray]:
    """P^k(x) (M, d) and DP^k (M, d, d) by forward differences of step ``h``: the d
    companions x + h e_j of every row go through ``pmap.advance`` in one batch with it.

    Parameters
    ----------
    pmap : PeriodMap
        The period map.
    idx : array_like
        Rows (M,).
    x : array_like
        States (M, d).
    k : int or array_like
        Periods.
    h : float
        Difference step (the state's units).

    Returns
    -------
    y : numpy.ndarray
        P^k(x), (M, d).
    J : numpy.ndarray
        DP^k by differences, (M, d, d).
    """
    x = np.asarray(x, dtype=float)
    M, d = x.shape
    k = np.broadcast_to(np.asarray(k, dtype=int), (M,))
    X = np.concatenate([x] + [x + h * np.eye(d)[j] for j in range(d)])
    Y = pmap.advance(np.tile(np.asarray(idx), d + 1), X, np.tile(k, d + 1))
    J = np.stack([(Y[(j + 1) * M:(j + 2) * M] - Y[:M]) / h for j in range(d)], axis=-1)
    return Y[:M], J


def least_period(x, pts, k, n, *, turn_axis: int, turns=True, tol: float):
    """The least period of orbits found as fixed points of P^k: a period-d orbit (d | k)
    is one too. ``x`` (M, d) the orbit points, ``pts`` (K, M, d) their images P^j(x),
    j = 1..K (NaN past a row's own k), ``k`` and ``n`` (M,) the lag and turns Newton
    used. Returns (k_min, n_min): the smallest divisor d of k with P^d(x) = x + 2 pi n'
    e_heading within ``tol``, and its turns n'.

    Parameters
    ----------
    x : array_like
        Orbit points (M, d).
    pts : array_like
        Their images (K, M, d).
    k, n : array_like
        Lag and turns (M,).
    turn_axis : int
        The heading's column.
    turns : bool or array_like
        Whether whole turns are allowed.
    tol : float
        Tolerance.

    Returns
    -------
    k_min, n_min : numpy.ndarray
        The least period and its turns (M,).
    """
    k = np.asarray(k, dtype=int)
    kmin, nmin = k.copy(), np.asarray(n, dtype=int).copy()
    allow = np.broadcast_to(np.asarray(turns, dtype=bool), (k.size,))
    for dv in range(int(k.max(initial=1)) - 1, 0, -1):
        dd = pts[dv - 1] - x
        nd = _less_whole_turns(dd, turn_axis, allow)
        with np.errstate(invalid="ignore"):
            same = (k % dv == 0) & (dv < k) & (np.abs(dd).max(axis=1) <= tol)
        kmin[same], nmin[same] = dv, nd[same].astype(int)
    return kmin, nmin


def distance_to_orbit(state, pts, *, turn_axis: int, turns=True):
    """Distance (max-norm; the heading modulo 2 pi where ``turns`` allows it) from states
    (M, d) to the nearest of the orbit points ``pts`` (K, M, d) (NaN rows ignored), and
    the index of that point. Returns (distance (M,), index (M,)).

    Parameters
    ----------
    state : array_like
        States (M, d).
    pts : array_like
        Orbit points (K, M, d).
    turn_axis : int
        The heading's column.
    turns : bool or array_like
        Whether the heading counts modulo 2 pi.

    Returns
    -------
    distance : numpy.ndarray
        (M,), the state's units.
    index : numpy.ndarray
        The nearest point's index (M,).
    """
    dd = np.asarray(state, dtype=float)[None] - pts
    allow = np.broadcast_to(np.asarray(turns, dtype=bool), (dd.shape[1],))
    dd[..., turn_axis] = np.where(allow, wrap_angle(dd[..., turn_axis]), dd[..., turn_axis])
    d = np.abs(dd).max(axis=2)
    d = np.where(np.isnan(d), np.inf, d)
    j = d.argmin(axis=0)
    return d[j, np.arange(d.shape[1])], j


def reached(d_now, d_then, rho, periods_ratio, *, tol: float, floor: float) -> np.ndarray:
    """Whether a run has reached an attracting orbit: its distance to the orbit ``d_now``
    is below ``floor``, or below ``tol`` and shrinking since ``d_then`` (an earlier
    distance, ``periods_ratio`` = periods between / k periods of the orbit earlier) no
    slower than the slowest multiplier ``rho`` (= |mu_1|) allows:
    d_now <= 3 d_then rho^periods_ratio + floor.

    Parameters
    ----------
    d_now, d_then : array_like
        Distances to the orbit now and earlier (N,).
    rho : array_like
        |mu_1| (N,).
    periods_ratio : float or array_like
        Periods between the two distances over k.
    tol, floor : float
        The reach tolerance and floor.

    Returns
    -------
    numpy.ndarray
        (N,) bool.
    """
    d_now, d_then = np.asarray(d_now, dtype=float), np.asarray(d_then, dtype=float)
    shrink = (d_now < d_then) & (d_now <= 3.0 * d_then * np.asarray(rho) ** periods_ratio + floor)
    return (d_now <= floor) | ((d_now <= tol) & shrink)


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


def classify(lam_T, se_T, returns, *, band: float, return_tol: float, max_period: int,
             sigmas: float = SIGMAS) -> tuple[np.ndarray, np.ndarray]:
    """The rule for runs that reach no attracting orbit, from the largest Lyapunov exponent
    per period lambda T and its standard error SE T (both (N,)), and the section's
    :func:`section_returns` (N,): ``chaotic`` when lambda T > max(``sigmas`` SE T,
    ``band``); ``quasiperiodic`` when |lambda T| <= band, SE T <= band / 3 and the
    section returns within ``return_tol``; else ``undecided``, with the reason.
    Returns (regime (N,) object, reason (N,) object).

    Parameters
    ----------
    lam_T, se_T : array_like
        lambda T and its standard error (dimensionless, per period), (N,).
    returns : array_like
        :func:`section_returns` (N,).
    band : float
        The band of zero.
    return_tol : float
        Tolerance on the section's return.
    max_period : int
        Longest period tried (for the reasons).
    sigmas : float
        Standard errors for "chaotic".

    Returns
    -------
    regime, reason : numpy.ndarray
        (N,) object arrays.
    """
    lam, se = np.asarray(lam_T, dtype=float), np.asarray(se_T, dtype=float)
    chaotic = lam > np.maximum(sigmas * se, band)
    zero = ~chaotic & (np.abs(lam) <= band) & (se <= band / 3)
    quasi = zero & (np.asarray(returns) <= return_tol)
    regime = np.where(chaotic, "chaotic", np.where(quasi, "quasiperiodic", "undecided")).astype(object)
    reason = np.where(chaotic | quasi, "", np.where(
        lam < -np.maximum(sigmas * se, band), f"contracting, but no attracting orbit of period <= {max_period} reached",
        np.where(zero, "Lyapunov exponent zero, but the section does not return near itself "
                       "(no closed curve: a slow transient or a bifurcation)",
                 "Lyapunov exponent not resolved from zero"))).astype(object)
    return regime, reason


def held(regime, lost, tracked=True) -> np.ndarray:
    """The book's one definition of "held": the run reaches an attracting ``periodic`` orbit,
    its heading is not ``lost``, and, where the flow tracks a position, the position is
    ``tracked`` (within the flow's stated tolerance). Returns (N,) bool.

    Parameters
    ----------
    regime : array_like
        Verdicts (N,).
    lost : array_like
        Heading lost (N,) bool.
    tracked : bool or array_like
        Position tracked.

    Returns
    -------
    numpy.ndarray
        (N,) bool.
    """
    return (np.asarray(regime) == "periodic") & ~np.asarray(lost, dtype=bool) & np.asarray(tracked, dtype=bool)


def orbit_points(pmap: PeriodMap, idx, x, k) -> np.ndarray:
    """P^j(x) for j = 1, ..., K = max k (K, M, d), NaN past each row's own k.

    Parameters
    ----------
    pmap : PeriodMap
        The period map.
    idx : array_like
        Rows (M,).
    x : array_like
        Orbit points (M, d).
    k : array_like
        Periods (M,).

    Returns
    -------
    numpy.ndarray
        (K, M, d).
    """
    k = np.broadcast_to(np.asarray(k, dtype=int), (len(idx),))
    K = int(k.max())
    pts = np.full((K,) + np.shape(x), np.nan)
    y = np.array(x, dtype=float)
    for j in range(K):
        act = k > j
        y[act] = pmap.advance(np.asarray(idx)[act], y[act], 1)
        pts[j, act] = y[act]
    return pts


def find_orbits(step: Callable, pmap: PeriodMap, idx, hist, *, max_period: int, candidate_tol: float,
                newton_tol: float, reach_tol: float, reach_floor: float, newton_options: dict, turns=True,
                fixed_turns: bool = True, ends: int = 2, tried=None) -> dict:
    """The attracting periodic orbits that runs reach, from their recent section states.

    ``hist`` (L, N, d): the last L section states of the rows ``idx`` (N,) of ``pmap``,
    the heading continuous. For k = 1, 2, ... <= ``max_period`` in turn, each row whose
    section repeats at lag k (:func:`lag_candidates`, ``ends`` states, ``candidate_tol``)
    and has no orbit yet goes to :func:`newton` (``step``, ``newton_options``) from its
    last state, with the turns of the candidate (``fixed_turns``) or free. An orbit
    counts when Newton converges to ``newton_tol``, every Floquet multiplier lies inside
    the unit circle and the run has :func:`reached` it (``reach_tol``, ``reach_floor``;
    the earlier distance taken k floor(M / k) periods back, M = min(L - 1, 2
    ``max_period``)). Where an attracting orbit of period k is found but not yet
    reached, its multiples are not tried (they would find it again). ``tried``
    (max_period, N), updated in place when given: the lag-k defect at which Newton last
    ran; lag k is tried again only once the defect has halved.

    Returns a dict of (N,) arrays: found, k (least period), n (turns per k periods), lag
    (the k of P^k Newton solved, a multiple of the least period, to which mult belong),
    rho (the largest |multiplier| of the least period's map P^k: |mu_1(P^lag)|^(k / lag)), x
    (the orbit point Newton found), mult (N, d) multipliers, residual, distance (of the
    last state to the orbit), near (N, d) the orbit point nearest to the last state, and
    status ("" no candidate, "not converged", "not attracting", "not reached", "found")
    with floquet (largest |multiplier| of the last attempt).

    Parameters
    ----------
    step : callable
        (idx, x, k) -> (P^k(x), DP^k).
    pmap : PeriodMap
        The period map.
    idx : array_like
        Rows (N,).
    hist : array_like
        Section states (L, N, d).
    max_period : int
        Longest period.
    candidate_tol, newton_tol, reach_tol, reach_floor : float
        Tolerances (the state's units).
    newton_options : dict
        Keywords of :func:`lib.dynamics.orbits.newton`.
    turns : bool or array_like
        Whether whole turns are allowed.
    fixed_turns : bool
        Keep the candidate's turns.
    ends : int
        States compared per lag.
    tried : array_like, optional
        The lag-k defect at which Newton last ran, (max_period, N), updated in place.

    Returns
    -------
    dict
        (N,) arrays: found, k, n, lag, rho, x, mult, residual, distance, near, status,
    floquet (see above).
    """
    hist = np.asarray(hist, dtype=float)
    L, N, d = hist.shape
    ax = pmap.turn_axis
    idx = np.asarray(idx)
    allow = np.broadcast_to(np.asarray(turns, dtype=bool), (N,))
    cand, nslip, defect = lag_candidates(hist, max_period, candidate_tol, turn_axis=ax, turns=allow, ends=ends)
    if tried is not None:
        cand &= defect < 0.5 * tried
    out = dict(found=np.zeros(N, bool), k=np.zeros(N, int), lag=np.zeros(N, int), rho=np.full(N, np.nan),
               n=np.zeros(N, int),
               x=np.full((N, d), np.nan),
               mult=np.full((N, d), np.nan + 0j), residual=np.full(N, np.nan), distance=np.full(N, np.nan),
               near=np.full((N, d), np.nan), status=np.full(N, "", dtype=object), floquet=np.full(N, np.nan))
    back = min(L - 1, 2 * max_period)
    waiting = np.zeros((max_period, N), bool)
    for kk in range(1, max_period + 1):
        c = np.flatnonzero(cand[kk - 1] & ~out["found"] & ~waiting[kk - 1])
        if c.size == 0:
            continue
        x, J, res, n, _ = newton(step, idx[c], hist[-1, c], kk, turn_axis=ax,
                                 turns=nslip[kk - 1, c] if fixed_turns else None, tol=newton_tol, **newton_options)
        if tried is not None:
            tried[kk - 1, c] = defect[kk - 1, c]
        ok = res <= newton_tol
        mult = np.full((c.size, d), np.nan + 0j)
        if ok.any():
            mult[ok] = floquet_multipliers(J[ok])
        rho = np.abs(mult[:, 0])
        att = ok & (rho < 1.0)
        out["status"][c] = np.where(~ok, "not converged", np.where(att, "not reached", "not attracting"))
        out["floquet"][c] = rho
        waiting[kk - 1::kk, c[att]] = True
        if not att.any():
            continue
        a, xa = c[att], x[att]
        pts = orbit_points(pmap, idx[a], xa, kk)
        kmin, nmin = least_period(xa, pts, np.full(a.size, kk), n[att], turn_axis=ax, turns=allow[a],
                                  tol=100 * newton_tol)
        d_now, j_now = distance_to_orbit(hist[-1, a], pts, turn_axis=ax, turns=allow[a])
        m = kk * max(1, back // kk)
        d_then, _ = distance_to_orbit(hist[-1 - m, a], pts, turn_axis=ax, turns=allow[a])
        hit = reached(d_now, d_then, rho[att], m / kk, tol=reach_tol, floor=reach_floor)
        g = a[hit]
        out["found"][g], out["status"][g] = True, "found"
        out["k"][g], out["n"][g], out["lag"][g] = kmin[hit], nmin[hit], kk
        out["rho"][g] = rho[att][hit] ** (kmin[hit] / kk)
        out["x"][g], out["mult"][g], out["residual"][g] = xa[hit], mult[att][hit], res[att][hit]
        out["distance"][g] = d_now[hit]
        out["near"][g] = pts[j_now, np.arange(a.size)][hit]
    return out


def redecide_undecided(frame, horizon: int, factor: int, redo: Callable):
    """A copy of a verdict frame (one row per run, column ``regime``) whose ``undecided`` rows
    are decided again by ``redo(rows, factor)`` (a frame for those rows, over ``factor`` times
    the ``horizon`` in periods), with a column ``horizon``: the periods each row was observed.

    Parameters
    ----------
    frame : pandas.DataFrame
        A verdict frame.
    horizon : int
        Its periods observed.
    factor : int
        Horizon factor.
    redo : callable
        (rows, factor) -> the frame of those rows.

    Returns
    -------
    pandas.DataFrame
        The frame with a column ``horizon``.
    """
    out = frame.copy()
    out["horizon"] = horizon
    todo = np.flatnonzero((frame.regime == "undecided").to_numpy())
    if todo.size == 0:
        return out
    redone = redo(todo, factor)
    redone["horizon"] = horizon * factor
    redone.index = frame.index[todo]
    out.loc[redone.index, redone.columns] = redone
    return out


def orbit_regime(turns) -> np.ndarray:
    """``periodic`` for an attracting orbit reached with n = 0 turns per k periods,
    ``slipping`` for n != 0.

    Parameters
    ----------
    turns : array_like
        Whole turns per k periods (N,).

    Returns
    -------
    numpy.ndarray
        (N,) object array of verdicts.
    """
    return np.where(np.asarray(turns) == 0, "periodic", "slipping").astype(object)


def heading_lost(orbit, turns, drift, drift_se, *, slip_band: float) -> np.ndarray:
    """Whether the heading is lost (the book's one definition: it *slips*, gaining or losing
    whole turns against the reference): on an orbit (``orbit`` (N,) bool) when the orbit
    slips (``turns`` != 0 per k periods); without one when the heading's net drift (turns per
    period) differs from zero by more than 3 standard errors plus ``slip_band``. A heading
    that swings over more than a turn and comes back is not lost by this definition
    (:func:`turns_round` counts it). Returns (N,) bool.

    Parameters
    ----------
    orbit : array_like
        Orbit reached (N,) bool.
    turns : array_like
        Its turns (N,).
    drift, drift_se : array_like
        Drift (turns per period) and its standard error (N,).
    slip_band : float
        The band (turns per period).

    Returns
    -------
    numpy.ndarray
        (N,) bool.
    """
    orbit = np.asarray(orbit, dtype=bool)
    drifting = np.abs(np.asarray(drift, dtype=float)) > SIGMAS * np.asarray(drift_se, dtype=float) + slip_band
    return np.where(orbit, np.asarray(turns) != 0, drifting)


def turns_round(p_range) -> np.ndarray:
    """The other reading of "lost", reported beside it: the heading error ranges over more
    than a full turn (``p_range`` > 2 pi rad), over the orbit or the observed run, whether
    or not it comes back. Returns (N,) bool.

    Parameters
    ----------
    p_range : array_like
        Range of the heading error (rad).

    Returns
    -------
    numpy.ndarray
        bool, of the shape of p_range.
    """
    return np.asarray(p_range, dtype=float) > TWO_PI


def enclosed_orbit(step: Callable, idx, sec, *, turn_axis: int, newton_tol: float, newton_options: dict):
    """Is there an attracting period-1 orbit inside a closed section curve? Newton from the
    curve's centre: the mean of the section states ``sec`` (L, M, d) of the rows ``idx``,
    the heading by its circular mean. A zero exponent and a closed section mean a torus
    only if the orbit inside repels (or none is found); an attracting one inside means a
    slow spiral onto it. Returns (attracting (M,) bool, largest |multiplier| (M,), NaN
    where Newton did not converge).

    Parameters
    ----------
    step : callable
        (idx, x, k) -> (P^k(x), DP^k).
    idx : array_like
        Rows (M,).
    sec : array_like
        Section states (L, M, d).
    turn_axis : int
        The heading's column.
    newton_tol : float
        Tolerance.
    newton_options : dict
        Keywords of :func:`lib.dynamics.orbits.newton`.

    Returns
    -------
    attracting : numpy.ndarray
        (M,) bool.
    largest : numpy.ndarray
        The largest |multiplier| (M,), NaN where Newton did not converge.
    """
    sec = np.asarray(sec, dtype=float)
    x0 = sec.mean(axis=0)
    x0[:, turn_axis] = np.angle(np.exp(1j * sec[:, :, turn_axis]).mean(axis=0))
    _, J, res, _, _ = newton(step, idx, x0, 1, turn_axis=turn_axis, tol=newton_tol, **newton_options)
    ok = res <= newton_tol
    mu = np.full(ok.size, np.nan)
    if ok.any():
        mu[ok] = np.abs(floquet_multipliers(J[ok])[:, 0])
    return ok & (mu < 1.0), mu
