"""Numerical model of the body: configuration form (2)-(4) and body-frame
state-space form (5)-(10).

Arrays are vectorised over leading axes: a configuration ``z`` has shape
(..., 3) = [x (m), y (m), phi (rad)], a state ``q`` has shape (..., 6) =
[x, y, phi, v1 (m/s), v2 (m/s), omega (rad/s)], where (v1, v2) is the velocity
of C in the body frame (v1 along the symmetry line).
"""

from __future__ import annotations

import numpy as np

from .params import Body

__all__ = [
    "config_accel", "generalized_force", "input_matrix", "f", "f_printed", "g1", "g2", "state_rhs",
    "state_from_config", "config_from_state",
]


def _last_axis(arr, n: int, name: str) -> np.ndarray:
    arr = np.asarray(arr, dtype=float)
    if arr.ndim == 0 or arr.shape[-1] != n:
        raise ValueError(f"{name} must have a last axis of length {n}, got shape {arr.shape}")
    return arr


def generalized_force(F, beta, phi) -> np.ndarray:
    """Q of eq. (22) without the lever arm: [F cos(phi+beta), F sin(phi+beta), F sin(beta)].

    Multiply the last entry by ``a`` to get the torque (N m); see :func:`config_accel`.

    Parameters
    ----------
    F : array_like
        Force magnitude (N).
    beta : array_like
        Force angle to the body axis (rad).
    phi : array_like
        Heading (rad).

    Returns
    -------
    numpy.ndarray
        [F cos(phi+beta) (N), F sin(phi+beta) (N), F sin(beta) (N)], shape (..., 3) of the
        broadcast inputs.
    """
    F, beta, phi = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (F, beta, phi)))
    return np.stack([F * np.cos(phi + beta), F * np.sin(phi + beta), F * np.sin(beta)], axis=-1)


def input_matrix(phi, body: Body) -> np.ndarray:
    """B(phi) with Q = B(phi) u, u = (u1, u2) = (F cos beta, F sin beta), eq. (22).

    B = [[cos phi, -sin phi], [sin phi, cos phi], [0, a]]; shape phi.shape + (3, 2).

    Parameters
    ----------
    phi : array_like
        Heading (rad).
    body : Body
        The body (its lever arm a (m)).

    Returns
    -------
    numpy.ndarray
        B(phi), shape phi.shape + (3, 2): Q (N, N, N m) = B u with u in N.
    """
    phi = np.asarray(phi, dtype=float)
    c, s = np.cos(phi), np.sin(phi)
    z, a = np.zeros_like(phi), np.full_like(phi, body.a)
    return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1), np.stack([z, a], -1)], -2)


def config_accel(body: Body, z, dz, F, beta) -> np.ndarray:
    """Accelerations ddz = [xddot, yddot, phiddot] of eqs. (2)-(4).

    ``F`` (N) is the force magnitude and ``beta`` (rad) its angle to the body
    axis; m xddot + c xdot = F cos(phi+beta), m yddot + c ydot = F sin(phi+beta),
    I_C phiddot + c_phi phidot = F a sin(beta).

    Parameters
    ----------
    body : Body
        The body.
    z : array_like
        Configuration [x (m), y (m), phi (rad)], shape (..., 3).
    dz : array_like
        Its rate (m/s, m/s, rad/s), shape (..., 3).
    F : array_like
        Force magnitude (N).
    beta : array_like
        Force angle to the body axis (rad).

    Returns
    -------
    numpy.ndarray
        ddz = [xddot (m/s^2), yddot (m/s^2), phiddot (rad/s^2)], shape (..., 3).
    """
    z = _last_axis(z, 3, "z")
    dz = _last_axis(dz, 3, "dz")
    Q = generalized_force(F, beta, z[..., 2])
    Q = Q * np.array([1.0, 1.0, body.a])
    return (Q - body.drag * dz) / np.array([body.m, body.m, body.I])


def f(body: Body, q) -> np.ndarray:
    """Drift vector field of eq. (5), derived from (2)-(4) (the corrected eq. (6)).

    ::

        f(q) = [v1 cos(phi) - v2 sin(phi), v1 sin(phi) + v2 cos(phi), omega,
                -c/m v1 + v2 omega, -c/m v2 - v1 omega, -c_phi/I_C omega].

    The fifth row differs in sign from the printed (6): see :func:`f_printed`.

    Parameters
    ----------
    body : Body
        The body.
    q : array_like
        State [x (m), y (m), phi (rad), v1 (m/s), v2 (m/s), omega (rad/s)], shape (..., 6).

    Returns
    -------
    numpy.ndarray
        f(q), shape (..., 6), in the units of dq/dt.
    """
    q = _last_axis(q, 6, "q")
    _, _, phi, v1, v2, w = np.moveaxis(q, -1, 0)
    k = body.c / body.m
    return np.stack([
        v1 * np.cos(phi) - v2 * np.sin(phi),
        v1 * np.sin(phi) + v2 * np.cos(phi),
        w,
        -k * v1 + v2 * w,
        -k * v2 - v1 * w,
        -body.c_phi / body.I * w,
    ], axis=-1)


def f_printed(body: Body, q) -> np.ndarray:
    """The drift exactly as printed in eq. (6), with +v1 omega in the v2 row (a typo).

    Parameters
    ----------
    body : Body
        The body.
    q : array_like
        State [x, y, phi, v1, v2, omega] (m, m, rad, m/s, m/s, rad/s), shape (..., 6).

    Returns
    -------
    numpy.ndarray
        The printed f(q), shape (..., 6).
    """
    out = f(body, q)
    q = np.asarray(q, dtype=float)
    out[..., 4] += 2.0 * q[..., 3] * q[..., 5]
    return out


def g1(body: Body) -> np.ndarray:
    """Input field of u1 = F cos(beta), eq. (9): [0, 0, 0, 1/m, 0, 0].

    Parameters
    ----------
    body : Body
        The body.

    Returns
    -------
    numpy.ndarray
        g1, shape (6,), per newton of u1 (1/kg in the v1 row).
    """
    return np.array([0.0, 0.0, 0.0, 1.0 / body.m, 0.0, 0.0])


def g2(body: Body) -> np.ndarray:
    """Input field of u2 = F sin(beta), eq. (10): [0, 0, 0, 0, 1/m, a/I_C].

    Parameters
    ----------
    body : Body
        The body.

    Returns
    -------
    numpy.ndarray
        g2, shape (6,), per newton of u2 (1/kg in the v2 row, m/(kg m^2) in the omega row).
    """
    return np.array([0.0, 0.0, 0.0, 0.0, 1.0 / body.m, body.a / body.I])


def state_rhs(body: Body, q, F, beta, *, printed: bool = False) -> np.ndarray:
    """qdot = f(q) + g1 u1 + g2 u2, eq. (5), with u1 = F cos(beta), u2 = F sin(beta) (7)-(8).

    ``printed=True`` uses the drift as printed in (6), for comparison only.

    Parameters
    ----------
    body : Body
        The body.
    q : array_like
        State [x, y, phi, v1, v2, omega] (m, m, rad, m/s, m/s, rad/s), shape (..., 6).
    F : array_like
        Force magnitude (N).
    beta : array_like
        Force angle to the body axis (rad).
    printed : bool
        Use the drift as printed in (6).

    Returns
    -------
    numpy.ndarray
        dq/dt, shape (..., 6).
    """
    drift = f_printed(body, q) if printed else f(body, q)
    u1 = np.asarray(F, dtype=float) * np.cos(beta)
    u2 = np.asarray(F, dtype=float) * np.sin(beta)
    return drift + np.multiply.outer(u1, g1(body)) + np.multiply.outer(u2, g2(body))


def state_from_config(z, dz) -> np.ndarray:
    """State q = [x, y, phi, v1, v2, omega] from configuration z and its rate dz.

    (v1, v2) is the inertial velocity (xdot, ydot) rotated by -phi into the body frame.

    Parameters
    ----------
    z : array_like
        Configuration [x (m), y (m), phi (rad)], shape (..., 3).
    dz : array_like
        Its rate (m/s, m/s, rad/s), shape (..., 3).

    Returns
    -------
    numpy.ndarray
        q = [x, y, phi, v1 (m/s), v2 (m/s), omega (rad/s)], shape (..., 6).
    """
    z, dz = np.broadcast_arrays(_last_axis(z, 3, "z"), _last_axis(dz, 3, "dz"))
    phi = z[..., 2]
    c, s = np.cos(phi), np.sin(phi)
    v1 = c * dz[..., 0] + s * dz[..., 1]
    v2 = -s * dz[..., 0] + c * dz[..., 1]
    return np.concatenate([z, np.stack([v1, v2, dz[..., 2]], axis=-1)], axis=-1)


def config_from_state(q) -> tuple[np.ndarray, np.ndarray]:
    """Inverse of :func:`state_from_config`: returns (z, dz).

    Parameters
    ----------
    q : array_like
        State [x, y, phi, v1, v2, omega] (m, m, rad, m/s, m/s, rad/s), shape (..., 6).

    Returns
    -------
    z : numpy.ndarray
        Configuration [x (m), y (m), phi (rad)], shape (..., 3).
    dz : numpy.ndarray
        Its rate (m/s, m/s, rad/s), shape (..., 3).
    """
    q = _last_axis(q, 6, "q")
    phi, v1, v2 = q[..., 2], q[..., 3], q[..., 4]
    c, s = np.cos(phi), np.sin(phi)
    dz = np.stack([c * v1 - s * v2, s * v1 + c * v2, q[..., 5]], axis=-1)
    return q[..., :3].copy(), dz
