"""Chapter 4's verdicts decided a second time from a moved start: the word ``transient``
(transient chaos: attractor not determined, the book's definition ``def-regimes``) for the
switched closed loop under limits.

Every run of :func:`lib.limits.verdicts.limit_verdicts` goes on past its transient to the
Lyapunov run, and its orbit, if any, is located on the section observed after the transient.
So every run that claims an attractor (periodic, slipping or chaotic) meets the trigger of
:func:`lib.dynamics.verdicts.needs_confirmation`. Some of these runs wander for tens of periods
before they settle, and a start moved by a relative 1e-12 may settle elsewhere, or not within
the horizon; a chaotic run whose exponent clears its threshold by little may, from a moved
start, not clear it. Such a verdict is decided by the last bits of the trajectory, and a
reader's machine may print another one. :func:`confirm_limit_verdicts` decides these runs
again from the start moved by :data:`lib.machinery.robustness.ROBUST_REL` and names
``transient`` the runs whose decisions differ (:func:`lib.dynamics.verdicts.attractor_determined`,
the rule Chapter 5's :func:`lib.rotation.fig5.confirm_attractors` applies).

Units: angles in rad, forces in N, states [x, y, phi, xdot, ydot, phidot] in m, rad, m/s, rad/s.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..dynamics import verdicts as dv
from ..machinery import checks
from ..machinery.robustness import ROBUST_REL, perturbed
from ..params import Body, Gains
from ..trajectories import Reference
from .runs import STEPS_PER_PERIOD, _check_parts, _limits_arrays, _start_states, switched_runs
from .verdicts import LimitVerdicts, _limit_chunk, _procedure, _SwitchedMap, limit_verdicts

__all__ = ["confirmed_limit_verdicts", "confirm_limit_verdicts", "same_orbit", "SAME_ORBIT_TOL", "MOVES",
           "QUICK_PERIODS"]

#: two located orbits are the same when every point of one lies this close (max-norm, the
#: heading modulo 2 pi) to a point of the other: Newton locates them to 1e-9, distinct
#: orbits of Chapter 4 lie at least 0.5 apart (:func:`same_orbit`; re-exported by
#: :mod:`lib.limits.attractors`, which names orbits by it)
SAME_ORBIT_TOL = 1e-6

#: the relative moves of the start (:func:`lib.machinery.robustness.perturbed`) from which a run is
#: decided again: ROBUST_REL with the fixed pseudo-random signs, as Chapter 5 moves its starts
#: (:data:`lib.rotation.fig5.CONFIRMATIONS`). Each move more can only add transient verdicts, at
#: the cost of a run of every chaotic row; one makes their count a lower bound
MOVES = (ROBUST_REL,)

#: periods over which a moved start is first run where the first decision located an orbit:
#: the orbits of Chapter 4 that its starts approach directly are reached within 10 periods
#: (at 0.05, their slowest multiplier then closes in); a run not reached by then is decided
#: again in full
QUICK_PERIODS = 32

#: the frame's columns that :func:`confirm_limit_verdicts` must read
_NEEDED = ("angle_limit", "force_limit", "regime", "period", "turns", "orbit")


def same_orbit(body: Body, gains: Gains, ref: Reference, angle_limits, force_limits, first, second, period, *,
               steps_per_period: int = STEPS_PER_PERIOD, locator: str = "dense") -> np.ndarray:
    """Whether two located orbits of the switched loop, of the same ``period`` k, are one:
    the point ``second`` (M, 6) lies within :data:`SAME_ORBIT_TOL`
    (max-norm, the heading modulo 2 pi) of one of the k points P^j(``first``), j = 1..k, of
    the orbit through ``first`` (M, 6). Newton locates both to about 1e-9; distinct orbits
    of Chapter 4 lie 0.5 or more apart. Returns (M,) bool.

    Parameters
    ----------
    body, gains, ref
        The plant, the gains of (23) and the reference.
    angle_limits, force_limits : array_like
        beta_max (rad) and F_max (N, inf for none) of each pair, (M,).
    first, second : array_like
        Orbit points at t = 0, (M, 6).
    period : array_like
        k of each pair (M,), >= 1.
    steps_per_period : int
        Fixed steps per period of the compiled integrator.
    locator : {"dense", "bracket"}
        How it locates events.

    Returns
    -------
    numpy.ndarray
        (M,) bool.
    """
    _check_parts(body, gains, ref)
    first = np.atleast_2d(checks.array("first", first, shape=(..., 6)))
    second = np.atleast_2d(checks.array("second", second, shape=first.shape))
    k = np.broadcast_to(np.asarray(period, dtype=int), (first.shape[0],))
    if np.any(k < 1):
        raise ValueError(f"period must be >= 1, got {k.min()}")
    b, f = (np.broadcast_to(v, k.shape) for v in _limits_arrays(angle_limits, force_limits))
    pmap = _SwitchedMap(body, gains, ref, b, f, steps_per_period, locator)
    pts = dv.orbit_points(pmap, np.arange(k.size), first, k)
    return dv.distance_to_orbit(second, pts, turn_axis=2)[0] <= SAME_ORBIT_TOL


def confirmed_limit_verdicts(body: Body, gains: Gains, ref: Reference, angle_limits, force_limits=None, *, s0=None,
                             steps_per_period: int = STEPS_PER_PERIOD, locator: str = "dense", measure: bool = True,
                             **options) -> LimitVerdicts:
    """:func:`lib.limits.verdicts.limit_verdicts`, its verdicts then confirmed by
    :func:`confirm_limit_verdicts` (the same arguments): Chapter 4's verdicts.

    Parameters
    ----------
    body, gains, ref, angle_limits, force_limits, s0, steps_per_period, locator, measure, **options
        As for :func:`lib.limits.verdicts.limit_verdicts` (``measure`` for the first decision only).

    Returns
    -------
    LimitVerdicts
        ``frame`` confirmed (with the column ``confirmed``) and ``runs``, the first decision's.
    """
    frame, runs = limit_verdicts(body, gains, ref, angle_limits, force_limits, s0=s0,
                                 steps_per_period=steps_per_period, locator=locator, measure=measure, **options)
    return LimitVerdicts(confirm_limit_verdicts(body, gains, ref, frame, s0=s0, steps_per_period=steps_per_period,
                                                locator=locator, **options), runs)


def _describe(regime, period, turns) -> str:
    """A decision's words: its regime, and on an orbit its period and its turns where it slips."""
    if regime not in dv.ORBIT_REGIMES:
        return regime
    return f"{regime}, period {period}" + (f", {turns:+d} turns" if turns else "")


def confirm_limit_verdicts(body: Body, gains: Gains, ref: Reference, frame: pd.DataFrame, *, s0=None,
                           steps_per_period: int = STEPS_PER_PERIOD, locator: str = "dense",
                           **options) -> pd.DataFrame:
    """A copy of a frame of :func:`lib.limits.verdicts.limit_verdicts` (or of
    :func:`lib.limits.verdicts.extend_undecided`, whose column ``horizon`` gives each row's
    periods observed) in which every run that claims an attractor
    (:func:`lib.dynamics.verdicts.needs_confirmation`: periodic, slipping or chaotic; every
    run here is observed past its transient) is decided again over the same horizon from its
    start moved by each relative move of :data:`MOVES` (:func:`lib.machinery.robustness.perturbed`).

    A moved run whose first decision located an orbit and that reaches that orbit within
    :data:`QUICK_PERIODS` periods (by the procedure's own test,
    :func:`lib.dynamics.verdicts.reached`) reaches the same attractor; every other moved run
    is decided in full, over the whole horizon (the procedure of
    :func:`lib.limits.verdicts.limit_verdicts`, without its measures over the run). Where the
    decisions differ (:func:`lib.dynamics.verdicts.attractor_determined`: another regime,
    such as chaotic against undecided or an orbit against none, another period, or, on
    orbits, other turns or other points, :func:`same_orbit`) the verdict becomes
    ``transient``, its period and turns 0, its orbit None, and its reason lists the
    decisions; the other columns keep the first decision's numbers.

    Column ``confirmed``: the moved starts from which the run was decided again
    (len(:data:`MOVES`)), 0 where not (undecided and quasi-periodic runs). Rows already
    confirmed (a ``confirmed`` column above 0, as after
    :func:`lib.limits.verdicts.extend_undecided` of a confirmed frame, which decides only its
    undecided rows again) are left as they are.

    Parameters
    ----------
    body : Body
        The plant and the controller's model.
    gains : Gains
        The gains of (23).
    ref : Circle or Eight
        The reference.
    frame : pandas.DataFrame
        Verdicts from the unmoved starts.
    s0 : array_like, optional
        The frame's starts, (6,) or (N, 6); default the paper's Table.
    steps_per_period : int
        Fixed steps per period, as for the frame.
    locator : {"dense", "bracket"}
        How events are located, as for the frame.
    **options
        The procedure's options, as for the frame (:data:`lib.limits.verdicts.LIMIT_DEFAULTS`).

    Returns
    -------
    pandas.DataFrame
        The frame, with ``transient`` verdicts and the column ``confirmed``.
    """
    _check_parts(body, gains, ref)
    checks.instance("frame", frame, pd.DataFrame)
    missing = [c for c in _NEEDED if c not in frame.columns]
    if missing:
        raise ValueError(f"frame lacks the columns {missing} of a limit_verdicts frame")
    o, steps_per_period, locator = _procedure(options, steps_per_period, locator)
    S0 = _start_states(s0, len(frame))
    horizon = (frame.horizon.to_numpy(dtype=int) if "horizon" in frame.columns
               else np.full(len(frame), o["periods"]))
    if np.any(horizon % o["periods"]):
        raise ValueError(f"each row's horizon must be a whole multiple of periods ({o['periods']})")
    out = frame.copy()
    out["confirmed"] = (out["confirmed"].fillna(0).to_numpy(dtype=int) if "confirmed" in out.columns
                        else np.zeros(len(out), int))
    done = out["confirmed"].to_numpy() > 0
    rows = np.flatnonzero(dv.needs_confirmation(frame.regime, o["transient"] + horizon, o["transient"]) & ~done)
    for h in np.unique(horizon[rows]):
        g = rows[horizon[rows] == h]
        _confirm_rows(out, frame, g, body, gains, ref, S0[g],
                      {**o, "periods": int(h), "block": o["block"] * int(h) // o["periods"]},
                      steps_per_period, locator)
    return out


def _reaches(frame, g, body, gains, ref, moved, o, steps_per_period, locator) -> np.ndarray:
    """Whether each run from ``moved`` (M, 6) reaches, within :data:`QUICK_PERIODS` periods, the
    orbit that the rows ``g`` of ``frame`` located, by the procedure's own test
    (:func:`lib.dynamics.verdicts.reached`, as in :func:`lib.dynamics.verdicts.find_orbits`:
    within ``reach_tol``, or within ``approach_tol`` and closing in no slower than the orbit's
    slowest multiplier allows over the last 2 ``max_period`` periods). (M,) bool."""
    b, f = frame.angle_limit.to_numpy()[g], frame.force_limit.to_numpy()[g]
    k = frame.period.to_numpy()[g].astype(int)
    first = np.stack([frame.orbit.iloc[q] for q in g])
    pmap = _SwitchedMap(body, gains, ref, b, f, steps_per_period, locator)
    pts = dv.orbit_points(pmap, np.arange(g.size), first, k)
    states = switched_runs(body, gains, ref, b, f, s0=moved, n_periods=QUICK_PERIODS,
                           steps_per_period=steps_per_period, locator=locator).states
    m = k * np.maximum(1, (2 * o["max_period"]) // k)
    d_now = dv.distance_to_orbit(states[:, -1], pts, turn_axis=2)[0]
    d_then = dv.distance_to_orbit(states[np.arange(g.size), QUICK_PERIODS - m], pts, turn_axis=2)[0]
    rho = frame.floquet.to_numpy(dtype=float)[g]
    return dv.reached(d_now, d_then, rho, m / k, tol=o["approach_tol"], floor=o["reach_tol"])


def _confirm_rows(out, frame, g, body, gains, ref, S0, o, steps_per_period, locator) -> None:
    """The rows ``g`` of ``frame`` decided again from their starts ``S0`` (M, 6) moved by each
    of :data:`MOVES`, as :func:`confirm_limit_verdicts` says (all moves in one batch of runs);
    ``confirmed`` and the ``transient`` verdicts written into ``out`` (in place)."""
    out.iloc[g, out.columns.get_loc("confirmed")] = len(MOVES)
    r1, k1, n1 = (frame[c].to_numpy()[g] for c in ("regime", "period", "turns"))
    # the batch: every row once per move, (D M,), the moves slowest
    D = len(MOVES)
    G, R1, K1, N1 = np.tile(g, D), np.tile(r1, D), np.tile(k1, D), np.tile(n1, D)
    moved = np.concatenate([[perturbed(s, rel) for s in S0] for rel in MOVES])
    R2, K2, N2 = R1.copy(), K1.copy(), N1.copy()
    same = np.ones(G.size, bool)
    has1 = np.isin(R1, dv.ORBIT_REGIMES)
    quick = np.zeros(G.size, bool)
    if has1.any():
        quick[has1] = _reaches(frame, G[has1], body, gains, ref, moved[has1], o, steps_per_period, locator)
    full = np.flatnonzero(~quick)
    if full.size:
        b, f = frame.angle_limit.to_numpy()[G[full]], frame.force_limit.to_numpy()[G[full]]
        redo = _limit_chunk(b, f, moved[full], body=body, gains=gains, ref=ref, o=o,
                            steps_per_period=steps_per_period, locator=locator, measure=False)[0]
        R2[full], K2[full], N2[full] = (redo[c].to_numpy() for c in ("regime", "period", "turns"))
        pair = np.flatnonzero(np.isin(R1[full], dv.ORBIT_REGIMES) & (R2[full] == R1[full]) & (K2[full] == K1[full])
                              & (N2[full] == N1[full]))
        same[full] = False
        if pair.size:
            both = full[pair]
            first = np.stack([frame.orbit.iloc[q] for q in G[both]])
            same[both] = same_orbit(body, gains, ref, b[pair], f[pair], first, np.stack(redo.orbit.iloc[pair]),
                                    K1[both], steps_per_period=steps_per_period, locator=locator)
    ok = dv.attractor_determined([r1] + list(R2.reshape(D, -1)), [k1] + list(K2.reshape(D, -1)),
                                 same.reshape(D, -1))
    R2, K2, N2, same = (v.reshape(D, -1) for v in (R2, K2, N2, same))
    for j in np.flatnonzero(~ok):
        words = [f"the start: {_describe(r1[j], k1[j], n1[j])}"]
        for d, rel in enumerate(MOVES):
            other = (R2[d, j], K2[d, j], N2[d, j]) == (r1[j], k1[j], n1[j]) and not same[d, j]
            words.append(f"start {'+' if rel > 0 else '-'} 1e-12: {_describe(R2[d, j], K2[d, j], N2[d, j])}"
                         + (", another orbit" if other else ""))
        i = frame.index[g[j]]
        out.loc[i, ["regime", "period", "turns", "reason"]] = [
            dv.TRANSIENT, 0, 0, "transient chaos: attractor not determined (" + "; ".join(words) + ")"]
        out.at[i, "orbit"] = None
