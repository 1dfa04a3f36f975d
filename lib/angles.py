"""Angles: wrapping to one turn, and differences of states whose third entry is an angle."""

from __future__ import annotations

import numpy as np

__all__ = ["wrap_angle", "state_difference"]


def wrap_angle(angle) -> np.ndarray:
    """Wrap angles (rad) to the interval (-pi, pi].

    Parameters
    ----------
    angle : array_like
        Angles (rad).

    Returns
    -------
    numpy.ndarray or float
        The same angles (rad) in (-pi, pi], of the input's shape (a float for a scalar).
    """
    angle = np.asarray(angle, dtype=float)
    w = np.pi - np.mod(np.pi - angle, 2 * np.pi)
    # a hair above an odd multiple of pi, pi - angle is a hair below a multiple of 2 pi and
    # its remainder rounds up to 2 pi itself: w = -pi, outside the interval; it is the angle pi
    return np.where(w == -np.pi, np.pi, w)[()]


def state_difference(a, b) -> np.ndarray:
    """a - b for states [x, y, phi, xdot, ydot, phidot] with the phi entry wrapped to (-pi, pi].

    Parameters
    ----------
    a, b : array_like
        States [x (m), y (m), phi (rad), xdot (m/s), ydot (m/s), phidot (rad/s)], shape (..., 6)
        (broadcast).

    Returns
    -------
    numpy.ndarray
        a - b, shape (..., 6), its phi entry (rad) in (-pi, pi].
    """
    d = np.asarray(a, dtype=float) - np.asarray(b, dtype=float)
    d[..., 2] = wrap_angle(d[..., 2])
    return d
