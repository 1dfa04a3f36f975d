"""The weighted law's fields compiled, for fixed-step loops on a few rows at a time: under limits
(Chapter 8's rows of the weighted law, :func:`lib.optimal.compare.law_loop`), and the lean field
without limits of Chapter 6's verdicts (``lib.weighting.verdicts._PeriodFlow``, ``_lean_rows``).

The rates of :class:`lib.closed_loop.ClosedLoop` with ``Allocation("limited", weights)``, the
body both plant and model: the path's kinematics with its heading (the circle (27), the eight
(28), as :func:`lib.trajectories.circle_kinematics` and :func:`lib.trajectories.eight_kinematics`
write them), the demand (23), the weighted least-squares problem of
:func:`lib.allocation.least_squares_problem` (its closed form; a row whose normal equations are
singular is solved by the pseudo-inverse, in numpy), the allocation under the limits by the
compiled ``lib.allocation._limited_rows``, and (2)-(4). The same formulas, in their order,
compiled: equal to rounding (``tests/test_weighting_field.py``), about seven times faster a call
on a few rows than the numpy loop, whose cost is its calls' overhead.

Units: SI (m, rad, s, N).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from ..allocation import Limits, _limited_rows, _pinv_rows
from ..machinery import checks
from ..params import Body, Gains

__all__ = ["limited_weighted_field"]


@numba.njit(cache=True)
def _lean_rows(ref, turns, wind, Y, T, Tm, TI, w, k, b, out):  # pragma: no cover (compiled)
    """The lean field of ``_PeriodFlow`` (its formulas, in their order) on every row of Y (M, 6):
    ref (9, M) the path's (z_d, dz_d, ddz_d) at the stage's phase, the heading advanced by
    ``turns`` whole periods of ``wind`` (M,) rad; T, Tm = T / m, TI = T / I (M,); w (4, M) the
    weights w_x, w_y, w_phi a and w_phi a^2; k = (kp, kv) (6,); b = (m, I, c, c_phi, a)."""
    m, I, c_lin, c_phi, a = b[0], b[1], b[2], b[3], b[4]
    for q in range(Y.shape[0]):
        x, yy, phi, vx, vy, vp = Y[q, 0], Y[q, 1], Y[q, 2], Y[q, 3], Y[q, 4], Y[q, 5]
        wx, wy, wpa, wpa2 = w[0, q], w[1, q], w[2, q], w[3, q]
        ep = ref[2, q] - phi
        if turns:
            ep = ep + turns * wind[q]
        tx = m * ref[6, q] + c_lin * vx + k[3] * (ref[3, q] - vx) + k[0] * (ref[0, q] - x)          # (23)
        ty = m * ref[7, q] + c_lin * vy + k[4] * (ref[4, q] - vy) + k[1] * (ref[1, q] - yy)
        tp = I * ref[8, q] + c_phi * vp + k[5] * (ref[5, q] - vp) + k[2] * ep
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
def _path(t, R, Th, eight):  # pragma: no cover (compiled)
    """(x, y, phi, x', y', phi', x'', y'', phi'') of the path at t (s): eight_kinematics's or
    circle_kinematics's formulas."""
    s = Th * t
    if eight:
        c1, s1, c2, s2 = math.cos(s), math.sin(s), math.cos(2 * s), math.sin(2 * s)
        heading = math.pi + math.atan2(-c1, -c2) - (math.pi if Th < 0 else 0.0)
        num = 2 * c1 * s2 - c2 * s1
        den = c2**2 + c1**2
        dnum = 3 * c1 * c2
        dden = -2 * math.sin(4 * s) - s2
        return (0.5 * R * s2, R * s1, heading, R * Th * c2, R * Th * c1, Th * num / den,
                -2 * R * Th**2 * s2, -R * Th**2 * s1, Th**2 * (dnum * den - num * dden) / den**2)
    c, sn = math.cos(s), math.sin(s)
    return (R * c, R * sn, s + math.pi / 2, -R * Th * sn, R * Th * c, Th, -R * Th**2 * c, -R * Th**2 * sn, 0.0)


@numba.njit(cache=True)
def _problem_rows(t, Y, p, sw, R, Th, eight, u, G, r, bb, regular, A, b):  # pragma: no cover (compiled)
    """(23) at every row of Y (M, 6) and its weighted least-squares problem: u* (M, 2), G (M, 2, 2),
    r (M, 2), |b|^2 (M,), whether G is regular (M,), A (M, 3, 2) and b (M, 3), as
    ``lib.allocation._ls_kernel`` states them. p = (m, I, a, c, c_phi, kp (3), kv (3)); sw the
    square roots of the weights."""
    m, I, a, c, cphi = p[0], p[1], p[2], p[3], p[4]
    zd0, zd1, zd2, vd0, vd1, vd2, ad0, ad1, ad2 = _path(t, R, Th, eight)
    for q in range(Y.shape[0]):
        y = Y[q]
        b0 = sw[0] * (m * ad0 + c * y[3] + p[8] * (vd0 - y[3]) + p[5] * (zd0 - y[0]))        # (23)
        b1 = sw[1] * (m * ad1 + c * y[4] + p[9] * (vd1 - y[4]) + p[6] * (zd1 - y[1]))
        b2 = sw[2] * (I * ad2 + cphi * y[5] + p[10] * (vd2 - y[5]) + p[7] * (zd2 - y[2]))
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
    """(2)-(4): the rates (M, 6) of the states Y under (F, beta), as ``lib.model.config_accel``."""
    m, I, a, c, cphi = p[0], p[1], p[2], p[3], p[4]
    for q in range(Y.shape[0]):
        y, f, b = Y[q], F[q], beta[q]
        psi = y[2] + b
        out[q, 0], out[q, 1], out[q, 2] = y[3], y[4], y[5]
        out[q, 3] = (f * math.cos(psi) - c * y[3]) / m
        out[q, 4] = (f * math.sin(psi) - c * y[4]) / m
        out[q, 5] = (f * math.sin(b) * a - cphi * y[5]) / I


def limited_weighted_field(body: Body, gains: Gains, ref, limits: Limits | None = None, weights=(1.0, 1.0, 1.0)):
    """The compiled rates of the weighted law under limits (the module's docstring): those of
    ``ClosedLoop.of(body, gains, reference_of(ref), Allocation("limited", weights), limits)``,
    to rounding.

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
    checks.instance("body", body, Body)
    checks.instance("gains", gains, Gains)
    kind = checks.one_of("ref (its path's kind)", getattr(ref, "_kind", None), ("eight", "circle"))
    limits = checks.instance("limits", Limits() if limits is None else limits, Limits)
    w = checks.array("weights", weights, shape=(3,), nonnegative=True)
    if not np.any(w > 0):
        raise ValueError(f"weights (w_x, w_y, w_phi) must not all be zero, got {weights!r}")
    fmax, bmax = (d if v is None else float(v) for v, d in ((limits.force, math.inf), (limits.angle, math.pi)))
    p = np.r_[body.m, body.I, body.a, body.c, body.c_phi, gains.kp, gains.kv].astype(float)
    sw, R, Th, eight = np.sqrt(w), float(ref.R), float(ref.theta), kind == "eight"

    def rates(t, Y):
        Y = np.ascontiguousarray(Y, dtype=float)
        rows = Y.reshape(-1, 6)
        n = rows.shape[0]
        u, G, r, bb, regular = np.empty((n, 2)), np.empty((n, 2, 2)), np.empty((n, 2)), np.empty(n), np.empty(n, bool)
        A, b = np.empty((n, 3, 2)), np.empty((n, 3))
        _problem_rows(float(t), rows, p, sw, R, Th, eight, u, G, r, bb, regular, A, b)
        if not regular.all():                     # the minimum-norm solution there, as the numpy kernel's
            u = np.ascontiguousarray(_pinv_rows(u, regular, A, b))
        F, beta = _limited_rows(u, G, r, bb, fmax, bmax, 129, 5)
        out = np.empty_like(rows)
        _plant_rows(rows, F, beta, p, out)
        return out.reshape(Y.shape)
    return rates
