"""The tracker's loop under a push (Chapter 8): the clipped closed loop of
:mod:`lib.optimal.tracker` with a constant world-frame force on the body, decided by the same
procedure as :func:`lib.optimal.verdict.motion_verdict` on its own RK4 period maps.
"""

from __future__ import annotations

import numpy as np

from ..allocation import Limits
from ..integrators.batch import RK4, integrate
from ..integrators.smooth import SimulationError
from ..machinery import checks
from ..model import config_accel
from ..params import Body
from .tracker import (DEFAULT_STARTS, NEWTON_TOL, PeriodicLQR, _edges, _inside, _limits, _loop_inputs, _loop_reference,
                      _reference, periodic_lqr)
from .verdict import ORBIT_SHIFT_TOL, MotionVerdict, _decide, _ladder, _orbit

__all__ = ["pushed_verdict"]


def _pushed_loop(lqr: PeriodicLQR, F_max: float, beta_max, rows: int, push, memo: dict):
    """The clipped loop's rates on an input piece, as :func:`lib.optimal.tracker.track_motion`'s,
    plus the constant world-frame force ``push`` (N) on the body ``lqr.body``; ``memo`` keeps
    (x*, u*, K) by (t, lo, hi), which fixed steps meet every period."""
    body, (px, py) = lqr.body, push

    def piece(lo, hi):
        def rhs(t, s):
            X = s.reshape(rows, 6)
            ref = memo.get((t, lo, hi))
            if ref is None:
                ref = memo[t, lo, hi] = _loop_reference(lqr, t, _inside(t, lo, hi))
            F, beta = _loop_inputs(lqr, t, X, F_max, beta_max, ref=ref)
            acc = config_accel(body, X[:, :3], X[:, 3:], F, beta)
            acc[:, 0] += px / body.m
            acc[:, 1] += py / body.m
            out = np.concatenate([X[:, 3:], acc], -1).ravel()
            if not np.all(np.isfinite(out)):
                raise SimulationError(f"pushed loop became non-finite at t = {t:.6g} s")
            return out
        return rhs
    return piece


def _pushed_map(lqr: PeriodicLQR, F_max, beta_max, steps: int, push):
    """The pushed loop's period map (as :func:`_period_map` with ``steps``
    RK4 steps an input piece): x (M, 6) at t = 0 -> one period later, less the heading's turns."""
    motion = lqr.motion
    shift, edges, memo = 2 * np.pi * motion.turns * np.eye(6)[2], _edges(motion, 0.0, motion.period), {}

    def advance(X):
        y = X.ravel()
        try:
            for a, b in zip(edges[:-1], edges[1:]):
                y = integrate(_pushed_loop(lqr, F_max, beta_max, X.shape[0], push, memo)(a, b), y, a, b,
                              (b - a) / steps, RK4)[1][-1]
        except FloatingPointError as err:
            raise SimulationError(f"the pushed period map blew up: {err}") from None
        return y.reshape(X.shape) - shift
    return advance


def pushed_verdict(body: Body, motion, push, *, limits: Limits | None = None, lqr: PeriodicLQR | None = None,
                   starts=None, periods: int = 20, steps: int = 8, h: float = 1e-5) -> MotionVerdict:
    """:func:`lib.optimal.verdict.motion_verdict` of the loop with a constant world-frame force ``push`` = (Fx, Fy)
    (N) on ``body``: Newton on two RK4 maps (``steps`` and twice as many steps an input piece,
    doubled while the orbit moves by more than :data:`lib.optimal.verdict.ORBIT_SHIFT_TOL`), the multipliers, and the
    starts' reach test, by the same decision. Integrated in numpy (no compiled kernel takes a
    push): about a second of CPU a verdict at Chapter 8's steps.

    Parameters
    ----------
    body, motion, limits, lqr
        As in :func:`lib.optimal.verdict.motion_verdict` (``lqr`` may be a :func:`lib.optimal.studies.margins.plant_lqr`).
    push : array_like
        (Fx, Fy) (N), world frame.
    starts, periods, steps, h
        As in :func:`lib.optimal.verdict.motion_verdict`.

    Returns
    -------
    MotionVerdict
    """
    checks.instance("body", body, Body)
    push = tuple(float(p) for p in checks.array("push", push, shape=(2,)))
    steps = checks.integer("steps", steps, minimum=1)
    periods = checks.integer("periods", periods, minimum=2)
    lqr = lqr or periodic_lqr(body, motion)
    if lqr.body != body or lqr.motion is not motion:
        raise ValueError("lqr must be a periodic LQR of this body and motion")
    starts = checks.array("starts", DEFAULT_STARTS if starts is None else starts, shape=(None, 6), nonempty=True)
    F_max, beta_max = _limits(limits, motion)
    x_star = _reference(motion, 0.0)[0]
    pieces = len(_edges(motion, 0.0, motion.period)) - 1
    ladder = _ladder(steps, pieces)
    coarse = _pushed_map(lqr, F_max, beta_max, ladder[0][0], push)
    orb_c = _orbit(coarse, x_star, h)
    for j in range(1, len(ladder)):
        fine = _pushed_map(lqr, F_max, beta_max, ladder[j][0], push)
        orb_f = _orbit(fine, orb_c.x[0] if orb_c.residual[0] <= NEWTON_TOL else x_star, h)
        shift = float(np.abs(orb_f.x[0] - orb_c.x[0]).max())
        if not (shift > ORBIT_SHIFT_TOL) or j == len(ladder) - 1:
            break
        coarse, orb_c = fine, orb_f
    return _decide(orb_c, orb_f, coarse, fine, x_star, starts, periods, h, ladder[j - 1][0], shift,
                   refine=lambda s: (_pushed_map(lqr, F_max, beta_max, s, push) if s * pieces <= checks.MAX_STEPS
                                     else None))
