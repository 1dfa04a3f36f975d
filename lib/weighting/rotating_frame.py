"""The frame that rotates with the circle's reference (27): the closed loop's state written
in it and back (:func:`rotating_to_inertial`, :func:`inertial_to_rotating`), and the closed
loop's field in it, which is autonomous on the circle (the steady motion of
:mod:`lib.weighting.circle` is an equilibrium there). :mod:`lib.weighting.circle` re-exports
the two maps.

Units: positions in m, angles in rad, rates per s; Theta in rad/s, t in s.
"""

from __future__ import annotations

import math

import numpy as np

from ..closed_loop import ClosedLoop

__all__ = ["rotating_to_inertial", "inertial_to_rotating"]


def _rot(angle):
    c, s = np.cos(angle), np.sin(angle)
    return c, s


def rotating_to_inertial(y, Theta: float, t: float) -> np.ndarray:
    """The inertial state s = (x, y, phi, x', y', phi') (m, rad, m/s, rad/s) at time ``t`` (s) of
    the rotating-frame state ``y`` = (xi, eta, p, xi', eta', p') (shape (..., 6)) on the circle
    run at ``Theta`` (rad/s): X = Rot(Theta t) (xi, eta), X' = Rot(Theta t) [(xi', eta') +
    Theta S (xi, eta)] with S the rotation by pi/2, phi = p + Theta t + pi/2, phi' = p' + Theta.

    Parameters
    ----------
    y : array_like
        Rotating-frame states (..., 6) (m, m, rad, m/s, m/s, rad/s).
    Theta : float
        Rate (rad/s).
    t : float
        Time (s).

    Returns
    -------
    numpy.ndarray
        Inertial states (..., 6) in the same units.
    """
    y = np.asarray(y, dtype=float)
    c, s = _rot(Theta * t)
    xi, eta, p, dxi, deta, dp = np.moveaxis(y, -1, 0)
    vx, vy = dxi - Theta * eta, deta + Theta * xi
    return np.stack([c * xi - s * eta, s * xi + c * eta, p + Theta * t + math.pi / 2,
                     c * vx - s * vy, s * vx + c * vy, dp + Theta], axis=-1)


def inertial_to_rotating(s, Theta: float, t: float) -> np.ndarray:
    """The inverse of :func:`rotating_to_inertial`.

    Parameters
    ----------
    s : array_like
        Inertial states (..., 6) (m, m, rad, m/s, m/s, rad/s).
    Theta : float
        Rate (rad/s).
    t : float
        Time (s).

    Returns
    -------
    numpy.ndarray
        Rotating-frame states (..., 6).
    """
    s = np.asarray(s, dtype=float)
    c, sn = _rot(Theta * t)
    x, y, phi, dx, dy, dphi = np.moveaxis(s, -1, 0)
    xi, eta = c * x + sn * y, -sn * x + c * y
    vx, vy = c * dx + sn * dy, -sn * dx + c * dy
    return np.stack([xi, eta, phi - Theta * t - math.pi / 2, vx + Theta * eta, vy - Theta * xi,
                     dphi - Theta], axis=-1)


def _field(loop: ClosedLoop, Theta: float, y, t: float = 0.0) -> np.ndarray:
    """The unvalidated rotating-frame field y' of :func:`rotating_field`."""
    y = np.asarray(y, dtype=float)
    s = rotating_to_inertial(y, Theta, t)
    ds, _ = loop.rates(t, s)
    c, sn = _rot(Theta * t)
    ax, ay = ds[..., 3], ds[..., 4]
    xi, eta, _, dxi, deta, dp = np.moveaxis(y, -1, 0)
    # (xi'', eta'') = Rot(-Theta t) X'' - 2 Theta S (xi', eta') + Theta^2 (xi, eta)
    ddxi = c * ax + sn * ay + 2 * Theta * deta + Theta**2 * xi
    ddeta = -sn * ax + c * ay - 2 * Theta * dxi + Theta**2 * eta
    return np.stack([dxi, deta, dp, ddxi, ddeta, ds[..., 5]], axis=-1)
