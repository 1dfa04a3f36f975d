"""The heading when P follows a path exactly: the zero dynamics of the output P, in closed form.

With P = P_d(t) for all t, P'' + k P' = w(t) := P_d'' + k P_d' is known, and the body-frame
form of P's equation (:mod:`lib.percussion.point`) splits into

    eps phi' = w . e2 = |w| sin(psi - phi),       u1 = m (w . e1 + s_P phi'^2),

psi = arg w: a *first-order* equation for the heading (the zero dynamics are one-dimensional;
with eps = 0, c/m = c_phi/I_C, they collapse to phi = psi or psi + pi). For a frozen w turning
at psi' the heading lags psi by delta, sin delta = -eps psi' / |w|, which exists (the heading
stays *locked*) iff |eps psi'| <= |w|; the branch with eps cos delta > 0 is stable, with rate
-sqrt(|w|^2 - (eps psi')^2) / |eps| (1/s), the other unstable.

On the circle (27) run by P (radius R, rate Theta > 0) everything is constant:
|w| = R Theta sqrt(Theta^2 + k^2), psi' = Theta, and (:func:`circle_steady_motion`)

    p = arctan(Theta / k) - arcsin(eps / (R sqrt(Theta^2 + k^2)))      (eps > 0),
    u1 = m (|w| cos delta + s_P Theta^2),  u2 = c_phi Theta / a,  F = |(u1, u2)|,
    radius of C = sqrt(R^2 + 2 R s_P sin p + s_P^2),
    rate = -sqrt(|w|^2 - (eps Theta)^2) / |eps|,

locked iff R >= |eps| / sqrt(Theta^2 + k^2) (:func:`circle_lock_radius`; the paper's (36) for
C has c_phi / (a sqrt(m^2 Theta^2 + c^2)), larger by the factor c_phi / (c_phi - c I_C / m)).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from ..machinery import checks
from ..angles import wrap_angle
from ..params import Body
from ..trajectories import POSITIONS, Reference, _Path
from .point import _eps, centre_of_percussion, lateral_drag_speed

__all__ = ["path_drive", "heading_rate", "frozen_lock", "CircleSteadyMotion", "circle_steady_motion", "circle_slip",
           "circle_lock_radius", "zero_dynamics_run"]


def path_drive(body: Body, ref: Reference, t) -> tuple[np.ndarray, np.ndarray]:
    """w = P_d'' + (c/m) P_d' (m/s^2) and its rate w' (m/s^3) of the reference's position at t (s),
    each (..., 2); exact for the circle (27) and the eight (28).

    Parameters
    ----------
    body : Body
        The body.
    ref : Reference
        The path P follows (its x, y).
    t : array_like
        Times (s).

    Returns
    -------
    w, dw : numpy.ndarray
        (..., 2).
    """
    k = body.c / body.m
    t = np.asarray(t, float)
    if isinstance(ref, _Path):
        _, _, vx, vy, ax, ay, jx, jy = POSITIONS[ref._kind](ref.R, ref.theta, t)
        v, acc, jerk = np.stack([vx, vy], -1), np.stack([ax, ay], -1), np.stack([jx, jy], -1)
    else:
        v, acc = ref.dz(t)[..., :2], ref.ddz(t)[..., :2]
        h = 1e-4
        jerk = (ref.ddz(t + h)[..., :2] - ref.ddz(t - h)[..., :2]) / (2 * h)
    return acc + k * v, jerk + k * acc


def heading_rate(body: Body, phi, w) -> np.ndarray:
    """The zero dynamics: phi' = (w_y cos phi - w_x sin phi) / eps (rad/s) for P on its path.

    Parameters
    ----------
    body : Body
        The body.
    phi : array_like
        Heading (rad).
    w : array_like
        P_d'' + k P_d' (..., 2) (m/s^2).

    Returns
    -------
    numpy.ndarray
        phi' (rad/s).
    """
    checks.instance("body", body, Body)
    return _heading_rate(_eps(body), phi, w)


def _heading_rate(eps: float, phi, w) -> np.ndarray:
    """:func:`heading_rate`'s kernel for a checked body's eps (m/s), for inner loops."""
    w = np.asarray(w, float)
    return (w[..., 1] * np.cos(phi) - w[..., 0] * np.sin(phi)) / eps


def frozen_lock(body: Body, w, dpsi) -> dict:
    """The frozen-w picture of the zero dynamics: for |w| (m/s^2) and psi' (rad/s), the lock
    margin |w| - |eps psi'| (>= 0: locked), the stable lag delta = phi - psi (rad) and its rate
    (1/s, negative). Arrays broadcast; NaN where not locked.

    Parameters
    ----------
    body : Body
        The body.
    w : array_like
        |w| (m/s^2).
    dpsi : array_like
        psi' (rad/s).

    Returns
    -------
    dict
        margin, delta, rate.
    """
    eps = lateral_drag_speed(body)
    w, dpsi = np.asarray(w, float), np.asarray(dpsi, float)
    x = eps * dpsi / w
    with np.errstate(invalid="ignore"):
        delta = -np.arcsin(x) + (0.0 if eps > 0 else np.pi)
        rate = -np.sqrt(w**2 - (eps * dpsi) ** 2) / abs(eps)
    return dict(margin=w - np.abs(eps * dpsi), delta=delta, rate=rate)


def circle_lock_radius(body: Body, Theta: float) -> float:
    """The smallest circle (m) P can run at Theta (rad/s) with the heading locked:
    |eps| / sqrt(Theta^2 + (c/m)^2).

    Parameters
    ----------
    body : Body
        The body.
    Theta : float
        Rate (rad/s), > 0.

    Returns
    -------
    float
        R (m).
    """
    checks.instance("body", body, Body)
    Theta = checks.number("Theta", Theta, positive=True, unit="rad/s")
    return abs(lateral_drag_speed(body)) / math.hypot(Theta, body.c / body.m)


@dataclass(frozen=True)
class CircleSteadyMotion:
    """The steady motion with P on the circle (27) of radius R (m) at Theta (rad/s).

    p (rad): phi - Theta t - pi/2, the paper's rotation error on the circle; delta (rad): the
    heading's lag behind w; u1, u2, F (N) and beta (rad): the force; radius_C (m): C's circle;
    rate (1/s): the heading's linearised rate (negative: stable); R_lock (m): the smallest
    locked radius at this Theta."""

    R: float
    Theta: float
    p: float
    delta: float
    u1: float
    u2: float
    F: float
    beta: float
    radius_C: float
    rate: float
    R_lock: float


def circle_steady_motion(body: Body, R: float, Theta: float) -> CircleSteadyMotion:
    """The steady motion of the body with P exactly on the circle (27), in closed form (see the
    module's docstring). Raises ValueError below the lock radius (no steady heading).

    Parameters
    ----------
    body : Body
        The body.
    R : float
        Radius of P's circle (m), > 0.
    Theta : float
        Rate (rad/s), > 0.

    Returns
    -------
    CircleSteadyMotion
        The steady motion.
    """
    checks.instance("body", body, Body)
    R = checks.number("R", R, positive=True, unit="m")
    Theta = checks.number("Theta", Theta, positive=True, unit="rad/s")
    s, eps, k, m = centre_of_percussion(body), lateral_drag_speed(body), body.c / body.m, body.m
    R_lock = circle_lock_radius(body, Theta)
    if R < R_lock:
        raise ValueError(f"R must be at least the lock radius {R_lock:.6g} m at Theta = {Theta} rad/s, got {R} m")
    W = R * Theta * math.hypot(Theta, k)
    fl = frozen_lock(body, W, Theta)
    delta, rate = float(fl["delta"]), float(fl["rate"])
    psi_rel = math.atan2(k * Theta, -Theta**2)              # arg w - Theta t (w in the (e_r, e_t) frame)
    p = float(wrap_angle(psi_rel + delta - math.pi / 2))
    u1 = m * (W * math.cos(delta) + s * Theta**2)
    u2 = body.c_phi * Theta / body.a
    radius_C = math.sqrt(R**2 + 2 * R * s * math.sin(p) + s**2)
    return CircleSteadyMotion(R=R, Theta=Theta, p=p, delta=delta, u1=u1, u2=u2, F=math.hypot(u1, u2),
                              beta=math.atan2(u2, u1), radius_C=radius_C, rate=rate, R_lock=R_lock)


def zero_dynamics_run(body: Body, ref: Reference, t, phi0: float, *, rtol: float = 1e-11,
                      atol: float = 1e-12) -> np.ndarray:
    """The heading phi(t) (rad) of the zero dynamics eps phi' = w . e2 from phi(0) = ``phi0``,
    sampled at the increasing times ``t`` (s) from 0 (adaptive DOP853; a check, not a sweep).

    Parameters
    ----------
    body : Body
        The body.
    ref : Reference
        The path of P.
    t : array_like
        Output times (s), increasing, t[0] = 0.
    phi0 : float
        Start heading (rad).
    rtol, atol : float
        Tolerances.

    Returns
    -------
    numpy.ndarray
        phi at t.
    """
    checks.instance("body", body, Body)
    if not all(callable(getattr(ref, k, None)) for k in ("z", "dz", "ddz")):
        raise TypeError(f"ref must be a reference with z, dz and ddz methods, got {type(ref).__name__}")
    t = checks.array("t", t, ndim=1, nonempty=True)
    phi0 = checks.number("phi0", phi0)
    rtol, atol = checks.number("rtol", rtol, positive=True), checks.number("atol", atol, positive=True)
    # the heading relaxes at up to (a_ref + (c/m) v) / |eps| (1/s): a stiff first-order equation,
    # DOP853's steps about that rate times the span over 4 (the domain check, before any run)
    speed, accel = checks.path_extremes(ref)
    rate = (accel + body.c / body.m * speed) / abs(_eps(body))
    name = f"ref (R = {ref.R:g} m, theta = {ref.theta:g} rad/s)" if hasattr(ref, "R") else "ref"
    checks.within_budget({name: checks.run_steps(-rate, float(t[-1]))}, checks.MAX_ODE_STEPS,
                         what="the run would need", unit="steps of DOP853", fix="a shorter t, or a smaller R Theta")

    eps = _eps(body)

    def rhs(tt, y):                             # the kernels: body and ref were checked above
        return [_heading_rate(eps, y[0], path_drive(body, ref, tt)[0])]

    sol = solve_ivp(rhs, (0.0, float(t[-1])), [phi0], method="DOP853", t_eval=t, rtol=rtol, atol=atol)
    return sol.y[0]


def circle_slip(body: Body, R: float, Theta: float) -> float:
    """Below the lock radius, the heading error's mean drift on the circle (turns of p per
    period, negative: it falls behind): -sqrt(1 - (R / R_lock)^2), from the autonomous equation
    delta' = -(|w| / eps) sin delta - Theta of the lag behind w; 0 at and above the lock radius.

    Parameters
    ----------
    body : Body
        The body.
    R : float
        Radius of P's circle (m), > 0.
    Theta : float
        Rate (rad/s), > 0.

    Returns
    -------
    float
        Turns per period.
    """
    R = checks.number("R", R, positive=True, unit="m")
    ratio = R / circle_lock_radius(body, Theta)
    return -math.sqrt(1 - ratio**2) if ratio < 1 else 0.0
