"""The steps that find a flow's attracting orbits on its period map, for the book's one
decision procedure (:mod:`lib.dynamics.verdicts`, which re-exports them): where the
section nearly repeats (:func:`lag_candidates`), a Jacobian by differences
(:func:`difference_jacobian`), an orbit's least period (:func:`least_period`), the
distance of a state to an orbit (:func:`distance_to_orbit`) and whether a run has reached
it (:func:`reached`), an orbit's points (:func:`orbit_points`), and an orbit inside a
closed section curve (:func:`enclosed_orbit`). A flow supplies only its period map
(:class:`PeriodMap`) and its heading's column, which may advance by whole turns.
"""

from __future__ import annotations

from typing import Callable, Protocol

import numpy as np

from ..angles import wrap_angle
from .orbits import floquet_multipliers, newton

__all__ = ["PeriodMap", "lag_candidates", "difference_jacobian", "least_period", "distance_to_orbit", "reached",
           "orbit_points", "enclosed_orbit"]

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
