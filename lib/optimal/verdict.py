"""The controller of :mod:`lib.optimal.tracker` decided by the book's procedure: Newton on the
clipped closed loop's period map, its Floquet multipliers, and the reach test from a set of starts
(:mod:`lib.dynamics.verdicts`), each on a map shown converged in its step.

The clipped loop is a continuous field whose derivative jumps where a demanded input meets its
limit. Along a best motion the force sits at its cap for most of the period, so the orbit runs
beside those kinks. Three consequences shape this module:

- RK4 with a kink inside a step keeps only second order (the orbit moves 4 times less when the
  step is halved, ``tests/test_optimal_convergence.py``), and no grid of steps can follow kinks
  that move with the state. Each verdict is therefore taken on two maps, h and h / 2, and decided
  only when the orbit moves by at most :data:`ORBIT_SHIFT_TOL` between them; the steps are doubled
  from the ones asked for until it does (at most :data:`lib.machinery.domain.MAX_STEPS` a period).
- The field is continuous, so where the orbit crosses a kink transversally the saltation matrix is
  the identity and the period map is differentiable; but a kink within a difference step of the
  orbit bends the difference quotient, and one through the orbit point makes the map not
  differentiable there. The Jacobian is taken by central differences of step d, and the verdict
  stands only when the largest multiplier's modulus from the central differences of step d and
  the forward and backward ones of step d and d / 2 agree (:func:`multipliers_agree`: relative,
  so that a factor 2 is told apart; a kink through the point parts forward from backward; one
  between d / 2 and d, the steps).
- Along a best motion the plan sits *at* the cap (within 1e-7 N) on most pieces, and often at the
  angle limit: the orbit runs along the kink, not across it. The period map is then piecewise
  linear about the orbit at every scale above that sliver, and its "multiplier" is that of the
  side of the kink the orbit happens to sit on: RK4's own O(h^2) error puts its orbit on one
  side, the same at h and h / 2, and a tight adaptive map or an event-located variational
  integration on the exact orbit (which never crosses the kink) on others. The largest
  multiplier is therefore a numerical estimate, not a property certified by any one map: its
  error (``multiplier_error``) is the largest distance from the value (the finer map's central
  differences of step d) of |mu_1| from the central and one-sided differences of steps d, d / 2
  and :data:`KINK_STEP` d (a step that crosses the kinks) on the finer map, the central ones on
  the coarser, and the central and one-sided ones of steps d and d / 2 on the *resolved* map:
  the first doubling of the finer map's steps whose orbit error (a third of the shift between
  the two maps, RK4 keeping second order across kinks, a quarter of it at each doubling) is at
  most d / :data:`RESOLVE`, so that a step d meets the kinks where the exact loop meets them
  (within :data:`lib.machinery.domain.MAX_STEPS` a period). At 30 deg + 4 N on the eight the
  value is 0.030 and the resolved map's quotients fall to 0.007-0.019: the error is 0.023.
- A start far from the orbit wanders for periods before it meets the basin, and where it meets it
  depends on the step. A start reaches the orbit when it does on both maps; a start whose fate
  differs between them is not settled (``settled`` False).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..allocation import Limits
from ..dynamics.orbits import floquet_multipliers, newton
from ..dynamics.verdicts import reached
from ..integrators.batch import RK4, fixed_steps, integrate
from ..integrators.smooth import Integration, SimulationError
from ..machinery import checks
from ..params import Body
from .floquet import MULTIPLIER_RTOL, MULTIPLIER_TOL, multipliers_agree
from .riccati import loop_steps
from .tracker import (DEFAULT_STARTS, NEWTON_ITER, NEWTON_STALL, NEWTON_TOL, REACH_FLOOR, REACH_TOL, RTOL,
                      PeriodicLQR, _check_loop, _edges, _inside_bounds, _limits, _loop, _piecewise_ivp, _reference,
                      periodic_lqr)

__all__ = ["MotionVerdict", "motion_verdict", "basin", "offset_starts", "ORBIT_SHIFT_TOL", "KINK_STEP", "RESOLVE",
           "FINE_RTOL"]

#: the most the orbit may move (max-norm, state units) when the step is halved, a tenth of the
#: reach tolerance :data:`lib.optimal.tracker.REACH_TOL`, so that a start's distance to it is
#: decided by the dynamics, not by the step
ORBIT_SHIFT_TOL = 0.1 * REACH_TOL
#: the differencing step, in units of the verdict's step h, that crosses the clip's kinks beside the orbit
#: (the RK4 orbit sits off them by its O(h^2) error, about 1e-5 state units): its one-sided
#: quotients are those of the kink's other side, and enter the multiplier's stated error
KINK_STEP = 10.0
#: the resolved map's orbit error is at most the differencing step / RESOLVE
RESOLVE = 10.0
#: the adaptive map's second tolerance (``steps`` = 0): DOP853 at rtol = atol = RTOL / 100
FINE_RTOL = RTOL / 100
#: a state beyond this magnitude (m, rad, m/s, rad/s) has blown up
BLOWUP = Integration.blowup


@dataclass(frozen=True)
class MotionVerdict:
    """What :func:`motion_verdict` decides: ``regime`` ("periodic" or "undecided", words of
    :data:`lib.dynamics.verdicts.REGIMES`) and ``reason`` ("" when periodic); ``x`` (6,) the
    orbit's point at t = 0 mod T on the finer map (m, m, rad, m/s, m/s, rad/s; NaN without one),
    ``residual`` Newton's there (max-norm), ``multipliers`` (6,) its Floquet multipliers from
    differences of step h (complex, decreasing modulus); ``offset`` (6,) = x minus the motion's
    own state at 0 (how far the clipped loop's orbit is from the designed motion),
    ``position_offset`` (m) and ``heading_offset`` (rad) its parts. The integration: ``steps``
    RK4 steps on each input piece for the coarser map, twice as many for the finer (0: DOP853 at
    :data:`lib.optimal.tracker.RTOL` and :data:`FINE_RTOL`); ``orbit_shift`` how far the orbit
    moved between the two (max-norm, state units), ``multiplier_spread`` the range of |mu_1| over
    the central and one-sided difference Jacobians of step h and h / 2, ``multiplier_error`` the
    stated error of |mu_1| (the module's docstring; :func:`lib.optimal.floquet.floquet_estimate`). Per start (S,):
    ``reached`` (on both maps), ``settled``
    (the same fate on both) and ``distance``, the finer map's final section distance to the orbit
    point (max-norm, heading unwrapped; NaN when the starts were not run), after ``periods``
    periods; starts are run only when the orbit is periodic."""

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
    steps: int = 0
    orbit_shift: float = math.nan
    multiplier_spread: float = math.nan
    settled: np.ndarray | None = None
    multiplier_error: float = math.nan


def _period_map(lqr: PeriodicLQR, F_max, beta_max, steps: int = 0, rtol: float = RTOL):
    """x (M, 6) at t = 0 -> the state after one period less the heading's 2 pi turns (M, 6): back
    in the frame of t = 0, so the motion is a fixed point. ``steps`` > 0: classical RK4 with that
    many fixed steps on each input piece, all rows at once (no step straddles an input jump),
    compiled (:func:`lib.optimal.riccati.loop_steps`) for a motion with collocation polynomials;
    0: DOP853 at ``rtol`` piece by piece, row by row when a limit may clip."""
    shift, edges = 2 * np.pi * lqr.motion.turns * np.eye(6)[2], _edges(lqr.motion, 0.0, lqr.motion.period)
    memo, compiled = {}, None     # memo: the motion and its gain at each stage time, which every call meets
    if steps:
        n, h = np.array([fixed_steps(a, b, (b - a) / steps) for a, b in zip(edges[:-1], edges[1:])]).T
        inside = np.array([_inside_bounds(a, b) for a, b in zip(edges[:-1], edges[1:])])
        compiled = loop_steps(lqr, F_max, beta_max, edges, n.astype(int), h, inside)

    def fixed(X):
        if compiled is not None:
            Y, code, t, row = compiled(X, BLOWUP)
            if code:
                raise SimulationError(f"the period map blew up at t = {t:.6g} s (start {row}: a state beyond "
                                      f"{BLOWUP:g} or a rate not finite)")
            return Y
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
        return np.concatenate([_piecewise_ivp(_loop(lqr, F_max, beta_max, len(b)), b.ravel(), edges, [], rtol,
                                              "the period map", rtol=rtol)[1].reshape(-1, 6) for b in B]) - shift
    return advance


def _difference_step(advance, d: float):
    """Newton's ``step``: P(x) and its Jacobian by central differences of step d, all rows at once."""
    def step(idx, x, k):
        N, E = x.shape[0], d * np.eye(6)
        Y = advance(np.concatenate([x] + [x + e for e in E] + [x - e for e in E]))
        plus, minus = Y[N:7 * N].reshape(6, N, 6), Y[7 * N:].reshape(6, N, 6)
        return Y[:N], np.moveaxis((plus - minus) / (2 * d), 0, -1)
    return step


def _quotients(advance, x, d: float) -> list:
    """The central, forward and backward difference Jacobians of step d of the map at x (6,)."""
    E = d * np.eye(6)
    Y = advance(np.concatenate([x[None], x + E, x - E]))
    fw, bw = (Y[1:7] - Y[0]).T / d, (Y[0] - Y[7:]).T / d
    return [(fw + bw) / 2, fw, bw]


def _one_sided(advance, x, d: float) -> list:
    """The four one-sided difference Jacobians of the map at x (6,): forward and backward, of step
    d and d / 2. Where the map is differentiable near x they agree with the central ones to
    O(d |P''|); a kink of the map through x parts the forward from the backward, one between
    d / 2 and d the steps."""
    E = np.eye(6)
    Y = advance(np.concatenate([x[None]] + [x + s * e * E for e in (d, d / 2) for s in (1.0, -1.0)]))
    return [s * (Y[1 + 6 * i:7 + 6 * i] - Y[0]).T / e for i, (e, s) in enumerate((e, s) for e in (d, d / 2)
                                                                                for s in (1.0, -1.0))]


def _orbit(advance, x0, d: float):
    """Newton's result on the map ``advance`` from x0 (6,) with differences of step d."""
    return newton(_difference_step(advance, d), np.zeros(1, int), x0[None], 1, turn_axis=2, turns=np.zeros(1, int),
                  tol=NEWTON_TOL, max_iter=NEWTON_ITER, stall_after=NEWTON_STALL)


def _radius(mult) -> float:
    """|mu_1|, the modulus of the largest multiplier (``mult`` sorted by decreasing modulus)."""
    return float(np.abs(mult[0]))


def _ladder(steps: int, pieces: int) -> list:
    """The maps tried, coarse to fine: (steps, rtol) doubling from ``steps`` while a period's
    steps stay within :data:`lib.machinery.domain.MAX_STEPS` (at least one halving), or the two
    tolerances of DOP853 for ``steps`` = 0."""
    if steps == 0:
        return [(0, RTOL), (0, FINE_RTOL)]
    out = [(steps, RTOL), (2 * steps, RTOL)]
    while 2 * out[-1][0] * pieces <= checks.MAX_STEPS:
        out.append((2 * out[-1][0], RTOL))
    return out


def motion_verdict(body: Body, motion, *, limits: Limits | None = None, starts=None, periods: int = 20,
                   lqr: PeriodicLQR | None = None, h: float = 1e-5, steps: int = 8) -> MotionVerdict:
    """Decide the clipped closed loop of :func:`lib.optimal.tracker.track_motion` with the book's procedure.

    Newton (:func:`lib.dynamics.orbits.newton`, tol :data:`lib.optimal.tracker.NEWTON_TOL`,
    :data:`lib.optimal.tracker.NEWTON_ITER` steps, after :data:`lib.optimal.tracker.NEWTON_STALL`
    only while the residual halves) on the period map P (one period of the loop from a state at
    t = 0 mod T), P(x) = x + (0, 0, 2 pi turns, 0, 0, 0), from the motion's state at 0; the
    Jacobian by central differences of step ``h`` (the state's units). Newton runs on a map and
    on the map of half its step (from the first map's orbit); while the orbit moves by more than
    :data:`ORBIT_SHIFT_TOL` between them the steps are doubled. "periodic" when Newton converges
    on both, the orbit moved by at most :data:`ORBIT_SHIFT_TOL`, |mu_1| from the central
    differences and from the forward and backward ones of step h and h / 2 on the finer map
    agree (:func:`multipliers_agree`) and every Floquet multiplier lies inside the unit circle;
    else "undecided" with the reason. Then each of ``starts``
    ((S, 6) states at t = 0, default :data:`lib.optimal.tracker.DEFAULT_STARTS`) runs
    ``periods`` (>= 2) periods on both maps and has reached the orbit
    (:func:`lib.dynamics.verdicts.reached`, tol :data:`lib.optimal.tracker.REACH_TOL`, floor
    :data:`lib.optimal.tracker.REACH_FLOOR`) when on both its last section distance to the
    map's orbit is below the tolerance and has shrunk since ``periods // 2`` periods before as
    |mu_1| allows.

    Parameters
    ----------
    body, motion, limits, lqr
        As in :func:`lib.optimal.tracker.track_motion` (``lqr`` default: :func:`periodic_lqr`'s default weights).
    starts, periods, h
        See above.
    steps : int
        > 0: classical RK4 with ``steps`` fixed steps on each input piece for the first (coarsest)
        map, doubled as above; 0: DOP853 piece by piece at rtol = atol =
        :data:`lib.optimal.tracker.RTOL` and at :data:`FINE_RTOL` (row by row where a limit may
        clip: far dearer).

    Returns
    -------
    MotionVerdict
    """
    _check_loop(body, motion, limits, lqr)
    starts = checks.array("starts", DEFAULT_STARTS if starts is None else starts, shape=(None, 6), nonempty=True)
    periods = checks.integer("periods", periods, minimum=2)
    h = checks.number("h", h, positive=True, maximum=0.1)
    steps = checks.integer("steps", steps, minimum=0)
    pieces = len(_edges(motion, 0.0, motion.period)) - 1
    checks.within_budget({"steps": 2 * steps * pieces}, checks.MAX_STEPS, what="its finer map would need",
                         unit="fixed steps a period", values={"steps": (steps, "a piece")},
                         fix=f"the motion has {pieces} input pieces a period")
    lqr = lqr or periodic_lqr(body, motion)
    F_max, beta_max = _limits(limits, motion)
    x_star = _reference(motion, 0.0)[0]
    ladder = _ladder(steps, pieces)
    coarse = _period_map(lqr, F_max, beta_max, *ladder[0])
    orb_c = _orbit(coarse, x_star, h)
    for j in range(1, len(ladder)):
        fine = _period_map(lqr, F_max, beta_max, *ladder[j])
        start = orb_c.x[0] if orb_c.residual[0] <= NEWTON_TOL else x_star
        orb_f = _orbit(fine, start, h)
        shift = float(np.abs(orb_f.x[0] - orb_c.x[0]).max())
        if not (shift > ORBIT_SHIFT_TOL) or j == len(ladder) - 1:
            break
        coarse, orb_c = fine, orb_f
    return _decide(orb_c, orb_f, coarse, fine, x_star, starts, periods, h, ladder[j - 1][0], shift,
                   refine=lambda s: _period_map(lqr, F_max, beta_max, s) if s * pieces <= checks.MAX_STEPS else None)


def _resolved_radii(refine, steps: int, shift: float, x, h: float) -> list:
    """|mu_1| from the central and one-sided differences of steps h and h / 2 on the resolved map
    (the module's docstring): ``refine(s)`` the map of s RK4 steps a piece, or None beyond the
    budget; ``steps`` the finer map's, ``shift`` the orbit's between it and the coarser. Empty
    when the finer map is resolved already, or when Newton does not converge on the resolved map."""
    s, err = steps, shift / 3.0
    while err > h / RESOLVE and refine(2 * s) is not None:
        s, err = 2 * s, err / 4.0
    if s == steps:
        return []
    resolved = refine(s)
    orb = _orbit(resolved, x, h)
    if not orb.residual[0] <= NEWTON_TOL:
        return []
    Js = [orb.jacobian[0]] + _one_sided(resolved, orb.x[0], h)
    return [_radius(floquet_multipliers(J)) if np.all(np.isfinite(J)) else math.inf for J in Js]


def _decide(orb_c, orb_f, coarse, fine, x_star, starts, periods, h, steps, shift, refine=None) -> MotionVerdict:
    """The verdict from Newton's results on the two maps, and the runs from the starts when periodic;
    ``refine(s)`` the map of s RK4 steps a piece (None beyond the budget), for the multiplier's error."""
    ok = bool(orb_c.residual[0] <= NEWTON_TOL and orb_f.residual[0] <= NEWTON_TOL)
    x, J = orb_f.x[0], orb_f.jacobian[0]
    mult = floquet_multipliers(J) if np.all(np.isfinite(J)) else np.full(6, np.nan + 0j)
    rho, spread, error, agree = _radius(mult), math.nan, math.nan, False
    if ok:
        def radii(Js):
            return [_radius(floquet_multipliers(Jd)) if np.all(np.isfinite(Jd)) else math.inf for Jd in Js]
        near = radii(_one_sided(fine, x, h)) + [rho]
        spread, agree = max(near) - min(near), multipliers_agree(max(near), min(near))
        wide = near + radii(_quotients(fine, x, KINK_STEP * h)) + radii([orb_c.jacobian[0]])
        if refine is not None and steps:
            wide += _resolved_radii(refine, 2 * steps, shift, x, h)
        error = max(abs(r - rho) for r in wide)
    what = f"{2 * steps} RK4 steps a piece" if steps else f"rtol {FINE_RTOL:g}"
    reason = ("" if ok and shift <= ORBIT_SHIFT_TOL and agree and rho < 1.0
              else f"Newton did not converge (residual {max(orb_c.residual[0], orb_f.residual[0]):.3g})" if not ok
              else f"the orbit moved by {shift:.3g} (more than {ORBIT_SHIFT_TOL:g}) at {what}"
              if not shift <= ORBIT_SHIFT_TOL
              else f"|mu_1| from central and one-sided differences of step {h:g} and {h / 2:g} differ by "
                   f"{spread:.3g} (more than {MULTIPLIER_RTOL:g} of the larger, at most {MULTIPLIER_TOL:g}): the "
                   "map is not differentiable there"
              if not agree
              else f"the orbit does not attract (|mu_1| = {rho:.6g})")
    S = len(starts)
    hit, settled, dist = np.zeros(S, bool), np.zeros(S, bool), np.full(S, np.nan)
    if not reason:
        fates = [_reach(adv, orb.x[0], starts, periods, rho) for adv, orb in ((coarse, orb_c), (fine, orb_f))]
        hit, settled, dist = fates[0][0] & fates[1][0], fates[0][0] == fates[1][0], fates[1][1]
    xo = x if ok else np.full(6, np.nan)
    off = xo - x_star
    return MotionVerdict(regime="undecided" if reason else "periodic", reason=reason, x=xo,
                         residual=float(orb_f.residual[0]), multipliers=mult, offset=off,
                         position_offset=float(np.hypot(off[0], off[1])), heading_offset=float(off[2]),
                         reached=hit, distance=dist, periods=periods, steps=steps, orbit_shift=shift,
                         multiplier_spread=spread, settled=settled, multiplier_error=error)


def _reach(advance, x, starts, periods: int, rho: float):
    """Run the starts ``periods`` periods on one map: (reached (S,), final distance to x (S,)); a
    run that blows up has not reached."""
    dist, X = np.full((periods + 1, len(starts)), np.nan), np.array(starts, dtype=float)
    with np.errstate(all="ignore"):
        for j in range(periods + 1):
            dist[j] = np.abs(X - x).max(axis=1)
            if j < periods:
                X = _advance_rows(advance, X)
    dist = np.where(np.isfinite(dist), dist, np.inf)
    return reached(dist[-1], dist[-1 - periods // 2], rho, periods // 2, tol=REACH_TOL, floor=REACH_FLOOR), dist[-1]


def _advance_rows(advance, X):
    """One period of the rows X; where the batch blows up, the rows alone (those that blow up become NaN)."""
    try:
        return advance(X)
    except SimulationError:
        out = np.full_like(X, np.nan)
        for i, s in enumerate(X):
            if np.isfinite(s).all():
                try:
                    out[i] = advance(s[None])[0]
                except SimulationError:
                    pass
        return out


def offset_starts(heading_offsets, position_offsets) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The basins' grid: the paper's start at rest moved by each heading offset and each offset of x.

    Parameters
    ----------
    heading_offsets, position_offsets : array_like
        1-D offsets (rad, m), checked.

    Returns
    -------
    H, X, starts : numpy.ndarray
        The offsets on a meshgrid and the starts (H.size, 6).
    """
    H, X = np.meshgrid(checks.array("heading_offsets", heading_offsets, ndim=1, nonempty=True),
                       checks.array("position_offsets", position_offsets, ndim=1, nonempty=True))
    S0 = np.tile(DEFAULT_STARTS[0], (H.size, 1))
    S0[:, 2] += H.ravel()
    S0[:, 0] += X.ravel()
    return H, X, S0


def basin(body: Body, motion, verdict: MotionVerdict, *, limits: Limits | None = None, lqr: PeriodicLQR | None = None,
          heading_offsets=np.linspace(-np.pi, np.pi, 13), position_offsets=np.linspace(-1.0, 1.0, 9),
          periods: int = 8, steps: int | None = None):
    """Which starts the controller brings to the orbit of ``verdict``: the paper's start at rest
    moved by each heading offset (rad) and each offset of x (m), run ``periods`` periods on the
    period maps of :func:`motion_verdict` with RK4 of ``steps`` and twice as many steps on each
    input piece (``steps`` at least ``verdict.steps``, whose orbit moved by at most
    :data:`ORBIT_SHIFT_TOL` when they were doubled; default ``verdict.steps``, or 8 after an
    adaptive verdict); reached when on both maps the final section distance to the orbit point
    (max-norm) is below :data:`lib.optimal.tracker.REACH_TOL`, settled when both maps agree.

    Returns
    -------
    pandas.DataFrame
        Columns heading_offset (rad), x_offset (m), distance (state units, the finer map's),
        reached, settled.
    """
    _check_loop(body, motion, limits, lqr)
    checks.instance("verdict", verdict, MotionVerdict)
    H, X, S0 = offset_starts(heading_offsets, position_offsets)
    periods = checks.integer("periods", periods, minimum=1)
    steps = max(verdict.steps or 8, 0 if steps is None else checks.integer("steps", steps, minimum=1))
    if not np.isfinite(verdict.x).all():
        raise ValueError("verdict has no orbit (regime 'undecided'): no basin to draw")
    lqr = lqr or periodic_lqr(body, motion)
    d = []
    for s in (steps, 2 * steps):
        advance, S = _period_map(lqr, *_limits(limits, motion), s), S0
        with np.errstate(all="ignore"):
            for _ in range(periods):
                S = _advance_rows(advance, S)
        e = np.abs(S - verdict.x).max(axis=1)
        d.append(np.where(np.isfinite(e), e, np.inf))
    hit = (d[0] < REACH_TOL, d[1] < REACH_TOL)
    return pd.DataFrame(dict(heading_offset=H.ravel(), x_offset=X.ravel(), distance=d[1], reached=hit[0] & hit[1],
                             settled=hit[0] == hit[1]))
