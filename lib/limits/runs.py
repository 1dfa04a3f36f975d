"""The switched closed loop of paper Sec. 5 run many times at once (Chapter 4): the
compiled, event-located fixed-step integrator (:mod:`lib.integrators.switched_compiled`)
behind a checked entry point, :func:`switched_runs`, and the tracking error state
(:func:`error_state`) its samples are read in. :mod:`lib.limits` decides verdicts on these
runs and re-exports both names.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..machinery import checks
from ..angles import wrap_angle
from ..integrators.batch import dop853
from ..integrators.switched_compiled import dop853_dense, run_periods
from ..params import PAPER_DZ0, PAPER_Z0, Body, Gains
from ..trajectories import KINEMATICS, Circle, Eight, Reference

__all__ = ["error_state", "SwitchedRuns", "switched_runs", "STEPS_PER_PERIOD", "LOCATORS"]

def error_state(ref: Reference, t, y) -> np.ndarray:
    """Tracking errors of states ``y`` (n, 6) at times ``t``: columns
    [e_x (m), e_y (m), de_x (m/s), de_y (m/s), p (rad), dp (rad/s)] with
    e = z_d - z as in (24) and the rotation error p = phi - phi_d wrapped to (-pi, pi].

    Parameters
    ----------
    ref : Reference
        The reference.
    t : array_like
        Times (s), (n,).
    y : array_like
        States [x, y, phi, xdot, ydot, phidot] (m, m, rad, m/s, m/s, rad/s), (n, 6).

    Returns
    -------
    numpy.ndarray
        The error states (n, 6) in the units above.
    """
    t = np.asarray(t, dtype=float)
    y = np.atleast_2d(np.asarray(y, dtype=float))
    zd, dzd = ref.z(t), ref.dz(t)
    p = y[:, 2] - zd[:, 2]
    p = wrap_angle(p)
    return np.column_stack([zd[:, 0] - y[:, 0], zd[:, 1] - y[:, 1], dzd[:, 0] - y[:, 3], dzd[:, 1] - y[:, 4],
                            p, y[:, 5] - dzd[:, 2]])


@dataclass(frozen=True)
class SwitchedRuns:
    """N runs of the switched closed loop by the compiled integrator
    (:func:`switched_runs`): ``states`` (N, n S + 1, 6) at the sample times t = k T / S
    (``t`` (n S + 1,), s; S samples per period, by default one), the error states there (``errors``, see :func:`error_state`),
    the final modes, ``log_growth`` (N, n_lyap) the companion's log(d / d0) over each
    period from ``lyapunov_from`` on, and the crossings of S, slides and time sliding (s)
    of each run; ``locating`` (N, 3): its events, the real steps spent locating them and the
    dense estimates handed on to the bracket locator (:mod:`lib.integrators.switched_events`);
    with ``record`` given to :func:`switched_runs`, ``recorded`` (N, m, 6) the same runs' states
    at the times ``recorded_t`` (m,), s (else both None)."""

    angle_limit: np.ndarray
    force_limit: np.ndarray
    period: float
    t: np.ndarray
    states: np.ndarray
    errors: np.ndarray
    mode_end: np.ndarray
    log_growth: np.ndarray
    lyapunov_from: int
    crossings: np.ndarray
    slides: np.ndarray
    t_sliding: np.ndarray
    locating: np.ndarray
    recorded: np.ndarray | None = None
    recorded_t: np.ndarray | None = None


#: steps of the compiled integrator per reference period (8th-order Dormand-Prince)
STEPS_PER_PERIOD = 200
#: how the compiled integrator locates events, on the step's dense output then one real step
#: (the default) or by real steps only (:mod:`lib.integrators.switched_events`)
LOCATORS = ("dense", "bracket")


def _limits_arrays(angle_limits, force_limits):
    b = np.atleast_1d(checks.array("angle_limits", angle_limits))
    f = np.atleast_1d(checks.array("force_limits", np.inf if force_limits is None else force_limits, finite=False))
    if b.ndim != 1 or f.ndim != 1 or b.size == 0:
        raise ValueError("angle_limits and force_limits must be scalars or 1-D arrays, not empty")
    try:
        b, f = np.broadcast_arrays(b, f)
    except ValueError:
        raise ValueError(f"angle_limits ({b.size}) and force_limits ({f.size}) must have equal lengths "
                         "(or length 1)") from None
    if not np.all((b > 0) & (b <= np.pi)):
        i = int(np.flatnonzero(~((b > 0) & (b <= np.pi)))[0])
        raise ValueError(f"angle_limits[{i}] must be in (0, pi] rad, got {float(b[i])!r}")
    if np.any(np.isnan(f)) or not np.all(f > 0):
        i = int(np.flatnonzero(np.isnan(f) | ~(f > 0))[0])
        where = f"[{i}]" if np.ndim(force_limits) else ""
        raise ValueError(f"force_limits{where} must be positive (N), or inf or None for no force limit, "
                         f"got {float(f[i])!r}")
    return b.copy(), f.copy()


def _check_parts(body, gains, ref, steps: int | None = None, option: str = "steps_per_period") -> None:
    """The body, gains and reference of a switched run (TypeError naming a wrong one), and the run's
    domain: with ``steps``, the fixed steps a period it takes (``option``) must follow its fastest mode,
    or stiff gains are refused at once, naming the gains (issue 59), instead of a run that diverges."""
    checks.instance("body", body, Body)
    checks.instance("gains", gains, Gains)
    checks.instance("ref", ref, (Circle, Eight), "lib.trajectories.Circle or Eight")
    checks.loop_domain(body, gains, KINEMATICS["circle" if isinstance(ref, Circle) else "eight"], [ref.R],
                       [ref.theta], heading_gains=False, names=("ref.R", "ref.theta"), steps=steps,
                       option=option)   # before any run (issue 37)


def _start_states(s0, n: int) -> np.ndarray:
    """The start of each of ``n`` runs (n, 6): the paper's initial state, or ``s0`` (6,) or (n, 6)."""
    S0 = np.concatenate([PAPER_Z0, PAPER_DZ0]) if s0 is None else checks.array("s0", s0)
    S0 = np.broadcast_to(S0, (n, 6)) if S0.shape == (6,) or S0.shape == (1, 6) else S0
    if S0.shape != (n, 6) or not np.all(np.isfinite(S0)):
        raise ValueError(f"s0 must be a finite state (6,) or one per run ({n}, 6), got shape {S0.shape}")
    return S0


def _concat_runs(parts: list) -> SwitchedRuns:
    """The :class:`SwitchedRuns` of consecutive chunks of runs as one (the runs in order)."""
    if len(parts) == 1:
        return parts[0]
    shared = ("period", "t", "lyapunov_from", "recorded_t")
    if parts[0].recorded is None:
        shared += ("recorded",)
    return SwitchedRuns(**{name: getattr(parts[0], name) if name in shared else
                           np.concatenate([getattr(r, name) for r in parts])
                           for name in SwitchedRuns.__dataclass_fields__})


def switched_runs(body: Body, gains: Gains, ref: Reference, angle_limits, force_limits=None, *, s0=None,
                  n_periods: int, lyapunov_from: int | None = None, steps_per_period: int = STEPS_PER_PERIOD,
                  samples_per_period: int = 1, d0: float = 1e-7, k_slide: float = 5.0,
                  locator: str = "dense", record: tuple[int, int] | None = None) -> SwitchedRuns:
    """Run the closed loop (2)-(4), (23), (25)-(26) with |beta| <= ``angle_limits`` (rad;
    pi for no angle limit) and F <= ``force_limits`` (N; None or inf for no cap), one run
    per pair, for ``n_periods`` reference periods from the states ``s0`` ((6,) or (N, 6);
    default the paper's initial state) at t = 0, by the compiled event-located integrator
    (:mod:`lib.integrators.switched_compiled`), recording the state ``samples_per_period``
    times per period (it must divide ``steps_per_period``). With ``lyapunov_from`` = k
    (only with one sample per period) a companion run starts d0 (m, rad, m/s, rad/s: the
    plain Euclidean distance of states) away at the end of period k and is renormalised
    every period (Benettin). With ``record`` = (k, S') the same runs' states are also kept
    S' times a period from the start of period k on (``recorded``; S' divides
    ``steps_per_period``; only with one sample per period): the states of the run itself,
    read at the ends of its steps, the run unchanged.

    ``ref`` must be the circle or the eight (:mod:`lib.trajectories`). Raises
    ``RuntimeError`` naming the run if its state becomes non-finite or the switching
    events accumulate (more than 200 in one step).

    Parameters
    ----------
    body : Body
        The body.
    gains : Gains
        The gains of (23).
    ref : Circle or Eight
        The reference.
    angle_limits : float or array_like
        beta_max (rad), in (0, pi], one or one per run.
    force_limits : float or array_like, optional
        F_max (N), > 0 (inf or None for none), one or one per run.
    s0 : array_like, optional
        Start states (m, rad, m/s, rad/s), (6,) or (N, 6).
    n_periods : int
        Reference periods (>= 1).
    lyapunov_from : int, optional
        Period from which the Lyapunov companion runs.
    steps_per_period : int
        Fixed steps per period (>= 16).
    samples_per_period : int
        Recorded states per period (divides ``steps_per_period``).
    d0 : float
        The companion's initial separation, in (0, 1e-3).
    k_slide : float
        The sliding exits' gain.
    locator : {"dense", "bracket"}
        How events are located (:data:`LOCATORS`): on the step's 7th-order dense output,
        then one real step, or by real steps only; both to 1e-11 s.
    record : tuple of int, optional
        (first period k, samples per period S'), 0 <= k < ``n_periods``.

    Returns
    -------
    SwitchedRuns
        The limits, the sample times, the recorded states and errors, the final modes, the
    companion's log-growths and the event statistics (crossings, slides, time sliding).
    """
    steps_per_period = checks.integer("steps_per_period", steps_per_period, minimum=16)
    _check_parts(body, gains, ref, steps_per_period)
    b, f = _limits_arrays(angle_limits, force_limits)
    n_periods = checks.integer("n_periods", n_periods, minimum=1)
    lf = -1 if lyapunov_from is None else checks.integer("lyapunov_from", lyapunov_from)
    if lyapunov_from is not None and not 0 <= lf < n_periods - 1:
        raise ValueError(f"lyapunov_from must be in [0, n_periods - 1), got {lyapunov_from!r}")
    S = checks.integer("samples_per_period", samples_per_period, minimum=1)
    if steps_per_period % S:
        raise ValueError(f"samples_per_period must be a positive integer dividing steps_per_period "
                         f"({steps_per_period}), got {S!r}")
    if S > 1 and lyapunov_from is not None:
        raise ValueError("the Lyapunov companion needs samples_per_period = 1")
    if record is not None:
        if S > 1:
            raise ValueError("record needs samples_per_period = 1")
        rec = tuple(record)
        if len(rec) != 2:
            raise ValueError(f"record must be (first period, samples per period), got {record!r}")
        k_rec = checks.integer("record[0]", rec[0], minimum=0)
        s_rec = checks.integer("record[1]", rec[1], minimum=1)
        if k_rec >= n_periods or steps_per_period % s_rec:
            raise ValueError(f"record must be (k, S) with k < n_periods ({n_periods}) and S dividing "
                             f"steps_per_period ({steps_per_period}), got {record!r}")
        record = (k_rec, s_rec)
    if not checks.number("d0", d0, positive=True) < 1e-3:
        raise ValueError(f"d0 must be in (0, 1e-3), got {d0!r}")
    locator = checks.one_of("locator", locator, LOCATORS)
    S0 = _start_states(s0, b.size)
    g = gains
    P = np.array([body.m, body.I, body.a, body.c, body.c_phi, g.kp[0], g.kp[1], g.kv[0], g.kv[1], ref.R, ref.theta,
                  k_slide, 0.0 if isinstance(ref, Circle) else 1.0])
    tab = dop853()
    T = ref.period
    # with S samples per period the kernel's "period" is T / S: the reference is T-periodic,
    # the kernel only needs the sampling interval and the steps within it
    states, modes, logs, stats, recorded = run_periods(
        P, b, f, S0, int(n_periods) * S, int(steps_per_period) // S, T / S, 0.0, lf, float(d0), tab.A,
        tab.b / tab.b_den, tab.c, dense_output=dop853_dense() if locator == "dense" else None, record=record)
    bad = np.flatnonzero(stats[:, 4] != 0)
    if bad.size:
        q = int(bad[0])
        why = "events accumulated (more than 200 in one step)" if stats[q, 4] == 1 else "the state became non-finite"
        raise RuntimeError(f"switched run {q} (angle limit {np.degrees(b[q]):.6g} deg, force limit {f[q]:g} N): "
                           f"{why}")
    t = np.arange(n_periods * S + 1) * (T / S)
    err = error_state(ref, np.tile(t, b.size), states.reshape(-1, 6)).reshape(states.shape)
    return SwitchedRuns(angle_limit=b, force_limit=f, period=T, t=t, states=states, errors=err, mode_end=modes,
                        log_growth=logs, lyapunov_from=lf, crossings=stats[:, 0].astype(int),
                        slides=stats[:, 1].astype(int), t_sliding=stats[:, 2],
                        locating=stats[:, [3, 5, 6]].astype(int), recorded=recorded,
                        recorded_t=None if record is None else
                        (record[0] * record[1] + np.arange(recorded.shape[1])) * (T / record[1]))
