"""Tracking results of paper Secs. 4-5: the runs behind Figs. 2-4 and the
numbers the chapters quote (steady rotation error, position-error deviation
from the analytic solution of (24), force needed, error left by a force cap); and
(re-exported from :mod:`lib.tracking.mismatch`) tracking with a wrong model, :func:`mismatch_sweep`.

Every function takes its parameters explicitly and returns plain numbers,
arrays or DataFrames; the figures are drawn by :mod:`lib.figures.maps`.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pandas as pd
from scipy.optimize import brentq

from ..machinery import checks
from ..allocation import Allocation, Limits, allocate
from ..angles import wrap_angle
from ..closed_loop import ClosedLoop, reference_of
from ..integrators.smooth import integrate
from ..control import computed_torque, error_dynamics_solution
from ..limits.runs import switched_runs
from .mismatch import mismatch_sweep
from ..machinery.parallel import concat_frames, map_chunks, map_in_processes
from ..params import Body, Gains
from ..simulate import Integration, SimulationResult, simulate
from ..trajectories import KINEMATICS, Circle, Eight, Reference, make

__all__ = [
    "run", "steady_mask", "restrict", "rotation_error_continuous", "position_deviation_from_eq24",
    "steady_summary", "refined_summary", "eight_sensitivity", "force_cap_sweep", "saturated_intervals",
    "circle_rotation_equilibrium", "mismatch_sweep",
]


def run(body: Body, gains: Gains, name: str, R: float, theta: float, n_periods: float, *,
        samples_per_period: int = 200, **kw) -> SimulationResult:
    """Simulate tracking of the named reference ("circle" (27) or "eight" (28)) of
    radius R (m) and rate theta (rad/s) for ``n_periods`` periods from the paper's
    initial state, sampled ``samples_per_period`` times per period. Extra keywords
    go to :func:`lib.simulate.simulate` (e.g. ``limits``, ``integration``).

    Parameters
    ----------
    body : Body
        The body.
    gains : Gains
        The gains of (23).
    name : str
        ``"circle"`` or ``"eight"``.
    R : float
        Radius (m), > 0.
    theta : float
        Rate (rad/s), non-zero.
    n_periods : float
        Reference periods to run, > 0.
    samples_per_period : int
        Output samples per period (>= 1).
    **kw
        Keywords of :func:`lib.simulate.simulate`.

    Returns
    -------
    SimulationResult
        The run, sampled n_periods * samples_per_period + 1 times.
    """
    ref = make(name, R, theta)
    n_periods = checks.number("n_periods", n_periods, positive=True)
    samples_per_period = checks.integer("samples_per_period", samples_per_period, minimum=1)
    t_end = n_periods * ref.period
    n = int(round(n_periods * samples_per_period))
    return simulate(body, gains, ref, t_end, t_eval=np.linspace(0.0, t_end, n + 1), **kw)


#: what :func:`steady_mask` and the summaries read of a run (a :class:`lib.simulate.SimulationResult`)
_RUN_FIELDS = ("t", "z", "z_d", "F", "ref")


def steady_mask(res: SimulationResult, n_periods: float) -> np.ndarray:
    """Boolean mask of the samples in the last ``n_periods`` reference periods.

    Parameters
    ----------
    res : SimulationResult
        A run (:func:`lib.simulate.simulate`).
    n_periods : float
        Reference periods at the end, > 0.

    Returns
    -------
    numpy.ndarray
        One bool per sample.
    """
    missing = [k for k in _RUN_FIELDS if not hasattr(res, k)]
    if missing:
        raise TypeError(f"res must be a run of lib.simulate.simulate (a SimulationResult), got "
                        f"{type(res).__name__}, which has no attribute {', '.join(missing)}")
    n_periods = checks.number("n_periods", n_periods, positive=True)
    if n_periods * res.ref.period > res.t[-1] - res.t[0] + 1e-9:
        raise ValueError(f"n_periods = {n_periods!r} periods ({n_periods * res.ref.period:g} s) is longer than the run "
                         f"({res.t[-1] - res.t[0]:g} s): the window would hold the transient from the start")
    return res.t >= res.t[-1] - n_periods * res.ref.period - 1e-9


def restrict(res: SimulationResult, mask) -> SimulationResult:
    """The samples of ``res`` selected by the boolean ``mask`` (e.g. :func:`steady_mask`).

    Parameters
    ----------
    res : SimulationResult
        A run (:func:`lib.simulate.simulate`).
    mask : array_like
        One bool per sample, not all False.

    Returns
    -------
    SimulationResult
        The selected samples.
    """
    mask = np.asarray(mask, dtype=bool)
    if mask.shape != res.t.shape or not mask.any():
        raise ValueError("mask must be a boolean array like res.t selecting at least one sample")
    fields = ("t", "z", "dz", "z_d", "dz_d", "F", "beta", "tau")
    extra = {"mode": res.mode[mask]} if res.mode is not None else {}
    return replace(res, **{k: getattr(res, k)[mask] for k in fields}, **extra)


def rotation_error_continuous(res: SimulationResult) -> np.ndarray:
    """Rotation error p = phi - phi_d (rad), continuous in time, shifted by a multiple of
    2 pi so that its final value lies in (-pi, pi].

    Parameters
    ----------
    res : SimulationResult
        A run (:func:`lib.simulate.simulate`).

    Returns
    -------
    numpy.ndarray
        p (rad) per sample.
    """
    p = np.unwrap(res.rotation_error())
    shift = 2 * np.pi * np.round((p[-1] - wrap_angle(p[-1])) / (2 * np.pi))
    return p - shift


def position_deviation_from_eq24(body: Body, gains: Gains, res: SimulationResult) -> float:
    """Largest |e_sim - e_(24)| (m) over x and y, e_(24) the analytic solution of (24)
    from the simulated initial error.

    Parameters
    ----------
    body : Body
        The body.
    gains : Gains
        The gains of (23).
    res : SimulationResult
        A run (:func:`lib.simulate.simulate`).

    Returns
    -------
    float
        The largest deviation (m).
    """
    exact = error_dynamics_solution(body, gains, res.error[0], res.derror[0], res.t)
    return float(np.abs(res.error[:, :2] - exact[:, :2]).max())


def steady_summary(res: SimulationResult, n_periods: float = 2.0) -> dict:
    """Steady-state measures over the last ``n_periods`` periods: range of the rotation
    error p (rad), largest position error (m) and the range of the force F (N).

    Parameters
    ----------
    res : SimulationResult
        A run (:func:`lib.simulate.simulate`).
    n_periods : float
        Reference periods at the end, > 0.

    Returns
    -------
    dict
        p_min, p_max, p_range (rad), pos_err_max (m), F_min, F_max, F_mean (N).
    """
    mask = steady_mask(res, n_periods)
    p = rotation_error_continuous(res)[mask]
    e = np.hypot(res.error[mask, 0], res.error[mask, 1])
    return {"p_min": float(p.min()), "p_max": float(p.max()), "p_range": float(p.max() - p.min()),
            "pos_err_max": float(e.max()), "F_min": float(res.F[mask].min()), "F_max": float(res.F[mask].max()),
            "F_mean": float(res.F[mask].mean())}


def _parabola_extreme(y, i: int, sign: float) -> float:
    """Extreme of the parabola through y[i-1], y[i], y[i+1] (y[i] at an end or without curvature)."""
    if i == 0 or i == len(y) - 1:
        return float(y[i])
    ym, y0, yp = y[i - 1], y[i], y[i + 1]
    curv = ym - 2 * y0 + yp
    return float(y0 - (ym - yp) ** 2 / (8 * curv)) if sign * curv < 0 else float(y0)


def refined_summary(body: Body, gains: Gains, res: SimulationResult, n_periods: float = 2.0, *,
                    limits: Limits | None = None, allocation: Allocation | None = None,
                    n_fine: int = 401) -> dict:
    """:func:`steady_summary` with the extremes of the force F (N) and of the rotation error
    p (rad) taken on the continuous signal, not on the samples: around each sampled extreme
    the closed loop (:class:`lib.closed_loop.ClosedLoop`, with the ``limits`` and
    ``allocation`` of the run) is integrated again from the sample before it to the sample
    after it, at ``n_fine`` points and rtol = atol = 1e-12, and the extreme refined by the
    parabola through the finest samples (error of order (h / n_fine)^3).

    Parameters
    ----------
    body : Body
        The body.
    gains : Gains
        The gains of (23).
    res : SimulationResult
        A run (:func:`lib.simulate.simulate`).
    n_periods : float
        Reference periods at the end, > 0.
    limits : Limits, optional
        The run's limits.
    allocation : Allocation, optional
        The run's allocation.
    n_fine : int
        Points of each refining run.

    Returns
    -------
    dict
        The keys of :func:`steady_summary`, refined.
    """
    out = steady_summary(res, n_periods)
    loop = ClosedLoop.of(body, gains, reference_of(res.ref), allocation, limits)
    idx = np.flatnonzero(steady_mask(res, n_periods))
    p = rotation_error_continuous(res)
    shift = p - res.rotation_error()
    tight = Integration(rtol=1e-12, atol=1e-12)

    def fine(i):
        """t, F and p on n_fine points between the samples beside sample i."""
        a, b = max(i - 1, idx[0]), min(i + 1, idx[-1])
        t0 = res.t[a]
        tau = np.linspace(0.0, res.t[b] - t0, n_fine)
        _, S = integrate(lambda t, s: loop.rates(t0 + t, s)[0], np.concatenate([res.z[a], res.dz[a]]),
                         float(tau[-1]), tau, tight, ("x", "y", "phi", "xdot", "ydot", "phidot"))
        t = t0 + tau
        F = loop.inputs(t, S[:, :3], S[:, 3:])[1]
        return F, S[:, 2] - res.ref.z(t)[:, 2] + shift[i]

    for key, values, sign, pick in (("F_min", res.F, -1.0, 0), ("F_max", res.F, 1.0, 0),
                                    ("p_min", p, -1.0, 1), ("p_max", p, 1.0, 1)):
        v = sign * values[idx]
        # every sampled local extreme close to the best one (one per period, say) is refined
        local = np.flatnonzero((v >= np.roll(v, 1)) & (v >= np.roll(v, -1)))
        near = local[v[local] >= v.max() - 0.01 * max(np.ptp(v), 1e-12)]
        best = []
        for i in idx[near]:
            y = fine(i)[pick]
            best.append(sign * _parabola_extreme(y, int(np.argmax(sign * y)), sign))
        out[key] = sign * max(best)
    out["p_range"] = out["p_max"] - out["p_min"]
    return out


def eight_sensitivity(body: Body, gains: Gains, Rs, thetas, *, n_periods: float = 12.0,
                      n_steady: float = 2.0, workers: int = 1, executor=None,
                      chunk_size: int | None = None, progress: bool | None = None) -> pd.DataFrame:
    """Steady-state measures of eight tracking (:func:`steady_summary`) over a grid of
    radii R (m) and rates theta (rad/s); one row per (R, theta). A run whose rotation
    does not settle to a periodic motion shows a large ``p_range``. The run's end state
    is returned too, so that a verdict can continue it: ``p_end`` (rad, in (-pi, pi]),
    ``dp_end`` (rad/s), the heading error and its rate, and ``e_end`` (m), the largest
    position error (the reduced rotation equation holds once it is negligible).
    ``workers`` spawned processes share the runs (:func:`lib.machinery.parallel.map_in_processes`);
    or, with an ``executor`` (any :class:`concurrent.futures.Executor`, not with
    ``workers`` > 1), the runs go to it in chunks of ``chunk_size``
    (:func:`lib.machinery.parallel.map_chunks`). Each run is on its own: the same frame either way.

    Parameters
    ----------
    body : Body
        The body.
    gains : Gains
        The gains of (23).
    Rs : array_like
        Radii R (m), > 0.
    thetas : array_like
        Rates theta (rad/s), non-zero.
    n_periods : float
        Periods per run, > 0.
    n_steady : float
        Last periods measured, > 0.
    workers : int
        Spawned processes (>= 1), not with ``executor``.
    executor : concurrent.futures.Executor, optional
        Where the chunks of runs go.
    chunk_size : int, optional
        Runs per chunk.
    progress : bool, optional
        A progress bar on stderr (:func:`lib.machinery.parallel.show_progress`; default None: only when
        run interactively, never under pytest or in the book build).

    Returns
    -------
    pandas.DataFrame
        One row per (R, theta), R varying slowest; the columns of :func:`steady_summary`
        and p_end (rad), dp_end (rad/s), e_end (m).
    """
    checks.instance("body", body, Body)
    checks.instance("gains", gains, Gains)
    Rs = np.atleast_1d(checks.array("Rs", Rs, positive=True))
    thetas = np.atleast_1d(checks.array("thetas", thetas))
    n_periods = checks.number("n_periods", n_periods, positive=True)
    n_steady = checks.number("n_steady", n_steady, positive=True)
    workers = checks.integer("workers", workers, minimum=1)
    items = [(body, gains, float(R), float(th), n_periods, n_steady) for R in Rs for th in thetas]
    if executor is None and chunk_size is None or not items:
        return pd.DataFrame(map_in_processes(_sensitivity_one, items, workers, progress))
    if workers != 1:
        raise ValueError(f"give workers (> 1) or an executor/chunk_size, not both (workers = {workers!r})")
    parts = map_chunks(_sensitivity_chunk, len(items), (items,), None, executor, chunk_size, progress)
    return pd.DataFrame([row for part in parts for row in part])


def _sensitivity_chunk(items) -> list:
    return [_sensitivity_one(x) for x in items]


def _sensitivity_one(args) -> dict:
    body, gains, R, th, n_periods, n_steady = args
    res = run(body, gains, "eight", R, th, n_periods,
              integration=Integration(rtol=1e-9, atol=1e-9))
    return {"R": R, "theta": th, **steady_summary(res, n_steady),
            "p_end": float(wrap_angle(res.rotation_error()[-1])),
            "dp_end": float(res.dz[-1, 2] - res.dz_d[-1, 2]),
            "e_end": float(np.abs(res.error[-1, :2]).max())}


def saturated_intervals(t, F, cap: float, rel: float = 1e-9) -> list[tuple[float, float]]:
    """Time intervals (s) on which the force sits at its cap, F >= cap (1 - rel).

    Parameters
    ----------
    t : array_like
        Times (s), 1-D.
    F : array_like
        Force (N), as long as t.
    cap : float
        The cap (N).
    rel : float
        Relative tolerance.

    Returns
    -------
    list of tuple
        (start (s), end (s)) of each interval at the cap.
    """
    t, F = np.asarray(t, dtype=float), np.asarray(F, dtype=float)
    if t.shape != F.shape or t.ndim != 1:
        raise ValueError("t and F must be 1-D arrays of the same length")
    sat = F >= cap * (1 - rel)
    edges = np.flatnonzero(np.diff(sat.astype(int)))
    starts = list(t[edges[sat[edges + 1]] + 1]) if edges.size else []
    ends = list(t[edges[~sat[edges + 1]]]) if edges.size else []
    if sat[0]:
        starts.insert(0, t[0])
    if sat[-1]:
        ends.append(t[-1])
    return [(float(a), float(b)) for a, b in zip(starts, ends)]


def force_cap_sweep(body: Body, gains: Gains, ref: Reference, caps, *, n_periods: int = 10,
                    n_steady: int = 2, samples_per_period: int = 400, executor=None,
                    chunk_size: int | None = None, progress: bool | None = None) -> pd.DataFrame:
    """Steady position-error amplitude (m) of tracking ``ref`` (the circle or the eight) with
    F <= cap and no angle limit, for each cap (N), from the paper's initial state.

    All caps run together in the compiled integrator (:func:`lib.limits.runs.switched_runs`,
    which locates the cap's kinks), sampled ``samples_per_period`` times per period.
    Columns: ``cap``, ``pos_err_max`` (largest |(e_x, e_y)| over the last ``n_steady``
    periods), ``pos_err_rms`` (its RMS over the same periods, each sample time once), ``ex_amp``, ``ey_amp`` (half peak-to-peak of each component) and
    ``sat_fraction`` (fraction of the samples at the cap). With an ``executor`` (any
    :class:`concurrent.futures.Executor`) the caps go to it in chunks of ``chunk_size``
    (:func:`lib.machinery.parallel.map_chunks`); each run is on its own: the same frame.

    Parameters
    ----------
    body : Body
        The body.
    gains : Gains
        The gains of (23).
    ref : Reference
        The circle or the eight.
    caps : array_like
        Force caps F_max (N), > 0, 1-D.
    n_periods : int
        Periods per run (>= 2).
    n_steady : int
        Last periods measured (>= 1, < n_periods).
    samples_per_period : int
        Samples (and fixed steps) per period (>= 16).
    executor : concurrent.futures.Executor, optional
        Where the chunks of caps go.
    chunk_size : int, optional
        Caps per chunk.
    progress : bool, optional
        A progress bar on stderr (:func:`lib.machinery.parallel.show_progress`; default None: only when
        run interactively, never under pytest or in the book build).

    Returns
    -------
    pandas.DataFrame
        One row per cap: cap (N), pos_err_max (m), pos_err_rms (m), ex_amp (m), ey_amp (m), sat_fraction.
    """
    caps = np.atleast_1d(checks.array("caps", caps, positive=True))
    if caps.ndim != 1 or caps.size == 0:
        raise ValueError(f"caps must be a 1-D array of forces (N), not empty, got {caps!r}")
    n_periods = checks.integer("n_periods", n_periods, minimum=2)
    n_steady = checks.integer("n_steady", n_steady, minimum=1)
    samples_per_period = checks.integer("samples_per_period", samples_per_period, minimum=16)
    if not n_steady < n_periods:
        raise ValueError(f"need 0 < n_steady < n_periods, got {n_steady!r} and {n_periods!r}")
    checks.instance("body", body, Body)
    checks.instance("gains", gains, Gains)
    checks.instance("ref", ref, (Circle, Eight), "lib.trajectories.Circle or Eight")
    # its runs take samples_per_period fixed steps a period: stiff gains are refused here, naming them
    checks.loop_domain(body, gains, KINEMATICS["circle" if isinstance(ref, Circle) else "eight"], [ref.R],
                       [ref.theta], heading_gains=False, names=("ref.R", "ref.theta"), steps=samples_per_period,
                       option="samples_per_period")
    parts = map_chunks(_cap_chunk, caps.size, (caps,), dict(body=body, gains=gains, ref=ref, n_periods=n_periods,
                       n_steady=n_steady, samples_per_period=samples_per_period), executor, chunk_size,
                       progress)
    return concat_frames(parts)


def _cap_chunk(caps, *, body, gains, ref, n_periods, n_steady, samples_per_period) -> pd.DataFrame:
    """The rows of :func:`force_cap_sweep` for validated caps (one chunk of them)."""
    runs = switched_runs(body, gains, ref, np.pi, caps, n_periods=int(n_periods), samples_per_period=samples_per_period,
                         steps_per_period=samples_per_period)
    m = runs.t >= runs.t[-1] - n_steady * ref.period - 1e-9
    rows = []
    for j, cap in enumerate(caps):
        e = runs.errors[j, m]
        st = runs.states[j, m]
        tau = computed_torque(body, gains, ref, runs.t[m], st[:, :3], st[:, 3:])
        F, _ = allocate(tau, st[:, 2], force_limit=float(cap))      # (25)-(26) with the cap
        d = np.hypot(e[:, 0], e[:, 1])
        rows.append({"cap": float(cap), "pos_err_max": float(d.max()), "pos_err_rms": float(np.sqrt(np.mean(d[1:]**2))),
                     "ex_amp": float(np.ptp(e[:, 0]) / 2), "ey_amp": float(np.ptp(e[:, 1]) / 2),
                     "sat_fraction": float(np.mean(F >= cap * (1 - 1e-9)))})
    return pd.DataFrame(rows)


def circle_rotation_equilibrium(body: Body, R: float, theta: float) -> float:
    """Stable steady rotation error p* (rad) of circle tracking, found numerically.

    With the position tracked exactly, the torque of the allocated force is
    a (tau_y cos(phi) - tau_x sin(phi)) and eq. (4) becomes, for p = phi - theta t - pi/2,
    I p'' + c_phi (p' + theta) = a R theta (m theta cos p - c sin p).
    This function finds the roots of the right-hand side minus c_phi theta by
    bracketing on a grid and :func:`scipy.optimize.brentq`, and returns the one
    where the torque decreases with p (stable). Raises ValueError when no
    equilibrium exists (R below the critical radius, Chapter 5).

    Parameters
    ----------
    body : Body
        The body.
    R : float
        Radius (m).
    theta : float
        Angular rate (rad/s).

    Returns
    -------
    float
        p* (rad).
    """
    def g(p):
        return body.a * R * theta * (body.m * theta * math.cos(p) - body.c * math.sin(p)) - body.c_phi * theta

    grid = np.linspace(-math.pi, math.pi, 721)
    vals = np.array([g(p) for p in grid])
    roots = [brentq(g, grid[i], grid[i + 1], xtol=1e-14) for i in np.flatnonzero(np.diff(np.sign(vals)) != 0)]
    stable = [r for r in roots if g(r + 1e-6) < g(r - 1e-6)]
    if not stable:
        raise ValueError(f"no rotation equilibrium for R = {R} m, theta = {theta} rad/s")
    return float(stable[0])
