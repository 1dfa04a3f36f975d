"""The centre of percussion P in numbers: its place on the axis, its state, its acceleration.

Notation (Chapter 7): e1 = (cos phi, sin phi) the body axis, e2 = (-sin phi, cos phi);
s_P = -I_C / (m a) (m) the signed position of P from C, positive towards the force's point;
k = c / m (1/s) the drag rate of P's velocity; eps = s_P (c/m - c_phi/I_C) (m/s) the
coefficient of omega in P's lateral acceleration (:mod:`lib.percussion.derivation`):

    P'' + k P' = (u1/m - s_P omega^2) e1 + eps omega e2.
"""

from __future__ import annotations

import numpy as np

from ..machinery import checks
from ..params import Body

__all__ = ["centre_of_percussion", "drag_mismatch", "lateral_drag_speed", "point_state", "point_accel",
           "body_state_from_point"]


def _s_p(body: Body) -> float:
    """s_P (m) of a checked body: the kernel the public functions and the inner loops share."""
    return -body.I / (body.m * body.a)


def _eps(body: Body) -> float:
    """eps (m/s) of a checked body (:func:`lateral_drag_speed`'s kernel, for inner loops)."""
    return _s_p(body) * (body.c / body.m - body.c_phi / body.I)


def centre_of_percussion(body: Body) -> float:
    """P's signed position on the body axis from C (m), positive towards the force's point of
    application (C + a e1): s_P = -I_C / (m a), on the far side of C from the force.

    Parameters
    ----------
    body : Body
        The body.

    Returns
    -------
    float
        s_P (m).
    """
    checks.instance("body", body, Body)
    return _s_p(body)


def drag_mismatch(body: Body) -> float:
    """c/m - c_phi/I_C (1/s): zero when the two drag rates agree (then P'' + (c/m) P' lies
    along the axis); the book's body has 0.3 - 1.0 = -0.7 1/s.

    Parameters
    ----------
    body : Body
        The body.

    Returns
    -------
    float
        The mismatch (1/s).
    """
    checks.instance("body", body, Body)
    return body.c / body.m - body.c_phi / body.I


def lateral_drag_speed(body: Body) -> float:
    """eps = s_P (c/m - c_phi/I_C) = (c_phi m - c I_C) / (m^2 a) (m/s): P's lateral
    acceleration per unit omega. Positive when c_phi/I_C > c/m (the book's body: 0.0875 m/s).

    Parameters
    ----------
    body : Body
        The body.

    Returns
    -------
    float
        eps (m/s).
    """
    checks.instance("body", body, Body)
    return _eps(body)


def point_state(body: Body, z, dz) -> tuple[np.ndarray, np.ndarray]:
    """P and its velocity from the configuration z = (x, y, phi) and its rate (..., 3):
    P = C + s_P e1, P' = C' + s_P omega e2. Returns two (..., 2) arrays (m, m/s).

    Parameters
    ----------
    body : Body
        The body.
    z, dz : array_like
        Configuration (m, m, rad) and rate (m/s, m/s, rad/s), (..., 3).

    Returns
    -------
    P, dP : numpy.ndarray
        (..., 2).
    """
    checks.instance("body", body, Body)
    return _point_state(body, z, dz)


def _point_state(body: Body, z, dz) -> tuple[np.ndarray, np.ndarray]:
    """:func:`point_state` of a checked body (the law's inner loop)."""
    s = _s_p(body)
    z, dz = np.asarray(z, float), np.asarray(dz, float)
    e1 = np.stack([np.cos(z[..., 2]), np.sin(z[..., 2])], -1)
    e2 = np.stack([-e1[..., 1], e1[..., 0]], -1)
    return z[..., :2] + s * e1, dz[..., :2] + s * dz[..., 2:3] * e2


def point_accel(body: Body, phi, omega, dP, u1) -> np.ndarray:
    """P'' = (u1/m - s_P omega^2) e1 + eps omega e2 - (c/m) P' (m/s^2), (..., 2): the lateral
    force u2 does not enter.

    Parameters
    ----------
    body : Body
        The body.
    phi, omega : array_like
        Heading (rad) and its rate (rad/s).
    dP : array_like
        P's velocity (..., 2) (m/s).
    u1 : array_like
        Thrust along the axis, F cos beta (N).

    Returns
    -------
    numpy.ndarray
        (..., 2).
    """
    checks.instance("body", body, Body)
    return _point_accel(body, phi, omega, dP, u1)


def _point_accel(body: Body, phi, omega, dP, u1) -> np.ndarray:
    """:func:`point_accel` of a checked body (the law's inner loop)."""
    s, eps = _s_p(body), _eps(body)
    phi, omega, u1 = (np.asarray(v, float) for v in (phi, omega, u1))
    e1 = np.stack([np.cos(phi), np.sin(phi)], -1)
    e2 = np.stack([-e1[..., 1], e1[..., 0]], -1)
    along = (u1 / body.m - s * omega**2)[..., None]
    return along * e1 + (eps * omega)[..., None] * e2 - body.c / body.m * np.asarray(dP, float)


def body_state_from_point(body: Body, P, dP, phi, omega) -> tuple[np.ndarray, np.ndarray]:
    """The configuration z = (x, y, phi) and rate of a body whose P is at ``P`` moving at ``dP``
    (m, m/s) with heading ``phi`` (rad) turning at ``omega`` (rad/s): the inverse of
    :func:`point_state`. Returns z, dz, each (..., 3).

    Parameters
    ----------
    body : Body
        The body.
    P, dP : array_like
        P's position and velocity (..., 2).
    phi, omega : array_like
        Heading and its rate.

    Returns
    -------
    z, dz : numpy.ndarray
        (..., 3).
    """
    s = centre_of_percussion(body)
    phi, omega = np.asarray(phi, float), np.asarray(omega, float)
    e1 = np.stack([np.cos(phi), np.sin(phi)], -1)
    e2 = np.stack([-e1[..., 1], e1[..., 0]], -1)
    C = np.asarray(P, float) - s * e1
    dC = np.asarray(dP, float) - s * omega[..., None] * e2
    return np.concatenate([C, phi[..., None]], -1), np.concatenate([dC, omega[..., None]], -1)
