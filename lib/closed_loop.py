"""The closed loop: the body (2)-(4) driven by the computed-torque law (23) through an
allocation (:mod:`lib.allocation`), as one vector field vectorised over points.

This is the single closed-loop right-hand side behind the smooth integrator
(:func:`lib.simulate.simulate`) and the batch integrator
(:func:`lib.weighting.batch.closed_loop_batch`); the switched integrator
(:mod:`lib.integrators.switched`) uses a scalar fast path of the same equations,
tested against this one at random states.

Below it, the same loop compiled for the loops that integrate a few states at a time, each
tested against this one: :func:`paper_rates` (the paper's law, for the smooth integrator),
``_paper_rows_tabled`` (with a model and a reference per row, for the wrong-model loop of
:mod:`lib.tracking.mismatch`), ``_lean_rows`` (the weighted law without limits, for
:mod:`lib.weighting.verdicts`) and :func:`limited_weighted_field` (the weighted law under limits,
for Chapter 8). They share one compiled statement of each equation: the path (27)-(28), the
demand (23), the allocation (25)-(26) and the body (2)-(4).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numba
import numpy as np

from .machinery import checks
from .allocation import Allocation, Allocator, Limits, _limited_rows
from .control import computed_torque_from
from .model import config_accel
from .params import Body, Gains

__all__ = ["ClosedLoop", "reference_of", "paper_rates", "limited_weighted_field"]

#: t -> (z_d, dz_d, ddz_d), each of shape (..., 3)
Kinematics = Callable[[object], tuple]


def reference_of(ref) -> Kinematics:
    """The kinematics t -> (z_d, dz_d, ddz_d) of a reference object (:mod:`lib.trajectories`).

    Parameters
    ----------
    ref : Reference
        An object with ``z``, ``dz``, ``ddz`` of t (s); its ``kinematics`` of t, where it has
        one, gives the three at once (the paths of :mod:`lib.trajectories` compute them in one
        evaluation, three times fewer than asking for each).

    Returns
    -------
    callable
        t (s) -> (z_d (m, m, rad), dz_d, ddz_d), each (..., 3).
    """
    kin = getattr(ref, "kinematics", None)
    if callable(kin):
        return kin
    return lambda t: (ref.z(t), ref.dz(t), ref.ddz(t))


@dataclass(frozen=True)
class ClosedLoop:
    """s' = (dz, ddz) with ddz from (2)-(4) under the inputs (F, beta) that ``allocate``
    assigns to the demand (23) tracking ``kinematics``. Build it with :meth:`of`,
    which validates the parts once; :meth:`rates` checks nothing, for loops.

    ``body`` is the plant, integrated by (2)-(4); ``model`` the controller's own model
    (the m, I_C, c, c_phi, a used by (23) and by the allocation), None for the plant's."""

    body: Body
    gains: Gains
    kinematics: Kinematics
    allocate: Allocator
    model: Body | None = None

    @classmethod
    def of(cls, body: Body, gains: Gains, kinematics: Kinematics, allocation: Allocation | None = None,
           limits: Limits | None = None, model: Body | None = None) -> "ClosedLoop":
        """The closed loop of a plant, its gains and a reference, validated once.

        Parameters
        ----------
        body : Body
            The plant, integrated by (2)-(4).
        gains : Gains
            The gains Kp, Kv of (23).
        kinematics : callable
            t (s) -> (z_d, dz_d, ddz_d), each (..., 3) in m, m/s, m/s^2 (and rad for the
            heading): :func:`reference_of` a reference of :mod:`lib.trajectories`.
        allocation : Allocation, optional
            The allocation law (default the paper's (25)-(26)).
        limits : Limits, optional
            Force and angle limits (default none).
        model : Body, optional
            The controller's model of the body, used by (23) and the allocation
            (default None: the plant's own).

        Returns
        -------
        ClosedLoop
            The loop, whose :meth:`rates` checks nothing.

        Raises
        ------
        TypeError
            If a part is of the wrong type, naming it.
        """
        checks.instance("gains", gains, Gains)
        allocation = checks.instance("allocation", Allocation() if allocation is None else allocation, Allocation)
        if model is not None:
            checks.instance("model", model, Body, "lib.params.Body or None")
        return cls(body, gains, kinematics, allocation.bind(body if model is None else model, limits), model)

    def inputs(self, t, z, dz):
        """(tau, F, beta): the demand (23) and the allocated force (N) and angle (rad)."""
        z_d, dz_d, ddz_d = self.kinematics(t)
        model = self.body if self.model is None else self.model
        tau = computed_torque_from(model, self.gains, z_d, dz_d, ddz_d, z, dz)
        F, beta = self.allocate(tau, z[..., 2])
        return tau, F, beta

    def rates(self, t, s) -> tuple[np.ndarray, np.ndarray]:
        """(s', F) for states s = [x, y, phi, xdot, ydot, phidot] of shape (..., 6)."""
        z, dz = s[..., :3], s[..., 3:]
        _, F, beta = self.inputs(t, z, dz)
        return np.concatenate([dz, config_accel(self.body, z, dz, F, beta)], axis=-1), F


# ---------------------------------------------------------------- the same loop compiled
# For the loops that integrate a few states at a time, where numpy's call overhead is the cost.
# Each equation is written once below, in the order of the numpy definitions it twins (so the
# results agree to rounding, and mostly bit for bit), and every kernel of the loop calls them:
# kept in this one file, because numba keys a cached kernel on its own file only.


@numba.njit(cache=True)
def _path(t, R, Th, eight, heading):  # pragma: no cover (compiled)
    """(x, y, phi, x', y', phi', x'', y'', phi'') of the circle (27) or the eight (28) at t (s), as
    :func:`lib.trajectories.circle_kinematics` and :func:`lib.trajectories.eight_kinematics` write
    them; without ``heading`` the heading's three entries are 0 (not computed)."""
    s = Th * t
    if eight:
        c1, s1, c2, s2 = math.cos(s), math.sin(s), math.cos(2 * s), math.sin(2 * s)
        p = dp = ddp = 0.0
        if heading:
            p = math.pi + math.atan2(-c1, -c2) - (math.pi if Th < 0 else 0.0)
            num = 2 * c1 * s2 - c2 * s1
            den = c2**2 + c1**2
            dnum = 3 * c1 * c2
            dden = -2 * math.sin(4 * s) - s2
            dp, ddp = Th * num / den, Th**2 * (dnum * den - num * dden) / den**2
        return (0.5 * R * s2, R * s1, p, R * Th * c2, R * Th * c1, dp, -2 * R * Th**2 * s2, -R * Th**2 * s1, ddp)
    c, sn = math.cos(s), math.sin(s)
    return (R * c, R * sn, s + math.pi / 2, -R * Th * sn, R * Th * c, Th, -R * Th**2 * c, -R * Th**2 * sn, 0.0)


@numba.njit(cache=True)
def _demand(mass, drag, kp, kv, e, vd, ad, v):  # pragma: no cover (compiled)
    """(23) on one coordinate: M ddz_d + N dz + Kv (dz_d - dz) + Kp e, e = z_d - z its error."""
    return mass * ad + drag * v + kv * (vd - v) + kp * e


@numba.njit(cache=True)
def _wrap(angle):  # pragma: no cover (compiled)
    """:func:`lib.angles.wrap_angle`'s formula on one angle (rad): into (-pi, pi]."""
    w = math.pi - (math.pi - angle) % (2 * math.pi)
    return math.pi if w == -math.pi else w


@numba.njit(cache=True)
def _position(tx, ty, phi):  # pragma: no cover (compiled)
    """(25)-(26) on one demand: F = |(tau_x, tau_y)| (N) and beta (rad) wrapped to (-pi, pi], 0
    where F = 0 (``lib.allocation.allocate``, with :func:`_wrap`)."""
    F = math.hypot(tx, ty)
    beta = 0.0
    if F > 0:
        beta = _wrap(math.atan2(ty, tx) - phi)
    return F, beta


@numba.njit(cache=True)
def _accel(F, beta, phi, vx, vy, vp, m, I, c, c_phi, a):  # pragma: no cover (compiled)
    """(2)-(4): the accelerations (x'', y'', phi'') under (F, beta), as :func:`lib.model.config_accel`."""
    psi = phi + beta
    return (F * math.cos(psi) - c * vx) / m, (F * math.sin(psi) - c * vy) / m, (F * math.sin(beta) * a - c_phi * vp) / I


@numba.njit(cache=True)
def _paper_rows_tabled(ref, Y, T, model, k, plant, out):  # pragma: no cover (compiled)
    """dy/dtau of the rows of Y (M, 6) in the normalised time tau = t / T (T (M,) the rows'
    periods) under the paper's law without limits, each row with its own reference and model:
    ``ref`` (9, M) the path's (z_d, dz_d, ddz_d) at the time, ``model`` (2, M) the model's m and
    c in (23), k = (kp_x, kp_y, kv_x, kv_y), (2)-(4) of the plant (m, I, c, c_phi, a) (tau_phi is
    not formed: (25)-(26) do not read it). The wrong-model loop's field (:mod:`lib.tracking.mismatch`)."""
    m, I, c, c_phi, a = plant[0], plant[1], plant[2], plant[3], plant[4]
    for q in range(Y.shape[0]):
        x, yy, phi, vx, vy, vp = Y[q, 0], Y[q, 1], Y[q, 2], Y[q, 3], Y[q, 4], Y[q, 5]
        mx, cx = model[0, q], model[1, q]
        tx = _demand(mx, cx, k[0], k[2], ref[0, q] - x, ref[3, q], ref[6, q], vx)
        ty = _demand(mx, cx, k[1], k[3], ref[1, q] - yy, ref[4, q], ref[7, q], vy)
        F, beta = _position(tx, ty, phi)
        ax, ay, aw = _accel(F, beta, phi, vx, vy, vp, m, I, c, c_phi, a)
        Tq = T[q]
        out[q, 0], out[q, 1], out[q, 2], out[q, 3], out[q, 4], out[q, 5] = Tq * vx, Tq * vy, Tq * vp, \
            Tq * ax, Tq * ay, Tq * aw


@numba.njit(cache=True)
def _paper_rows(t, Y, eight, R, Th, model, k, plant, fmax, bmax, out):  # pragma: no cover (compiled)
    """s' of the rows of Y (M, 6) under the paper's law: the path at t, (23) with the model's m and
    c (``model``) and k = (kp_x, kp_y, kv_x, kv_y), (25)-(26) under the cap ``fmax`` and the angle
    limit ``bmax`` (``Limits.apply``), (2)-(4) of the plant (m, I, c, c_phi, a)."""
    xd, yd, _, vxd, vyd, _, axd, ayd, _ = _path(t, R, Th, eight, np.bool_(False))  # typed, not a literal
    mm, cm = model[0], model[1]
    m, I, c_lin, c_phi, a = plant[0], plant[1], plant[2], plant[3], plant[4]
    for q in range(Y.shape[0]):
        x, y, phi, vx, vy, vp = Y[q, 0], Y[q, 1], Y[q, 2], Y[q, 3], Y[q, 4], Y[q, 5]
        tx = _demand(mm, cm, k[0], k[2], xd - x, vxd, axd, vx)
        ty = _demand(mm, cm, k[1], k[3], yd - y, vyd, ayd, vy)
        F, beta = _position(tx, ty, phi)
        F, beta = min(F, fmax), min(max(beta, -bmax), bmax)
        ax, ay, aw = _accel(F, beta, phi, vx, vy, vp, m, I, c_lin, c_phi, a)
        out[q, 0], out[q, 1], out[q, 2], out[q, 3], out[q, 4], out[q, 5] = vx, vy, vp, ax, ay, aw


@numba.njit(cache=True)
def _lean_rows(ref, turns, wind, Y, T, Tm, TI, w, k, b, out):  # pragma: no cover (compiled)
    """The lean field of ``lib.weighting.verdicts._PeriodFlow`` (the weighted law without limits,
    its formulas in their order) on every row of Y (M, 6): ref (9, M) the path's (z_d, dz_d,
    ddz_d) at the stage's phase, the heading advanced by ``turns`` whole periods of ``wind`` (M,)
    rad; T, Tm = T / m, TI = T / I (M,); w (4, M) the weights w_x, w_y, w_phi a and w_phi a^2;
    k = (kp, kv) (6,); b = (m, I, c, c_phi, a). The normal equations solved in closed form and
    Q = B(phi) u, without passing through (F, beta)."""
    m, I, c_lin, c_phi, a = b[0], b[1], b[2], b[3], b[4]
    for q in range(Y.shape[0]):
        x, yy, phi, vx, vy, vp = Y[q, 0], Y[q, 1], Y[q, 2], Y[q, 3], Y[q, 4], Y[q, 5]
        wx, wy, wpa, wpa2 = w[0, q], w[1, q], w[2, q], w[3, q]
        ep = ref[2, q] - phi
        if turns:
            ep = ep + turns * wind[q]
        tx = _demand(m, c_lin, k[0], k[3], ref[0, q] - x, ref[3, q], ref[6, q], vx)
        ty = _demand(m, c_lin, k[1], k[4], ref[1, q] - yy, ref[4, q], ref[7, q], vy)
        tp = _demand(I, c_phi, k[2], k[5], ep, ref[5, q], ref[8, q], vp)
        c, s = math.cos(phi), math.sin(phi)
        cc, ss, cs = c * c, s * s, c * s
        G11, G12, G22 = wx * cc + wy * ss, (wy - wx) * cs, wx * ss + wy * cc + wpa2
        r1, r2 = wx * c * tx + wy * s * ty, wy * c * ty - wx * s * tx + wpa * tp
        det = G11 * G22 - G12 * G12
        u1, u2 = (G22 * r1 - G12 * r2) / det, (G11 * r2 - G12 * r1) / det
        out[q, 0], out[q, 1], out[q, 2] = T[q] * vx, T[q] * vy, T[q] * vp
        out[q, 3] = Tm[q] * (c * u1 - s * u2 - c_lin * vx)
        out[q, 4] = Tm[q] * (s * u1 + c * u2 - c_lin * vy)
        out[q, 5] = TI[q] * (a * u2 - c_phi * vp)


@numba.njit(cache=True)
def _problem_rows(t, Y, p, sw, R, Th, eight, u, G, r, bb, regular, A, b):  # pragma: no cover (compiled)
    """(23) at every row of Y (M, 6) and its weighted least-squares problem: u* (M, 2), G (M, 2, 2),
    r (M, 2), |b|^2 (M,), whether G is regular (M,), A (M, 3, 2) and b (M, 3), as
    ``lib.allocation._ls_kernel`` states them. p = (m, I, a, c, c_phi, kp (3), kv (3)); sw the
    square roots of the weights."""
    m, I, a, c, cphi = p[0], p[1], p[2], p[3], p[4]
    zd0, zd1, zd2, vd0, vd1, vd2, ad0, ad1, ad2 = _path(t, R, Th, eight, np.bool_(True))
    for q in range(Y.shape[0]):
        y = Y[q]
        b0 = sw[0] * _demand(m, c, p[5], p[8], zd0 - y[0], vd0, ad0, y[3])
        b1 = sw[1] * _demand(m, c, p[6], p[9], zd1 - y[1], vd1, ad1, y[4])
        b2 = sw[2] * _demand(I, cphi, p[7], p[10], zd2 - y[2], vd2, ad2, y[5])
        co, si = math.cos(y[2]), math.sin(y[2])
        # A = W^(1/2) B(phi), B = [[cos, -sin], [sin, cos], [0, a]]
        a00, a01, a10, a11, a20, a21 = sw[0] * co, sw[0] * -si, sw[1] * si, sw[1] * co, sw[2] * 0.0, sw[2] * a
        A[q, 0, 0], A[q, 0, 1], A[q, 1, 0], A[q, 1, 1], A[q, 2, 0], A[q, 2, 1] = a00, a01, a10, a11, a20, a21
        b[q, 0], b[q, 1], b[q, 2] = b0, b1, b2
        g = G[q]
        g[0, 0] = a00 * a00 + a10 * a10 + a20 * a20
        g[0, 1] = a00 * a01 + a10 * a11 + a20 * a21
        g[1, 0] = a01 * a00 + a11 * a10 + a21 * a20
        g[1, 1] = a01 * a01 + a11 * a11 + a21 * a21
        r1, r2 = a00 * b0 + a10 * b1 + a20 * b2, a01 * b0 + a11 * b1 + a21 * b2
        r[q, 0], r[q, 1] = r1, r2
        bb[q] = b0 * b0 + b1 * b1 + b2 * b2
        det = g[0, 0] * g[1, 1] - g[0, 1] * g[1, 0]
        regular[q] = det > 1e-8 * max(g[0, 0] + g[1, 1], 1e-300) ** 2
        safe = det if regular[q] else 1.0
        u[q, 0] = (g[1, 1] * r1 - g[0, 1] * r2) / safe
        u[q, 1] = (g[0, 0] * r2 - g[1, 0] * r1) / safe


@numba.njit(cache=True)
def _plant_rows(Y, F, beta, p, out):  # pragma: no cover (compiled)
    """(2)-(4): the rates (M, 6) of the states Y under (F, beta); p = (m, I, a, c, c_phi, ...)."""
    for q in range(Y.shape[0]):
        y = Y[q]
        ax, ay, aw = _accel(F[q], beta[q], y[2], y[3], y[4], y[5], p[0], p[1], p[3], p[4], p[2])
        out[q, 0], out[q, 1], out[q, 2], out[q, 3], out[q, 4], out[q, 5] = y[3], y[4], y[5], ax, ay, aw


def paper_rates(body: Body, gains: Gains, ref, allocation: Allocation | None = None, limits: Limits | None = None,
                model: Body | None = None):
    """The rates of :meth:`ClosedLoop.rates` compiled, where the loop is the paper's law
    ((25)-(26), ``Allocation()``, under any ``limits``, with any ``model``) on the circle or the
    eight of :mod:`lib.trajectories`: the same formulas, to rounding (``tests/test_simulate.py``);
    None for another law or path.

    Parameters
    ----------
    body, gains : Body, Gains
        The plant and the gains of (23).
    ref : Reference
        The path.
    allocation : Allocation, optional
        The allocation law (default the paper's).
    limits : Limits, optional
        Force and angle limits (default none).
    model : Body, optional
        The controller's model (default the plant).

    Returns
    -------
    callable or None
        ``rates(t, s)``: t (s) a float, s (..., 6) the states; s', of s's shape.
    """
    checks.instance("body", body, Body)
    checks.instance("gains", gains, Gains)
    allocation = checks.instance("allocation", Allocation() if allocation is None else allocation, Allocation)
    limits = checks.instance("limits", Limits() if limits is None else limits, Limits)
    kind = getattr(ref, "_kind", None)
    if allocation.law != "position" or kind not in ("eight", "circle"):
        return None
    md = body if model is None else checks.instance("model", model, Body, "lib.params.Body or None")
    args = (kind == "eight", float(ref.R), float(ref.theta), np.array([md.m, md.c]),
            np.array([gains.kp[0], gains.kp[1], gains.kv[0], gains.kv[1]], dtype=float),
            np.array([body.m, body.I, body.c, body.c_phi, body.a]),
            math.inf if limits.force is None else float(limits.force),
            math.inf if limits.angle is None else float(limits.angle))

    def rates(t, s):
        s = np.ascontiguousarray(s, dtype=float)
        out = np.empty_like(s)
        _paper_rows(float(t), s.reshape(-1, 6), *args, out.reshape(-1, 6))
        return out
    return rates


def limited_weighted_field(body: Body, gains: Gains, ref, limits: Limits | None = None, weights=(1.0, 1.0, 1.0)):
    """The rates of :meth:`ClosedLoop.rates` compiled, where the loop is the weighted law under
    limits (``Allocation("limited", weights)``, the body both plant and model) on the circle or the
    eight: the path with its heading, (23), the weighted least-squares problem of
    :func:`lib.allocation.least_squares_problem` (its closed form; a row whose normal equations are
    singular is solved by the pseudo-inverse), the allocation under the limits by the
    compiled ``lib.allocation._limited_rows``, and (2)-(4), all in one compiled kernel: to rounding
    (``tests/test_weighting_field.py``), for Chapter 8's fixed-step loops on a few rows.

    Parameters
    ----------
    body, gains : Body, Gains
        The body (plant and model) and the gains of (23).
    ref : Reference
        The eight or the circle (:func:`lib.trajectories.make`).
    limits : Limits, optional
        The force and angle limits (None: none).
    weights : array_like
        (w_x, w_y, w_phi) >= 0, not all zero, (3,).

    Returns
    -------
    callable
        ``rates(t, Y)``: t (s) a float, Y (..., 6) the states; the rates, of Y's shape.
    """
    args = _weighted_args(body, gains, ref, limits, weights)

    def rates(t, Y):
        Y = np.ascontiguousarray(Y, dtype=float)
        rows = Y.reshape(-1, 6)
        out = np.empty_like(rows)
        _weighted_rows(float(t), rows, out, *args)
        return out.reshape(Y.shape)
    return rates


def _weighted_args(body, gains, ref, limits, weights) -> tuple:  # _weighted_rows' (p, sw, R, Th, eight, fmax, bmax)
    checks.instance("body", body, Body)
    checks.instance("gains", gains, Gains)
    kind = checks.one_of("ref (its path's kind)", getattr(ref, "_kind", None), ("eight", "circle"))
    limits = checks.instance("limits", Limits() if limits is None else limits, Limits)
    w = checks.array("weights", weights, shape=(3,), nonnegative=True)
    if not np.any(w > 0):
        raise ValueError(f"weights (w_x, w_y, w_phi) must not all be zero, got {weights!r}")
    fmax, bmax = (d if v is None else float(v) for v, d in ((limits.force, math.inf), (limits.angle, math.pi)))
    p = np.r_[body.m, body.I, body.a, body.c, body.c_phi, gains.kp, gains.kv].astype(float)
    return p, np.sqrt(w), float(ref.R), float(ref.theta), kind == "eight", fmax, bmax


@numba.njit(cache=True)
def _weighted_rows(t, Y, out, p, sw, R, Th, eight, fmax, bmax):  # pragma: no cover (compiled)
    """The weighted law under limits at every row of Y (M, 6), its rates into out (M, 6): (23) and
    its weighted least-squares problem (:func:`_problem_rows`), the minimum-norm solution A^+ b on
    a singular row (NaN where A or b is not finite, as ``lib.allocation._pinv_rows``), the
    allocation under the limits (``lib.allocation._limited_rows``) and (2)-(4)."""
    n = Y.shape[0]
    u, G, r, bb = np.empty((n, 2)), np.empty((n, 2, 2)), np.empty((n, 2)), np.empty(n)
    regular, A, b = np.empty(n, np.bool_), np.empty((n, 3, 2)), np.empty((n, 3))
    _problem_rows(t, Y, p, sw, R, Th, eight, u, G, r, bb, regular, A, b)
    for q in range(n):
        if not regular[q]:
            if np.all(np.isfinite(A[q])) and np.all(np.isfinite(b[q])):
                u[q] = np.linalg.pinv(A[q]) @ b[q]
            else:
                u[q] = np.nan
    F, beta = _limited_rows(u, G, r, bb, fmax, bmax, 129, 5)
    _plant_rows(Y, F, beta, p, out)
