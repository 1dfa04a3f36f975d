"""Closed-loop simulation of eqs. (2)-(4) under the computed-torque law (23) with an
allocation (by default the paper's position-only (25)-(26)) and optional limits.

:func:`simulate` takes its options grouped: a :class:`lib.allocation.Limits`, a
:class:`lib.allocation.Allocation` and an :class:`Integration`. With
``Integration(switching="stepsize")`` the closed loop
(:class:`lib.closed_loop.ClosedLoop`) is integrated by one adaptive ``solve_ivp``
run (:mod:`lib.integrators.smooth`); with an angle limit the field is then only
piecewise smooth and the step-size control resolves the switching, at a cost that
grows without bound along a sliding motion. ``Integration(switching="events")``
locates every crossing of the switching surface and slides along it
(:mod:`lib.integrators.switched`); the default, ``"auto"``, takes it wherever it
applies (an angle limit below pi on the position-only law, the plant its own model).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import pandas as pd

from .machinery import checks
from .allocation import Allocation, Limits
from .closed_loop import ClosedLoop, paper_rates, reference_of
from .integrators.smooth import Integration, SimulationError, integrate
from .integrators.switched import SwitchedLoop
from .model import config_accel, config_from_state, state_from_config, state_rhs
from .params import PAPER_DZ0, PAPER_Z0, Body, Gains
from .trajectories import Circle, Eight, Reference

__all__ = ["SimulationError", "SimulationResult", "simulate", "Integration", "simulate_open_loop",
           "open_loop_comparison", "OPEN_LOOP_FORMS", "DEFAULT_RTOL", "DEFAULT_ATOL", "run_budget", "default_times",
           "IMPLICIT_STEPS_PER_RADIAN"]

#: the default tolerances of :class:`Integration`
DEFAULT_RTOL = Integration.rtol
DEFAULT_ATOL = Integration.atol
#: points per second of the default output grid
DEFAULT_RATE = 20.0
_NAMES = ("x", "y", "phi", "xdot", "ydot", "phidot")


@dataclass(frozen=True)
class SimulationResult:
    """Sampled closed-loop solution.

    ``t`` (s), shape (n,); ``z`` = [x, y, phi] and ``dz`` its rate, shape (n, 3);
    ``z_d`` the reference at ``t``; ``F`` (N) and ``beta`` (rad) the applied
    inputs, shape (n,); ``tau`` the computed-torque demand (23), shape (n, 3).
    """

    t: np.ndarray
    z: np.ndarray
    dz: np.ndarray
    z_d: np.ndarray
    dz_d: np.ndarray
    F: np.ndarray
    beta: np.ndarray
    tau: np.ndarray
    ref: Reference
    #: with ``Integration(switching="events")``: +1 / -1 the side of the angle-limit
    #: switching surface, 0 sliding on it (see :class:`lib.integrators.switched.SwitchedLoop`); else None
    mode: np.ndarray | None = None

    @property
    def error(self) -> np.ndarray:
        """Tracking error e = z_d - z of eq. (24), shape (n, 3)."""
        return self.z_d - self.z

    @property
    def derror(self) -> np.ndarray:
        """Rate of the tracking error, de = dz_d - dz, shape (n, 3)."""
        return self.dz_d - self.dz

    def rotation_error(self) -> np.ndarray:
        """Rotation error p = phi - phi_d (rad) as in Sec. 6 (note: the opposite sign of e_phi)."""
        return self.z[:, 2] - self.z_d[:, 2]

    def to_frame(self) -> pd.DataFrame:
        """All samples as a DataFrame, one row per time, SI units in column names."""
        e = self.error
        return pd.DataFrame({
            "t_s": self.t,
            "x_m": self.z[:, 0], "y_m": self.z[:, 1], "phi_rad": self.z[:, 2],
            "xd_m": self.z_d[:, 0], "yd_m": self.z_d[:, 1], "phid_rad": self.z_d[:, 2],
            "ex_m": e[:, 0], "ey_m": e[:, 1], "ephi_rad": e[:, 2],
            "F_N": self.F, "beta_rad": self.beta,
        })


def _vector(name: str, value, default) -> np.ndarray:
    return checks.array(name, default if value is None else value, shape=(3,))


def _instance(name: str, value, cls):
    return cls() if value is None else checks.instance(name, value, cls)


#: explicit methods of :func:`scipy.integrate.solve_ivp` (their step is bounded by stability)
EXPLICIT_METHODS = ("RK23", "RK45", "DOP853")


#: an implicit method's cost of one radian of an oscillating mode, counted in the steps of
#: :data:`lib.machinery.domain.MAX_RUN_STEPS` (measured on the closed loop: Radau 4 to 31 ms a
#: radian, DOP853's ten steps 0.3 to 1.2 ms; at 30 the budget holds a Radau run to about 40 s of
#: CPU); a decaying mode costs it nothing (Radau is L-stable)
IMPLICIT_STEPS_PER_RADIAN = 30.0


def _round_down(x: float) -> float:
    """``x`` > 0 rounded down to 3 significant digits (a bound that stays one when printed)."""
    e = 10.0 ** (np.floor(np.log10(x)) - 2)
    return float(np.floor(x / e) * e)


def run_budget(body: Body, ref, t_end: float, integration, modes) -> None:
    """Refuse, before any work, a run whose fastest mode would make its method take more than
    :data:`lib.machinery.domain.MAX_RUN_STEPS` steps, naming the argument that sets it and a fix
    that works: an explicit method pays for every mode (:func:`lib.machinery.domain.run_steps`),
    an implicit one for the oscillating modes only, at :data:`IMPLICIT_STEPS_PER_RADIAN`; a stiff
    method is advised only where it would be inside the budget, else the longest t_end that is.
    On the book's paths, also a heading damped too slowly
    (:func:`lib.machinery.domain.heading_damping`). The one check of :func:`simulate` and of the
    law for P's run (:func:`lib.percussion.run.simulate`).

    Parameters
    ----------
    body : Body
        The body.
    ref : Reference
        The path.
    t_end : float
        The run's end time (s).
    integration : Integration
        Its method and tolerances.
    modes : callable
        (the path's largest speed (m/s), acceleration (m/s^2)) -> dict of argument name -> the
        fastest mode it sets (complex, 1/s), ``"ref"`` for the heading driven by the path.

    Returns
    -------
    None
    """
    if isinstance(ref, (Circle, Eight)):         # the book's paths: the heading's domain, as every sweep's
        checks.heading_damping(body, ref.theta, "ref.theta")
    found = modes(*checks.path_extremes(ref))
    named = {"ref": f"ref (R = {ref.R:g} m, theta = {ref.theta:g} rad/s)"} if isinstance(ref, (Circle, Eight)) else {}
    if named and "body and gains" in found and np.any(checks.rate_culprit(body, ref.theta, found["body and gains"])):
        # the gains' mode costs what it does because the path is slow, not because the gains are stiff
        named["body and gains"] = f"ref.theta = {ref.theta:g} rad/s (a period of {ref.period:.3g} s)"
    explicit = integration.method in EXPLICIT_METHODS

    def per_second(mode, stiff: bool) -> float:
        mode = complex(mode)
        if stiff:
            return IMPLICIT_STEPS_PER_RADIAN * abs(mode.imag)
        return float(checks.run_steps(mode, 1.0))

    rates = {named.get(name, name): per_second(mode, not explicit) for name, mode in found.items()}
    worst = max(rates.values())
    if worst * t_end <= checks.MAX_RUN_STEPS:
        return
    rate = max(abs(m) for m in found.values())
    shorter = f"t_end <= {_round_down(checks.MAX_RUN_STEPS / worst):g} s"
    if explicit and max(per_second(m, True) for m in found.values()) * t_end <= checks.MAX_RUN_STEPS:
        fix = f"use a stiff method, integration=Integration(method='Radau'), or {shorter}"
    else:
        fix = (f"the fastest mode oscillates (about {max(abs(complex(m).imag) for m in found.values()):.3g} rad/s), "
               f"which every method follows step by step: {shorter}")
    checks.within_budget({k: v * t_end for k, v in rates.items()}, checks.MAX_RUN_STEPS, what="the run would need",
                         unit=f"steps of {integration.method} over t_end = {t_end:g} s (the closed loop's fastest "
                         f"rate, about {rate:.3g} 1/s)", fix=fix)


def _check_budget(body: Body, gains: Gains, ref, t_end: float, integration, allocation) -> None:
    """:func:`run_budget` with the modes of (23)-(24)'s error dynamics and of the heading driven
    by the path (:func:`lib.machinery.domain.loop_modes`)."""
    run_budget(body, ref, t_end, integration, lambda speed, accel: checks.loop_modes(
        body, gains, speed=speed, accel=accel, heading_gains=allocation.law != "position"))


def simulate(body: Body, gains: Gains, ref: Reference, t_end: float, z0=None, dz0=None, *,
             limits: Limits | None = None, allocation: Allocation | None = None, t_eval=None,
             integration: Integration | None = None, model: Body | None = None) -> SimulationResult:
    """Integrate the closed loop (2)-(4), (23) with an allocation from t = 0 to ``t_end`` (s).

    ``z0``, ``dz0``: initial configuration and rate (default: the paper's Table,
    x = 1 m, y = 0, phi = pi/2, at rest). ``limits``: force and angle limits
    (:class:`lib.allocation.Limits`, default none). ``allocation``: the allocation
    law (:class:`lib.allocation.Allocation`, default the paper's (25)-(26)).
    ``t_eval``: output times (default: 20 per second). ``integration``: method,
    tolerances and switching (:class:`Integration`, default DOP853 at 1e-10). A
    state that blows up or becomes non-finite raises :class:`SimulationError`
    naming the time and the variable. ``model``: the controller's model of the body
    (the m, I_C, c, c_phi, a of (23) and of the allocation; default None, the plant
    ``body`` itself); a model other than the plant needs ``switching="stepsize"``.

    With ``Integration(switching="events")``, and by default (``"auto"``) wherever it applies, the
    angle limit's switching surface
    is located (:class:`lib.integrators.switched.SwitchedLoop`): it needs an angle
    limit below pi and the position-only law; in the result, ``beta`` while
    sliding is the Filippov average angle and ``mode`` records the side.

    Parameters
    ----------
    body : Body
        The plant.
    gains : Gains
        The gains Kp, Kv of (23).
    ref : Reference
        The reference (:func:`lib.trajectories.circle`, :func:`lib.trajectories.eight`, or
        any object with ``z``, ``dz``, ``ddz`` of t).
    t_end : float
        End time (s), > 0.
    z0, dz0 : array_like, optional
        Initial configuration (x (m), y (m), phi (rad)) and its rate (m/s, m/s, rad/s), (3,).
    limits : Limits, optional
        Force and angle limits.
    allocation : Allocation, optional
        The allocation law.
    t_eval : array_like, optional
        Increasing output times (s) within [0, t_end].
    integration : Integration, optional
        Method, tolerances and switching.
    model : Body, optional
        The controller's model of the body.

    Returns
    -------
    SimulationResult
        Times t (s), configuration z and rate dz, the reference z_d, dz_d, the inputs F (N),
        beta (rad) and the demand tau (N, N, N m) at each output time.

    Raises
    ------
    TypeError
        If an argument is of the wrong type (a str, a bool), naming it.
    ValueError
        If an argument is out of range or not finite (an array's first bad index named).
    SimulationError
        If the state blows up or becomes non-finite.
    """
    checks.instance("body", body, Body)
    checks.instance("gains", gains, Gains)
    if not all(callable(getattr(ref, k, None)) for k in ("z", "dz", "ddz")):
        raise TypeError(f"ref must be a reference with z, dz and ddz methods, got {type(ref).__name__}")
    t_end = checks.number("t_end", t_end, positive=True, unit="s")
    z0 = _vector("z0", z0, PAPER_Z0)
    dz0 = _vector("dz0", dz0, PAPER_DZ0)
    limits = _instance("limits", limits, Limits)
    allocation = _instance("allocation", allocation, Allocation)
    integration = _instance("integration", integration, Integration)
    if model is not None:
        checks.instance("model", model, Body, "lib.params.Body or None")
    _check_budget(body, gains, ref, t_end, integration, allocation)     # before the output times are built
    t_eval = default_times(t_end, t_eval)
    if integration.switching == "auto":         # events wherever the event-located loop applies
        events = (limits is not None and limits.angle is not None and limits.angle < np.pi
                  and allocation.law == "position" and (model is None or model == body))
        integration = replace(integration, switching="events" if events else "stepsize")
    if integration.switching == "events":
        if model is not None and model != body:
            raise ValueError("switching='events' runs the plant's own model; give model=None")
        if allocation.law != "position":
            raise ValueError("switching='events' supports the position-only allocation only")
        return _simulate_events(body, gains, ref, t_end, z0, dz0, limits, t_eval, integration)

    loop = ClosedLoop.of(body, gains, reference_of(ref), allocation, limits, model)
    # the paper's law on the circle or the eight: the same rates compiled (to rounding), since the
    # integrator calls them on one state at a time; the inputs below are read over the samples
    rates = paper_rates(body, gains, ref, allocation, limits, model) or (lambda t, s: loop.rates(t, s)[0])

    def rhs(t: float, s: np.ndarray) -> np.ndarray:
        out = rates(t, s)
        if not np.all(np.isfinite(out)):
            bad = [n for n, v in zip(_NAMES, out) if not np.isfinite(v)]
            raise SimulationError(f"closed loop became non-finite at t = {t:.6g} s in the rates of {bad}")
        return out

    t, s = integrate(rhs, np.concatenate([z0, dz0]), t_end, t_eval, integration, _NAMES)
    z, dz = s[:, :3], s[:, 3:]
    tau, F, beta = loop.inputs(t, z, dz)
    return SimulationResult(t=t, z=z, dz=dz, z_d=ref.z(t), dz_d=ref.dz(t), F=F, beta=beta, tau=tau, ref=ref)


def default_times(t_end: float, t_eval=None) -> np.ndarray:
    """The output times of a run to ``t_end`` (s): ``t_eval`` checked (increasing, 1-D, within
    [0, t_end]), or by default :data:`DEFAULT_RATE` a second, refused beyond
    :data:`lib.machinery.domain.MAX_SAMPLES` samples before the array is built.

    Parameters
    ----------
    t_end : float
        The run's end time (s), checked.
    t_eval : array_like, optional
        The caller's output times (s).

    Returns
    -------
    numpy.ndarray
        The output times (s).
    """
    if t_eval is None:
        n = t_end * DEFAULT_RATE + 1
        if not n <= checks.MAX_SAMPLES:
            raise ValueError(f"t_end = {t_end:g} s: the default output times ({DEFAULT_RATE:g} a second) would be "
                             f"{n:.3g} samples, beyond the budget of {checks.MAX_SAMPLES:g}; give t_eval (the times "
                             f"you need) or t_end <= {(checks.MAX_SAMPLES - 1) / DEFAULT_RATE:g} s")
        t_eval = np.linspace(0.0, t_end, int(round(t_end * DEFAULT_RATE)) + 1)
    t_eval = checks.array("t_eval", t_eval)
    if t_eval.ndim != 1 or t_eval.size == 0 or t_eval[0] < 0 or t_eval[-1] > t_end or np.any(np.diff(t_eval) <= 0):
        raise ValueError("t_eval must be a non-empty increasing 1-D array within [0, t_end]")
    return t_eval


def _simulate_events(body, gains, ref, t_end, z0, dz0, limits: Limits, t_eval,
                     integration: Integration) -> SimulationResult:
    """``simulate`` with ``Integration(switching="events")``: :class:`SwitchedLoop`."""
    if limits.angle is None or limits.angle >= np.pi:
        raise ValueError("switching='events' needs an angle_limit below pi (rad)")
    loop = SwitchedLoop(body, gains, ref, limits.angle, limits.force)
    seg = loop.integrate(np.concatenate([z0, dz0]), 0.0, float(t_end), t_eval=t_eval, rtol=integration.rtol,
                         atol=integration.atol, method=integration.method, max_step=integration.max_step)
    z, dz = seg.y[:, :3], seg.y[:, 3:]
    tau = ClosedLoop.of(body, gains, reference_of(ref)).inputs(seg.t, z, dz)[0]
    return SimulationResult(t=seg.t, z=z, dz=dz, z_d=ref.z(seg.t), dz_d=ref.dz(seg.t), F=seg.F, beta=seg.beta,
                            tau=tau, ref=ref, mode=seg.mode)


#: The model forms :func:`simulate_open_loop` integrates (``form``).
OPEN_LOOP_FORMS = ("config", "state", "printed")


def simulate_open_loop(body: Body, F, beta, q0, t_end: float, *, form: str = "config", t_eval=None,
                       rtol: float = DEFAULT_RTOL, atol: float = DEFAULT_ATOL) -> tuple[np.ndarray, np.ndarray]:
    """Integrate the uncontrolled body under given inputs F(t) (N), beta(t) (rad).

    ``form`` chooses the equations: ``"config"`` the configuration form (2)-(4),
    ``"state"`` the body-frame form (5) with the derived drift, ``"printed"``
    the body-frame form with the drift exactly as printed in (6). ``q0`` is the
    initial state [x, y, phi, v1, v2, omega]. Returns (t, q) with q of shape
    (n, 6) in body-frame state coordinates whatever the form, so the three can
    be compared directly.

    Parameters
    ----------
    body : Body
        The body.
    F, beta : callable
        Inputs of time t (s): force (N) and its angle to the body axis (rad).
    q0 : array_like
        Initial state [x, y, phi, v1, v2, omega] (m, m, rad, m/s, m/s, rad/s), (6,).
    t_end : float
        End time (s), > 0.
    form : str
        ``"config"``, ``"state"`` or ``"printed"`` (:data:`OPEN_LOOP_FORMS`).
    t_eval : array_like, optional
        Output times (s), default 20 per second.
    rtol, atol : float
        Tolerances of ``solve_ivp``.

    Returns
    -------
    t : numpy.ndarray
        Times (s), (n,).
    q : numpy.ndarray
        Body-frame states, (n, 6).
    """
    if form not in OPEN_LOOP_FORMS:
        raise ValueError(f"unknown model form {form!r}; known: {OPEN_LOOP_FORMS}")
    if not (callable(F) and callable(beta)):
        raise TypeError("F and beta must be callables of time t (s)")
    checks.instance("body", body, Body)
    q0 = checks.array("q0", q0)
    if q0.shape != (6,):
        raise ValueError(f"q0 must be a finite array of shape (6,), got {q0!r}")
    t_end = checks.number("t_end", t_end, positive=True, unit="s")
    if t_eval is None:
        t_eval = np.linspace(0.0, t_end, int(round(t_end * DEFAULT_RATE)) + 1)

    if form == "config":
        z0, dz0 = config_from_state(q0)

        def rhs(t, s):
            return np.concatenate([s[3:], config_accel(body, s[:3], s[3:], F(t), beta(t))])

        s0 = np.concatenate([z0, dz0])
    else:
        printed = form == "printed"

        def rhs(t, s):
            return state_rhs(body, s, F(t), beta(t), printed=printed)

        s0 = q0
    t, q = integrate(rhs, s0, t_end, t_eval, Integration(rtol=rtol, atol=atol), _NAMES)
    if form == "config":
        q = state_from_config(q[:, :3], q[:, 3:])
    return t, q


def _demo_force(t):
    return 1.0 + 0.5 * np.sin(t)


def _demo_angle(t):
    return 0.8 * np.sin(0.7 * t)


#: The initial state [x, y, phi, v1, v2, omega] of the open-loop comparison (moving forward and turning).
DEMO_Q0 = (0.0, 0.0, 0.0, 0.5, 0.0, 0.2)


#: the horizon (s) of the open-loop comparison, in Chapter 1 and in the report
OPEN_LOOP_HORIZON = 20.0


def open_loop_comparison(body: Body, t_end: float, *, F=_demo_force, beta=_demo_angle,
                         q0=DEMO_Q0) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Run every model form of :data:`OPEN_LOOP_FORMS` with the same inputs and initial state.

    Defaults are the smooth inputs of Chapter 1, F(t) = 1 + 0.5 sin t (N) and
    beta(t) = 0.8 sin 0.7t (rad), from q0 = :data:`DEMO_Q0`, chosen so that the
    body both translates and turns. Returns (t, {form: q}) with q of shape (n, 6).

    Parameters
    ----------
    body : Body
        The body.
    t_end : float
        End time (s), > 0.
    F, beta : callable
        Inputs of time t (s): force (N) and angle (rad).
    q0 : array_like
        Initial state (6,).

    Returns
    -------
    t : numpy.ndarray
        Times (s), (n,).
    q : dict of numpy.ndarray
        The body-frame states (n, 6) of each form, by name.
    """
    runs = {form: simulate_open_loop(body, F, beta, q0, t_end, form=form) for form in OPEN_LOOP_FORMS}
    return runs["config"][0], {form: q for form, (_, q) in runs.items()}
