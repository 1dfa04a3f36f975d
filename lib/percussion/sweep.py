"""Fig. 5 under the law for P: the heading's verdict at each (R, Theta), by the book's one
decision procedure (:mod:`lib.dynamics.verdicts`) on the exact period map of the zero dynamics
(:class:`lib.percussion.engine.HeadingMap`), started on the reference (p(0) = 0, P on the path).

The schedule is Chapter 5's, shortened because the map is one-dimensional and, where it locks,
contracts by factors like exp(-100) per period: a transient in chunks with Newton on the rows
whose section repeats; the rest run a Lyapunov run in blocks (the exact log-derivative per
period), with Newton again on the rows that are not expanding, and the rule
(:func:`lib.dynamics.verdicts.classify`) at the end.
"""

from __future__ import annotations

from types import MappingProxyType

import numpy as np
import pandas as pd

from ..machinery import checks
from ..angles import wrap_angle
from ..dynamics import verdicts as dv
from ..machinery.parallel import concat_frames, map_chunks
from ..params import Body
from ..rotation.reduced import check_grid
from ..rotation.verdicts import FIG5_GRID
from ..dynamics.sampled import sampled_range
from .engine import HeadingEngine, HeadingMap, coefficients

__all__ = ["SWEEP_DEFAULTS", "heading_sweep", "percussion_fig5_map", "rotation_sweep"]

_DEFAULTS = dict(steps=128, transient=16, chunk=4, min_transient=4, max_period=4, lyapunov_periods=120, block=12,
                 newton_tol=1e-10, candidate_tol=0.05, reach_tol=0.05, reach_floor=1e-9, lyapunov_band=0.01,
                 slip_band=1e-3, return_tol=0.05)
#: the default options of :func:`heading_sweep` (read-only)
SWEEP_DEFAULTS = MappingProxyType(_DEFAULTS)
_NEWTON = dict(max_iter=30, max_step=1.0, polish=1e-13)
#: the largest exponent h |S| of one Magnus step (exp of it stays far from overflow at 709; the book's
#: Fig. 5 grid needs at most 8 at the default 128 steps a period)
MAX_EXPONENT = 100.0


def _check_domain(body: Body, kind: str, R, Theta, steps: int) -> None:
    """Refuse a point outside the verdicts' domain: a rate below Fig. 5's floor
    (:func:`lib.machinery.domain.slow_rate`, as :func:`lib.rotation.verdicts.eight_rotation_sweep`),
    or a heading that turns so fast per period that more than :data:`lib.machinery.domain.MAX_STEPS`
    Magnus steps would be needed for each to carry an exponent at most :data:`MAX_EXPONENT` (the
    flow's matrix S grows as R Theta / eps and R (c / m) / eps), naming R or Theta, whichever lies
    farther from the body's scales; then a point that needs more than ``steps``, naming the option
    ``steps`` and the count that every point needs."""
    checks.slow_rate(body, Theta)
    eng = HeadingEngine(kind, 64)
    cA, cV = coefficients(body, R, Theta)
    rate = np.abs(cA) * np.hypot(eng.eX2, eng.eY2).max() + np.abs(cV) * np.hypot(eng.eX1, eng.eY1).max()
    need = 2 * np.pi * rate / MAX_EXPONENT
    unit = f"Magnus steps (each step's exponent <= {MAX_EXPONENT:g})"
    values = {"R": (R, "m"), "Theta": (Theta, "rad/s")}
    checks.within_budget(checks.by_scale(body, R, Theta, need), checks.MAX_STEPS, what="a period would need",
                         unit=unit, values=values,
                         fix="outside the verdicts' domain (R far beyond the body's scale, or Theta far from its rates)")
    checks.within_budget(checks.by_scale(body, R, Theta, need), steps, what="a period would need", unit=unit,
                         values=values, fix=f"raise the option steps to {int(np.ceil(np.max(need)))} (steps={steps} "
                         "given)")


def _options(options: dict) -> dict:
    return checks.options(options, _DEFAULTS, dict(steps=2, transient=1, chunk=1, min_transient=1, max_period=1,
                                                   block=2, lyapunov_periods=0))


def heading_sweep(body: Body, R, Theta, *, kind: str = "eight", p0=0.0, executor=None,
                   chunk_size: int | None = None, progress: bool | None = None, **options) -> pd.DataFrame:
    """The verdict on the heading under the law for P, P exactly on the path ``kind`` (the
    eight (28) by default) of size R_i (m) at Theta_i (rad/s), from p(0) = ``p0`` (rad), with
    the columns of :func:`lib.stability.eight_rotation_sweep` (R, Theta, regime, period, range,
    floquet, lyapunov, lyapunov_stderr, slip, slip_stderr, lost, orbit_p, distance, residual,
    mirror, periods, drift_periods, reason, turns_round, steps, verdict_steps). ``executor``,
    ``chunk_size``, ``progress``: as in :func:`lib.machinery.parallel.map_chunks`. ``options``: :data:`SWEEP_DEFAULTS`.

    Parameters
    ----------
    body : Body
        The body.
    R, Theta : array_like
        Sizes (m) and rates (rad/s), > 0, 1-D, equal lengths.
    kind : str
        ``"eight"`` or ``"circle"``.
    p0 : float or array_like
        Start heading error (rad).
    executor : concurrent.futures.Executor, optional
        Where the chunks run.
    chunk_size : int, optional
        Points per chunk.
    progress : bool, optional
        A progress bar on stderr.
    **options
        The schedule's options.

    Returns
    -------
    pandas.DataFrame
        One row per point.
    """
    checks.instance("body", body, Body)
    checks.one_of("kind", kind, ("eight", "circle"))
    R, Theta = check_grid(R, Theta)
    o = _options(options)
    _check_domain(body, kind, R, Theta, o["steps"])
    p0 = checks.array("p0", p0)
    try:
        p0 = np.broadcast_to(p0, R.shape).copy()
    except ValueError as e:
        raise ValueError(f"p0 must be a scalar or an array of length {R.size}") from e
    parts = map_chunks(_frame, R.size, (R, Theta, p0), dict(body=body, kind=kind, opts=o), executor, chunk_size,
                       progress)
    return concat_frames(parts)


#: the former name of :func:`heading_sweep` (deprecated, as it was also the name of
#: :func:`lib.rotation.reduced.rotation_sweep`, Chapter 5's first-edition classifier)
rotation_sweep = heading_sweep


def percussion_fig5_map(body: Body, R_range=FIG5_GRID["R"], Theta_range=FIG5_GRID["Theta"],
                        n: int = FIG5_GRID["n"], **kw) -> pd.DataFrame:
    """:func:`heading_sweep` on the n x n grid of Fig. 5 (Theta varying slowest), as
    :func:`lib.rotation.fig5.fig5_map` lays it out.

    Parameters
    ----------
    body : Body
        The body.
    R_range, Theta_range : tuple
        The grid's ranges (m, rad/s); default those of :data:`lib.rotation.verdicts.FIG5_GRID`.
    n : int
        Points per side (>= 2); default ``FIG5_GRID["n"]``.
    **kw
        Keywords of :func:`heading_sweep`.

    Returns
    -------
    pandas.DataFrame
        n^2 rows.
    """
    n = checks.integer("n", n, minimum=2)
    checks.grid_budget(n)
    R, Th = np.meshgrid(np.linspace(*R_range, n), np.linspace(*Theta_range, n))
    return heading_sweep(body, R.ravel(), Th.ravel(), **kw)


def _new_out(N):
    return dict(regime=np.full(N, "undecided", dtype=object), period=np.zeros(N, int), range=np.full(N, np.nan),
                floquet=np.full(N, np.nan), lyapunov=np.full(N, np.nan), lyapunov_stderr=np.full(N, np.nan),
                slip=np.full(N, np.nan), slip_stderr=np.full(N, np.nan), lost=np.zeros(N, bool),
                orbit_p=np.full(N, np.nan), distance=np.full(N, np.nan), residual=np.full(N, np.nan),
                mirror=np.full(N, np.nan), periods=np.zeros(N, int), drift_periods=np.zeros(N, int),
                reason=np.full(N, "", dtype=object), x=np.full(N, np.nan), slip_n=np.zeros(N, int))


def _frame(R, Theta, p0, *, body, kind, opts) -> pd.DataFrame:
    eng = HeadingEngine(kind, opts["steps"])
    cA, cV = coefficients(body, R, Theta)
    out = _new_out(R.size)
    live = np.arange(R.size)
    phi = eng.H0 + p0
    hist = phi[None, :, None]
    t = 0
    tried = np.full((opts["max_period"], R.size), np.inf)

    def orbits(rows, hist, t):
        """find_orbits on the live rows ``rows`` (positions in ``live``); returns the decided mask."""
        hmap = HeadingMap(eng, cA[live[rows]], cV[live[rows]])
        tr = tried[:, live[rows]]
        r = dv.find_orbits(hmap.step, hmap, np.arange(rows.size), hist[:, rows], max_period=opts["max_period"],
                           candidate_tol=opts["candidate_tol"], newton_tol=opts["newton_tol"],
                           reach_tol=opts["reach_tol"], reach_floor=opts["reach_floor"], newton_options=_NEWTON,
                           tried=tr)
        tried[:, live[rows]] = tr
        f = np.flatnonzero(r["found"])
        g = live[rows[f]]
        k, nn = r["k"][f], r["n"][f]
        out["regime"][g], out["period"][g], out["slip_n"][g] = dv.orbit_regime(nn), k, nn
        out["slip"][g], out["slip_stderr"][g], out["lost"][g] = nn / k, 0.0, nn != 0
        out["x"][g], out["floquet"][g] = r["x"][f, 0], r["rho"][f]
        with np.errstate(divide="ignore"):
            out["lyapunov"][g] = np.log(r["rho"][f]) * Theta[g] / (2 * np.pi * k)
        out["orbit_p"][g] = wrap_angle(r["near"][f, 0] - eng.H0)
        out["distance"][g], out["residual"][g], out["periods"][g] = r["distance"][f], r["residual"][f], t
        done = np.zeros(live.size, bool)
        done[rows[f]] = True
        return done

    while t < opts["transient"] and live.size:
        c = min(opts["chunk"], opts["transient"] - t)
        o = eng.flow(phi, cA[live], cV[live], c)
        phi, t = o["phi"], t + c
        hist = np.concatenate([hist, o["sec"][:, :, None]])[-(2 * opts["max_period"] + 1):]
        if t >= opts["min_transient"]:
            done = orbits(np.arange(live.size), hist, t)
            live, phi, hist = live[~done], phi[~done], hist[:, ~done]
    if live.size:
        _lyapunov_run(eng, cA, cV, Theta, live, phi, hist, t, opts, out, orbits)
    _ranges(eng, cA, cV, out)
    cols = {k: v for k, v in out.items() if k not in ("x", "slip_n")}
    cols["turns_round"] = dv.turns_round(out["range"])
    return pd.DataFrame({"R": R, "Theta": Theta, **cols, "steps": opts["steps"], "verdict_steps": opts["steps"]})


def _lyapunov_run(eng, cA, cV, Theta, live, phi, hist, t, opts, out, orbits):
    """The rows without an orbit after the transient: blocks of the exact log-derivative, Newton
    on the rows not expanding, the rule at the end (:func:`lib.dynamics.verdicts.classify`)."""
    nb_max, blk = opts["lyapunov_periods"] // opts["block"], opts["block"]
    if nb_max < 2:
        out["reason"][live] = "no attracting orbit reached within the period budget"
        out["periods"][live] = t
        return
    rows_all = live.copy()
    pos = {int(g): i for i, g in enumerate(rows_all)}
    logs, pb = np.full((rows_all.size, nb_max), np.nan), np.full((rows_all.size, nb_max + 1), np.nan)
    secs, lo, hi = [], np.full(rows_all.size, np.inf), np.full(rows_all.size, -np.inf)
    pb[:, 0] = phi
    for b in range(nb_max):
        ix = np.array([pos[int(g)] for g in live])
        o = eng.flow(phi, cA[live], cV[live], blk, record=True)
        phi, t = o["phi"], t + blk
        logs[ix, b], pb[ix, b + 1] = o["logs"].mean(axis=0), phi
        lo[ix], hi[ix] = np.minimum(lo[ix], o["p"].min(axis=1)), np.maximum(hi[ix], o["p"].max(axis=1))
        full = np.full((blk, rows_all.size), np.nan)
        full[:, ix] = o["sec"]
        secs.append(full)
        hist = np.concatenate([hist, o["sec"][:, :, None]])[-(2 * opts["max_period"] + 1):]
        lam, se = dv.batch_means(logs[ix, :b + 1]) if b >= 1 else (np.zeros(ix.size), np.full(ix.size, np.inf))
        done = np.zeros(live.size, bool)
        if b >= 1:
            done = orbits(np.flatnonzero(lam < dv.SIGMAS * se), hist, t)
        live, phi, hist = live[~done], phi[~done], hist[:, ~done]
        if live.size == 0:
            return
    ix = np.array([pos[int(g)] for g in live])
    lam, se = dv.batch_means(logs[ix])
    T = 2 * np.pi / Theta[live]
    out["lyapunov"][live], out["lyapunov_stderr"][live] = lam / T, se / T
    sec = np.concatenate(secs)[:, ix, None]
    regime, reason = dv.classify(lam, se, dv.section_returns(sec), band=opts["lyapunov_band"],
                                 return_tol=opts["return_tol"], max_period=opts["max_period"])
    out["regime"][live], out["reason"][live] = regime, reason
    drift, dse = dv.heading_drift(pb[ix], blk)
    out["slip"][live], out["slip_stderr"][live] = drift, dse
    out["range"][live] = hi[ix] - lo[ix]
    out["lost"][live] = dv.heading_lost(False, 0, drift, dse, slip_band=opts["slip_band"])
    out["periods"][live], out["drift_periods"][live] = t, nb_max * blk


def _ranges(eng, cA, cV, out):
    """The range of p over each orbit (every step, Hermite-refined extremes) and, on the eight,
    the distance from the orbit to its mirror image p(s) -> -p(s + pi)."""
    orb = np.flatnonzero(np.isin(out["regime"], ("periodic", "slipping")))
    for k in np.unique(out["period"][orb]):
        g = orb[out["period"][orb] == k]
        o = eng.flow(out["x"][g], cA[g], cV[g], int(k), record=True)
        p0 = out["x"][g] - eng.H0
        p = np.column_stack([p0, o["p"]])
        dp0 = eng.rate(out["x"][g], cA[g], cV[g], -1) - eng.H1[-1]
        dp = np.column_stack([dp0, o["dp"]])
        cyc = out["slip_n"][g] == 0
        rng = np.empty(g.size)
        if cyc.any():
            rng[cyc] = sampled_range(p[cyc, 1:], cyclic=True, dy=dp[cyc, 1:], h=eng.h)
        if (~cyc).any():
            rng[~cyc] = sampled_range(p[~cyc], cyclic=False, dy=dp[~cyc], h=eng.h)
        out["range"][g] = rng
        if eng.kind == "eight" and eng.n % 2 == 0:
            half = np.arange(int(k)) * eng.n + eng.n // 2 - 1
            out["mirror"][g] = np.abs(wrap_angle(p0[:, None] + o["p"][:, half])).min(axis=1)
