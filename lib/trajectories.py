"""Reference trajectories z_d(t) = [x_d (m), y_d (m), phi_d (rad)]: the circle
(27) and the figure eight (28), with exact first and second derivatives.

All methods take a scalar or an array of times t (s) and return an array of
shape t.shape + (3,).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .machinery import checks

__all__ = ["Reference", "Circle", "Eight", "circle", "eight", "make", "NAMES", "circle_kinematics",
           "eight_kinematics", "KINEMATICS", "circle_position", "eight_position", "position_kinematics", "POSITIONS",
           "eight_heading_fourier", "heading_series", "PAPER_HEADING_SERIES", "heading_turns"]


def _check_shape(R: float, theta: float) -> tuple[float, float]:
    R = checks.number("trajectory radius R", R, positive=True, unit="m")
    theta = checks.number("trajectory angular rate theta", theta, unit="rad/s")
    if theta == 0:
        raise ValueError("trajectory angular rate theta must be non-zero (theta = 0 is a standstill)")
    return R, theta


class Reference:
    """Interface of a reference: ``z(t)``, ``dz(t)``, ``ddz(t)`` and ``period`` (s)."""

    period: float

    def z(self, t) -> np.ndarray:  # pragma: no cover - interface
        raise NotImplementedError

    def dz(self, t) -> np.ndarray:  # pragma: no cover - interface
        raise NotImplementedError

    def ddz(self, t) -> np.ndarray:  # pragma: no cover - interface
        raise NotImplementedError

    def kinematics(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(z_d, dz_d, ddz_d) at t (s), each (..., 3): what a closed loop reads at every step.
        :class:`Circle` and :class:`Eight` compute the three at once; this default asks for each."""
        return self.z(t), self.dz(t), self.ddz(t)


@dataclass(frozen=True)
class _Path(Reference):
    """A closed path of size R (m) run at angular rate theta (rad/s); subclasses
    name their array-form kinematics in ``_kind`` (a key of :data:`KINEMATICS`)."""

    R: float = 2.0
    theta: float = math.pi / 4
    _kind = ""

    def __post_init__(self) -> None:
        R, th = _check_shape(self.R, self.theta)
        object.__setattr__(self, "R", R)
        object.__setattr__(self, "theta", th)

    @property
    def period(self) -> float:
        return 2 * math.pi / abs(self.theta)

    def _kin(self, t):
        return KINEMATICS[self._kind](self.R, self.theta, t)

    def kinematics(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(z_d, dz_d, ddz_d) at t (s), from one evaluation of the path's kinematics."""
        return self._kin(t)

    def z(self, t) -> np.ndarray:
        return self._kin(t)[0]

    def dz(self, t) -> np.ndarray:
        return self._kin(t)[1]

    def ddz(self, t) -> np.ndarray:
        return self._kin(t)[2]


@dataclass(frozen=True)
class Circle(_Path):
    """Circle of radius R (m) run at angular rate theta (rad/s), heading tangent, eq. (27).

    z_d = [R cos(theta t), R sin(theta t), theta t + pi/2].
    """

    _kind = "circle"


@dataclass(frozen=True)
class Eight(_Path):
    """Figure eight, eq. (28): x_d = R/2 sin(2 theta t), y_d = R sin(theta t).

    The desired heading is the direction of the path's tangent. The paper
    writes it as Arg(cos 2 theta t + i cos theta t), which jumps by 2 pi where
    the tangent points backwards along x. Here it is the continuous branch

        phi_d = pi + atan2(-cos(theta t), -cos(2 theta t)),

    equal to the paper's Arg modulo 2 pi. It is continuous because
    -(cos 2s + i cos s) never lies on the negative real axis (that would need
    cos s = 0 and cos 2s > 0, but cos s = 0 gives cos 2s = -1). It is periodic
    with the period of the path and oscillates about pi.
    """

    _kind = "eight"

    def heading(self, t) -> np.ndarray:
        """Continuous tangent angle phi_d(t) (rad)."""
        return self.z(t)[..., 2]


def circle_position(R, theta, t, cos=np.cos, sin=np.sin) -> tuple:
    """Position of the circle (27) and its first three time derivatives, as the tuple
    (x_d, y_d, vx_d, vy_d, ax_d, ay_d, jx_d, jy_d) (m, m/s, m/s^2, m/s^3).

    The one definition of (27)'s position, for arrays; with ``cos=math.cos,
    sin=math.sin`` the same formulas run on Python floats at scalar speed (the
    switched integrator calls them at every step, see :func:`position_kinematics`).

    Parameters
    ----------
    R, theta, t : array_like or float
        Radius (m), rate (rad/s), time (s).
    cos, sin : callable
        The cosine and sine to use (numpy's, or math's for floats).

    Returns
    -------
    tuple
        (x_d, y_d, vx_d, vy_d, ax_d, ay_d, jx_d, jy_d).
    """
    s = theta * t
    c, sn = cos(s), sin(s)
    return (R * c, R * sn, -R * theta * sn, R * theta * c, -R * theta**2 * c, -R * theta**2 * sn,
            R * theta**3 * sn, -R * theta**3 * c)


def eight_position(R, theta, t, cos=np.cos, sin=np.sin) -> tuple:
    """Position of the eight (28), x_d = R/2 sin 2 theta t, y_d = R sin theta t, and its
    first three time derivatives, ordered as in :func:`circle_position`.

    Parameters
    ----------
    R, theta, t : array_like or float
        Size (m), rate (rad/s), time (s).
    cos, sin : callable
        The cosine and sine to use.

    Returns
    -------
    tuple
        (x_d, y_d, vx_d, vy_d, ax_d, ay_d, jx_d, jy_d) (m, m/s, m/s^2, m/s^3).
    """
    s = theta * t
    return _eight_terms(R, theta, cos(s), sin(s), cos(2 * s), sin(2 * s))


def _eight_terms(R, theta, c1, s1, c2, s2) -> tuple:
    """:func:`eight_position`'s tuple from the cosines and sines of s = theta t and of 2 s."""
    return (0.5 * R * s2, R * s1, R * theta * c2, R * theta * c1, -2 * R * theta**2 * s2, -R * theta**2 * s1,
            -4 * R * theta**3 * c2, -R * theta**3 * c1)


def circle_kinematics(R, theta, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(z_d, dz_d, ddz_d) of the circle (27), broadcast over arrays R (m), theta (rad/s), t (s).

    Unvalidated array form behind :class:`Circle`, for batch computations;
    each array has shape broadcast(R, theta, t) + (3,). The heading is
    phi_d = theta t + pi/2.

    Parameters
    ----------
    R : array_like
        Radius (m).
    theta : array_like
        Angular rate (rad/s).
    t : array_like
        Time (s).

    Returns
    -------
    z_d, dz_d, ddz_d : numpy.ndarray
        Position (m, m, rad), velocity (m/s, m/s, rad/s) and acceleration (m/s^2, m/s^2,
        rad/s^2), each of shape broadcast(R, theta, t) + (3,).
    """
    R, th, t = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (R, theta, t)))
    x, y, vx, vy, ax, ay, _, _ = circle_position(R, th, t)
    s = th * t
    z = np.stack([x, y, s + np.pi / 2], axis=-1)
    dz = np.stack([vx, vy, th], axis=-1)
    ddz = np.stack([ax, ay, np.zeros_like(s)], axis=-1)
    return z, dz, ddz


def eight_kinematics(R, theta, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(z_d, dz_d, ddz_d) of the eight (28) with the continuous heading, broadcast
    over arrays R (m), theta (rad/s), t (s); the array form behind :class:`Eight`.

    phi_d = pi + atan2(-cos s, -cos 2s) (minus pi for theta < 0), s = theta t;
    phi_d' = theta N / D and phi_d'' = theta^2 (N' D - N D') / D^2 with
    N = 2 cos s sin 2s - cos 2s sin s, D = cos^2 2s + cos^2 s,
    N' = 3 cos s cos 2s, D' = -2 sin 4s - sin 2s.

    Parameters
    ----------
    R : array_like
        Size (m).
    theta : array_like
        Angular rate (rad/s).
    t : array_like
        Time (s).

    Returns
    -------
    z_d, dz_d, ddz_d : numpy.ndarray
        As :func:`circle_kinematics`.
    """
    R, th, t = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (R, theta, t)))
    s = th * t
    c1, s1, c2, s2 = np.cos(s), np.sin(s), np.cos(2 * s), np.sin(2 * s)
    x, y, vx, vy, ax, ay, _, _ = _eight_terms(R, th, c1, s1, c2, s2)
    heading = np.pi + np.arctan2(-c1, -c2) - np.where(th < 0, np.pi, 0.0)
    num = 2 * c1 * s2 - c2 * s1
    den = c2**2 + c1**2
    dnum = 3 * c1 * c2
    dden = -2 * np.sin(4 * s) - s2
    z = np.stack([x, y, heading], axis=-1)
    dz = np.stack([vx, vy, th * num / den], axis=-1)
    ddz = np.stack([ax, ay, th**2 * (dnum * den - num * dden) / den**2], axis=-1)
    return z, dz, ddz


def position_kinematics(ref: Reference):
    """Scalar function t -> (x_d, y_d, vx_d, vy_d, ax_d, ay_d, jx_d, jy_d) of a reference:
    position (m), velocity, acceleration and jerk (needed by the rate of the switching
    function of :class:`lib.integrators.switched.SwitchedLoop`). Exact for the circle
    (27) and the eight (28) (:func:`circle_position`, :func:`eight_position`); for
    another reference the jerk is a fourth-order central difference of ``ref.ddz``.

    Parameters
    ----------
    ref : Reference
        The reference.

    Returns
    -------
    callable
        t (s) -> the 8-tuple of floats above.
    """
    if isinstance(ref, _Path):
        position, R, th = POSITIONS[ref._kind], ref.R, ref.theta
        return lambda t: position(R, th, float(t), math.cos, math.sin)

    def kin(t: float) -> tuple:
        h = 1e-3
        z, dz, ddz = ref.z(t), ref.dz(t), ref.ddz(t)
        j = (ref.ddz(t - 2 * h) - 8 * ref.ddz(t - h) + 8 * ref.ddz(t + h) - ref.ddz(t + 2 * h)) / (12 * h)
        return (z[0], z[1], dz[0], dz[1], ddz[0], ddz[1], j[0], j[1])
    return kin


def circle(R: float = 2.0, theta: float = math.pi / 4) -> Circle:
    """The circle reference of eq. (27); defaults from the paper's Table.

    Parameters
    ----------
    R : float
        Radius (m), > 0.
    theta : float
        Angular rate Theta (rad/s), non-zero (negative runs the circle clockwise).

    Returns
    -------
    Circle
        The reference: position z_d(t) (m, m, rad) with its first two derivatives
        (``z``, ``dz``, ``ddz``) and its ``period`` 2 pi / abs(theta) (s).

    Raises
    ------
    TypeError
        If R or theta is not a real number.
    ValueError
        If R is not positive and finite, or theta is zero or not finite.
    """
    return Circle(R, theta)


def eight(R: float = 2.0, theta: float = math.pi / 4) -> Eight:
    """The figure-eight reference of eq. (28). The paper does not state R and
    theta for its Fig. 3; the defaults reuse the circle's (see Chapter 3).

    Parameters
    ----------
    R : float
        Size of the eight (m), > 0: x_d = (R / 2) sin(2 Theta t), y_d = R sin(Theta t).
    theta : float
        Angular rate Theta (rad/s), non-zero.

    Returns
    -------
    Eight
        The reference, as :func:`circle` returns one; the heading is the continuous
        tangent angle (rad).

    Raises
    ------
    TypeError
        If R or theta is not a real number.
    ValueError
        If R is not positive and finite, or theta is zero or not finite.
    """
    return Eight(R, theta)


NAMES = {"circle": circle, "eight": eight}


def heading_turns(ref: Reference) -> int:
    """Whole turns of the path's heading phi_d over one period: 1 on the circle (27) run forward
    (-1 backward), 0 on the eight (28), whose tangent oscillates about pi.

    Parameters
    ----------
    ref : Reference
        A path with ``z`` of t and ``period`` (s).

    Returns
    -------
    int
        The turns of phi_d per period.
    """
    z0, z1 = ref.z(0.0), ref.z(ref.period)
    return int(round((float(z1[2]) - float(z0[2])) / (2 * math.pi)))


def make(name: str, R: float, theta: float) -> Reference:
    """Build a reference by name.

    Parameters
    ----------
    name : str
        ``"circle"`` (27) or ``"eight"`` (28).
    R : float
        Radius (m), > 0.
    theta : float
        Angular rate (rad/s), non-zero.

    Returns
    -------
    Reference
        :func:`circle` or :func:`eight` of (R, theta).
    """
    try:
        factory = NAMES[name]
    except (KeyError, TypeError):
        raise ValueError(f"name must be one of {sorted(NAMES)} (the trajectory), got {name!r}") from None
    return factory(R, theta)


#: the array forms, by name, for batch computations over many (R, theta)
KINEMATICS = {"circle": circle_kinematics, "eight": eight_kinematics}
#: the position with three derivatives, by name (:func:`position_kinematics`)
POSITIONS = {"circle": circle_position, "eight": eight_position}


# ------------------------------------------------------------------ the eight's tangent angle as a series (Sec. 6)

#: The paper's 3-term approximation of the eight's tangent angle (Sec. 6):
#: phi_d ~ pi - 2.26 cos s - 0.24 cos 3s + 0.16 cos 5s, s = Theta t.
PAPER_HEADING_SERIES = {0: math.pi, 1: -2.26, 3: -0.24, 5: 0.16}


def eight_heading_fourier(n_harmonics: int = 9, n_samples: int = 4096) -> np.ndarray:
    """Cosine Fourier coefficients a_0..a_{n_harmonics} of the eight's continuous
    tangent angle phi_d(s) = pi + atan2(-cos s, -cos 2s) (rad), s = Theta t, by FFT.

    phi_d is even in s, so phi_d = a_0 + sum_k a_k cos(k s); the half-period
    symmetry phi_d(s + pi) - pi = -(phi_d(s) - pi) leaves only odd k.

    Parameters
    ----------
    n_harmonics : int
        Highest harmonic (>= 0).
    n_samples : int
        FFT samples per period (>= 2 n_harmonics + 2).

    Returns
    -------
    numpy.ndarray
        a_0..a_{n_harmonics} (rad), shape (n_harmonics + 1,).
    """
    n_harmonics = checks.integer("n_harmonics", n_harmonics, minimum=0)
    n_samples = checks.integer("n_samples", n_samples, minimum=2 * n_harmonics + 2)
    s = 2 * np.pi * np.arange(n_samples) / n_samples
    H = eight_kinematics(1.0, 1.0, s)[0][..., 2]
    c = np.fft.rfft(H) / n_samples
    a = 2 * c.real
    a[0] = c[0].real
    return a[: n_harmonics + 1]


def heading_series(coefficients: dict, s) -> np.ndarray:
    """Evaluate a cosine series {k: a_k} at phases s (rad).

    Parameters
    ----------
    coefficients : dict
        {k: a_k (rad)}.
    s : array_like
        Phases (rad).

    Returns
    -------
    numpy.ndarray
        sum_k a_k cos(k s) (rad), of the shape of s.
    """
    s = np.asarray(s, dtype=float)
    return sum(a * np.cos(k * s) for k, a in coefficients.items())
