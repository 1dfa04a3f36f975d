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
  model represents; its loop is integrated in numpy (:func:`lib.optimal.pushed.pushed_verdict`,
  the same two RK4 maps and the same decision as :func:`lib.optimal.verdict.motion_verdict`).
* The *entry* planned on the model (:func:`lib.optimal.entry.entry_motion`), run open loop on a
  wrong or pushed plant or from a disturbed start (:func:`lib.optimal.studies.entries.entry_end`), then the tracker: whether the
  paper's start reaches the orbit (:func:`wrong_model_cases`), and the margin (:func:`entry_margin`).
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

from ...allocation import Limits
from ...machinery import checks
from ...machinery.cache import cached
from ...machinery.kinds import upper_bound
from ...params import Body, Gains
from ...tracking.mismatch import PARAMETERS, model_of
from ...trajectories import make
from ..bound import cap_bound, exact_peak_force
from ..entry import Entry, entry_motion
from .entries import entry_end
from .compare import OPTIMAL_PERIODS, OPTIMAL_STEPS, limits_study, paper_rows
from ..loop import steady_measures
from ..motion import periodic_motion
from .study import PAPER_CAP, setting_label
from ..tracker import DEFAULT_STARTS, RTOL, PeriodicLQR, _edges, _limits, _loop_inputs, _piecewise_ivp, periodic_lqr, track_motion
from ..floquet import floquet_text
from ..pushed import _pushed_loop, pushed_verdict
from ..verdict import motion_verdict

__all__ = ["MARGIN", "MARGIN_SETTINGS", "WRONG_DELTA", "PUSH", "SECOND_EIGHT", "ENTRY_FIRST",
           "ENTRY_DOUBLINGS", "ENTRY_HALVINGS", "plant_lqr", "tracked_case", "entry_margin",
           "margin_cases", "wrong_model_cases", "eight_comparison", "issue_study", "margin_table",
           "wrong_model_table", "entry_margin_table"]

#: the margin, the plan's cap as a fraction of the cap in the loop
MARGIN = 0.9
#: the settings (angle limit in deg or None, cap in N) of the margin and the wrong model
MARGIN_SETTINGS = ((None, PAPER_CAP), (30, PAPER_CAP))
#: the plant's relative error in each parameter, high and low
WRONG_DELTA = 0.1
#: the disturbance, a constant world-frame push (N) along x
PUSH = (0.2, 0.0)
#: the entry's disturbances (:func:`entry_margin`), each with its first level (heading in rad, x and y
#: in m, m relative), and the search's doublings and halvings
ENTRY_FIRST, ENTRY_DOUBLINGS, ENTRY_HALVINGS = {"heading": 0.05, "x": 0.05, "y": 0.05, "m": 0.025}, 4, 2
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
                 lqr: PeriodicLQR | None = None, entry_start=None) -> dict:
    """The tracker of ``motion``, planned and gained on ``model``, run on ``plant`` (default the
    model) with an optional constant world-frame ``push`` (N), decided by the book's procedure
    (:func:`lib.optimal.verdict.motion_verdict` on :func:`plant_lqr`, or
    :func:`lib.optimal.pushed.pushed_verdict`) at the chapter's steps and periods
    (:data:`lib.optimal.studies.compare.OPTIMAL_STEPS`, :data:`lib.optimal.studies.compare.OPTIMAL_PERIODS`) and
    measured over one period of its orbit.

    Parameters
    ----------
    model, motion, limits : Body, PeriodicMotion, Limits
        The body the motion (of ``model``) and the gain were computed for; the loop's limits.
    plant : Body, optional
        The body that moves.
    push : array_like, optional
        (Fx, Fy) (N), world frame.
    lqr : PeriodicLQR, optional
        The model's periodic LQR of ``motion`` (computed if not given).
    entry_start : array_like, shape (6,), optional
        An eighth start, decided beside the seven (where an entry brought the plant, :func:`entry_end`).

    Returns
    -------
    dict
        regime, reason, floquet (|mu_1|) and floquet_error (its stated error), starts_reached, starts,
        paper_start_reached (on both maps), settled (of the seven starts, those with one fate on both
        maps), and max_error, rms_error (m), F_peak (N), beta_peak (rad), p_range (rad) over one period
        of the orbit (NaN without one); with ``entry_start``, entry_reached and entry_settled, its fate.
    """
    checks.instance("model", model, Body)
    checks.instance("limits", limits, Limits, "lib.allocation.Limits")
    plant = model if plant is None else checks.instance("plant", plant, Body)
    lqr = lqr or periodic_lqr(model, motion)
    if lqr.body != model or lqr.motion is not motion:
        raise ValueError("lqr must be the periodic_lqr of model and motion")
    plq = lqr if plant == model else plant_lqr(lqr, plant)
    n, starts = len(DEFAULT_STARTS), DEFAULT_STARTS
    if entry_start is not None:
        starts = np.vstack([starts, checks.array("entry_start", entry_start, shape=(6,))])
    run = dict(limits=limits, lqr=plq, starts=starts, steps=OPTIMAL_STEPS, periods=OPTIMAL_PERIODS)
    if push is None:
        v = motion_verdict(plant, motion, **run)
    else:
        push = tuple(float(p) for p in checks.array("push", push, shape=(2,)))
        v = pushed_verdict(plant, motion, push, **run)
    meas = _orbit_measures(plant, motion, limits, plq, v.x, push)
    extra = {} if entry_start is None else dict(entry_reached=bool(v.reached[n]), entry_settled=bool(v.settled[n]))
    return dict(regime=v.regime, reason=v.reason, floquet=float(np.abs(v.multipliers).max()),
                floquet_error=float(v.multiplier_error),
                starts_reached=int(v.reached[:n].sum()), starts=n, paper_start_reached=bool(v.reached[0]),
                settled=int(v.settled[:n].sum()), **extra, **meas)


def entry_margin(body: Body, motion, limits: Limits, *, first=ENTRY_FIRST, doublings: int = ENTRY_DOUBLINGS,
                 halvings: int = ENTRY_HALVINGS) -> pd.DataFrame:
    """How far the paper's start may be disturbed while the entry planned from it on ``body``
    (:func:`lib.optimal.entry.entry_motion`), run open loop (:func:`lib.optimal.studies.entries.entry_end`), and then the
    periodic LQR still reach the orbit, as :func:`lib.optimal.verdict.motion_verdict` decides
    (both maps, the chapter's steps and periods). Each quantity of ``first`` (quantity -> first
    level: "heading" (rad), "x", "y" (m), the start moved; "m" (relative), the plant
    :func:`lib.tracking.mismatch.model_of`) is moved either way: the level doubles from the first
    while the orbit is reached (at most ``doublings`` times), then the bracket between the last
    level reached (0 if none) and the first that failed (an undecided verdict fails) is halved
    ``halvings`` times. A measured margin, not a bound: levels between those tried are not tried.

    Returns
    -------
    pandas.DataFrame
        One row a direction: quantity, sign (+1, -1), reached (the largest level reached, every level
        tried below it reached too), failed (the next level tried, not reached; NaN if none), tried.
    """
    checks.instance("body", body, Body)
    checks.instance("limits", limits, Limits, "lib.allocation.Limits")
    dirs = [(checks.one_of("first", q, ("heading", "x", "y", "m")), sgn, checks.number(f"first[{q!r}]", v, positive=True))
            for q, v in first.items() for sgn in (1, -1)]
    doublings, halvings = checks.integer("doublings", doublings, minimum=0), checks.integer("halvings", halvings, minimum=0)
    lqr, plan = periodic_lqr(body, motion), entry_motion(body, motion)
    level = np.array([d[2] for d in dirs])
    lo, hi, tried = np.zeros(len(dirs)), np.full(len(dirs), np.nan), np.zeros(len(dirs), int)
    for k in range(doublings + 1 + halvings):
        todo = np.flatnonzero(np.isnan(hi) if k <= doublings else np.isfinite(hi))
        if k > doublings:
            level[todo] = (lo[todo] + hi[todo]) / 2
        ok = _entry_reaches(body, motion, limits, lqr, plan, [(*dirs[i][:2], level[i]) for i in todo])
        tried[todo] += 1
        lo[todo[ok]], hi[todo[~ok]] = level[todo[ok]], level[todo[~ok]]
        level[todo[ok]] *= 2 if k < doublings else 1
    return pd.DataFrame(dict(quantity=[d[0] for d in dirs], sign=[d[1] for d in dirs], reached=lo, failed=hi, tried=tried))


def _entry_reaches(body: Body, motion, limits: Limits, lqr: PeriodicLQR, plan: Entry, cases) -> np.ndarray:
    """Whether each case (quantity, sign, level) reaches the orbit after the entry: the moved
    starts in one verdict, each plant of another mass in its own."""
    run, out = dict(limits=limits, steps=OPTIMAL_STEPS, periods=OPTIMAL_PERIODS), np.zeros(len(cases), bool)
    moved = [j for j, c in enumerate(cases) if c[0] != "m"]
    if moved:
        starts = np.tile(DEFAULT_STARTS[0], (len(moved), 1))
        for r, j in enumerate(moved):
            starts[r, ("x", "y", "heading").index(cases[j][0])] += cases[j][1] * cases[j][2]
        out[moved] = motion_verdict(body, motion, lqr=lqr, starts=entry_end(body, motion, plan, starts), **run).reached
    for j, (q, sgn, level) in enumerate(cases):
        if q == "m":
            plant = model_of(body, m=sgn * level)
            out[j] = motion_verdict(plant, motion, lqr=plant_lqr(lqr, plant), starts=entry_end(plant, motion, plan)[None],
                                    **run).reached[0]
    return out


def _limits_of(setting) -> Limits:
    return Limits(setting[1], None if setting[0] is None else math.radians(setting[0]))


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
                      push_at=MARGIN_SETTINGS[:1], parameters=PARAMETERS, entry: bool = True) -> pd.DataFrame:
    """Each plan's tracker on a plant with one parameter off by +-``delta``, and under ``push``;
    with ``entry``, the paper's start brought by the plan's entry (planned on the model,
    :func:`lib.optimal.entry.entry_motion`) run open loop on the plant (:func:`lib.optimal.studies.entries.entry_end`),
    and decided in the same verdict as an eighth start.

    Parameters
    ----------
    body, plans : Body, dict
        The model (the plans' body); (setting, margin) -> (PeriodicMotion, PeriodicLQR) (:func:`margin_cases`).
    delta, parameters : float, sequence of str
        The plant's relative error, in (0, 1), in each of ``parameters`` (of
        :data:`lib.tracking.mismatch.PARAMETERS`).
    push, push_at : array_like or None, sequence of tuple
        (Fx, Fy) (N), world frame, on the nominal plant (None for no push case), at the settings
        ``push_at`` (a numpy loop: about a second of CPU a case).
    entry : bool
        Decide the paper's start after the entry too (an IPOPT solve a plan, 0.05 s of CPU a plant).

    Returns
    -------
    pandas.DataFrame
        One row a (setting, margin, case): setting, margin, parameter ("push" for the push),
        delta (relative, 0 for the push), and the columns of :func:`tracked_case` (entry_reached
        and entry_settled with ``entry``).
    """
    checks.instance("body", body, Body)
    delta = checks.number("delta", delta, positive=True, maximum=0.99)
    for p in parameters:
        checks.one_of("parameters", p, PARAMETERS)
    rows = []
    for ((angle, cap), margin), (motion, lqr) in plans.items():
        base = dict(setting=setting_label(angle, cap), margin=margin)
        limits, plan = _limits_of((angle, cap)), entry_motion(body, motion) if entry else None
        for p in parameters:
            for d in (delta, -delta):
                plant = model_of(body, **{p: d})
                rows.append(dict(base, parameter=p, delta=d, **tracked_case(
                    body, motion, limits, plant=plant, lqr=lqr,
                    entry_start=None if plan is None else entry_end(plant, motion, plan))))
        if push is not None and (angle, cap) in push_at:
            end = None if plan is None else entry_end(body, motion, plan, push=push)
            rows.append(dict(base, parameter="push", delta=0.0,
                             **tracked_case(body, motion, limits, push=push, lqr=lqr, entry_start=end)))
    return pd.DataFrame(rows)


def eight_comparison(body: Body, gains: Gains, R: float, Theta: float, *, cap: float = PAPER_CAP,
                     nodes: int = 80) -> dict:
    """Chapter 8's headline comparison on the eight (R, Theta) under the cap alone: the
    certified bound (:func:`lib.optimal.bound.cap_bound`, 256 nodes), the paper's law
    (:func:`lib.optimal.studies.compare.paper_rows`, Chapter 4's procedure from the paper's start, as
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
    it; the unmargined motions are those of :func:`lib.optimal.studies.compare.limits_study`, read
    through the cache): at each of :data:`MARGIN_SETTINGS` the best motion found at 80
    intervals (the cap alone's first mesh, :func:`lib.optimal.studies.study.cap_alone_chain`) and its
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
    """:func:`wrong_model_cases`' rows (a frame) at one ``setting`` (its label,
    :func:`lib.optimal.studies.study.setting_label`) and ``margin`` (bool) as the page shows them, one row
    a case: the plant's parameter, its change, the tracker's cells and, where the frame has them,
    whether the paper's start reaches the orbit after the entry ("yes", "no", or "undecided"
    where the verdict's two maps disagree).

    Returns
    -------
    pandas.DataFrame
        The cells, formatted.
    """
    rows = frame[(frame.setting == setting) & (frame.margin == margin)]
    if rows.empty:
        raise ValueError(f"setting = {setting!r} with margin = {margin} has no rows")
    change = ["0.2 N along x" if p == "push" else f"{d:+.0%}".replace("%", " %")
              for p, d in zip(rows.parameter, rows.delta)]
    entry = {} if "entry_reached" not in rows else {"after the entry": [
        "yes" if r else ("no" if s else "undecided") for r, s in zip(rows.entry_reached, rows.entry_settled)]}
    return pd.DataFrame({"plant's": [_PARAMETER_NAMES[p] for p in rows.parameter], "change": change,
                         **_tracked_cells(rows), **entry})


def entry_margin_table(margin: pd.DataFrame) -> pd.DataFrame:
    """:func:`entry_margin`'s frame as the page shows it.

    Returns
    -------
    pandas.DataFrame
        One row a direction: the disturbance, the largest level at which the entry and the LQR
        reach the orbit, and the next level tried, which fails ("none failed" when every level
        tried reaches); exact levels, the mass in per cent.
    """
    unit = {"heading": ("heading", "rad", 1), "x": ("x", "m", 1), "y": ("y", "m", 1), "m": ("m", "%", 100)}
    name = [f"{unit[q][0]} {'+' if s > 0 else '-'} ({unit[q][1]})" for q, s in zip(margin.quantity, margin.sign)]
    at = lambda col: [f"{v * unit[q][2]:.4g}" if np.isfinite(v) else "none failed"   # noqa: E731
                      for q, v in zip(margin.quantity, margin[col])]
    return pd.DataFrame({"disturbance": name, "reaches at": at("reached"), "fails at": at("failed")})
