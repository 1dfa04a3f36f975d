"""The one decision procedure behind every long-run verdict of the book.

A periodically driven motion is observed at its stroboscopic section (t = j T, T the
period of the forcing) through a *period map* P: the state after one period. Every
flow of the book (the reduced rotation (32), the switched closed loop under limits,
the full closed loop under any allocation) supplies only that map and which of its
coordinates is the heading, which may advance by whole turns; the steps below, and
the words they decide, are written here once.

The words (the book's definition ``def-regimes``, on its Methods page):

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
``transient`` (transient chaos: attractor not determined)
    the point's run was decided again (:func:`needs_confirmation` says which runs are) from
    the same start at another integration resolution or from the start moved by 1e-12, or
    over a longer horizon, and the attractors reached differ: another regime, another period,
    or another orbit (:func:`attractor_determined`). The run wanders irregularly for a while
    and which attractor it then settles on is decided by the last bits of the trajectory.
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

The steps (in :mod:`lib.dynamics.orbit_search` and :mod:`lib.dynamics.statistics`, re-exported
here): :func:`lag_candidates` (where the section nearly repeats),
:func:`newton` (exact Jacobian or :func:`difference_jacobian`), Floquet multipliers
(:func:`lib.dynamics.orbits.floquet_multipliers`), :func:`least_period`,
:func:`distance_to_orbit` and :func:`reached`, :func:`block_statistics` (an exponent or
a drift with its batch-means standard error), :func:`section_returns`, and the rule
:func:`classify`.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from .orbit_search import (PeriodMap, difference_jacobian, distance_to_orbit, enclosed_orbit, lag_candidates,
                           least_period, orbit_points, reached)
from .orbits import NewtonResult, floquet_multipliers, newton
from .statistics import batch_means, block_statistics, drift_statistics, heading_drift, section_returns  # re-exported

__all__ = ["REGIMES", "SIGMAS", "PeriodMap", "lag_candidates", "difference_jacobian", "newton", "NewtonResult", "least_period",
           "distance_to_orbit", "reached", "block_statistics", "batch_means", "drift_statistics", "heading_drift", "section_returns", "classify",
           "heading_lost", "turns_round", "held", "TRANSIENT", "needs_confirmation", "attractor_determined", "redecide_undecided", "orbit_regime", "orbit_points", "find_orbits", "enclosed_orbit"]

#: the verdicts, in the order the book lists them
REGIMES = ("periodic", "slipping", "chaotic", "transient", "quasiperiodic", "undecided")

#: the regime of a point whose decisions reach different attractors (transient chaos)
TRANSIENT = "transient"

#: the regimes of an attracting orbit reached
ORBIT_REGIMES = ("periodic", "slipping")

#: standard errors by which a positive exponent must clear zero to be called chaotic
SIGMAS = 3.0

TWO_PI = 2 * np.pi


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


def needs_confirmation(regime, periods, transient: int) -> np.ndarray:
    """The trigger for deciding a run again (:func:`attractor_determined`): its first
    decision saw a chaotic transient, that is, it reached no attracting orbit within the
    ``transient`` periods and went on to the Lyapunov run, and was then decided ``chaotic``
    or reached its orbit there (``periods`` > ``transient``: an orbit reached late).
    Orbits reached within the transient, and quasi-periodic and undecided runs, are not
    decided again. Returns (N,) bool.

    Parameters
    ----------
    regime : array_like
        First verdicts (N,).
    periods : array_like
        Periods integrated before each verdict (N,).
    transient : int
        The transient's periods.

    Returns
    -------
    numpy.ndarray
        (N,) bool.
    """
    regime, periods = np.asarray(regime, dtype=object), np.asarray(periods)
    return (regime == "chaotic") | (np.isin(regime, ORBIT_REGIMES) & (periods > transient))


def attractor_determined(regime, period, same_orbit) -> np.ndarray:
    """The rule of ``transient``: whether D decisions of the same N runs (the first one the
    map's, the others from a perturbed start, at another resolution or over a longer horizon)
    reach the same attractor: the same regime, the same period, and, where the first reaches
    an orbit, the same orbit (``same_orbit``, decided by the flow: the orbits' points agree
    within its accuracy). Returns (N,) bool; where False the verdict is ``transient``.

    Parameters
    ----------
    regime, period : array_like
        Verdicts and periods (D, N), the first row the map's.
    same_orbit : array_like
        (D - 1, N) bool: decision j + 1 reached the first decision's orbit (read only where
        both reach an orbit of the same period).

    Returns
    -------
    numpy.ndarray
        (N,) bool.
    """
    regime, period = np.atleast_2d(np.asarray(regime, dtype=object)), np.atleast_2d(np.asarray(period))
    same = (regime[1:] == regime[0]) & (period[1:] == period[0])
    orbit = np.isin(regime[0], ORBIT_REGIMES)
    same &= ~orbit | np.atleast_2d(np.asarray(same_orbit, dtype=bool))
    return same.all(axis=0)


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
    ``max_period``)). Its least period is the smallest divisor d of k whose P^d returns
    the orbit point to within 100 ``newton_tol`` (:func:`least_period`: Newton's point is
    accurate to ``newton_tol``, its images to a few times that, and a shorter orbit closer
    than this is not told apart). Where an attracting orbit of period k is found but not yet
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


