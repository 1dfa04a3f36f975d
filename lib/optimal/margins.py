"""Chapter 8's tracker with an authority margin, on a wrong model, under a push, and on a second eight.

* A *margin*: the best motion is planned under a reduced cap, ``fraction`` times the paper's 4 N
  (:data:`MARGIN`), and tracked with the full limits in the loop, so that the feedback may raise
  the force above the plan as well as lower it (:func:`margin_cases`).
* A *wrong model*: the plan and the gain use the nominal :class:`lib.params.Body`, the plant has
  one parameter (m, I_C, c, c_phi or a, :data:`lib.tracking.mismatch.PARAMETERS`) off by
  :data:`WRONG_DELTA` high or low, as :func:`lib.tracking.mismatch.model_of` scales it. The
  periodic LQR's gain K = R^-1 B' P depends on the body through B alone, whose rows of x'', y''
  scale with 1 / m and whose row of phi'' with a / I_C; :func:`plant_lqr` moves that scaling into
  P, so the loop of :func:`lib.optimal.tracker.track_motion` and the verdict of
  :func:`lib.optimal.verdict.motion_verdict`, run on the plant (their compiled kernels included),
  apply the nominal gain exactly (to rounding) while the plant moves by its own parameters.
* A *push*: a constant world-frame force (Fx, Fy) (N) on the body, which no parameter of the
  model represents; its loop is integrated in numpy (:func:`pushed_verdict`, the same two RK4
  maps and the same decision as :func:`lib.optimal.verdict.motion_verdict`).
* A *second eight*: the bound, the paper's law under the cap and the best motion found with its
  tracker at another point of Fig. 5's grid (:func:`eight_comparison`).

:func:`issue_study` computes Chapter 8's cases in one call (cached by the chapter).
Units: SI (m, rad, s, N); errors are distances of C from the path (m).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pandas as pd

from ..allocation import Limits
from ..integrators.batch import RK4, fixed_steps, integrate
from ..integrators.smooth import SimulationError
from ..machinery import checks
from ..machinery.cache import cached
from ..machinery.kinds import lower_bound, upper_bound
from ..model import config_accel
from ..params import Body, Gains
from ..tracking.mismatch import PARAMETERS, model_of
from ..trajectories import make
from .bound import cap_bound, exact_peak_force
from .compare import OPTIMAL_PERIODS, OPTIMAL_STEPS, limits_study, paper_rows
from .loop import steady_measures
from .motion import periodic_motion
from .study import PAPER_CAP, setting_label
from .tracker import (DEFAULT_STARTS, RTOL, PeriodicLQR, _edges, _inside, _inside_bounds, _limits, _loop_inputs, _loop_reference,
                      _piecewise_ivp, _reference, periodic_lqr, track_motion)
from .verdict import NEWTON_TOL, ORBIT_SHIFT_TOL, MotionVerdict, _decide, _ladder, _orbit, floquet_text, motion_verdict

__all__ = ["MARGIN", "MARGIN_SETTINGS", "WRONG_DELTA", "PUSH", "SECOND_EIGHT", "plant_lqr", "pushed_verdict",
           "tracked_case", "margin_cases", "wrong_model_cases", "eight_comparison", "issue_study",
           "margin_table", "wrong_model_table", "eights_table"]

#: the margin, the plan's cap as a fraction of the cap in the loop
MARGIN = 0.9
#: the settings (angle limit in deg or None, cap in N) of the margin and the wrong model
MARGIN_SETTINGS = ((None, PAPER_CAP), (30, PAPER_CAP))
#: the plant's relative error in each parameter, high and low
WRONG_DELTA = 0.1
#: the disturbance, a constant world-frame push (N) along x
PUSH = (0.2, 0.0)
#: the second eight (R in m, Theta in rad/s), a point of Fig. 5's grid where the 4 N cap binds
SECOND_EIGHT = (1.5, 1.2)


def plant_lqr(lqr: PeriodicLQR, plant: Body) -> PeriodicLQR:
    """The periodic LQR ``lqr`` of the nominal model, carried onto a ``plant`` with other parameters.

    K(t) = R^-1 B(t)' P(t), and B (:func:`lib.optimal.tracker.jacobians`) depends on the body only
    through 1 / m (rows x'', y'') and a / I_C (row phi''): B_plant = S B_model with S diagonal.
    The result holds ``plant`` as its body and S^-1 P, S^-1 P' as its Riccati solution, so that
    every loop built on it (numpy or compiled) applies the model's gain K exactly, to rounding,
    while its rates are the plant's. Its ``multipliers`` stay those of the nominal loop.

    Parameters
    ----------
    lqr : PeriodicLQR
        The gain of the model (:func:`lib.optimal.tracker.periodic_lqr`).
    plant : Body
        The body that moves.

    Returns
    -------
    PeriodicLQR
        For :func:`lib.optimal.tracker.track_motion` and :func:`lib.optimal.verdict.motion_verdict`
        with ``body=plant`` and ``lqr=`` this.
    """
    checks.instance("lqr", lqr, PeriodicLQR, "lib.optimal.tracker.PeriodicLQR")
    checks.instance("plant", plant, Body)
    model = lqr.body
    ratio = (plant.a / plant.I) / (model.a / model.I)
    s = np.array([1.0, 1.0, 1.0, model.m / plant.m, model.m / plant.m, ratio])
    return replace(lqr, body=plant, P=lqr.P / s[:, None], dP=lqr.dP / s[:, None])


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
    """The pushed loop's period map (as :func:`lib.optimal.verdict._period_map` with ``steps``
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
                   starts=None, periods: int = OPTIMAL_PERIODS, steps: int = OPTIMAL_STEPS,
                   h: float = 1e-5) -> MotionVerdict:
    """:func:`lib.optimal.verdict.motion_verdict` of the loop with a constant world-frame force
    ``push`` = (Fx, Fy) (N) on ``body``: Newton on two RK4 maps (``steps`` and twice as many steps
    an input piece, doubled while the orbit moves by more than
    :data:`lib.optimal.verdict.ORBIT_SHIFT_TOL`), the multipliers, and the starts' reach test, by
    the same decision. Integrated in numpy (no compiled kernel takes a push): about a second of
    CPU a verdict at the chapter's steps.

    Parameters
    ----------
    body, motion, limits, lqr
        As in :func:`lib.optimal.verdict.motion_verdict` (``lqr`` may be a :func:`plant_lqr`).
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


def _orbit_measures(plant: Body, motion, limits: Limits, lqr: PeriodicLQR, x, push) -> dict:
    """The errors and inputs over one period of the loop from its orbit point x (6,) at t = 0,
    1024 equal samples (DOP853 at :data:`lib.optimal.tracker.RTOL`), by
    :func:`lib.optimal.loop.steady_measures`; NaN without an orbit."""
    T = float(motion.period)
    t = np.arange(1024) * (T / 1024)
    if not np.isfinite(x).all():
        return dict(max_error=math.nan, rms_error=math.nan, F_peak=math.nan, beta_peak=math.nan, p_range=math.nan)
    if push is None:
        res = track_motion(plant, motion, T, limits=limits, z0=x[:3], dz0=x[3:], lqr=lqr, t_eval=t)
        states, F, beta, path = np.c_[res.z, res.dz], res.F, res.beta, res.z_d
    else:
        F_max, beta_max = _limits(limits, motion)
        states = _piecewise_ivp(_pushed_loop(lqr, F_max, beta_max, 1, push, {}), x, _edges(motion, 0.0, T), t,
                                RTOL, "the pushed loop")[0]
        F, beta = _loop_inputs(lqr, t, states, F_max, beta_max)
        path = make(motion.kind, motion.R, motion.Theta).z(t)
    return steady_measures(t, states, F, beta, path, F_cap=limits.force, beta_max=limits.angle)


def tracked_case(model: Body, motion, limits: Limits, *, plant: Body | None = None, push=None,
                 lqr: PeriodicLQR | None = None) -> dict:
    """The tracker of ``motion``, planned and gained on ``model``, run on ``plant`` (default the
    model) with an optional constant world-frame ``push`` (N), decided by the book's procedure
    (:func:`lib.optimal.verdict.motion_verdict` on :func:`plant_lqr`, or :func:`pushed_verdict`)
    at the chapter's steps and periods (:data:`lib.optimal.compare.OPTIMAL_STEPS`,
    :data:`lib.optimal.compare.OPTIMAL_PERIODS`) and measured over one period of its orbit.

    Parameters
    ----------
    model : Body
        The body the motion and the gain were computed for.
    motion : PeriodicMotion
        The motion (of ``model``).
    limits : Limits
        The limits enforced in the loop.
    plant : Body, optional
        The body that moves.
    push : array_like, optional
        (Fx, Fy) (N), world frame.
    lqr : PeriodicLQR, optional
        The model's periodic LQR of ``motion`` (computed if not given).

    Returns
    -------
    dict
        regime, reason, floquet (|mu_1|) and floquet_error (its stated error), starts_reached, starts,
        paper_start_reached (on both maps), settled (starts with one fate on both maps), and max_error, rms_error (m),
        F_peak (N), beta_peak (rad), p_range (rad) over one period of the orbit (NaN without one).
    """
    checks.instance("model", model, Body)
    checks.instance("limits", limits, Limits, "lib.allocation.Limits")
    plant = model if plant is None else checks.instance("plant", plant, Body)
    lqr = lqr or periodic_lqr(model, motion)
    if lqr.body != model or lqr.motion is not motion:
        raise ValueError("lqr must be the periodic_lqr of model and motion")
    plq = lqr if plant == model else plant_lqr(lqr, plant)
    if push is None:
        v = motion_verdict(plant, motion, limits=limits, lqr=plq, steps=OPTIMAL_STEPS, periods=OPTIMAL_PERIODS)
    else:
        push = tuple(float(p) for p in checks.array("push", push, shape=(2,)))
        v = pushed_verdict(plant, motion, push, limits=limits, lqr=plq)
    meas = _orbit_measures(plant, motion, limits, plq, v.x, push)
    return dict(regime=v.regime, reason=v.reason, floquet=float(np.abs(v.multipliers).max()),
                floquet_error=float(v.multiplier_error), starts_reached=int(v.reached.sum()), starts=int(v.reached.size),
                paper_start_reached=bool(v.reached[0]), settled=int(v.settled.sum()), **meas)


def _limits_of(setting) -> Limits:
    angle, cap = setting
    return Limits(cap, None if angle is None else math.radians(angle))


def margin_cases(body: Body, motions: dict, *, fraction: float = MARGIN) -> dict:
    """Each best motion of ``motions`` planned again under ``fraction`` of its cap, and both
    tracked with the full limits in the loop.

    The margined motion (:func:`lib.optimal.motion.periodic_motion` on the same mesh, its cap
    ``fraction`` times the setting's, the angle limit kept) starts from the unmargined one and
    from the ``"force"`` start; each is tracked by its periodic LQR under the setting's limits
    (:func:`tracked_case`).

    Parameters
    ----------
    body : Body
        The body.
    motions : dict
        (angle limit in deg or None, cap in N) -> PeriodicMotion, the unmargined best found.
    fraction : float
        The plan's cap over the loop's, in (0, 1].

    Returns
    -------
    dict
        ``plans``: (setting, margin) -> (PeriodicMotion, PeriodicLQR); ``table``: one row a
        (setting, margin) with setting, margin, plan_cap (N), plan_rms, plan_max (the plan's
        errors, m) and the columns of :func:`tracked_case`.
    """
    checks.instance("body", body, Body)
    fraction = checks.number("fraction", fraction, positive=True, maximum=1.0)
    plans, rows = {}, []
    for (angle, cap), m in motions.items():
        if cap is None:
            raise ValueError(f"motions must have a cap at every setting; {setting_label(angle, cap)} has none")
        beta = None if angle is None else math.radians(angle)
        mm = periodic_motion(body, m.R, m.Theta, kind=m.kind, F_max=fraction * cap, beta_max=beta, nodes=m.nodes,
                             starts=("force",), guess={"unmargined": m})
        for margin, plan in ((False, m), (True, mm)):
            lqr = periodic_lqr(body, plan)
            plans[(angle, cap), margin] = plan, lqr
            rows.append(dict(setting=setting_label(angle, cap), margin=margin, plan_cap=plan.F_max,
                             plan_rms=plan.rms_error, plan_max=plan.max_error,
                             **tracked_case(body, plan, _limits_of((angle, cap)), lqr=lqr)))
    return dict(plans=plans, table=pd.DataFrame(rows))


def wrong_model_cases(body: Body, plans: dict, *, delta: float = WRONG_DELTA, push=PUSH,
                      push_at=MARGIN_SETTINGS[:1], parameters=PARAMETERS) -> pd.DataFrame:
    """Each plan's tracker on a plant with one parameter off by +-``delta``, and under ``push``.

    Parameters
    ----------
    body : Body
        The model (the plans' body).
    plans : dict
        (setting, margin) -> (PeriodicMotion, PeriodicLQR) (:func:`margin_cases`).
    delta : float
        The plant's relative error, in (0, 1).
    push : array_like or None
        (Fx, Fy) (N), world frame, on the nominal plant; None for no push case.
    push_at : sequence of tuple
        The settings at which the push is run (a numpy loop: about a second of CPU a case).
    parameters : sequence of str
        Of :data:`lib.tracking.mismatch.PARAMETERS`.

    Returns
    -------
    pandas.DataFrame
        One row a (setting, margin, case): setting, margin, parameter ("push" for the push),
        delta (relative, 0 for the push), and the columns of :func:`tracked_case`.
    """
    checks.instance("body", body, Body)
    delta = checks.number("delta", delta, positive=True, maximum=0.99)
    for p in parameters:
        checks.one_of("parameters", p, PARAMETERS)
    rows = []
    for ((angle, cap), margin), (motion, lqr) in plans.items():
        base = dict(setting=setting_label(angle, cap), margin=margin)
        limits = _limits_of((angle, cap))
        for p in parameters:
            for d in (delta, -delta):
                rows.append(dict(base, parameter=p, delta=d, **tracked_case(
                    body, motion, limits, plant=model_of(body, **{p: d}), lqr=lqr)))
        if push is not None and (angle, cap) in push_at:
            rows.append(dict(base, parameter="push", delta=0.0,
                             **tracked_case(body, motion, limits, push=push, lqr=lqr)))
    return pd.DataFrame(rows)


def eight_comparison(body: Body, gains: Gains, R: float, Theta: float, *, cap: float = PAPER_CAP,
                     nodes: int = 80) -> dict:
    """Chapter 8's headline comparison on the eight (R, Theta) under the cap alone: the
    certified bound (:func:`lib.optimal.bound.cap_bound`, 256 nodes), the paper's law
    (:func:`lib.optimal.compare.paper_rows`, Chapter 4's procedure from the paper's start, as
    the side-by-side table's row), and the best motion found
    (:func:`lib.optimal.motion.periodic_motion` from every start, the convex one included, at
    ``nodes`` intervals) with its tracker (:func:`tracked_case`). Refuses an eight whose exact
    tracking needs no more than ``cap`` (the cap does not bind).

    Parameters
    ----------
    body, gains : Body, Gains
        The body and the gains of (23).
    R, Theta : float
        The eight (m, rad/s).
    cap : float
        The force cap (N).
    nodes : int
        The collocation's intervals.

    Returns
    -------
    dict
        R, Theta, need (N, the exact-tracking peak), bound (CapBound), paper (the paper's row),
        motion (PeriodicMotion), tracked (:func:`tracked_case`'s row).
    """
    checks.instance("body", body, Body)
    checks.instance("gains", gains, Gains)
    cap = checks.number("cap", cap, positive=True, unit="N")
    need = float(exact_peak_force(body, R, Theta))
    if not need > cap:
        raise ValueError(f"cap = {cap:g} N does not bind on the eight R = {R:g} m, Theta = {Theta:g} rad/s: "
                         f"exact tracking needs {need:.4g} N; choose a faster or larger eight")
    bound = cap_bound(body, R, Theta, cap)
    paper = paper_rows(body, gains, make("eight", R, Theta), ((None, cap),))[0]
    motion = periodic_motion(body, R, Theta, F_max=cap, nodes=nodes)
    return dict(R=float(R), Theta=float(Theta), need=need, bound=bound, paper=paper, motion=motion,
                tracked=tracked_case(body, motion, Limits(cap, None)))


def issue_study(body: Body, gains: Gains, R: float, Theta: float, *, fraction: float = MARGIN) -> dict:
    """Chapter 8's margin, wrong-model and second-eight cases in one call (the chapter caches
    it; the unmargined motions are those of :func:`lib.optimal.compare.limits_study`, read
    through the cache): at each of :data:`MARGIN_SETTINGS` the best motion found at 80
    intervals (the cap alone's first mesh, :func:`lib.optimal.study.cap_alone_chain`) and its
    margined plan (:func:`margin_cases`), each tracked on the wrong plants and under
    :data:`PUSH` (:func:`wrong_model_cases`), and the comparison on :data:`SECOND_EIGHT`
    (:func:`eight_comparison`).

    Parameters
    ----------
    body, gains : Body, Gains
        The body and the gains of (23).
    R, Theta : float
        The chapter's eight (m, rad/s).
    fraction : float
        The margin (:data:`MARGIN`).

    Returns
    -------
    dict
        ``margin`` (:func:`margin_cases`' table), ``wrong`` (:func:`wrong_model_cases`),
        ``second`` (:func:`eight_comparison`).
    """
    checks.instance("body", body, Body)
    checks.instance("gains", gains, Gains)
    lim = cached(limits_study, body, gains, R, Theta)
    motions = {s: (lim["cap_chain"][0] if s[0] is None else lim["motions"][s]) for s in MARGIN_SETTINGS}
    margin = margin_cases(body, motions, fraction=fraction)
    return dict(margin=margin["table"], wrong=wrong_model_cases(body, margin["plans"]),
                second=eight_comparison(body, gains, *SECOND_EIGHT))


#: how the page names the plant's parameters and the push
_PARAMETER_NAMES = {"m": "$m$", "I": "$I_C$", "c": "$c$", "c_phi": r"$c_\varphi$", "a": "$a$", "push": "push"}


def _tracked_cells(frame: pd.DataFrame) -> dict:
    """The tracker's columns as the page writes them: regime, |mu_1| (verdict.floquet_text), starts reached,
    largest and RMS distance (m, rounded up: values of a motion that exists)."""
    return {"regime": list(frame.regime),
            "largest $|\\mu_1|$": [floquet_text(v, e) for v, e in zip(frame.floquet, frame.floquet_error)],
            "starts reached": [f"{int(r)} of {int(n)}" for r, n in zip(frame.starts_reached, frame.starts)],
            "largest (m)": [upper_bound(v, ".3f").text() if np.isfinite(v) else "-" for v in frame.max_error],
            "RMS (m)": [upper_bound(v, ".4f").text() if np.isfinite(v) else "-" for v in frame.rms_error]}


def margin_table(table: pd.DataFrame) -> pd.DataFrame:
    """:func:`margin_cases`' table as the page shows it: setting, the plan's cap (N), then the
    tracker's regime, |mu_1|, starts reached and errors under the full limits.

    Parameters
    ----------
    table : pandas.DataFrame
        :func:`margin_cases`' ``table``.

    Returns
    -------
    pandas.DataFrame
        One row a (setting, margin), the cells formatted.
    """
    return pd.DataFrame({"setting": list(table.setting), "plan's cap (N)": [f"{c:g}" for c in table.plan_cap],
                         **_tracked_cells(table)})


def wrong_model_table(frame: pd.DataFrame, setting: str, margin: bool) -> pd.DataFrame:
    """:func:`wrong_model_cases`' rows at one setting and margin as the page shows them:
    the plant's parameter, its change, and the tracker's cells.

    Parameters
    ----------
    frame : pandas.DataFrame
        :func:`wrong_model_cases`' frame.
    setting : str
        The setting's label (:func:`lib.optimal.study.setting_label`).
    margin : bool
        With the margin or without.

    Returns
    -------
    pandas.DataFrame
        One row a case.
    """
    rows = frame[(frame.setting == setting) & (frame.margin == margin)]
    if rows.empty:
        raise ValueError(f"setting = {setting!r} with margin = {margin} has no rows")
    change = ["0.2 N along x" if p == "push" else f"{d:+.0%}".replace("%", " %")
              for p, d in zip(rows.parameter, rows.delta)]
    return pd.DataFrame({"plant's": [_PARAMETER_NAMES[p] for p in rows.parameter], "change": change,
                         **_tracked_cells(rows)})


def eights_table(rows: list) -> pd.DataFrame:
    """The headline comparison on each eight: the certified bound on the largest distance
    (rounded down), the paper's law's and the tracker of the best motion found's (rounded up),
    and the paper's law over the bound (rounded up: the bound is a lower bound).

    Parameters
    ----------
    rows : list of dict
        Each with name, R (m), Theta (rad/s), bound, paper, best (largest distances, m).

    Returns
    -------
    pandas.DataFrame
        One row an eight.
    """
    return pd.DataFrame({"eight": [r["name"] for r in rows],
                         "$R$ (m), $\\Theta$ (rad/s)": [f"{r['R']:g}, {r['Theta']:.3g}" for r in rows],
                         "bound (m)": [lower_bound(r["bound"], ".4f").text() for r in rows],
                         "paper's law (m)": [upper_bound(r["paper"], ".3f").text() for r in rows],
                         "best found + LQR (m)": [upper_bound(r["best"], ".4f").text() for r in rows],
                         "paper / bound": [upper_bound(r["paper"] / r["bound"], ".2f").text() for r in rows]})
