"""The computed-torque tracking law (23), its time derivative, and the error equation (24).

The law computes a generalized force tau = [tau_x (N), tau_y (N), tau_phi (N m)]
that would make the tracking error obey the linear equation (24). With one
force of magnitude F and angle beta the body can realise (tau_x, tau_y) exactly
but not tau_phi at the same time: how the demand is allocated to (F, beta) is
:mod:`lib.allocation`, whose public functions are re-exported here.
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import expm

from .machinery import checks
from .allocation import allocate, allocate_least_squares, allocate_limited, residual
from .angles import wrap_angle
from .model import input_matrix
from .params import Body, Gains

__all__ = ["computed_torque", "computed_torque_from", "demand", "computed_torque_rate", "error_dynamics_solution",
           # re-exported from lib.allocation, lib.model and lib.angles, where they are defined
           "allocate", "allocate_least_squares", "allocate_limited", "residual", "input_matrix", "wrap_angle"]


def computed_torque(body: Body, gains: Gains, ref, t, z, dz) -> np.ndarray:
    """Computed-torque demand, eq. (23).

    tau = M ddz_d + N(dz) + Kv (dz_d - dz) + Kp (z_d - z), with N(dz) = (c xdot, c ydot, c_phi phidot).

    Parameters
    ----------
    body : Body
        The controller's model of the body (m, I_C and the drag).
    gains : Gains
        The gains Kp, Kv.
    ref : Reference
        The reference (:mod:`lib.trajectories`).
    t : float or array_like
        Time(s) (s), broadcast against the leading axes of ``z``.
    z : array_like
        Actual configuration (x (m), y (m), phi (rad)), shape (..., 3).
    dz : array_like
        Its rate (m/s, m/s, rad/s), shape (..., 3).

    Returns
    -------
    numpy.ndarray
        tau = [tau_x (N), tau_y (N), tau_phi (N m)], shape (..., 3).

    Raises
    ------
    TypeError
        If an argument is of the wrong type, naming it.
    ValueError
        If an array has the wrong shape or a non-finite entry (its index named).
    """
    checks.instance("body", body, Body)
    checks.instance("gains", gains, Gains)
    if not all(callable(getattr(ref, k, None)) for k in ("z", "dz", "ddz")):
        raise TypeError(f"ref must be a reference with z, dz and ddz methods, got {type(ref).__name__}")
    t = checks.array("t", t)
    z, dz = checks.array("z", z, shape=(..., 3)), checks.array("dz", dz, shape=(..., 3))
    return computed_torque_from(body, gains, ref.z(t), ref.dz(t), ref.ddz(t), z, dz)


def computed_torque_from(body: Body, gains: Gains, z_d, dz_d, ddz_d, z, dz) -> np.ndarray:
    """Eq. (23) from the reference values themselves: z_d, dz_d, ddz_d and the actual
    z, dz, all of shape (..., 3) (broadcast); see :func:`computed_torque`.

    Parameters
    ----------
    body : Body
        The controller's model of the body.
    gains : Gains
        The gains Kp, Kv.
    z_d, dz_d, ddz_d : array_like
        The reference configuration (m, m, rad) and its first two derivatives, (..., 3).
    z, dz : array_like
        The actual configuration and its rate, (..., 3).

    Returns
    -------
    numpy.ndarray
        tau = [tau_x (N), tau_y (N), tau_phi (N m)], shape (..., 3).
    """
    return demand(np.array([body.m, body.m, body.I]), body.drag, gains, z_d, dz_d, ddz_d, z, dz)


def demand(mass, drag, gains: Gains, z_d, dz_d, ddz_d, z, dz) -> np.ndarray:
    """Eq. (23) with the model's inertia M = diag(m, m, I_C) and drag N = diag(c, c, c_phi) given
    as arrays, tau = M ddz_d + N dz + Kv (dz_d - dz) + Kp (z_d - z): the one statement of (23),
    which :func:`computed_torque_from` calls with a body's values and a controller with a wrong
    model per point (:mod:`lib.tracking.mismatch`) with its own.

    Parameters
    ----------
    mass, drag : array_like
        The diagonals of M (kg, kg, kg m^2) and N (kg/s, kg/s, kg m^2/s), (..., 3), broadcast.
    gains : Gains
        The gains Kp, Kv.
    z_d, dz_d, ddz_d, z, dz : array_like
        As in :func:`computed_torque_from`, (..., 3).

    Returns
    -------
    numpy.ndarray
        tau = [tau_x (N), tau_y (N), tau_phi (N m)], shape (..., 3).
    """
    z = np.asarray(z, dtype=float)
    dz = np.asarray(dz, dtype=float)
    return mass * ddz_d + drag * dz + gains.kv * (dz_d - dz) + gains.kp * (z_d - z)


def computed_torque_rate(body: Body, gains: Gains, dz_d, ddz_d, dddz_d, dz, ddz) -> np.ndarray:
    """Time derivative of (23): M dddz_d + N(ddz) + Kv (ddz_d - ddz) + Kp (dz_d - dz) (N/s,
    N m/s), from the reference's rate, acceleration and jerk and the actual rate and
    acceleration, all of shape (..., 3) (broadcast). The switched integrator needs it for
    the rate of its switching function (:mod:`lib.integrators.switched`).

    Parameters
    ----------
    body : Body
        The controller's model of the body.
    gains : Gains
        The gains Kp, Kv.
    dz_d, ddz_d, dddz_d : array_like
        The reference's rate, acceleration and jerk (m/s, m/s^2, m/s^3; rad for the heading), (..., 3).
    dz, ddz : array_like
        The actual rate and acceleration, (..., 3).

    Returns
    -------
    numpy.ndarray
        d tau / dt = [N/s, N/s, N m/s], shape (..., 3).
    """
    m = np.array([body.m, body.m, body.I])
    return (m * np.asarray(dddz_d, dtype=float) + body.drag * np.asarray(ddz, dtype=float)
            + gains.kv * (ddz_d - np.asarray(ddz, dtype=float)) + gains.kp * (dz_d - np.asarray(dz, dtype=float)))


def error_dynamics_solution(body: Body, gains: Gains, e0, de0, t) -> np.ndarray:
    """Analytic solution e(t) of the error equation (24), M ë + Kv ė + Kp e = 0.

    ``e0``, ``de0`` are the errors z_d - z and their rates at t = 0 (length 3);
    ``t`` is an array of times (s). Returns e(t), shape t.shape + (3,). Each
    axis is the free response of a linear oscillator, computed with the
    matrix exponential of its companion matrix.

    Parameters
    ----------
    body : Body
        The body (its m and I_C).
    gains : Gains
        The gains Kp, Kv.
    e0 : array_like
        Errors z_d - z at t = 0 (m, m, rad), length 3.
    de0 : array_like
        Their rates (m/s, m/s, rad/s), length 3.
    t : array_like
        Times (s).

    Returns
    -------
    numpy.ndarray
        e(t) (m, m, rad), shape t.shape + (3,).
    """
    t = np.asarray(t, dtype=float)
    m = np.array([body.m, body.m, body.I])
    out = np.empty(t.shape + (3,))
    for i in range(3):
        A = np.array([[0.0, 1.0], [-gains.kp[i] / m[i], -gains.kv[i] / m[i]]])
        Phi = expm(A * t.reshape(-1, 1, 1))
        out[..., i] = (Phi @ np.array([e0[i], de0[i]]))[:, 0].reshape(t.shape)
    return out
