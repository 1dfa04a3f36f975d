"""The force and angle limits of paper Sec. 5 (Chapter 4): the long-run regime of the
closed loop under an angle limit (and a force cap), decided from a stroboscopic
section, located periodic orbits with their Floquet multipliers, and the largest
Lyapunov exponent, for one pair of limits or many at once.

Two integrators run the switched closed loop: the adaptive, event-located
:class:`lib.integrators.switched.SwitchedLoop` (the reference, one run at a time:
:mod:`lib.limits.sections`, whose names are re-exported here)
and the compiled fixed-step one (:mod:`lib.integrators.switched_compiled`, many
runs at once, about a hundred times faster: :func:`lib.limits.runs.switched_runs`,
re-exported here, and :func:`limit_verdicts`, which Chapter 4 uses). The verdict tools are generic
(:mod:`lib.dynamics`) and re-exported here.
"""

from __future__ import annotations

from dataclasses import replace
from typing import NamedTuple

import numpy as np
import pandas as pd

from ..machinery import checks
from ..angles import state_difference
from ..dynamics import verdicts as dv
from ..dynamics.lyapunov import LyapunovEstimate, largest_lyapunov
from ..dynamics.sections import distinct_points, section_margin, section_period
from ..integrators.switched import Segments, SwitchedLoop
from ..machinery.parallel import map_chunks
from .sections import Regime, classify, section_sweep, stroboscopic_section, sweep_angle_limit  # re-exported
from ..params import Body, Gains
from ..dynamics.sampled import sampled_extremes, sampled_range
from .runs import (LOCATORS, STEPS_PER_PERIOD, SwitchedRuns, _check_parts, _concat_runs, _limits_arrays, _start_states,
                   error_state, switched_runs)
from ..trajectories import Reference, heading_turns

__all__ = [
    "error_state", "stroboscopic_section", "Regime", "classify", "section_sweep", "sweep_angle_limit",
    "SwitchedRuns", "switched_runs", "limit_verdicts", "LimitVerdicts", "extend_undecided", "UNDECIDED_FACTOR", "regime_edges", "LIMIT_DEFAULTS", "STEPS_PER_PERIOD",
    # re-exported from where they are defined
    "SwitchedLoop", "Segments", "largest_lyapunov", "LyapunovEstimate", "distinct_points", "section_period",
    "section_margin", "state_difference",
]


# ---------------------------------------------------------------- the compiled runs and their verdicts


#: the options of :func:`limit_verdicts`; the thresholds mean what they mean in :mod:`lib.dynamics.verdicts`
LIMIT_DEFAULTS = dict(transient=60, periods=120, block=12, max_period=8, candidate_tol=1e-3, newton_tol=1e-9,
                      fd_step=1e-6, reach_tol=1e-3, approach_tol=0.05, lyapunov_band=0.01, return_tol=0.05,
                      slip_band=1e-3)

class LimitVerdicts(NamedTuple):
    """What :func:`limit_verdicts` returns: ``frame``, one row of verdicts per pair, and ``runs``,
    the :class:`SwitchedRuns` behind it (the sections and trajectories Chapter 4 draws). A tuple,
    so that ``frame, runs = limit_verdicts(...)`` unpacks it as before."""

    frame: pd.DataFrame
    runs: SwitchedRuns


#: Newton on the switched loop's period map: the Jacobian by differences, steps cut to 0.1
_NEWTON = dict(max_iter=9, max_step=0.1)

_STATUS = {"not converged": "Newton did not converge", "not attracting": "the orbit found is not attracting",
           "not reached": "the run has not reached the orbit"}


class _SwitchedMap:
    """The switched loop's period map (a :class:`lib.dynamics.verdicts.PeriodMap`) over runs
    with their own limits: the state (x, y, phi, and rates), the heading phi in column 2."""

    turn_axis = 2

    def __init__(self, body, gains, ref, b, f, steps_per_period, locator="dense"):
        self.body, self.gains, self.ref, self.b, self.f, self.steps = body, gains, ref, b, f, steps_per_period
        self.locator = locator

    def advance(self, idx, x, k):
        k = np.unique(np.asarray(k, dtype=int))
        if k.size != 1:
            raise ValueError("the switched runs of one call share their number of periods")
        return switched_runs(self.body, self.gains, self.ref, self.b[idx], self.f[idx], s0=x, n_periods=int(k[0]),
                             steps_per_period=self.steps, locator=self.locator).states[:, -1]

    def step(self, idx, x, k, h):
        return dv.difference_jacobian(self, idx, x, k, h)


def limit_verdicts(body: Body, gains: Gains, ref: Reference, angle_limits, force_limits=None, *, s0=None,
                   steps_per_period: int = STEPS_PER_PERIOD, locator: str = "dense", measure: bool = True,
                   executor=None, chunk_size: int | None = None, progress: bool | None = None, **options):
    """Decide the long-run regime of the switched closed loop for each (angle limit (rad),
    force limit (N)) pair by the book's one decision procedure (:mod:`lib.dynamics.verdicts`)
    on the full state. Options (:data:`LIMIT_DEFAULTS`): ``transient`` periods dropped,
    then ``periods`` periods of section and of Lyapunov renormalisation.

    - **periodic** (or **slipping** if the heading advances by whole turns every k
      periods): the section repeats at a lag k <= ``max_period`` to ``candidate_tol``
      over its last 2 ``max_period`` states; Newton on P^k(x) = x + (0, 0, 2 pi n, 0, 0, 0),
      with the Jacobian by forward differences (step ``fd_step``), converges to
      ``newton_tol``; the orbit attracts (all Floquet multipliers, the eigenvalues of
      DP^k, inside the unit circle) and the run has reached it
      (:func:`lib.dynamics.verdicts.reached`: within ``reach_tol``, or within
      ``approach_tol`` and closing in no slower than the slowest multiplier allows).
    - **chaotic**, **quasiperiodic**, **undecided**: the rule
      :func:`lib.dynamics.verdicts.classify` on the largest Lyapunov exponent lambda (1/s)
      with its standard error SE from the means of blocks of ``block`` periods; a
      quasi-periodic section must also enclose no *attracting* period-1 orbit
      (:func:`lib.dynamics.verdicts.enclosed_orbit`; column floquet then holds the largest
      |multiplier| of the orbit inside, above 1, where a torus is born from an orbit that
      lost stability). An attracting one inside means a slow spiral onto it: undecided.

    Columns: angle_limit (rad), angle_deg, force_limit (N, inf for none), regime, period,
    turns (of the heading per k periods of a slipping orbit), floquet (largest |multiplier|),
    lyapunov and lyapunov_stderr (1/s), returns; p_range (rad) and pos_err (m, largest
    position error) over the whole orbit, or over the observed run without one, sampled
    :data:`MEASURE_SAMPLES` times a period; drift and drift_stderr (turns of the heading per
    period: n / k on an orbit, else measured with its batch-means error); lost (the heading
    slips, :func:`lib.dynamics.verdicts.heading_lost`) and turns_round (p_range > 2 pi);
    crossings, slides, t_sliding (s), reason, and orbit (the located orbit's state at t = 0,
    [x, y, phi, xdot, ydot, phidot], or None).

    Scale-out: with an ``executor`` (any :class:`concurrent.futures.Executor`) the pairs go to
    it in consecutive chunks of ``chunk_size`` (default: two chunks per worker; without an
    executor, ``chunk_size`` runs the chunks here one after another), by
    :func:`lib.machinery.parallel.map_chunks`; each run is decided on its own, so the frame is the one
    of the single call, and the runs' arrays are concatenated in order into one
    :class:`SwitchedRuns`.
    ``progress``: a bar over the pairs on stderr (:func:`lib.machinery.parallel.show_progress`; default None: only when run
    interactively, never under pytest or in the book build).

    Parameters
    ----------
    body : Body
        The plant and the controller's model.
    gains : Gains
        The gains of (23).
    ref : Circle or Eight
        The reference (:mod:`lib.trajectories`).
    angle_limits : float or array_like
        beta_max (rad), in (0, pi], one or one per pair.
    force_limits : float or array_like, optional
        F_max (N), > 0 (inf or None for none), one or one per pair.
    s0 : array_like, optional
        Start [x, y, phi, xdot, ydot, phidot] (m, rad, m/s, rad/s), (6,) or (N, 6);
        default the paper's Table.
    steps_per_period : int
        Fixed steps per reference period of the compiled integrator (>= 16).
    locator : {"dense", "bracket"}
        How the compiled integrator locates events (:mod:`lib.integrators.switched_events`).
    measure : bool
        Whether to take the measures over the whole orbit or run (the decided run's states kept
        40 times a period after the transient, and a run over each located orbit). False, for a
        caller that reads only the verdicts: p_range,
        pos_err, drift and drift_stderr are NaN without an orbit (an orbit's drift is still
        n / k), lost is NA without an orbit and turns_round NA everywhere (pandas' nullable
        booleans); the verdicts, periods, multipliers, exponents and orbits are the same.
    executor : concurrent.futures.Executor, optional
        Where the chunks of pairs run (a process pool, a dask ``Client.get_executor()``).
    chunk_size : int, optional
        Points per chunk (default: two chunks per worker with an executor, else all).
    progress : bool, optional
        A progress bar on stderr (default None: only when run interactively).
    **options
        The procedure's options, :data:`LIMIT_DEFAULTS`.

    Returns
    -------
    LimitVerdicts
        A named pair: ``frame`` (pandas.DataFrame), one row per pair, the columns above; ``runs``
        (:class:`SwitchedRuns`), the runs behind it, in the order of the pairs.
    """
    o, steps_per_period, locator = _procedure(options, steps_per_period, locator)
    _check_parts(body, gains, ref, steps_per_period)
    b, f = _limits_arrays(angle_limits, force_limits)
    S0 = _start_states(s0, b.size)
    measure = checks.flag("measure", measure)
    parts = map_chunks(_limit_chunk, b.size, (b, f, S0), dict(body=body, gains=gains, ref=ref, o=o,
                                                             steps_per_period=steps_per_period, locator=locator,
                                                             measure=measure),
                       executor, chunk_size, progress)
    if len(parts) == 1:
        return LimitVerdicts(*parts[0])
    return LimitVerdicts(pd.concat([p[0] for p in parts], ignore_index=True), _concat_runs([p[1] for p in parts]))


def _procedure(options: dict, steps_per_period, locator) -> tuple[dict, int, str]:
    """The checked options of the procedure (:data:`LIMIT_DEFAULTS`), steps per period and
    locator of :func:`limit_verdicts` (and of the decisions that confirm its verdicts)."""
    o = checks.options(options, LIMIT_DEFAULTS, dict(transient=0, periods=2, block=2, max_period=1))
    npr, blk, kmax = o["periods"], o["block"], o["max_period"]
    if npr < 2 * blk or npr < 2 * kmax + 2:
        raise ValueError(f"periods ({npr}) must cover two blocks ({blk}) and twice max_period ({kmax})")
    return (o, checks.integer("steps_per_period", steps_per_period, minimum=16),
            checks.one_of("locator", locator, LOCATORS))


def _limit_chunk(b, f, S0, *, body, gains, ref, o, steps_per_period, locator, measure=True):
    """(frame, runs) of :func:`limit_verdicts` for validated pairs (one chunk of them)."""
    ntr, npr, blk, kmax = o["transient"], o["periods"], o["block"], o["max_period"]
    # with the measures, the run also keeps its states MEASURE_SAMPLES times a period after the transient
    record = (ntr, MEASURE_SAMPLES) if measure and steps_per_period % MEASURE_SAMPLES == 0 else None
    runs = switched_runs(body, gains, ref, b, f, s0=S0, n_periods=ntr + npr,
                         lyapunov_from=ntr, steps_per_period=steps_per_period, locator=locator, record=record)
    T, N = runs.period, runs.states.shape[0]
    pmap = _SwitchedMap(body, gains, ref, runs.angle_limit, runs.force_limit, steps_per_period, locator)
    step = lambda i, x, k: pmap.step(i, x, k, o["fd_step"])  # noqa: E731
    lamT, seT = dv.block_statistics(runs.log_growth, blk)
    hist = np.moveaxis(runs.states[:, ntr:], 0, 1).copy()
    hist[..., 2] = np.mod(hist[..., 2], 2 * np.pi)     # the map commutes with whole turns of phi
    idx = np.arange(N)
    orb = dv.find_orbits(step, pmap, idx, hist, max_period=kmax, candidate_tol=o["candidate_tol"],
                         newton_tol=o["newton_tol"], reach_tol=o["approach_tol"], reach_floor=o["reach_tol"],
                         newton_options=_NEWTON, fixed_turns=False, ends=2 * kmax)
    found = orb["found"]
    # the turns against the path's heading: on the circle (27) phi_d itself turns once a period,
    # so an orbit that follows it gains k turns per k periods and still holds the heading
    orb["n"] = np.where(found, orb["n"] - orb["k"] * heading_turns(ref), orb["n"])
    sec = runs.errors[:, ntr:]
    returns = dv.section_returns(np.moveaxis(sec, 0, 1), angles=(4,))
    regime, reason = dv.classify(lamT, seT, returns, band=o["lyapunov_band"], return_tol=o["return_tol"],
                                 max_period=kmax)
    mu = np.where(orb["status"] != "", orb["floquet"], np.nan)
    ring = np.flatnonzero(~orb["found"] & (regime == "quasiperiodic"))
    if ring.size:
        att, mu[ring] = dv.enclosed_orbit(step, ring, hist[:, ring], turn_axis=2, newton_tol=o["newton_tol"],
                                          newton_options=_NEWTON)
        spiral = ring[att]
        regime[spiral] = "undecided"
        reason[spiral] = [f"slow spiral onto an attracting orbit inside the curve (|mu| = {m:.4f})" for m in mu[spiral]]
    tried = ~orb["found"] & (orb["status"] != "") & (regime == "undecided")
    reason[tried] = [f"{_STATUS[s]}; {r}" for s, r in zip(orb["status"][tried], reason[tried])]
    mu[found] = orb["rho"][found]
    regime[found] = dv.orbit_regime(orb["n"][found])
    reason[found] = ""
    m = _over_the_run(pmap, runs.states[:, ntr], orb, npr, blk, runs) if measure else _orbit_measures(orb)
    runs = replace(runs, recorded=None, recorded_t=None)           # read: not kept with the runs
    lost = dv.heading_lost(found, orb["n"], m["drift"], m["drift_stderr"], slip_band=o["slip_band"])
    frame = pd.DataFrame(dict(
        angle_limit=runs.angle_limit, angle_deg=np.degrees(runs.angle_limit), force_limit=runs.force_limit,
        regime=regime, period=orb["k"], turns=orb["n"], floquet=mu, lyapunov=lamT / T, lyapunov_stderr=seT / T,
        returns=returns, p_range=m["p_range"], pos_err=m["pos_err"], drift=m["drift"],
        drift_stderr=m["drift_stderr"], lost=lost, turns_round=dv.turns_round(m["p_range"]),
        crossings=runs.crossings, slides=runs.slides, t_sliding=runs.t_sliding, reason=reason,
        orbit=[orb["x"][q].copy() if found[q] else None for q in range(N)]))
    if not measure:
        frame["lost"] = pd.array(np.where(found, lost, False), dtype="boolean")
        frame.loc[~found, "lost"] = pd.NA
        frame["turns_round"] = pd.array([pd.NA] * N, dtype="boolean")
    return frame, runs


def _orbit_measures(orb: dict) -> dict:
    """The measures of :func:`limit_verdicts` without the run that takes them (``measure``
    False): NaN, except an orbit's drift, n / k turns a period with no error."""
    N = orb["found"].size
    out = {key: np.full(N, np.nan) for key in ("p_range", "pos_err", "drift", "drift_stderr")}
    f = orb["found"]
    out["drift"][f], out["drift_stderr"][f] = orb["n"][f] / orb["k"][f], 0.0
    return out


#: samples per reference period of the runs that measure ranges over a whole orbit or run
MEASURE_SAMPLES = 40


def _over_the_run(pmap: "_SwitchedMap", start, orb: dict, periods: int, block: int, runs: SwitchedRuns) -> dict:
    """What the section alone cannot show, sampled ``MEASURE_SAMPLES`` times a period: the
    range of p (rad) and the largest position error (m) over the whole orbit (its k periods
    from the orbit's point) or, without one, over the observed run (``periods`` periods from
    ``start``, the state at the end of the transient); and the heading's drift (turns per
    period) with its batch-means standard error (blocks of ``block`` periods): n / k with no
    error on an orbit. Without an orbit the samples are the decided run's own (``runs.recorded``,
    kept by the run the verdict was read from), or, where it kept none, the run integrated again
    from ``start`` on the same step grid (for a chaotic one a second trajectory on the attractor)."""
    N = start.shape[0]
    out = dict(p_range=np.full(N, np.nan), pos_err=np.full(N, np.nan), drift=np.full(N, np.nan),
               drift_stderr=np.full(N, np.nan))
    groups = [(np.flatnonzero(~orb["found"]), periods, start)]
    groups += [(np.flatnonzero(orb["found"] & (orb["lag"] == k)), int(k), orb["x"])
               for k in np.unique(orb["lag"][orb["found"]])]
    S = MEASURE_SAMPLES
    own = runs.recorded is not None
    for j, (rows, k, x0) in enumerate(groups):
        if rows.size == 0:
            continue
        if j == 0 and own:                     # the run's own samples, from the transient's end on
            t, states = runs.recorded_t, runs.recorded[rows]
            err = error_state(pmap.ref, np.tile(t, rows.size), states.reshape(-1, 6)).reshape(states.shape)
        else:
            r = switched_runs(pmap.body, pmap.gains, pmap.ref, pmap.b[rows], pmap.f[rows], s0=x0[rows],
                              n_periods=k, steps_per_period=pmap.steps, samples_per_period=S, locator=pmap.locator)
            t, states, err = r.t, r.states, r.errors
        p = states[:, :, 2] - pmap.ref.z(t)[:, 2][None]
        e = np.hypot(err[..., 0], err[..., 1])
        with np.errstate(invalid="ignore", divide="ignore"):
            de = np.where(e > 0, (err[..., 0] * err[..., 2] + err[..., 1] * err[..., 3]) / e, 0.0)
        h = t[1] - t[0]
        out["p_range"][rows] = sampled_range(p, cyclic=False, dy=err[..., 5], h=h)     # Hermite-refined extremes
        out["pos_err"][rows] = sampled_extremes(e, cyclic=False, dy=de, h=h)[1]
        if k == periods and not orb["found"][rows[0]]:
            nb = periods // block
            ends = p[:, ::S * block][:, :nb + 1]
            out["drift"][rows], out["drift_stderr"][rows] = dv.heading_drift(ends, block)
        else:
            out["drift"][rows], out["drift_stderr"][rows] = orb["n"][rows] / orb["k"][rows], 0.0
    return out


#: how many times longer :func:`extend_undecided` runs the points left undecided
UNDECIDED_FACTOR = 8


def extend_undecided(body: Body, gains: Gains, ref: Reference, frame: pd.DataFrame,
                     factor: int = UNDECIDED_FACTOR, *,
                     s0=None, steps_per_period: int = STEPS_PER_PERIOD, **options) -> pd.DataFrame:
    """Decide the undecided rows of ``frame`` (:func:`limit_verdicts`) again over a horizon
    ``factor`` times longer (the section and the Lyapunov run, and the blocks of the
    standard error with them; the same transient and start). On an invariant torus the
    log-growth of a separation is bounded, so its mean falls as 1 / horizon, and with
    blocks ``factor`` times longer so does its standard error: a longer horizon resolves a
    zero exponent where a chaotic one stays positive. Returns a copy of ``frame`` with
    those rows replaced and a column ``horizon`` (periods of section and Lyapunov run).

    Parameters
    ----------
    body : Body
        The body.
    gains : Gains
        The gains of (23).
    ref : Circle or Eight
        The reference.
    frame : pandas.DataFrame
        A frame of :func:`limit_verdicts`.
    factor : int
        Horizon factor.
    s0 : array_like, optional
        The start of the frame's runs.
    steps_per_period : int
        Fixed steps per period.
    **options
        The options of :func:`limit_verdicts` (:data:`LIMIT_DEFAULTS`, and its ``measure``).

    Returns
    -------
    pandas.DataFrame
        The frame, its undecided rows decided again, with a column ``horizon``.
    """
    o = {**LIMIT_DEFAULTS, **options}

    def redo(rows, k):
        long = {**o, "periods": o["periods"] * k, "block": o["block"] * k}
        return limit_verdicts(body, gains, ref, frame.angle_limit.to_numpy()[rows], frame.force_limit.to_numpy()[rows],
                              s0=s0, steps_per_period=steps_per_period, **long)[0]

    return dv.redecide_undecided(frame, o["periods"], factor, redo)


def regime_edges(frame: pd.DataFrame, regime: str = "chaotic") -> pd.DataFrame:
    """Where a sweep over the angle limit enters or leaves ``regime``: for each force limit
    of ``frame`` (:func:`limit_verdicts`), the pairs of neighbouring angle limits (rad)
    with ``regime`` on one side only. Columns force_limit, lo, hi, below, above (the
    regimes at lo and at hi).

    Parameters
    ----------
    frame : pandas.DataFrame
        A frame of :func:`limit_verdicts`.
    regime : str
        The regime.

    Returns
    -------
    pandas.DataFrame
        Columns force_limit (N), lo, hi (rad), below, above.
    """
    rows = []
    for cap, g in frame.sort_values("angle_limit").groupby("force_limit", sort=True):
        a, r = g.angle_limit.to_numpy(), g.regime.to_numpy()
        for i in np.flatnonzero((r[:-1] == regime) != (r[1:] == regime)):
            rows.append(dict(force_limit=cap, lo=a[i], hi=a[i + 1], below=r[i], above=r[i + 1]))
    return pd.DataFrame(rows, columns=["force_limit", "lo", "hi", "below", "above"])
