"""The circle's rotation in closed form, paper Sec. 6, eqs. (33)-(36): in the rotation error
p = phi - theta t - pi/2 the heading on the circle (27) obeys the autonomous,
pendulum-like (33) (corrected; see :mod:`lib.rotation.equations`); its field, its
equilibria, their linearisation (34)-(35) and the critical radius (36).
:mod:`lib.rotation.circle_global` (the global behaviour, the bistable window) re-exports them.

Units: R in m, theta in rad/s, angles in rad, times in s.
"""

from __future__ import annotations

import math

import numpy as np

from ..machinery import checks
from ..angles import wrap_angle
from ..params import Body

__all__ = ["circle_critical_radius", "circle_equilibria", "circle_jacobian", "circle_eigenvalues",
           "circle_rotation_rhs"]


def _check_circle_args(body: Body, R=None, theta=None) -> None:
    checks.instance("body", body, Body)
    if R is not None:
        checks.number("circle radius R", R, positive=True, unit="m")
    if theta is not None:
        checks.number("angular rate theta", theta, positive=True, unit="rad/s")


def circle_critical_radius(body: Body, theta: float) -> float:
    """Critical radius of (36), R_crit = c_phi / (a sqrt(m^2 theta^2 + c^2)) (m).

    Equilibria of (33) exist iff R >= R_crit; for R > R_crit there are two per
    turn, one stable and one saddle. ``theta`` > 0 in rad/s.

    Parameters
    ----------
    body : Body
        The body.
    theta : float
        Angular rate (rad/s), > 0.

    Returns
    -------
    float
        R_crit (m).
    """
    _check_circle_args(body, None, theta)
    return body.c_phi / (body.a * math.hypot(body.m * theta, body.c))


def circle_equilibria(body: Body, R: float, theta: float) -> tuple[float, float]:
    """The two equilibria (stable, saddle) of the corrected (33), p = phi - theta t - pi/2 (rad).

    With gamma = arctan(m theta / c) and k = R_crit / R <= 1, (33) at rest reads
    sin(p - gamma) = -k, so p_stable = gamma - arcsin k and
    p_saddle = gamma + pi + arcsin k, both wrapped to (-pi, pi].
    Raises ValueError when R < R_crit (no equilibrium: the rotation slips for ever).

    Parameters
    ----------
    body : Body
        The body.
    R : float
        Radius (m), >= R_crit.
    theta : float
        Angular rate (rad/s), > 0.

    Returns
    -------
    p_stable, p_saddle : float
        The two equilibria (rad), in (-pi, pi].
    """
    _check_circle_args(body, R, theta)
    r_crit = circle_critical_radius(body, theta)
    if R < r_crit:
        raise ValueError(f"no equilibrium: R = {R!r} m is below the critical radius "
                         f"R_crit = {r_crit:.6g} m of (36) at theta = {theta!r} rad/s")
    k = min(r_crit / R, 1.0)
    gamma = math.atan(body.m * theta / body.c)
    return float(wrap_angle(gamma - math.asin(k))), float(wrap_angle(gamma + math.pi + math.asin(k)))


def circle_jacobian(body: Body, R: float, theta: float, p0: float) -> np.ndarray:
    """Jacobian of (33) (corrected) at (p0, 0): the matrix of the linearisation (34).

    Parameters
    ----------
    body : Body
        The body.
    R : float
        Radius (m), > 0.
    theta : float
        Angular rate (rad/s), > 0.
    p0 : float
        The equilibrium (rad).

    Returns
    -------
    numpy.ndarray
        The 2 x 2 Jacobian of (p, p') -> (p', p'') (1/s, 1/s^2).
    """
    k21 = -body.a * R * theta / body.I * (body.c * math.cos(p0) + body.m * theta * math.sin(p0))
    return np.array([[0.0, 1.0], [k21, -body.c_phi / body.I]])


def circle_eigenvalues(body: Body, R: float, theta: float) -> np.ndarray:
    """Eigenvalues (1/s) of the linearisation (34) at the stable equilibrium:
    the roots of (35), lambda^2 + c_phi/I lambda + theta/I sqrt(a^2 R^2 (m^2 theta^2 + c^2) - c_phi^2).
    Complex array of two values, sorted by real part.

    Parameters
    ----------
    body : Body
        The body.
    R : float
        Radius (m), >= R_crit.
    theta : float
        Angular rate (rad/s), > 0.

    Returns
    -------
    numpy.ndarray
        The two eigenvalues (1/s), complex, sorted by real part.
    """
    p_s, _ = circle_equilibria(body, R, theta)
    k0 = theta / body.I * math.sqrt(max(body.a**2 * R**2 * (body.m**2 * theta**2 + body.c**2)
                                        - body.c_phi**2, 0.0))
    lam = np.roots([1.0, body.c_phi / body.I, k0]).astype(complex)
    return lam[np.argsort(lam.real)]


def circle_rotation_rhs(body: Body, R, theta, p, v_p) -> np.ndarray:
    """Right side of the corrected (33): returns v_p' (rad/s^2); vectorised over arrays.

    Parameters
    ----------
    body : Body
        The body.
    R, theta : array_like
        Radius (m) and angular rate (rad/s).
    p, v_p : array_like
        The rotation error (rad) and its rate (rad/s).

    Returns
    -------
    numpy.ndarray
        v_p' (rad/s^2), of the broadcast shape.
    """
    p, v_p = np.asarray(p, dtype=float), np.asarray(v_p, dtype=float)
    return (-body.c_phi / body.I * v_p - body.a * body.c * theta * R / body.I * np.sin(p)
            + body.a * body.m * theta**2 * R / body.I * np.cos(p) - body.c_phi * theta / body.I)
