"""The allocation step: which force F (N) at which angle beta (rad) realises a demanded
generalized force tau = [tau_x (N), tau_y (N), tau_phi (N m)] (paper Sec. 4).

* :func:`allocate`: the paper's position-only law (25)-(26), which realises
  (tau_x, tau_y) exactly and leaves tau_phi to itself;
* :func:`allocate_least_squares`: the weighted least-squares problem the paper
  poses after (24) and leaves open, in closed form (Chapter 6);
* :func:`allocate_limited`: the same problem solved exactly under force and angle limits.

The limits of the paper's Sec. 5, F <= F_max (29) and |beta| <= beta_max (30), are a
:class:`Limits` object. The public functions validate their arguments at every call;
loops (the integrators) bind an :class:`Allocation` to a body and limits once with
:meth:`Allocation.bind` and call the unvalidated kernel it returns.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numba
import numpy as np

from .machinery import checks
from .angles import wrap_angle
from .model import input_matrix
from .params import Body

__all__ = ["Limits", "Allocation", "LAWS", "allocate", "allocate_least_squares", "allocate_limited", "residual",
           "least_squares_problem"]


def _check_limit(name: str, value, upper: float | None) -> float:
    return checks.number(name, value, positive=True, maximum=upper)


@dataclass(frozen=True)
class Limits:
    """Force and angle limits of the paper's Sec. 5 (Fig. 4; the paper gives them no equation
    number): F <= ``force`` (N) and |beta| <= ``angle`` (rad, in (0, pi]); None means no
    limit. Validated on construction.

    Parameters
    ----------
    force : float, optional
        F_max (N), > 0; None for no cap.
    angle : float, optional
        beta_max (rad), in (0, pi]; None for no limit.

    Raises
    ------
    TypeError
        If a limit is not a real number (a str, a bool, an array), naming it
        (``force``, ``angle``).
    ValueError
        If a limit is not positive and finite, or the angle exceeds pi.
    """

    force: float | None = None
    angle: float | None = None

    def __post_init__(self) -> None:
        if self.force is not None:
            object.__setattr__(self, "force", _check_limit("force", self.force, upper=None))
        if self.angle is not None:
            object.__setattr__(self, "angle", _check_limit("angle", self.angle, upper=np.pi))

    def apply(self, F, beta):
        """Cap F at ``force`` (the direction kept) and clip beta to [-angle, angle]:
        the projection of the paper's Sec. 5."""
        if self.force is not None:
            F = np.minimum(F, self.force)
        if self.angle is not None:
            beta = np.clip(beta, -self.angle, self.angle)
        return F, beta


def _limits_named(force_limit, angle_limit) -> Limits:
    """``Limits`` from a function's ``force_limit`` and ``angle_limit``, an error naming them so."""
    if force_limit is not None:
        force_limit = _check_limit("force_limit", force_limit, upper=None)
    if angle_limit is not None:
        angle_limit = _check_limit("angle_limit", angle_limit, upper=np.pi)
    return Limits(force_limit, angle_limit)


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

    Parameters
    ----------
    tau : array_like
        Demanded generalized force [tau_x (N), tau_y (N), (tau_phi (N m))], shape (..., 2)
        or (..., 3).
    phi : array_like
        Heading (rad), broadcast against ``tau[..., 0]``.
    force_limit : float, optional
        F_max (N), > 0: F is capped at it; None for no cap.
    angle_limit : float, optional
        beta_max (rad), in (0, pi]: beta is clipped to [-beta_max, beta_max];
        None for no limit.

    Returns
    -------
    F : numpy.ndarray
        Force magnitude (N), >= 0, of the broadcast shape of ``tau[..., 0]`` and ``phi``.
    beta : numpy.ndarray
        Force angle to the body axis (rad), in (-pi, pi]; 0 where F = 0.

    Raises
    ------
    TypeError
        If an argument is of the wrong type (a str, a bool), naming it.
    ValueError
        If an argument is out of range or not finite (an array's first bad index named).
    """
    return _position(_check_tau(tau, (2, 3)), checks.array("phi", phi), _limits_named(force_limit, angle_limit))


def _position(tau, phi, limits: Limits):
    """The unvalidated kernel of :func:`allocate`, for loops."""
    tx, ty = tau[..., 0], tau[..., 1]
    F = np.hypot(tx, ty)
    beta = np.where(F > 0, wrap_angle(np.arctan2(ty, tx) - np.asarray(phi, dtype=float)), 0.0)
    F = np.broadcast_to(F, beta.shape).copy()
    return limits.apply(F, beta)


def _check_weights(weights) -> np.ndarray:
    w = np.array(checks.array("weights", weights, shape=(..., 3), nonnegative=True), dtype=float)
    if not np.all(np.any(w > 0, -1)):
        raise ValueError(f"weights (w_x, w_y, w_phi) must be non-negative and not all zero, got {weights!r}")
    return w


def _check_tau(tau, n=(3,)) -> np.ndarray:
    tau = checks.array("tau", tau)
    if tau.ndim == 0 or tau.shape[-1] not in n:
        names = "3 (tau_x, tau_y, tau_phi)" if n == (3,) else "2 or 3"
        raise ValueError(f"tau must have a last axis of length {names}, got shape {tau.shape}")
    return tau


def _checked_body(body) -> Body:
    return checks.instance("body", body, Body)


def least_squares_problem(tau, phi, body: Body, weights):
    """The weighted least-squares problem of :func:`allocate_least_squares`, validated;
    see ``_ls_kernel``.

    Parameters
    ----------
    tau : array_like
        Demanded generalized force [tau_x (N), tau_y (N), tau_phi (N m)], shape (..., 3).
    phi : array_like
        Heading (rad).
    body : Body
        The body.
    weights : array_like
        (w_x, w_y, w_phi) >= 0, not all zero, (3,) or (..., 3).

    Returns
    -------
    u_star : numpy.ndarray
        The unconstrained optimum (u1, u2) (N), shape (..., 2).
    G : numpy.ndarray
        A^T A, shape (..., 2, 2).
    r : numpy.ndarray
        A^T b (N), shape (..., 2).
    bb : numpy.ndarray
        |b|^2 (N^2), shape (...).
    """
    tau = _check_tau(tau)
    w = _check_weights(weights)
    return _ls_kernel(tau, checks.array("phi", phi), _checked_body(body), np.sqrt(w))


def _ls_kernel(tau, phi, body: Body, sw):
    """The unvalidated kernel of the weighted least-squares allocation, for loops:
    returns its unconstrained solution u* (..., 2), and G = A^T A (..., 2, 2),
    r = A^T b (..., 2) and |b|^2 (...), so that the residual is
    J(u) = u^T G u - 2 r^T u + |b|^2, with A = W^(1/2) B(phi) and b = W^(1/2) tau
    (``sw`` = W^(1/2), the square roots of the weights)."""
    A = sw[..., :, None] * input_matrix(phi, body)             # (..., 3, 2)
    A = np.broadcast_to(A, np.broadcast_shapes(A.shape, tau.shape[:-1] + (3, 2)))
    b = sw * tau                                               # (..., 3)
    # normal equations G u = r with G = A^T A (2 x 2), solved in closed form where G is well
    # conditioned; the closed form's relative error grows as eps cond(G) (measured 1e-8 at
    # cond(G) = 1e8, 7e-5 at 1e12), so beyond cond(G) ~ 1e8 (det G < 1e-8 trace(G)^2) the
    # pseudo-inverse of A (error eps cond(A), cond(A) = cond(G)^(1/2)) gives u, the minimum-norm
    # one where G is singular (tests/test_core_mutants.py, the error across conditions and scales)
    G = np.einsum("...ki,...kj->...ij", A, A)
    r = np.einsum("...ki,...k->...i", A, b)
    det = G[..., 0, 0] * G[..., 1, 1] - G[..., 0, 1] * G[..., 1, 0]
    regular = det > 1e-8 * np.maximum(G[..., 0, 0] + G[..., 1, 1], 1e-300) ** 2
    safe = np.where(regular, det, 1.0)
    u = np.stack([(G[..., 1, 1] * r[..., 0] - G[..., 0, 1] * r[..., 1]) / safe,
                  (G[..., 0, 0] * r[..., 1] - G[..., 1, 0] * r[..., 0]) / safe], axis=-1)
    if not np.all(regular):
        u = _pinv_rows(u, regular, A, b)
    return u, G, r, np.einsum("...k,...k->...", b, b)


def _pinv_rows(u, regular, A, b):
    """u with its singular rows (``regular`` False) replaced by the minimum-norm solution
    A^+ b, computed on those rows only; a row with a non-finite A or b (a state that has
    blown up) gets NaN there instead of failing the whole batch's SVD."""
    shape = np.broadcast_shapes(u.shape[:-1], regular.shape, A.shape[:-2], b.shape[:-1])
    u = np.array(np.broadcast_to(u, shape + (2,)))
    bad = ~np.broadcast_to(regular, shape)
    Ab, bb = np.broadcast_to(A, shape + (3, 2))[bad], np.broadcast_to(b, shape + (3,))[bad]
    ok = np.all(np.isfinite(Ab), axis=(-2, -1)) & np.all(np.isfinite(bb), axis=-1)
    sol = np.full(bb.shape[:-1] + (2,), np.nan)
    sol[ok] = (np.linalg.pinv(Ab[ok]) @ bb[ok][..., None])[..., 0]
    u[bad] = sol
    return u


def residual(u, G, r, bb) -> np.ndarray:
    """J(u) = u^T G u - 2 r^T u + |b|^2 of :func:`least_squares_problem`, for u of shape (..., 2).

    Parameters
    ----------
    u : array_like
        Inputs (u1, u2) = (F cos beta, F sin beta) (N), shape (..., 2).
    G, r, bb : array_like
        The problem's A^T A (..., 2, 2), A^T b (..., 2) and |b|^2 (...), as
        :func:`least_squares_problem` returns them.

    Returns
    -------
    numpy.ndarray
        J(u), the weighted squared residual (N^2), shape (...).
    """
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
    minimised by sampling it at 129 angles and refining each of the two best sampled
    local minima by safeguarded Newton steps on its derivative to machine precision). The candidate with the least J
    is returned; this holds for the non-convex sector too, since it only uses that
    an interior minimum of a convex function is unconstrained.

    With no limit it is :func:`allocate_least_squares`; with w_phi = 0 and no limit,
    exactly (25)-(26).

    Parameters
    ----------
    tau : array_like
        Demanded generalized force [tau_x (N), tau_y (N), tau_phi (N m)], shape (..., 3).
    phi : array_like
        Heading (rad), broadcast against ``tau[..., 0]``.
    body : Body
        The body (its lever arm a (m) enters B(phi)).
    weights : array_like
        (w_x, w_y, w_phi) >= 0, not all zero, shape (3,) or (..., 3).
    force_limit : float, optional
        F_max (N), > 0: F is capped at it; None for no cap.
    angle_limit : float, optional
        beta_max (rad), in (0, pi]: beta is clipped to [-beta_max, beta_max];
        None for no limit.

    Returns
    -------
    F : numpy.ndarray
        Force magnitude (N), >= 0, of the broadcast shape of ``tau[..., 0]`` and ``phi``.
    beta : numpy.ndarray
        Force angle to the body axis (rad), in (-pi, pi]; 0 where F = 0.

    Raises
    ------
    TypeError
        If an argument is of the wrong type (a str, a bool), naming it.
    ValueError
        If an argument is out of range or not finite (an array's first bad index named).
    """
    limits = _limits_named(force_limit, angle_limit)
    return _limited(_check_tau(tau), checks.array("phi", phi), _checked_body(body), np.sqrt(_check_weights(weights)), limits)


def _limited(tau, phi, body: Body, sw, limits: Limits):
    """The unvalidated kernel of :func:`allocate_limited`, for loops (``sw`` the square roots of
    the weights): the problem by ``_ls_kernel``, its candidates by the compiled ``_limited_rows``."""
    u_star, G, r, bb = _ls_kernel(tau, phi, body, sw)
    fmax, bmax = (d if x is None else float(x) for x, d in ((limits.force, np.inf), (limits.angle, np.pi)))
    shape = np.broadcast_shapes(u_star.shape[:-1], G.shape[:-2], r.shape[:-1], bb.shape)
    rows = [np.require(np.broadcast_to(x, shape + x.shape[x.ndim - k:]).reshape(-1, *x.shape[x.ndim - k:]), float, "CW")
            for x, k in ((u_star, 1), (G, 2), (r, 1), (bb, 0))]  # writable: a read-only array is another numba type
    F, beta = _limited_rows(*rows, fmax, bmax, 129, 5)
    return F.reshape(shape), beta.reshape(shape)


@numba.njit(cache=True)
def _limited_rows(u_star, G, r, bb, fmax, bmax, n_samples, n_newton):  # pragma: no cover (compiled)
    """(F, beta) row by row, as :func:`allocate_limited` states: the candidate of least J (a NaN
    J, a state that has blown up, never wins; ties to the earlier) among the admissible
    unconstrained optimum, the origin, the two rays and the arc's two points of ``_arc_pair``."""
    n = u_star.shape[0]
    F, beta, cands = np.empty(n), np.empty(n), np.empty((6, 2))
    for q in range(n):
        g, r1, r2 = G[q], r[q, 0], r[q, 1]
        us1, us2 = u_star[q, 0], u_star[q, 1]
        fs = np.hypot(us1, us2)
        ok = fs <= fmax and (fs == 0 or abs(np.arctan2(us2, us1)) <= bmax)
        cands[0], cands[1], m = (us1, us2) if ok else (np.nan, np.nan), (0.0, 0.0), 2
        if bmax < np.pi:
            for d1, d2 in ((np.cos(bmax), np.sin(bmax)), (np.cos(bmax), -np.sin(bmax))):
                dGd = _quad(g, d1, d2)
                t = min(max((r1 * d1 + r2 * d2) / dGd if dGd > 0 else 0.0, 0.0), fmax)
                cands[m], m = (t * d1, t * d2), m + 1
        if np.isfinite(fmax):
            for b in _arc_pair(g, r[q], fmax, bmax, n_samples, n_newton):
                cands[m], m = (fmax * np.cos(b), fmax * np.sin(b)), m + 1
        win, least = 0, np.inf
        for i in range(m):
            v = _quad(g, cands[i, 0], cands[i, 1]) - 2 * (r1 * cands[i, 0] + r2 * cands[i, 1]) + bb[q]
            if v < least:                              # False for NaN
                win, least = i, v
        F[q] = np.hypot(cands[win, 0], cands[win, 1])
        beta[q] = np.arctan2(cands[win, 1], cands[win, 0]) if F[q] > 0 else 0.0
    return F, beta


@numba.njit(cache=True)
def _quad(G, u1, u2):  # pragma: no cover (compiled)
    """u' G u, u = (u1, u2), G (2, 2)."""
    return u1 * (G[0, 0] * u1 + G[0, 1] * u2) + u2 * (G[1, 0] * u1 + G[1, 1] * u2)


@numba.njit(cache=True)
def _arc_pair(G, r, fmax, bmax, n_samples, n_newton):  # pragma: no cover (compiled)
    """The angles (2,) of the two best sampled local minima of J on the arc u = fmax (cos beta,
    sin beta), |beta| <= bmax (the least J first, ties to the lower angle; G (2, 2), r (2,)),
    each refined by safeguarded Newton on dJ/dbeta = 0 inside the bracket of its two
    neighbouring samples (bisection where Newton would leave it or J'' <= 0). Along the arc
    J - |b|^2 = fmax^2 (A0 + A1 cos 2beta + A2 sin 2beta) - 2 fmax (r1 cos beta + r2 sin beta),
    A1 = (G11 - G22) / 2, A2 = G12: at most two local minima. Newton from a sample within one
    spacing (about 0.05 rad for bmax = pi) squares its error at every step, so 5 steps reach
    rounding; the sampling separates minima about 0.14 rad apart or more (measured to 5e-9 rad,
    tests/test_core_mutants.py); two closer ones may be found as one."""
    betas = np.linspace(-bmax, bmax, n_samples)
    h, Js, best = betas[1] - betas[0], np.empty(n_samples), np.full(2, -1)
    for k in range(n_samples):
        e1, e2 = fmax * np.cos(betas[k]), fmax * np.sin(betas[k])
        Js[k] = _quad(G, e1, e2) - 2 * (r[0] * e1 + r[1] * e2)
    for pick in range(2):                              # the least local minimum, then the next
        val = np.inf
        for k in range(n_samples):
            local = (k == 0 or Js[k] <= Js[k - 1]) and (k == n_samples - 1 or Js[k] <= Js[k + 1])
            v = Js[k] if local else np.inf
            if k != best[0] and (v < val or best[pick] < 0):
                best[pick], val = k, v
    A1, A2, out = 0.5 * (G[0, 0] - G[1, 1]), G[0, 1], betas[best]
    for j in range(2):
        b = out[j]
        lo, hi = max(b - h, -bmax), min(b + h, bmax)
        for _ in range(n_newton):
            c, s = np.cos(b), np.sin(b)
            c2, s2 = c * c - s * s, 2 * s * c
            j1 = 2 * fmax ** 2 * (A2 * c2 - A1 * s2) - 2 * fmax * (r[1] * c - r[0] * s)
            j2 = -4 * fmax ** 2 * (A1 * c2 + A2 * s2) + 2 * fmax * (r[0] * c + r[1] * s)
            lo, hi = b if j1 < 0 else lo, b if j1 > 0 else hi
            step = b - j1 / j2 if j2 > 0 else np.nan
            b = step if lo <= step <= hi else 0.5 * (lo + hi)
        out[j] = b
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

    Parameters
    ----------
    tau : array_like
        Demanded generalized force [tau_x (N), tau_y (N), tau_phi (N m)], shape (..., 3).
    phi : array_like
        Heading (rad), broadcast against ``tau[..., 0]``.
    body : Body
        The body (its lever arm a (m) enters B(phi)).
    weights : array_like
        (w_x, w_y, w_phi) >= 0, not all zero, shape (3,) or (..., 3).
    force_limit : float, optional
        F_max (N), > 0: F is capped at it; None for no cap.
    angle_limit : float, optional
        beta_max (rad), in (0, pi]: beta is clipped to [-beta_max, beta_max];
        None for no limit.

    Returns
    -------
    F : numpy.ndarray
        Force magnitude (N), >= 0, of the broadcast shape of ``tau[..., 0]`` and ``phi``.
    beta : numpy.ndarray
        Force angle to the body axis (rad), in (-pi, pi]; 0 where F = 0.

    Raises
    ------
    TypeError
        If an argument is of the wrong type (a str, a bool), naming it.
    ValueError
        If an argument is out of range or not finite (an array's first bad index named).
    """
    limits = _limits_named(force_limit, angle_limit)
    return _weighted(_check_tau(tau), checks.array("phi", phi), _checked_body(body), np.sqrt(_check_weights(weights)), limits)


def _weighted(tau, phi, body: Body, sw, limits: Limits):
    """The unvalidated kernel of :func:`allocate_least_squares`, for loops."""
    u, _, _, _ = _ls_kernel(tau, phi, body, sw)
    F = np.hypot(u[..., 0], u[..., 1])
    beta = np.where(F > 0, np.arctan2(u[..., 1], u[..., 0]), 0.0)
    return limits.apply(F, beta)


Allocator = Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]

#: the allocation laws :class:`Allocation` knows
LAWS = ("position", "least_squares", "limited")


@dataclass(frozen=True)
class Allocation:
    """Which allocation law the closed loop uses, validated on construction.

    ``law``: ``"position"`` (the paper's (25)-(26), :func:`allocate`, the default),
    ``"least_squares"`` (:func:`allocate_least_squares` with ``weights`` =
    (w_x, w_y, w_phi), limits by projection) or ``"limited"``
    (:func:`allocate_limited`, the same law solved exactly under the limits).
    ``weights`` may be (3,) or, for a batch of points, (N, 3).
    """

    law: str = "position"
    weights: tuple | np.ndarray = (1.0, 1.0, 0.0)

    def __post_init__(self) -> None:
        if self.law not in LAWS:
            raise ValueError(f"unknown allocation {self.law!r}; known: {LAWS}")
        w = _check_weights(self.weights)
        w.setflags(write=False)
        object.__setattr__(self, "weights", w)

    def bind(self, body: Body, limits: Limits | None = None) -> Allocator:
        """The allocation step (tau, phi) -> (F (N), beta (rad)) for ``body`` under
        ``limits``, validated here once; the returned function checks nothing."""
        _checked_body(body)
        limits = Limits() if limits is None else limits
        if not isinstance(limits, Limits):
            raise TypeError(f"limits must be a lib.allocation.Limits, got {type(limits).__name__}")
        if self.law == "position":
            return lambda tau, phi: _position(tau, phi, limits)
        sw = np.sqrt(self.weights)
        kernel = _weighted if self.law == "least_squares" else _limited
        return lambda tau, phi: kernel(tau, phi, body, sw, limits)
