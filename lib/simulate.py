"""Closed-loop simulation of eqs. (2)-(4) under the computed-torque law (23)
with the position-only allocation (25)-(26).

Integration uses :func:`scipy.integrate.solve_ivp` with the 8th-order
Dormand-Prince method (``DOP853``) and tolerances rtol = 1e-10, atol = 1e-10 by
default. The right-hand side is smooth (when no limit is active), so a
high-order method at tight tolerances reaches the 1e-8 agreement with the
analytic error solution of (24) that the tests demand, in a few thousand steps.
With force or angle limits the right-hand side is only piecewise smooth; the
step-size control still resolves the switching, at some cost.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.integrate import solve_ivp

from .control import allocate, allocate_least_squares, allocate_limited, computed_torque
from .model import config_accel
from .params import PAPER_DZ0, PAPER_Z0, Body, Gains
from .trajectories import Reference

__all__ = ["SimulationError", "SimulationResult", "simulate", "DEFAULT_RTOL", "DEFAULT_ATOL"]

DEFAULT_RTOL = 1e-10
DEFAULT_ATOL = 1e-10
#: points per second of the default output grid
DEFAULT_RATE = 20.0


class SimulationError(RuntimeError):
    """The closed-loop integration failed or the solution became non-finite."""


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
    #: with ``switching="events"``: +1 / -1 the side of the angle-limit switching
    #: surface, 0 sliding on it (see :class:`lib.limits.SwitchedLoop`); else None
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
    arr = np.asarray(default if value is None else value, dtype=float)
    if arr.shape != (3,):
        raise ValueError(f"{name} must have shape (3,), got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite, got {arr}")
    return arr


ALLOCATIONS = ("position", "least_squares", "limited")


def allocator(body: Body, allocation: str = "position", weights=(1.0, 1.0, 0.0), force_limit=None, angle_limit=None):
    """The allocation step tau, phi -> (F, beta) of the closed loop.

    ``"position"``: the paper's position-only law (25)-(26), :func:`lib.control.allocate`;
    ``"least_squares"``: the weighted law :func:`lib.control.allocate_least_squares`
    with ``weights`` = (w_x, w_y, w_phi) (Chapter 6), limits applied by projection;
    ``"limited"``: the same weighted law solved exactly under the limits,
    :func:`lib.control.allocate_limited`.
    """
    if allocation == "position":
        allocate(np.zeros(2), 0.0, force_limit, angle_limit)  # validate once
        return lambda tau, phi: allocate(tau, phi, force_limit, angle_limit)
    if allocation == "least_squares":
        allocate_least_squares(np.zeros(3), 0.0, body, weights, force_limit, angle_limit)  # validate once
        return lambda tau, phi: allocate_least_squares(tau, phi, body, weights, force_limit, angle_limit)
    if allocation == "limited":
        allocate_limited(np.zeros(3), 0.0, body, weights, force_limit, angle_limit)  # validate once
        return lambda tau, phi: allocate_limited(tau, phi, body, weights, force_limit, angle_limit)
    raise ValueError(f"unknown allocation {allocation!r}; known: {ALLOCATIONS}")


def closed_loop_rhs(body: Body, gains: Gains, ref: Reference, force_limit=None, angle_limit=None, *,
                    allocation: str = "position", weights=(1.0, 1.0, 0.0)):
    """The closed-loop vector field s' = F(t, s) with s = [z, dz] (length 6)."""
    alloc = allocator(body, allocation, weights, force_limit, angle_limit)

    def rhs(t: float, s: np.ndarray) -> np.ndarray:
        z, dz = s[:3], s[3:]
        tau = computed_torque(body, gains, ref, t, z, dz)
        F, beta = alloc(tau, z[2])
        out = np.concatenate([dz, config_accel(body, z, dz, F, beta)])
        if not np.all(np.isfinite(out)):
            bad = [n for n, v in zip(("x", "y", "phi", "xdot", "ydot", "phidot"), out) if not np.isfinite(v)]
            raise SimulationError(f"closed loop became non-finite at t = {t:.6g} s in the rates of {bad}")
        return out

    return rhs


def simulate(body: Body, gains: Gains, ref: Reference, t_end: float, z0=None, dz0=None, *,
             force_limit: float | None = None, angle_limit: float | None = None,
             t_eval=None, rtol: float = DEFAULT_RTOL, atol: float = DEFAULT_ATOL,
             method: str = "DOP853", max_step: float = np.inf,
             blowup: float = 1e8, switching: str = "stepsize", allocation: str = "position",
             weights=(1.0, 1.0, 0.0)) -> SimulationResult:
    """Integrate the closed loop (2)-(4), (23), (25)-(26) from t = 0 to ``t_end`` (s).

    ``z0``, ``dz0``: initial configuration and rate (default: the paper's
    Table, x = 1 m, y = 0, phi = pi/2, at rest). ``force_limit`` (N) and
    ``angle_limit`` (rad) are passed to :func:`lib.control.allocate`.
    ``t_eval``: output times (default: 20 per second). A state whose magnitude
    exceeds ``blowup`` or that becomes non-finite raises :class:`SimulationError`
    naming the time and the variable.

    ``switching`` says how an angle limit's discontinuity is integrated:
    ``"stepsize"`` (default) leaves it to the step-size control of one
    ``solve_ivp`` run; ``"events"`` locates every crossing of the switching
    surface and slides along it where the two sides push against each other
    (Filippov), with :class:`lib.limits.SwitchedLoop`. ``"events"`` needs an
    ``angle_limit`` below pi; in the result, ``beta`` while sliding is the
    Filippov average angle and ``mode`` records the side.

    ``allocation`` selects the allocation step: ``"position"`` (default, the
    paper's (25)-(26)), ``"least_squares"`` (the weighted law of Chapter 6,
    :func:`lib.control.allocate_least_squares`, with ``weights`` =
    (w_x, w_y, w_phi), limits by projection) or ``"limited"`` (the same law
    solved exactly under the limits, :func:`lib.control.allocate_limited`); see
    :func:`allocator`. The event-located switching
    supports the position-only law only.
    """
    if not isinstance(body, Body):
        raise TypeError(f"body must be a lib.params.Body, got {type(body).__name__}")
    if not isinstance(gains, Gains):
        raise TypeError(f"gains must be a lib.params.Gains, got {type(gains).__name__}")
    if not all(callable(getattr(ref, k, None)) for k in ("z", "dz", "ddz")):
        raise TypeError(f"ref must be a reference with z, dz and ddz methods, got {type(ref).__name__}")
    if isinstance(t_end, bool) or not np.isscalar(t_end) or not np.isfinite(t_end) or t_end <= 0:
        raise ValueError(f"t_end must be a positive finite time in s, got {t_end!r}")
    z0 = _vector("z0", z0, PAPER_Z0)
    dz0 = _vector("dz0", dz0, PAPER_DZ0)
    if t_eval is None:
        t_eval = np.linspace(0.0, t_end, int(round(t_end * DEFAULT_RATE)) + 1)
    t_eval = np.asarray(t_eval, dtype=float)
    if t_eval.ndim != 1 or t_eval.size == 0 or t_eval[0] < 0 or t_eval[-1] > t_end or np.any(np.diff(t_eval) <= 0):
        raise ValueError("t_eval must be a non-empty increasing 1-D array within [0, t_end]")
    alloc = allocator(body, allocation, weights, force_limit, angle_limit)  # validates limits and weights
    if switching not in ("stepsize", "events"):
        raise ValueError(f"switching must be 'stepsize' or 'events', got {switching!r}")
    if switching == "events":
        if allocation != "position":
            raise ValueError("switching='events' supports allocation='position' only")
        return _simulate_events(body, gains, ref, t_end, z0, dz0, force_limit, angle_limit, t_eval,
                                rtol, atol, method, max_step)

    rhs = closed_loop_rhs(body, gains, ref, force_limit, angle_limit, allocation=allocation, weights=weights)

    def blew_up(t, s):
        return blowup - np.max(np.abs(s))

    blew_up.terminal = True
    sol = solve_ivp(rhs, (0.0, t_end), np.concatenate([z0, dz0]), method=method, t_eval=t_eval,
                    rtol=rtol, atol=atol, max_step=max_step, events=blew_up)
    if sol.status == 1:
        s = sol.y_events[0][0]
        names = ("x", "y", "phi", "xdot", "ydot", "phidot")
        raise SimulationError(
            f"closed loop blew up at t = {sol.t_events[0][0]:.6g} s: "
            f"|{names[int(np.argmax(np.abs(s)))]}| reached {blowup:g}")
    if sol.status != 0:
        raise SimulationError(f"integration failed: {sol.message}")
    z, dz = sol.y[:3].T, sol.y[3:].T
    t = sol.t
    tau = computed_torque(body, gains, ref, t, z, dz)
    F, beta = alloc(tau, z[:, 2])
    return SimulationResult(t=t, z=z, dz=dz, z_d=ref.z(t), dz_d=ref.dz(t), F=F, beta=beta, tau=tau, ref=ref)


def _simulate_events(body, gains, ref, t_end, z0, dz0, force_limit, angle_limit, t_eval,
                     rtol, atol, method, max_step) -> SimulationResult:
    """``simulate(..., switching="events")``: event-located integration (lib.limits)."""
    from .limits import SwitchedLoop

    if angle_limit is None or angle_limit >= np.pi:
        raise ValueError("switching='events' needs an angle_limit below pi (rad)")
    loop = SwitchedLoop(body, gains, ref, angle_limit, force_limit)
    seg = loop.integrate(np.concatenate([z0, dz0]), 0.0, float(t_end), t_eval=t_eval, rtol=rtol, atol=atol,
                         method=method, max_step=max_step)
    z, dz = seg.y[:, :3], seg.y[:, 3:]
    tau = computed_torque(body, gains, ref, seg.t, z, dz)
    return SimulationResult(t=seg.t, z=z, dz=dz, z_d=ref.z(seg.t), dz_d=ref.dz(seg.t), F=seg.F, beta=seg.beta,
                            tau=tau, ref=ref, mode=seg.mode)


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
    """
    from .model import config_from_state, state_from_config, state_rhs

    if form not in OPEN_LOOP_FORMS:
        raise ValueError(f"unknown model form {form!r}; known: {OPEN_LOOP_FORMS}")
    if not (callable(F) and callable(beta)):
        raise TypeError("F and beta must be callables of time t (s)")
    q0 = np.asarray(q0, dtype=float)
    if q0.shape != (6,) or not np.all(np.isfinite(q0)):
        raise ValueError(f"q0 must be a finite array of shape (6,), got {q0!r}")
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
    sol = solve_ivp(rhs, (0.0, t_end), s0, method="DOP853", t_eval=t_eval, rtol=rtol, atol=atol)
    if sol.status != 0:
        raise SimulationError(f"open-loop integration failed: {sol.message}")
    q = sol.y.T
    if form == "config":
        q = state_from_config(q[:, :3], q[:, 3:])
    return sol.t, q


def _demo_force(t):
    return 1.0 + 0.5 * np.sin(t)


def _demo_angle(t):
    return 0.8 * np.sin(0.7 * t)


#: initial state of the open-loop comparison: moving forward and turning
DEMO_Q0 = (0.0, 0.0, 0.0, 0.5, 0.0, 0.2)


def open_loop_comparison(body: Body, t_end: float, *, F=_demo_force, beta=_demo_angle,
                         q0=DEMO_Q0) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Run every model form of :data:`OPEN_LOOP_FORMS` with the same inputs and initial state.

    Defaults are the smooth inputs of Chapter 1, F(t) = 1 + 0.5 sin t (N) and
    beta(t) = 0.8 sin 0.7t (rad), from q0 = :data:`DEMO_Q0`, chosen so that the
    body both translates and turns. Returns (t, {form: q}) with q of shape (n, 6).
    """
    runs = {form: simulate_open_loop(body, F, beta, q0, t_end, form=form) for form in OPEN_LOOP_FORMS}
    return runs["config"][0], {form: q for form, (_, q) in runs.items()}
