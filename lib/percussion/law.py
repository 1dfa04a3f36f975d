"""A tracking law for the centre of percussion P, and its closed loop.

P'' does not contain the lateral force u2 (:mod:`lib.percussion.derivation`): static feedback
is singular. With the thrust u1 made a state xi (an integrator, xi' = nu), P''' is affine in
(nu, u2) through a matrix with determinant -(c/m - c_phi/I_C)/m^2, regular for the book's
body. Writing P''' from :mod:`lib.percussion.point`,

    P''' = (nu/m) e1 + omega' (-2 s_P omega e1 + eps e2) + (xi/m - s_P omega^2) omega e2
           - k P'' - eps omega^2 e1,

the law asks P''' = D := P_d''' + k2 e'' + k1 e' + k0 e (e = P_d - P), i.e.

    omega' = r . e2 / eps,  nu = m (r . e1 + 2 s_P omega omega'),  u2 = (I_C omega' + c_phi omega) / a,
    r = D + k P'' - (xi/m - s_P omega^2) omega e2 + eps omega^2 e1,

so that every component of P's error obeys e''' + k2 e'' + k1 e' + k0 e = 0, the polynomial
(lambda + pole)(lambda^2 + (Kv/m) lambda + Kp/m): the paper's error equation (24) for the
position times one more real pole (:func:`error_polynomial`).

Under limits (the paper's Sec. 5 force cap and angle limit) the applied force differs from the
law's (xi, u2) and the thrust's integrator runs away: nu contains m 2 s_P omega omega' with the
law's omega' = r . e2 / eps, which the clipped lateral force cannot deliver (eps is small, so
this demand is large), and xi drifts from the thrust actually applied. The optional anti-windup
of :func:`closed_loop_rates` corrects both while a limit is active (the law's F above the cap,
or its |beta| above the angle limit), with the applied (F_a, beta_a):

    xi' = m (r . e1 + 2 s_P omega omega'_a) + (xi_a - xi) / T_aw,
    omega'_a = (a F_a sin beta_a - c_phi omega) / I_C,   xi_a = F_a cos beta_a,

the integrator's input built from the angular acceleration actually applied, and
back-calculation pulling xi towards the applied thrust with the time constant T_aw (s, default
:data:`ANTI_WINDUP_TIME`). Without saturation both terms are exactly zero (xi' = nu).
On the eight (R = 2 m, Theta = pi/4) under the 4 N cap, back-calculation alone still blows up
(at t = 4.6 s, as without anti-windup), and conditional integration (xi' = 0 while saturated
and nu pushes further out) switches the field so often that DOP853 at 1e-8 did not reach 15 s
of simulated time in 100 s of CPU; this pair keeps the run bounded under the cap alone and
under the cap with a 30 or 45 deg angle limit. Under the cap with a 60 deg limit, or a 30 deg
limit alone, the run reaches a reversed thrust (xi < 0) with u2 -> 0, where the clipped angle
of :func:`applied_force` flips between +beta_max and -beta_max (the branch cut of arctan2): a
sliding mode in which the adaptive integrator crawls (no 60 s run in 150 s at rtol 1e-8; the
cap with 90 deg gave none in 150 s at the default 1e-10 either).
"""

from __future__ import annotations

import numpy as np

from ..machinery import checks
from ..params import Body, Gains
from .point import _eps, _point_accel, _point_state, _s_p

__all__ = ["DEFAULT_POLE", "ANTI_WINDUP_TIME", "error_polynomial", "law_inputs", "closed_loop_rates",
           "applied_force"]

#: the extra real pole (1/s) of the default error polynomial
DEFAULT_POLE = 2.0
#: the back-calculation anti-windup's default time constant T_aw (s)
ANTI_WINDUP_TIME = 0.5


def error_polynomial(body: Body, gains: Gains, pole: float = DEFAULT_POLE) -> np.ndarray:
    """(k2, k1, k0) per axis (2, 3) of e''' + k2 e'' + k1 e' + k0 e = 0: the product of
    (lambda + pole) with the paper's (24) for the axis, lambda^2 + (Kv/m) lambda + Kp/m.

    Parameters
    ----------
    body : Body
        The body (its m).
    gains : Gains
        Kp, Kv (x and y entries).
    pole : float
        The extra pole (1/s), > 0.

    Returns
    -------
    numpy.ndarray
        (2, 3): rows x, y; columns k2 (1/s), k1 (1/s^2), k0 (1/s^3).
    """
    checks.instance("body", body, Body)
    checks.instance("gains", gains, Gains)
    pole = checks.number("pole", pole, positive=True, unit="1/s")
    b, c = gains.kv[:2] / body.m, gains.kp[:2] / body.m
    return np.stack([b + pole, c + pole * b, pole * c], -1)


def law_inputs(body: Body, coeffs: np.ndarray, ref_kin, z, dz, xi) -> tuple[np.ndarray, np.ndarray]:
    """The law's inputs (nu (N/s), u2 (N)) at the state (z, dz, xi), vectorised over (...).

    ``ref_kin`` = (P_d, P_d', P_d'', P_d''') each (..., 2); ``coeffs`` from
    :func:`error_polynomial`. The body is checked, the arrays are not: the closed loop's inner
    loop (:func:`closed_loop_rates`) calls the unchecked kernel behind it.

    Parameters
    ----------
    body : Body
        The body (m, I_C, a, c, c_phi).
    coeffs : numpy.ndarray
        (2, 3): k2 (1/s), k1 (1/s^2), k0 (1/s^3) per axis x, y (:func:`error_polynomial`).
    ref_kin : tuple of numpy.ndarray
        (P_d (m), P_d' (m/s), P_d'' (m/s^2), P_d''' (m/s^3)), each (..., 2).
    z : numpy.ndarray
        C's configuration (x, y, phi) (m, m, rad), (..., 3).
    dz : numpy.ndarray
        Its rate (m/s, m/s, rad/s), (..., 3).
    xi : numpy.ndarray
        The thrust state xi = F cos beta (N), (...).

    Returns
    -------
    nu : numpy.ndarray
        The thrust's rate xi' (N/s), (...).
    u2 : numpy.ndarray
        The lateral force F sin beta (N), (...).
    """
    checks.instance("body", body, Body)
    return _law_inputs(body, coeffs, ref_kin, z, dz, xi)


def _law_inputs(body: Body, coeffs, ref_kin, z, dz, xi):
    """:func:`law_inputs` of a checked body (the closed loop's inner loop)."""
    s, eps, k, m = _s_p(body), _eps(body), body.c / body.m, body.m
    phi, om = z[..., 2], dz[..., 2]
    P, dP = _point_state(body, z, dz)
    ddP = _point_accel(body, phi, om, dP, xi)
    Pd, dPd, ddPd, dddPd = ref_kin
    D = dddPd + coeffs[:, 0] * (ddPd - ddP) + coeffs[:, 1] * (dPd - dP) + coeffs[:, 2] * (Pd - P)
    c, sn = np.cos(phi), np.sin(phi)
    along = xi / m - s * om**2
    r1 = (D[..., 0] + k * ddP[..., 0]) * c + (D[..., 1] + k * ddP[..., 1]) * sn + eps * om**2
    r2 = -(D[..., 0] + k * ddP[..., 0]) * sn + (D[..., 1] + k * ddP[..., 1]) * c - along * om
    dom = r2 / eps
    nu = m * (r1 + 2 * s * om * dom)
    u2 = (body.I * dom + body.c_phi * om) / body.a
    return nu, u2


def applied_force(xi, u2, force_cap=None, angle_cap=None) -> tuple[np.ndarray, np.ndarray]:
    """(F, beta) of the body-frame force (xi, u2) (N), with F clipped to ``force_cap`` (N) and
    beta to |beta| <= ``angle_cap`` (rad) when given (the paper's Sec. 5 limits).

    Parameters
    ----------
    xi : array_like
        Thrust along the body axis, F cos beta (N).
    u2 : array_like
        Lateral force, F sin beta (N), broadcastable with ``xi``.
    force_cap : float, optional
        F_max (N); None for no cap.
    angle_cap : float, optional
        beta_max (rad); None for no limit.

    Returns
    -------
    F : numpy.ndarray
        Force magnitude (N), >= 0, the broadcast shape of ``xi`` and ``u2``.
    beta : numpy.ndarray
        Force angle from the body axis (rad), in [-pi, pi], same shape.
    """
    F, beta = np.hypot(xi, u2), np.arctan2(u2, xi)
    if angle_cap is not None:
        beta = np.clip(beta, -angle_cap, angle_cap)
    if force_cap is not None:
        F = np.minimum(F, force_cap)
    return F, beta


def closed_loop_rates(body: Body, coeffs, ref_kin, y, limits=None, anti_windup=None):
    """Rates of the closed loop's state y = (x, y, phi, x', y', phi', xi) (..., 7) under the
    law, and the applied (F, beta). Unvalidated kernel.

    Parameters
    ----------
    body : Body
        The plant (and the law's model).
    coeffs : numpy.ndarray
        (2, 3) from :func:`error_polynomial` (1/s, 1/s^2, 1/s^3).
    ref_kin : tuple of numpy.ndarray
        (P_d (m), P_d' (m/s), P_d'' (m/s^2), P_d''' (m/s^3)), each (..., 2).
    y : numpy.ndarray
        The state (m, m, rad, m/s, m/s, rad/s, N), (..., 7).
    limits : Limits, optional
        :class:`lib.allocation.Limits` applied to (F, beta); None for none.
    anti_windup : float, optional
        T_aw (s) of the anti-windup (the module's docstring): where a limit is active (the
        law's F above the cap, or its |beta| above the angle limit), nu's omega' is the applied
        one and xi is pulled towards F cos beta by (F cos beta - xi) / T_aw, with the applied
        (F, beta); elsewhere xi' = nu exactly. None (default): xi' = nu.

    Returns
    -------
    rates : numpy.ndarray
        y' (m/s, m/s, rad/s, m/s^2, m/s^2, rad/s^2, N/s), (..., 7).
    F : numpy.ndarray
        The applied force magnitude (N), (...).
    beta : numpy.ndarray
        Its angle from the body axis (rad), (...).
    """
    z, dz, xi = y[..., :3], y[..., 3:6], y[..., 6]
    nu, u2 = _law_inputs(body, coeffs, ref_kin, z, dz, xi)
    fc = None if limits is None else limits.force
    ac = None if limits is None else limits.angle
    F, beta = applied_force(xi, u2, fc, ac)
    phi = z[..., 2]
    acc = np.stack([(F * np.cos(phi + beta) - body.c * dz[..., 0]) / body.m,
                    (F * np.sin(phi + beta) - body.c * dz[..., 1]) / body.m,
                    (F * body.a * np.sin(beta) - body.c_phi * dz[..., 2]) / body.I], -1)
    if anti_windup is not None and (fc is not None or ac is not None):
        F0, beta0 = applied_force(xi, u2)
        saturated = np.zeros(np.shape(F0), bool)
        if fc is not None:
            saturated |= F0 > fc
        if ac is not None:
            saturated |= np.abs(beta0) > ac
        om = dz[..., 2]
        dom_law = (body.a * u2 - body.c_phi * om) / body.I          # the law's omega'
        s = _s_p(body)
        fix = body.m * 2 * s * om * (acc[..., 2] - dom_law) + (F * np.cos(beta) - xi) / anti_windup
        nu = nu + np.where(saturated, fix, 0.0)
    return np.concatenate([dz, acc, nu[..., None]], -1), F, beta
