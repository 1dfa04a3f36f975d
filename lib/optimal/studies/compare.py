"""Every law of the book under the paper's limits, beside the best motion and the bound
(Chapter 8's side-by-side table).

At each limit setting (:data:`lib.optimal.studies.study.SETTINGS`) four controllers run from the paper's
start on the eight: the paper's law (23), (25)-(26); the weighted law of Chapter 6 (the exact
limited allocation, weights (1, 1, 1)); the law for P of Chapter 7 with its anti-windup; and the
periodic LQR about the best periodic motion found (:mod:`lib.optimal.tracker`). The paper's law
is decided by Chapter 4's procedure (which also decides chaos), the next two by the book's orbit
procedure on two RK4 maps, h and h / 2 (:func:`lib.optimal.loop.halved_verdict`), the last by
:func:`lib.optimal.verdict.motion_verdict`. Each is measured over one period of its orbit,
or, without one, over the last ``measure_periods`` periods of its run (a horizon's statistics).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np
import pandas as pd

from ...allocation import Allocation, Limits, allocate
from ...closed_loop import ClosedLoop, _weighted_args, limited_weighted_field, reference_of
from ...control import computed_torque
from ...dynamics.statistics import block_statistics
from ...limits.runs import switched_runs
from ...limits.verdicts import limit_verdicts
from ...machinery import checks
from ...machinery.kinds import estimate, exact, lower_bound, upper_bound
from ...params import PAPER_DZ0, PAPER_Z0, Body, Gains
from ...percussion.full_loop import _limited_args, limited_field
from ...percussion.law import ANTI_WINDUP_TIME, closed_loop_rates, error_polynomial
from ...trajectories import POSITIONS, heading_turns, make
from ..bound import cap_bound
from ..loop import FlowMap, halved_verdict, rows_period_end, run_periods, steady_measures
from .study import PAPER_CAP, SETTINGS, cap_alone_chain, limit_motions, setting_label
from ..tracker import periodic_lqr, track_motion
from ..floquet import floquet_text
from ..verdict import basin, motion_verdict

__all__ = ["LAWS", "LawLoop", "law_loop", "law_row", "paper_rows", "side_by_side", "WEIGHTS", "THRUST0",
           "LAW_OPTIONS", "LAW_STEPS", "LAW_MAX_STEPS", "PAPER_HORIZON", "PAPER_MEASURED", "RMS_BLOCK",
           "limits_study", "LAW_NAMES", "error_table", "regime_table", "tracker_table", "eights_table"]

#: periods the paper's law runs from the paper's start where it reaches no orbit (:func:`paper_rows`)
PAPER_HORIZON = 120
#: the last periods of that run measured
PAPER_MEASURED = 100
#: the shortest block (periods) of the batch means behind the standard error of that run's RMS
#: distance; :func:`lib.dynamics.statistics.block_statistics` lengthens it to six integrated
#: autocorrelation times of the series where its memory asks
RMS_BLOCK = 2

#: the laws of the table, in its order
LAWS = ("paper", "weighted", "percussion", "optimal")
#: Chapter 6's weights (w_x, w_y, w_phi) for the weighted law under limits
WEIGHTS = (1.0, 1.0, 1.0)
#: the law for P's thrust state at the start (N), as Chapter 7 starts it
THRUST0 = 0.5


@dataclass(frozen=True)
class LawLoop:
    """One law's closed loop: ``rates(t, s)`` and ``inputs(t, s) -> (F, beta)`` vectorised over
    rows of states (d = 6, or 7 with the law for P's thrust state), its start ``s0`` (d,), and
    optionally ``period_end``, the fixed RK4 steps of ``rates`` compiled (:class:`lib.optimal.loop.FlowMap`)."""

    rates: Callable
    inputs: Callable
    s0: np.ndarray
    period_end: Callable | None = None


def law_loop(body: Body, gains: Gains, ref, law: str, limits: Limits) -> LawLoop:
    """The closed loop of ``law`` ("paper", "weighted" or "percussion") under ``limits``,
    started from the paper's start (with the thrust state :data:`THRUST0` for the law for P).

    Parameters
    ----------
    body, gains : Body, Gains
        The body and the gains of (23).
    ref : Reference
        The path (:func:`lib.trajectories.make`).
    law : str
        One of the first three of :data:`LAWS`.
    limits : Limits
        Force and angle limits.

    Returns
    -------
    LawLoop
    """
    checks.one_of("law", law, LAWS[:3])
    s0 = np.concatenate([PAPER_Z0, PAPER_DZ0])
    if law in ("paper", "weighted"):
        alloc = Allocation() if law == "paper" else Allocation("limited", WEIGHTS)
        loop = ClosedLoop.of(body, gains, reference_of(ref), alloc, limits)

        def inputs(t, s):
            return loop.inputs(t, s[..., :3], s[..., 3:])[1:]
        # the weighted law's fixed-step loops call the rates at one time on a few rows: its compiled
        # field, the same to rounding; the inputs, read once over a recorded run, from the loop
        if law == "paper":
            return LawLoop(lambda t, s: loop.rates(t, s)[0], inputs, s0)
        return LawLoop(limited_weighted_field(body, gains, ref, limits, WEIGHTS), inputs, s0,
                       rows_period_end("weighted", _weighted_args(body, gains, ref, limits, WEIGHTS)))
    coeffs = error_polynomial(body, gains)
    position = POSITIONS[ref._kind]

    def kin(t):
        k = np.stack(np.broadcast_arrays(*position(ref.R, ref.theta, np.asarray(t, dtype=float))), -1)
        return tuple(k[..., 2 * j:2 * j + 2] for j in range(4))

    def both(t, s):
        return closed_loop_rates(body, coeffs, kin(t), s, limits, ANTI_WINDUP_TIME)
    # the fixed-step loops call the rates at one time on a few rows: the compiled field, the same to
    # rounding; the inputs, read once over a recorded run, from lib.percussion.law
    return LawLoop(limited_field(body, gains, ref, limits, ANTI_WINDUP_TIME), lambda t, s: both(t, s)[1:],
                   np.r_[s0, THRUST0],
                   rows_period_end("percussion", _limited_args(body, gains, ref, limits, ANTI_WINDUP_TIME)))


def _measure(flow: FlowMap, loop: LawLoop, x, n_periods: int, ref, limits: Limits) -> dict:
    """steady_measures over ``n_periods`` periods from the state x at t = 0."""
    _, t, st = run_periods(flow, x, n_periods, samples=512, record=n_periods)
    F, beta = loop.inputs(t, st)
    return steady_measures(t, st[:, :6], np.broadcast_to(F, t.shape), np.broadcast_to(beta, t.shape), ref.z(t),
                           F_cap=limits.force, beta_max=limits.angle)


#: the verdict's options for the weighted law and the law for P (16 periods of transient, 8 searched
#: for an orbit), decided on two maps of classical RK4 (:func:`lib.optimal.loop.halved_verdict`)
LAW_OPTIONS = dict(transient=16, history=8)
#: fixed RK4 steps a period of each law's coarser map, h; the finer takes h / 2, both doubled while they disagree
LAW_STEPS = {"weighted": 128, "percussion": 256}
#: the most fixed RK4 steps a period of each law's finer map
LAW_MAX_STEPS = {"weighted": 1024, "percussion": 8192}


def law_row(body: Body, gains: Gains, ref, law: str, limits: Limits, *, measure_periods: int = 4) -> dict:
    """The weighted law's or the law for P's verdict and measures under ``limits``: the orbit
    procedure (:data:`LAW_OPTIONS`) from the paper's start on two RK4 maps, step h and h / 2, that
    must agree (:func:`lib.optimal.loop.halved_verdict`, :data:`LAW_STEPS`, :data:`LAW_MAX_STEPS`),
    then on the finer map one period of the orbit, or, without one, ``measure_periods`` periods
    from the last state.

    Parameters
    ----------
    body, gains : Body, Gains
        The body and the gains of (23).
    ref : Reference
        The path.
    law : str
        ``"weighted"`` or ``"percussion"``.
    limits : Limits
        Force and angle limits.
    measure_periods : int
        Periods measured without an orbit.

    Returns
    -------
    dict
        regime, reason, floquet, steps_a_period (the coarser map's RK4 steps), orbit_shift (state units)
        and the measures of :func:`lib.optimal.loop.steady_measures`.
    """
    checks.one_of("law", law, LAWS[1:3])
    loop = law_loop(body, gains, ref, law, limits)
    v = halved_verdict(loop.rates, ref.period, loop.s0, reference_turns=heading_turns(ref), steps=LAW_STEPS[law],
                       max_steps=LAW_MAX_STEPS[law], period_end=loop.period_end, **LAW_OPTIONS)
    how = dict(regime=v.regime, reason=v.reason, floquet=v.floquet, steps_a_period=v.steps,
               orbit_shift=v.orbit_shift)
    if not len(v.section):
        return dict(how, floquet=np.nan, max_error=np.inf, rms_error=np.inf, F_peak=np.nan, beta_peak=np.nan,
                    p_range=np.nan)
    flow = FlowMap(loop.rates, ref.period, steps=2 * v.steps, period_end=loop.period_end)
    found = v.regime != "undecided"
    meas = _measure(flow, loop, v.orbit if found else v.section[-1], v.period if found else measure_periods,
                    ref, limits)
    return dict(how, **meas)


def paper_rows(body: Body, gains: Gains, ref, settings=SETTINGS, *, horizon: int = PAPER_HORIZON,
               measured: int = PAPER_MEASURED) -> list:
    """The paper's law at each setting, decided by Chapter 4's procedure
    (:func:`lib.limits.verdicts.limit_verdicts`, the compiled switched loop, which also decides
    chaos) and measured on the same integrator (:func:`lib.limits.runs.switched_runs`, 200 samples
    a period): over one period of its orbit, or, without one, over the last ``measured`` of
    ``horizon`` periods from the paper's start. Without an orbit the RMS distance also gets
    its standard error (``rms_stderr``, m; NaN with an orbit): the batch means of the
    per-period mean squares in blocks of :data:`RMS_BLOCK` periods
    (:func:`lib.dynamics.statistics.block_statistics`), carried to the RMS by its derivative.

    Parameters
    ----------
    body, gains : Body, Gains
        The body and the gains of (23).
    ref : Reference
        The circle or the eight.
    settings : sequence of tuple
        (angle limit in deg or None, cap in N or None).
    horizon, measured : int
        Periods run and measured without an orbit (``measured`` at least two blocks of
        :data:`RMS_BLOCK` periods, at most ``horizon``).

    Returns
    -------
    list of dict
        One per setting: regime, reason, floquet, the measures and ``rms_stderr``.
    """
    horizon = checks.integer("horizon", horizon, minimum=1)
    measured = checks.integer("measured", measured, minimum=2 * RMS_BLOCK)
    if measured > horizon:
        raise ValueError(f"measured must be at most horizon ({horizon} periods), got {measured}")
    angles = np.array([math.pi if a is None else math.radians(a) for a, _ in settings])
    caps = np.array([np.inf if c is None else c for _, c in settings])
    frame = limit_verdicts(body, gains, ref, angles, caps)[0]
    rows = []
    for j, r in frame.iterrows():
        has_orbit = r.orbit is not None
        s0 = np.asarray(r.orbit) if has_orbit else np.concatenate([PAPER_Z0, PAPER_DZ0])
        n, keep = (int(r.period), int(r.period)) if has_orbit else (horizon, measured)
        run = switched_runs(body, gains, ref, angles[j], caps[j], s0=s0, n_periods=n, samples_per_period=200)
        m = run.t >= run.t[-1] - keep * ref.period - 1e-9
        t, st = run.t[m][:-1], run.states[0, m][:-1]
        tau = computed_torque(body, gains, ref, t, st[:, :3], st[:, 3:])
        F, beta = allocate(tau, st[:, 2], force_limit=None if np.isinf(caps[j]) else caps[j],
                           angle_limit=angles[j])
        path = ref.z(t)
        meas = steady_measures(t, st, F, beta, path, F_cap=None if np.isinf(caps[j]) else caps[j],
                               beta_max=angles[j])
        se = np.nan
        if not has_orbit:  # equal samples a period, so the RMS is that of the per-period mean squares
            d2 = np.sum((st[:, :2] - path[:, :2]) ** 2, axis=1).reshape(keep, -1).mean(axis=1)
            ms, se_ms = block_statistics(d2[None, :], RMS_BLOCK)
            se = float(se_ms[0] / (2 * np.sqrt(ms[0])))
        rows.append(dict(regime=r.regime, reason=r.reason, floquet=r.floquet, rms_stderr=se, **meas))
    return rows


#: the optimal motion's controller decided on its period map by RK4 with this many fixed steps on
#: each input piece (two a collocation interval), from the tracker's seven starts over this many periods
#: RK4 steps an input piece the verdict starts from (doubled by motion_verdict until the orbit
#: holds when h is halved), and the periods a start is run
OPTIMAL_STEPS, OPTIMAL_PERIODS = 2, 8


def _optimal_row(body: Body, motion, limits: Limits, solved: dict) -> dict:
    """The optimal motion's row; its periodic LQR and verdict go into ``solved`` under ``limits``
    (the basin of :func:`limits_study` reads them instead of solving them again)."""
    lqr = periodic_lqr(body, motion)
    v = motion_verdict(body, motion, limits=limits, lqr=lqr, steps=OPTIMAL_STEPS, periods=OPTIMAL_PERIODS)
    solved[limits] = lqr, v
    T = motion.period
    x = v.x if np.isfinite(v.x).all() else np.concatenate(motion.state(0.0))
    res = track_motion(body, motion, T, limits=limits, z0=x[:3], dz0=x[3:], lqr=lqr,
                       t_eval=np.arange(1024) * (T / 1024))
    meas = steady_measures(res.t, np.c_[res.z, res.dz], res.F, res.beta, res.z_d, F_cap=limits.force,
                           beta_max=limits.angle)
    return dict(regime=v.regime, reason=v.reason, floquet=float(np.abs(v.multipliers).max()),
                floquet_error=float(v.multiplier_error), paper_start_reached=bool(v.reached[0]),
                starts_reached=int(v.reached.sum()),
                starts=int(v.reached.size), paper_start_settled=bool(v.settled[0]),
                starts_settled=int(v.settled.sum()), verdict_steps=int(v.steps), orbit_shift=float(v.orbit_shift),
                multiplier_spread=float(v.multiplier_spread), **meas)


def side_by_side(body: Body, gains: Gains, R: float, Theta: float, motions: dict, bounds: dict, *,
                 settings=SETTINGS, kind: str = "eight") -> pd.DataFrame:
    """The table: for each setting (angle limit in deg or None, cap in N or None) the rows of the
    paper's, the weighted and the percussion law (:func:`law_row`), of the optimal motion's
    controller, and of the bound where there is a cap.

    Parameters
    ----------
    body, gains : Body, Gains
        The body and the gains of (23).
    R, Theta : float
        The path (m, rad/s).
    motions : dict
        (angle deg or None, cap or None) -> PeriodicMotion (:func:`lib.optimal.studies.study.limit_motions`).
    bounds : dict
        cap (N) -> CapBound (:func:`lib.optimal.bound.cap_bound`) for the settings with a cap.
    settings : sequence of tuple
        The settings.
    kind : str
        The path.

    Returns
    -------
    pandas.DataFrame
        Columns setting, angle_deg, cap, law, regime, reason, floquet (floquet_error, its stated error,
        on the best motion's rows), max_error, rms_error (m),
        F_peak (N), beta_peak (rad), p_range (rad).
    """
    return _side_by_side(body, gains, R, Theta, motions, bounds, settings, kind, {})


def _side_by_side(body, gains, R, Theta, motions, bounds, settings, kind, solved: dict) -> pd.DataFrame:
    """:func:`side_by_side`, keeping each setting's (periodic LQR, verdict) of the optimal motion in
    ``solved`` (Limits -> tuple)."""
    checks.instance("body", body, Body)
    checks.instance("gains", gains, Gains)
    ref = make(kind, R, Theta)
    paper = paper_rows(body, gains, ref, settings)
    rows = []
    for i, (angle, cap) in enumerate(settings):
        limits = Limits(cap, None if angle is None else math.radians(angle))
        base = dict(setting=setting_label(angle, cap), angle_deg=angle, cap=cap)
        rows.append(dict(base, law="paper", **paper[i]))
        for law in LAWS[1:3]:
            rows.append(dict(base, law=law, **law_row(body, gains, ref, law, limits)))
        rows.append(dict(base, law="optimal", **_optimal_row(body, motions[(angle, cap)], limits, solved)))
        if cap is not None:
            b = bounds[cap]
            rows.append(dict(base, law="bound", regime="", reason="", max_error=b.max_error,
                             rms_error=b.rms_error))
    return pd.DataFrame(rows)


def limits_study(body: Body, gains: Gains, R: float, Theta: float, *, kind: str = "eight") -> dict:
    """Chapter 8's comparison in one call (cached by the chapter, read by the report): the best
    motions found at every setting (:func:`lib.optimal.studies.study.limit_motions`), the bound under the
    paper's cap (:func:`lib.optimal.bound.cap_bound`, 256 nodes) and the table
    (:func:`side_by_side`).

    Returns
    -------
    dict
        ``motions`` (setting -> PeriodicMotion), ``bound`` (CapBound at the paper's cap),
        ``table`` (pandas.DataFrame), ``basin_setting`` (the first setting whose controller the
        paper's start does not reach, or the first setting), ``basin`` (its
        :func:`lib.optimal.verdict.basin` frame), ``cap_chain`` (the cap alone's best found on
        each mesh, :func:`lib.optimal.studies.study.cap_alone_chain`) and ``bound_at_mesh`` (the bound at
        the collocation's default mesh, as many nodes as it has intervals).
    """
    chain = cap_alone_chain(body, R, Theta, PAPER_CAP, kind=kind)
    motions = limit_motions(body, R, Theta, kind=kind, chains={PAPER_CAP: chain})
    bound = cap_bound(body, R, Theta, PAPER_CAP, kind=kind)
    solved = {}
    table = _side_by_side(body, gains, R, Theta, motions, {PAPER_CAP: bound}, SETTINGS, kind, solved)
    opt = table[table.law == "optimal"]
    missed = opt[~opt.paper_start_reached.astype(bool)]
    row = (missed if len(missed) else opt).iloc[0]
    key = (None if pd.isna(row.angle_deg) else int(row.angle_deg), None if pd.isna(row.cap) else float(row.cap))
    return dict(motions=motions, bound=bound, table=table, basin_setting=key,
                basin=_basin(body, motions[key], key, solved), cap_chain=chain,
                bound_at_mesh=cap_bound(body, R, Theta, PAPER_CAP, kind=kind, nodes=chain[0].nodes))


def _basin(body: Body, motion, key, solved: dict) -> pd.DataFrame:
    """:func:`lib.optimal.verdict.basin` of the best motion's controller at the setting ``key``,
    from its periodic LQR and verdict in ``solved`` (:func:`_side_by_side`)."""
    limits = Limits(key[1], None if key[0] is None else math.radians(key[0]))
    lqr, v = solved[limits]
    return basin(body, motion, v, limits=limits, lqr=lqr, periods=OPTIMAL_PERIODS, steps=OPTIMAL_STEPS)



#: the table's names of the laws
LAW_NAMES = {"paper": "paper's law", "weighted": "weighted (Ch. 6)", "percussion": "law for P (Ch. 7)",
             "optimal": "best motion + LQR", "bound": "bound"}


def _by_setting(table: pd.DataFrame, values: str, laws) -> pd.DataFrame:
    """One row a setting (in the table's order), one column a law of ``laws`` (by its name)."""
    order = list(dict.fromkeys(table.setting))
    return table.pivot(index="setting", columns="law", values=values).reindex(order)[list(laws)] \
        .rename(columns=LAW_NAMES)


def error_table(table: pd.DataFrame) -> pd.DataFrame:
    """:func:`side_by_side`'s table as the page shows it: one row a setting, one column a law, each
    cell "largest / RMS" distance (m, three significant digits, each written as its kind says:
    the bound's rounded down, the controller of the best motion found's rounded up, being values
    of a motion that exists; the RMS "± its standard error", to two decimals, where the row has
    one, ``rms_stderr``), "diverges" where the run blew up and "-" where there is no row (no bound
    without a cap).

    Parameters
    ----------
    table : pandas.DataFrame
        The frame of :func:`side_by_side`.

    Returns
    -------
    pandas.DataFrame
        Index the settings in the table's order; columns the laws' names.
    """
    def cell(r):
        if not np.isfinite(r.max_error):
            return "diverges"
        se = r.get("rms_stderr", np.nan)
        kind = {"bound": lower_bound, "optimal": upper_bound}.get(r.law, exact)
        rms = estimate(r.rms_error, se, ".2f") if np.isfinite(se) else kind(r.rms_error, ".3g")
        return f"{kind(r.max_error, '.3g').text()} / {rms.text()}"

    return _by_setting(table.assign(v=table.apply(cell, axis=1)), "v", LAW_NAMES).fillna("-")


def regime_table(table: pd.DataFrame) -> pd.DataFrame:
    """The regimes of :func:`side_by_side`'s table, one row a setting, one column a law.

    Parameters
    ----------
    table : pandas.DataFrame
        The frame of :func:`side_by_side`.

    Returns
    -------
    pandas.DataFrame
        Index the settings; columns the four controllers' names.
    """
    return _by_setting(table[table.law != "bound"], "regime", [k for k in LAW_NAMES if k != "bound"])


def tracker_table(table: pd.DataFrame) -> pd.DataFrame:
    """The best motions' controllers from :func:`side_by_side`'s table: setting, regime, largest
    |multiplier| (a numerical estimate with its stated error), starts reached (on both maps of the
    verdict, step h and h/2), whether the paper's start is ("undecided" where the two maps
    disagree), largest and RMS distance (m, rounded up: values of a motion that exists).

    Parameters
    ----------
    table : pandas.DataFrame
        The frame of :func:`side_by_side`.

    Returns
    -------
    pandas.DataFrame
        One row a setting, the cells formatted for the page.
    """
    opt = table[table.law == "optimal"]
    return pd.DataFrame({
        "setting": opt.setting, "regime": opt.regime,
        "largest |multiplier|": [floquet_text(v, e) for v, e in zip(opt.floquet, opt.floquet_error)],
        "starts reached": [f"{int(r)} of {int(n)}" for r, n in zip(opt.starts_reached, opt.starts)],
        "paper's start": ["yes" if r else ("no" if s else "undecided")
                          for r, s in zip(opt.paper_start_reached, opt.get("paper_start_settled",
                                                                           pd.Series(True, index=opt.index)))],
        "largest (m)": [upper_bound(v, ".3g").text() for v in opt.max_error],
        "RMS (m)": [upper_bound(v, ".3g").text() for v in opt.rms_error]})


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
