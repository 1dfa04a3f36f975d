"""Computed-torque tracking law (23) and the position-only allocation (25)-(26).

The law computes a generalized force tau = [tau_x (N), tau_y (N), tau_phi (N m)]
that would make the tracking error obey the linear equation (24). With one
force of magnitude F and angle beta the body can realise (tau_x, tau_y) exactly
but not tau_phi at the same time; (25)-(26) realise the position part and leave
the rotation to itself.
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import expm

from .params import Body, Gains

__all__ = ["computed_torque", "computed_torque_from", "allocate", "allocate_least_squares", "allocate_limited", "input_matrix", "wrap_angle",
           "error_dynamics_solution"]


def wrap_angle(angle) -> np.ndarray:
    """Wrap angles (rad) to the interval (-pi, pi]."""
    angle = np.asarray(angle, dtype=float)
    return np.pi - np.mod(np.pi - angle, 2 * np.pi)


def computed_torque(body: Body, gains: Gains, ref, t, z, dz) -> np.ndarray:
    """Computed-torque demand, eq. (23).

    tau = M ddz_d + N(dz) + Kv (dz_d - dz) + Kp (z_d - z), with N(dz) = (c xdot, c ydot, c_phi phidot).
    ``ref`` is a reference (:mod:`lib.trajectories`), ``t`` time(s) in s, ``z`` and
    ``dz`` the actual configuration and its rate, shape (..., 3).
    Returns tau = [tau_x (N), tau_y (N), tau_phi (N m)], shape (..., 3).
    """
    return computed_torque_from(body, gains, ref.z(t), ref.dz(t), ref.ddz(t), z, dz)


def computed_torque_from(body: Body, gains: Gains, z_d, dz_d, ddz_d, z, dz) -> np.ndarray:
    """Eq. (23) from the reference values themselves: z_d, dz_d, ddz_d and the actual
    z, dz, all of shape (..., 3) (broadcast); see :func:`computed_torque`."""
    z = np.asarray(z, dtype=float)
    dz = np.asarray(dz, dtype=float)
    m = np.array([body.m, body.m, body.I])
    return m * ddz_d + body.drag * dz + gains.kv * (dz_d - dz) + gains.kp * (z_d - z)


def allocate(tau, phi, force_limit: float | None = None, angle_limit: float | None = None):
    """Force magnitude and angle realising (tau_x, tau_y), eqs. (25)-(26).

    F = sqrt(tau_x^2 + tau_y^2) (N) and beta = Arg(tau_x + i tau_y) - phi (rad),
    wrapped to (-pi, pi]; tau_phi (``tau[..., 2]``, if present) is ignored.

    Limits, applied when given:

    * ``force_limit`` (N, > 0): F is capped, F <- min(F, force_limit), the
      direction kept;
    * ``angle_limit`` (rad, in (0, pi]): beta is clipped to
      [-angle_limit, angle_limit]. A demanded direction behind the body
      (|beta| > angle_limit) is replaced by the nearest admissible direction,
      so beta jumps from +angle_limit to -angle_limit when the demand passes
      straight behind the body.

    When tau_x = tau_y = 0 no force is needed: F = 0 and beta = 0 by
    definition (the direction of a zero force is immaterial).

    Returns (F, beta) as arrays of the broadcast shape of tau[..., 0] and phi.
    """
    tau = np.asarray(tau, dtype=float)
    if tau.ndim == 0 or tau.shape[-1] not in (2, 3):
        raise ValueError(f"tau must have a last axis of length 2 or 3, got shape {tau.shape}")
    tx, ty = tau[..., 0], tau[..., 1]
    F = np.hypot(tx, ty)
    beta = np.where(F > 0, wrap_angle(np.arctan2(ty, tx) - np.asarray(phi, dtype=float)), 0.0)
    F = np.broadcast_to(F, beta.shape).copy()
    return _limit(F, beta, force_limit, angle_limit)


def input_matrix(phi, body: Body) -> np.ndarray:
    """B(phi) with Q = B(phi) u, u = (u1, u2) = (F cos beta, F sin beta), eq. (22).

    B = [[cos phi, -sin phi], [sin phi, cos phi], [0, a]]; shape phi.shape + (3, 2).
    """
    phi = np.asarray(phi, dtype=float)
    c, s = np.cos(phi), np.sin(phi)
    z, a = np.zeros_like(phi), np.full_like(phi, body.a)
    return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1), np.stack([z, a], -1)], -2)


def _limit(F, beta, force_limit, angle_limit):
    if force_limit is not None:
        _check_limit("force_limit", force_limit, upper=np.inf)
        F = np.minimum(F, force_limit)
    if angle_limit is not None:
        _check_limit("angle_limit", angle_limit, upper=np.pi)
        beta = np.clip(beta, -angle_limit, angle_limit)
    return F, beta


def _least_squares(tau, phi, body: Body, weights):
    """The weighted least-squares problem of :func:`allocate_least_squares`, validated:
    returns its unconstrained solution u* (..., 2), and G = A^T A (..., 2, 2),
    r = A^T b (..., 2) and |b|^2 (...), so that the residual is
    J(u) = u^T G u - 2 r^T u + |b|^2, with A = W^(1/2) B(phi) and b = W^(1/2) tau."""
    tau = np.asarray(tau, dtype=float)
    if tau.ndim == 0 or tau.shape[-1] != 3:
        raise ValueError(f"tau must have a last axis of length 3 (tau_x, tau_y, tau_phi), got shape {tau.shape}")
    w = np.asarray(weights, dtype=float)
    if w.ndim == 0 or w.shape[-1] != 3 or not np.all(np.isfinite(w)) or np.any(w < 0) or not np.all(np.any(w > 0, -1)):
        raise ValueError(f"weights must be three finite non-negative numbers, not all zero, got {weights!r}")
    if not isinstance(body, Body):
        raise TypeError(f"body must be a lib.params.Body, got {type(body).__name__}")
    sw = np.sqrt(w)
    A = sw[..., :, None] * input_matrix(phi, body)             # (..., 3, 2)
    A = np.broadcast_to(A, np.broadcast_shapes(A.shape, tau.shape[:-1] + (3, 2)))
    b = sw * tau                                               # (..., 3)
    # normal equations G u = r with G = A^T A (2 x 2), solved in closed form;
    # where G is (nearly) singular, the pseudo-inverse gives the minimum-norm u
    G = np.einsum("...ki,...kj->...ij", A, A)
    r = np.einsum("...ki,...k->...i", A, b)
    det = G[..., 0, 0] * G[..., 1, 1] - G[..., 0, 1] * G[..., 1, 0]
    regular = det > 1e-12 * np.maximum(G[..., 0, 0] + G[..., 1, 1], 1e-300) ** 2
    safe = np.where(regular, det, 1.0)
    u = np.stack([(G[..., 1, 1] * r[..., 0] - G[..., 0, 1] * r[..., 1]) / safe,
                  (G[..., 0, 0] * r[..., 1] - G[..., 1, 0] * r[..., 0]) / safe], axis=-1)
    if not np.all(regular):
        u = np.where(regular[..., None], u, (np.linalg.pinv(A) @ b[..., None])[..., 0])
    return u, G, r, np.einsum("...k,...k->...", b, b)


def residual(u, G, r, bb) -> np.ndarray:
    """J(u) = u^T G u - 2 r^T u + |b|^2 of :func:`_least_squares`, for u of shape (..., 2)."""
    return np.einsum("...i,...ij,...j->...", u, G, u) - 2 * np.einsum("...i,...i->...", r, u) + bb


def allocate_limited(tau, phi, body: Body, weights=(1.0, 1.0, 0.0),
                     force_limit: float | None = None, angle_limit: float | None = None):
    """The weighted least-squares allocation *under* the limits, solved exactly.

    Minimises J(u) = sum_i w_i (tau_i - Q_i(u))^2 (see :func:`allocate_least_squares`)
    over the admissible forces u = (F cos beta, F sin beta) with F <= ``force_limit``
    (N) and |beta| <= ``angle_limit`` (rad): a disc sector, convex for
    angle_limit <= pi/2 and not for larger limits. J is a convex quadratic, so its
    minimum over the sector is the unconstrained optimum when that is admissible,
    and otherwise lies on the boundary: on one of the two rays beta = +-angle_limit
    (a quadratic in F, minimised in closed form and clipped to [0, force_limit]), or
    on the arc F = force_limit (a trigonometric polynomial of degree 2 in beta,
    minimised by sampling it at 129 angles and refining each sampled local minimum
    by golden-section search to machine precision). The candidate with the least J
    is returned; this holds for the non-convex sector too, since it only uses that
    an interior minimum of a convex function is unconstrained.

    With no limit it is :func:`allocate_least_squares`; with w_phi = 0 and no limit,
    exactly (25)-(26). Returns (F (N), beta (rad)) like :func:`allocate`.
    """
    u_star, G, r, bb = _least_squares(tau, phi, body, weights)
    if force_limit is not None:
        _check_limit("force_limit", force_limit, upper=np.inf)
    if angle_limit is not None:
        _check_limit("angle_limit", angle_limit, upper=np.pi)
    fmax = np.inf if force_limit is None else float(force_limit)
    bmax = np.pi if angle_limit is None else float(angle_limit)
    shape = np.broadcast_shapes(u_star.shape[:-1], G.shape[:-2], r.shape[:-1], bb.shape)
    u_star = np.broadcast_to(u_star, shape + (2,)).reshape(-1, 2)
    G = np.broadcast_to(G, shape + (2, 2)).reshape(-1, 2, 2)
    r = np.broadcast_to(r, shape + (2,)).reshape(-1, 2)
    bb = np.broadcast_to(bb, shape).reshape(-1)
    F_star = np.hypot(u_star[:, 0], u_star[:, 1])
    admissible = (F_star <= fmax) & ((F_star == 0) | (np.abs(np.arctan2(u_star[:, 1], u_star[:, 0])) <= bmax))
    cands = [np.where(admissible[:, None], u_star, np.nan),  # the unconstrained optimum, if admissible
             np.zeros_like(u_star)]                           # the corner at the origin
    if bmax < np.pi:                                          # the two rays beta = +-bmax
        for sign in (1.0, -1.0):
            d = np.array([np.cos(bmax), sign * np.sin(bmax)])
            dGd = np.einsum("i,nij,j->n", d, G, d)
            rd = r @ d
            # J(t d) = t^2 dGd - 2 t rd + |b|^2; dGd = 0 forces rd = 0 (J >= 0), so J is flat there
            t = np.divide(rd, dGd, out=np.zeros_like(rd), where=dGd > 0)
            cands.append(np.clip(t, 0.0, fmax)[:, None] * d)
    if np.isfinite(fmax):                                     # the arc F = fmax
        cands += _arc_minima(G, r, fmax, bmax)
    C = np.stack(cands, axis=1)                               # (n, candidates, 2)
    J = np.nan_to_num(residual(C, G[:, None], r[:, None], bb[:, None]), nan=np.inf)
    u = C[np.arange(C.shape[0]), np.argmin(J, axis=1)]
    F = np.hypot(u[:, 0], u[:, 1])
    beta = np.where(F > 0, np.arctan2(u[:, 1], u[:, 0]), 0.0)
    return F.reshape(shape), beta.reshape(shape)


def _arc_minima(G, r, fmax: float, bmax: float, n_samples: int = 129) -> list[np.ndarray]:
    """Points u = fmax (cos beta, sin beta), |beta| <= bmax, at the two best sampled local
    minima of J along the arc, each refined by golden-section search between its neighbours
    (J along the arc is a trigonometric polynomial of degree 2: at most two local minima)."""
    def J_arc(beta):  # J - |b|^2 at u = fmax e(beta), for beta of shape (n,)
        e = np.stack([np.cos(beta), np.sin(beta)], axis=-1) * fmax
        return np.einsum("ni,nij,nj->n", e, G, e) - 2 * np.einsum("ni,ni->n", r, e)

    betas = np.linspace(-bmax, bmax, n_samples)
    E = np.stack([np.cos(betas), np.sin(betas)], axis=-1) * fmax
    J = np.einsum("mi,nij,mj->nm", E, G, E) - 2 * r @ E.T                   # (n, samples)
    Jp = np.pad(J, ((0, 0), (1, 1)), constant_values=np.inf)
    local = (J <= Jp[:, :-2]) & (J <= Jp[:, 2:])
    ranked = np.argsort(np.where(local, J, np.inf), axis=1, kind="stable")[:, :2]
    h, g = betas[1] - betas[0], (np.sqrt(5.0) - 1) / 2
    out = []
    for j in range(ranked.shape[1]):
        c = betas[ranked[:, j]]
        lo, hi = np.maximum(c - h, -bmax), np.minimum(c + h, bmax)
        for _ in range(60):  # the bracket shrinks by 0.618 per step: 60 steps reach rounding
            x1, x2 = hi - g * (hi - lo), lo + g * (hi - lo)
            left = J_arc(x1) < J_arc(x2)
            lo, hi = np.where(left, lo, x1), np.where(left, x2, hi)
        best = 0.5 * (lo + hi)
        out.append(np.stack([np.cos(best), np.sin(best)], axis=-1) * fmax)
    return out


def allocate_least_squares(tau, phi, body: Body, weights=(1.0, 1.0, 0.0),
                           force_limit: float | None = None, angle_limit: float | None = None):
    """Force and angle minimising the weighted residual of the whole demand (23).

    Solves min_u sum_i w_i (tau_i - Q_i(u))^2 with Q = B(phi) u (see
    :func:`input_matrix`), u = (F cos beta, F sin beta): the optimisation the
    paper poses after eq. (24) and leaves unsolved. Q is linear in u, so this
    is linear least squares with the closed form

        u* = (W^(1/2) B)^+ W^(1/2) tau,

    the minimum-norm solution when B^T W B is singular (e.g. w_x = w_y = 0).
    For w_x = w_y = w it reduces to
    u1 = cos(phi) tau_x + sin(phi) tau_y and
    u2 = [w (-sin(phi) tau_x + cos(phi) tau_y) + a w_phi tau_phi] / (w + a^2 w_phi);
    with w_phi = 0 it is exactly the position-only law (25)-(26).

    ``weights`` = (w_x, w_y, w_phi) >= 0, not all zero (units: w_phi weighs a
    torque residual in (N m)^2 against force residuals in N^2); an array of
    shape (..., 3) gives one weight triple per demand. Limits are then
    applied as in :func:`allocate` (cap on F, clip of beta): a projection of the
    unconstrained optimum, not the optimum under the limits.

    Returns (F (N), beta (rad)), beta in (-pi, pi]; F = 0, beta = 0 when u* = 0.
    """
    u, _, _, _ = _least_squares(tau, phi, body, weights)
    F = np.hypot(u[..., 0], u[..., 1])
    beta = np.where(F > 0, np.arctan2(u[..., 1], u[..., 0]), 0.0)
    return _limit(F, beta, force_limit, angle_limit)


def _check_limit(name: str, value, upper: float) -> None:
    if isinstance(value, bool) or not np.isscalar(value) or not np.isfinite(value) or not 0 < value <= upper:
        raise ValueError(f"{name} must be a finite number in (0, {upper}], got {value!r}")


def error_dynamics_solution(body: Body, gains: Gains, e0, de0, t) -> np.ndarray:
    """Analytic solution e(t) of the error equation (24), M ë + Kv ė + Kp e = 0.

    ``e0``, ``de0`` are the errors z_d - z and their rates at t = 0 (length 3);
    ``t`` is an array of times (s). Returns e(t), shape t.shape + (3,). Each
    axis is the free response of a linear oscillator, computed with the
    matrix exponential of its companion matrix.
    """
    t = np.asarray(t, dtype=float)
    m = np.array([body.m, body.m, body.I])
    out = np.empty(t.shape + (3,))
    for i in range(3):
        A = np.array([[0.0, 1.0], [-gains.kp[i] / m[i], -gains.kv[i] / m[i]]])
        Phi = expm(A * t.reshape(-1, 1, 1))
        out[..., i] = (Phi @ np.array([e0[i], de0[i]]))[:, 0].reshape(t.shape)
    return out
