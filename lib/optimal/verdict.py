"""The controller of :mod:`lib.optimal.tracker` decided by the book's procedure: Newton on the
clipped closed loop's period map, its Floquet multipliers, and the reach test from a set of starts
(:mod:`lib.dynamics.verdicts`)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..allocation import Limits
from ..dynamics.orbits import floquet_multipliers, newton
from ..dynamics.verdicts import reached
from ..integrators.batch import RK4, integrate
from ..integrators.smooth import SimulationError
from ..machinery import checks
from ..params import Body
from .tracker import (DEFAULT_STARTS, NEWTON_ITER, NEWTON_STALL, NEWTON_TOL, REACH_FLOOR, REACH_TOL, RTOL,
                      PeriodicLQR, _check_loop, _edges, _limits, _loop, _piecewise_ivp, _reference, periodic_lqr)

__all__ = ["MotionVerdict", "motion_verdict", "basin"]


@dataclass(frozen=True)
class MotionVerdict:
    """What :func:`motion_verdict` decides: ``regime`` ("periodic" or "undecided", words of
    :data:`lib.dynamics.verdicts.REGIMES`) and ``reason`` ("" when periodic); ``x`` (6,) the
    orbit's point at t = 0 mod T (m, m, rad, m/s, m/s, rad/s; NaN without one), ``residual``
    Newton's (max-norm), ``multipliers`` (6,) the Floquet multipliers there (complex, decreasing
    modulus); ``offset`` (6,) = x minus the motion's own state at 0 (how far the clipped loop's
    orbit is from the designed motion), ``position_offset`` (m) and ``heading_offset`` (rad) its
    parts; per start (S,) ``reached`` and ``distance``, the final section distance to the orbit
    point (max-norm, heading unwrapped; NaN without an orbit), after ``periods`` periods."""

    regime: str
    reason: str
    x: np.ndarray
    residual: float
    multipliers: np.ndarray
    offset: np.ndarray
    position_offset: float
    heading_offset: float
    reached: np.ndarray
    distance: np.ndarray
    periods: int


def _period_map(lqr: PeriodicLQR, F_max, beta_max, steps: int = 0):
    """x (M, 6) at t = 0 -> the state after one period less the heading's 2 pi turns (M, 6): back
    in the frame of t = 0, so the motion is a fixed point. ``steps`` > 0: classical RK4 with that
    many fixed steps on each input piece, all rows at once (no step straddles an input jump)."""
    shift, edges = 2 * np.pi * lqr.motion.turns * np.eye(6)[2], _edges(lqr.motion, 0.0, lqr.motion.period)
    memo = {}     # every call meets the same stage times: the motion and its gain there, once

    def fixed(X):
        y = X.ravel()
        try:
            for a, b in zip(edges[:-1], edges[1:]):
                y = integrate(_loop(lqr, F_max, beta_max, X.shape[0], memo)(a, b), y, a, b, (b - a) / steps,
                              RK4)[1][-1]
        except FloatingPointError as err:
            raise SimulationError(f"the period map blew up: {err}") from None
        return y.reshape(X.shape)

    def advance(X):    # all rows in one run when smooth, else row by row (each row's clipping kinks its steps)
        if steps:
            return fixed(X) - shift
        B = [X] if F_max == math.inf and beta_max is None else [x[None] for x in X]
        return np.concatenate([_piecewise_ivp(_loop(lqr, F_max, beta_max, len(b)), b.ravel(), edges, [], RTOL,
                                              "the period map")[1].reshape(-1, 6) for b in B]) - shift
    return advance


def motion_verdict(body: Body, motion, *, limits: Limits | None = None, starts=None, periods: int = 20,
                   lqr: PeriodicLQR | None = None, h: float = 1e-5, steps: int = 0) -> MotionVerdict:
    """Decide the clipped closed loop of :func:`lib.optimal.tracker.track_motion` with the book's procedure.

    Newton (:func:`lib.dynamics.orbits.newton`, tol :data:`lib.optimal.tracker.NEWTON_TOL`, :data:`lib.optimal.tracker.NEWTON_ITER` steps,
    after :data:`lib.optimal.tracker.NEWTON_STALL` only while the residual halves) on the period map P (one period of
    the loop from a state at t = 0 mod T), P(x) = x + (0, 0, 2 pi turns, 0, 0, 0), from the
    motion's state at 0; the Jacobian by central differences of step ``h`` (the state's units).
    "periodic" when Newton converges and every Floquet
    multiplier lies inside the unit circle, else "undecided" with the reason. Then each of
    ``starts`` ((S, 6) states at t = 0, default :data:`lib.optimal.tracker.DEFAULT_STARTS`) runs ``periods`` (>= 2)
    periods and has reached the orbit (:func:`lib.dynamics.verdicts.reached`, tol
    :data:`lib.optimal.tracker.REACH_TOL`, floor :data:`lib.optimal.tracker.REACH_FLOOR`) when its last section distance is below the
    tolerance and has shrunk since ``periods // 2`` periods before as |mu_1| allows.

    Parameters
    ----------
    body, motion, limits, lqr
        As in :func:`lib.optimal.tracker.track_motion` (``lqr`` default: :func:`periodic_lqr`'s default weights).
    starts, periods, h
        See above.
    steps : int
        0: the period map by adaptive DOP853 (:data:`lib.optimal.tracker.RTOL`) piece by piece; > 0: classical RK4 with
        ``steps`` fixed steps on each input piece (the map of the discretised loop, far cheaper
        where the clipping kinks the field at the orbit).

    Returns
    -------
    MotionVerdict
    """
    _check_loop(body, motion, limits, lqr)
    starts = checks.array("starts", DEFAULT_STARTS if starts is None else starts, shape=(None, 6), nonempty=True)
    periods = checks.integer("periods", periods, minimum=2)
    h = checks.number("h", h, positive=True, maximum=0.1)
    steps = checks.integer("steps", steps, minimum=0)
    lqr = lqr or periodic_lqr(body, motion)
    advance = _period_map(lqr, *_limits(limits, motion), steps)

    def step(idx, x, k):
        N, E = x.shape[0], h * np.eye(6)
        Y = advance(np.concatenate([x] + [x + e for e in E] + [x - e for e in E]))
        plus, minus = Y[N:7 * N].reshape(6, N, 6), Y[7 * N:].reshape(6, N, 6)
        return Y[:N], np.moveaxis((plus - minus) / (2 * h), 0, -1)

    x_star = _reference(motion, 0.0)[0]
    res = newton(step, np.zeros(1, int), x_star[None], 1, turn_axis=2, turns=np.zeros(1, int), tol=NEWTON_TOL,
                 max_iter=NEWTON_ITER, stall_after=NEWTON_STALL)
    return _decide(res, advance, x_star, starts, periods)


def _decide(orb, advance, x_star, starts, periods) -> MotionVerdict:
    """The verdict from Newton's result, and the runs from the starts when there is an orbit."""
    ok, J = bool(orb.residual[0] <= NEWTON_TOL), orb.jacobian[0]
    mult = floquet_multipliers(J) if np.all(np.isfinite(J)) else np.full(6, np.nan + 0j)
    rho = float(np.abs(mult[0]))
    reason = ("" if ok and rho < 1.0 else f"the orbit does not attract (|mu_1| = {rho:.6g})" if ok
              else f"Newton did not converge (residual {orb.residual[0]:.3g})")
    x, dist, hit = (orb.x[0] if ok else np.full(6, np.nan)), np.full((periods + 1, len(starts)), np.nan), False
    if ok:
        X = np.array(starts, dtype=float)
        for j in range(periods + 1):
            dist[j], X = np.abs(X - x).max(axis=1), (advance(X) if j < periods else X)
        hit = reached(dist[-1], dist[-1 - periods // 2], rho, periods // 2, tol=REACH_TOL, floor=REACH_FLOOR) & (rho < 1)
    off = x - x_star
    return MotionVerdict(regime="undecided" if reason else "periodic", reason=reason, x=x,
                         residual=float(orb.residual[0]), multipliers=mult, offset=off,
                         position_offset=float(np.hypot(off[0], off[1])), heading_offset=float(off[2]),
                         reached=np.broadcast_to(hit, dist[-1].shape).copy(), distance=dist[-1], periods=periods)


def basin(body: Body, motion, verdict: MotionVerdict, *, limits: Limits | None = None, lqr: PeriodicLQR | None = None,
          heading_offsets=np.linspace(-np.pi, np.pi, 13), position_offsets=np.linspace(-1.0, 1.0, 9),
          periods: int = 8, steps: int = 2):
    """Which starts the controller brings to the orbit of ``verdict``: the paper's start at rest
    moved by each heading offset (rad) and each offset of x (m), run ``periods`` periods on the
    period map of :func:`motion_verdict` (``steps`` as there); reached when the final section
    distance to the orbit point (max-norm) is below :data:`lib.optimal.tracker.REACH_TOL`.

    Returns
    -------
    pandas.DataFrame
        Columns heading_offset (rad), x_offset (m), distance (state units), reached.
    """
    _check_loop(body, motion, limits, lqr)
    checks.instance("verdict", verdict, MotionVerdict)
    hs = checks.array("heading_offsets", heading_offsets, ndim=1, nonempty=True)
    xs = checks.array("position_offsets", position_offsets, ndim=1, nonempty=True)
    periods = checks.integer("periods", periods, minimum=1)
    steps = checks.integer("steps", steps, minimum=1)
    if not np.isfinite(verdict.x).all():
        raise ValueError("verdict has no orbit (regime 'undecided'): no basin to draw")
    lqr = lqr or periodic_lqr(body, motion)
    advance = _period_map(lqr, *_limits(limits, motion), steps)
    H, X = np.meshgrid(hs, xs)
    S = np.tile(DEFAULT_STARTS[0], (H.size, 1))
    S[:, 2] += H.ravel()
    S[:, 0] += X.ravel()
    with np.errstate(all="ignore"):
        for _ in range(periods):
            try:
                S = advance(S)
            except SimulationError:      # rows that blow up are not reached; run the rest alone
                S = np.array([advance(s[None])[0] if np.isfinite(s).all() else s for s in S])
    d = np.abs(S - verdict.x).max(axis=1)
    d = np.where(np.isfinite(d), d, np.inf)
    return pd.DataFrame(dict(heading_offset=H.ravel(), x_offset=X.ravel(), distance=d, reached=d < REACH_TOL))
