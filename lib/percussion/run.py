"""The closed loop under the law for P (:mod:`lib.percussion.law`), integrated like
:func:`lib.simulate.simulate`, and read as P's tracking error."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..machinery import checks
from ..allocation import Limits
from ..integrators.smooth import Integration, SimulationError, integrate
from ..params import PAPER_DZ0, PAPER_Z0, Body, Gains
from ..simulate import SimulationResult, default_times, run_budget
from ..trajectories import Reference, position_kinematics
from .law import ANTI_WINDUP_TIME, DEFAULT_POLE, closed_loop_rates, error_polynomial
from .point import point_accel, point_state

__all__ = ["PercussionResult", "simulate", "point_error", "reference_point_kinematics", "designed_error_deviation"]

_NAMES = ("x", "y", "phi", "xdot", "ydot", "phidot", "thrust")


@dataclass(frozen=True)
class PercussionResult(SimulationResult):
    """A :class:`lib.simulate.SimulationResult` of the law for P: ``z_d`` is the reference P
    follows (its heading column the path's tangent), ``z`` and ``dz`` are C's; ``tau`` is the
    applied generalized force Q (N, N, N m); ``thrust`` the extension state xi (N)."""

    thrust: np.ndarray | None = None


def reference_point_kinematics(ref: Reference, t) -> tuple:
    """(P_d, P_d', P_d'', P_d''') at times t (s), each (n, 2).

    Parameters
    ----------
    ref : Reference
        The path of P (its x, y; exact for the circle (27) and the eight (28), else the jerk
        by finite differences, :func:`lib.trajectories.position_kinematics`).
    t : float or array_like
        Times (s), a scalar or 1-D (n,).

    Returns
    -------
    tuple of numpy.ndarray
        (P_d (m), P_d' (m/s), P_d'' (m/s^2), P_d''' (m/s^3)), each (n, 2) (n = 1 for a scalar t).
    """
    kin = position_kinematics(ref)
    rows = np.array([kin(tt) for tt in np.atleast_1d(t)])
    return tuple(rows[:, 2 * j:2 * j + 2] for j in range(4))


def _check_budget(body: Body, ref, coeffs, t_end: float, integration: Integration) -> None:
    """:func:`lib.simulate.run_budget` with P's error dynamics (the roots of ``coeffs``'
    polynomials, gains and pole) and the heading driven by the path."""
    roots = np.concatenate([np.roots(np.r_[1.0, row]).astype(complex) for row in coeffs])
    run_budget(body, ref, t_end, integration, lambda speed, accel: {
        "gains and pole": roots[np.argmax(np.abs(roots))], **checks.loop_modes(body, speed=speed, accel=accel)})


def simulate(body: Body, gains: Gains, ref: Reference, t_end: float, z0=None, dz0=None, *,
             thrust0: float = 0.0, pole: float = DEFAULT_POLE, limits: Limits | None = None, t_eval=None,
             integration: Integration | None = None, anti_windup: bool = False,
             anti_windup_time: float = ANTI_WINDUP_TIME) -> PercussionResult:
    """Integrate (2)-(4) under the law for P from t = 0 to ``t_end`` (s): P follows the path of
    ``ref`` with its error obeying e''' + k2 e'' + k1 e' + k0 e = 0
    (:func:`lib.percussion.law.error_polynomial` with ``pole``).

    Parameters
    ----------
    body : Body
        The plant (and the law's model).
    gains : Gains
        Kp, Kv (x, y entries) of the error polynomial.
    ref : Reference
        The path of P (:func:`lib.trajectories.circle`, :func:`lib.trajectories.eight`).
    t_end : float
        End time (s), > 0.
    z0, dz0 : array_like, optional
        C's start configuration and rate (default: the paper's Table).
    thrust0 : float
        Start of the thrust state xi = F cos beta (N).
    pole : float
        The extra pole (1/s).
    limits : Limits, optional
        Force and angle limits applied to (F, beta).
    t_eval : array_like, optional
        Output times (s), default 20 per second.
    integration : Integration, optional
        Method and tolerances (default DOP853 at 1e-10).
    anti_windup : bool
        Anti-windup of the thrust integrator (:mod:`lib.percussion.law`): while a limit is
        active (the law's F above the cap or its |beta| above the angle limit), the thrust's
        rate uses the angular acceleration actually applied, and back-calculation
        (F cos beta - xi) / T_aw (N/s) pulls xi towards the applied thrust F cos beta (N);
        without saturation xi' = nu exactly. False (default): xi' = nu always (today's law).
    anti_windup_time : float
        T_aw (s), > 0, used with ``anti_windup``; default
        :data:`lib.percussion.law.ANTI_WINDUP_TIME`.

    Returns
    -------
    PercussionResult
        As :func:`lib.simulate.simulate`, plus ``thrust``.
    """
    checks.instance("body", body, Body)
    checks.instance("gains", gains, Gains)
    if not all(callable(getattr(ref, k, None)) for k in ("z", "dz", "ddz")):
        raise TypeError(f"ref must be a reference with z, dz and ddz methods, got {type(ref).__name__}")
    t_end = checks.number("t_end", t_end, positive=True, unit="s")
    z0 = checks.array("z0", PAPER_Z0 if z0 is None else z0, shape=(3,))
    dz0 = checks.array("dz0", PAPER_DZ0 if dz0 is None else dz0, shape=(3,))
    thrust0 = checks.number("thrust0", thrust0, unit="N")
    limits = Limits() if limits is None else checks.instance("limits", limits, Limits)
    integration = Integration() if integration is None else checks.instance("integration", integration, Integration)
    anti_windup = checks.flag("anti_windup", anti_windup)
    anti_windup_time = checks.number("anti_windup_time", anti_windup_time, positive=True, unit="s")
    t_aw = anti_windup_time if anti_windup else None
    coeffs = error_polynomial(body, gains, pole)
    _check_budget(body, ref, coeffs, t_end, integration)
    t_eval = default_times(t_end, t_eval)      # the one check, refused before the array is built
    kin = position_kinematics(ref)

    def rhs(t, y):
        k = np.array(kin(t))
        out = closed_loop_rates(body, coeffs, (k[0:2], k[2:4], k[4:6], k[6:8]), y, limits, t_aw)[0]
        if not np.all(np.isfinite(out)):
            raise SimulationError(f"closed loop became non-finite at t = {t:.6g} s")
        return out

    t, y = integrate(rhs, np.concatenate([z0, dz0, [thrust0]]), t_end, t_eval, integration, _NAMES)
    kd = reference_point_kinematics(ref, t)
    _, F, beta = closed_loop_rates(body, coeffs, kd, y, limits)
    phi = y[:, 2]
    tau = np.stack([F * np.cos(phi + beta), F * np.sin(phi + beta), body.a * F * np.sin(beta)], -1)
    return PercussionResult(t=t, z=y[:, :3], dz=y[:, 3:6], z_d=ref.z(t), dz_d=ref.dz(t), F=F, beta=beta,
                            tau=tau, ref=ref, thrust=y[:, 6])


def point_error(body: Body, res: SimulationResult) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """P's tracking error e = P_d - P, its rate and, for a :class:`PercussionResult`, its second
    derivative (else None), each (n, 2), from a run (P_d the reference's position).

    Parameters
    ----------
    body : Body
        The body.
    res : SimulationResult
        A run.

    Returns
    -------
    e, de, dde : numpy.ndarray
        (n, 2) each (dde None without the thrust state).
    """
    P, dP = point_state(body, res.z, res.dz)
    Pd, dPd, ddPd, _ = reference_point_kinematics(res.ref, res.t)
    dde = None
    thrust = getattr(res, "thrust", None)
    if thrust is not None:
        dde = ddPd - point_accel(body, res.z[:, 2], res.dz[:, 2], dP, thrust)
    return Pd - P, dPd - dP, dde


def designed_error_deviation(body: Body, gains: Gains, res: PercussionResult, pole: float = DEFAULT_POLE) -> float:
    """The largest distance (m) between P's error in the run ``res`` and the solution of the
    designed equation e''' + k2 e'' + k1 e' + k0 e = 0 from the run's start (matrix exponential).

    Parameters
    ----------
    body : Body
        The body.
    gains : Gains
        The gains of the run.
    res : PercussionResult
        A run of :func:`simulate` with ``pole``.
    pole : float
        The extra pole (1/s).

    Returns
    -------
    float
        max over samples and axes of |e - e_designed| (m).
    """
    from scipy.linalg import expm

    e, de, dde = point_error(body, res)
    k = error_polynomial(body, gains, pole)
    worst = 0.0
    for j in range(2):
        A = np.array([[0, 1, 0], [0, 0, 1], [-k[j, 2], -k[j, 1], -k[j, 0]]])
        x0 = np.array([e[0, j], de[0, j], dde[0, j]])
        want = np.array([(expm(A * t) @ x0)[0] for t in res.t - res.t[0]])
        worst = max(worst, float(np.abs(e[:, j] - want).max()))
    return worst
