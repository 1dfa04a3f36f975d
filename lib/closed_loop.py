"""The closed loop: the body (2)-(4) driven by the computed-torque law (23) through an
allocation (:mod:`lib.allocation`), as one vector field vectorised over points.

This is the single closed-loop right-hand side behind the smooth integrator
(:func:`lib.simulate.simulate`) and the batch integrator
(:func:`lib.weighting.batch.closed_loop_batch`); the switched integrator
(:mod:`lib.integrators.switched`) uses a scalar fast path of the same equations,
tested against this one at random states. :func:`paper_rates` is the paper's law on the
circle or the eight compiled, for the smooth integrator's one state at a time, and
``_paper_rows_tabled`` the same law with a model and a tabulated reference per row, for the
wrong-model loop (:mod:`lib.tracking.mismatch`); both allocate by one ``_position``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numba
import numpy as np

from .machinery import checks
from .allocation import Allocation, Allocator, Limits
from .control import computed_torque_from
from .model import config_accel
from .params import Body, Gains

__all__ = ["ClosedLoop", "reference_of", "paper_rates"]

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


@numba.njit(cache=True)
def _position(tx, ty, phi):  # pragma: no cover (compiled)
    """(25)-(26) on one demand: F = |(tau_x, tau_y)| (N) and beta (rad) wrapped to (-pi, pi], 0
    where F = 0 (``lib.allocation.allocate``, with :func:`lib.angles.wrap_angle`'s formula)."""
    F = math.hypot(tx, ty)
    beta = 0.0
    if F > 0:
        d = math.atan2(ty, tx) - phi
        beta = math.pi - (math.pi - d) % (2 * math.pi)
        if beta == -math.pi:
            beta = math.pi
    return F, beta


@numba.njit(cache=True)
def _paper_rows_tabled(ref, Y, T, model, k, plant, out):  # pragma: no cover (compiled)
    """dy/dtau of the rows of Y (M, 6) in the normalised time tau = t / T (T (M,) the rows'
    periods) under the paper's law without limits, each row with its own reference and model:
    ``ref`` (9, M) the path's (z_d, dz_d, ddz_d) at the time, ``model`` (2, M) the model's m and
    c in (23), k = (kp_x, kp_y, kv_x, kv_y), (2)-(4) of the plant (m, I, c, c_phi, a); the
    operations of :meth:`ClosedLoop.rates`, in their order (tau_phi is not formed: (25)-(26) do
    not read it). The wrong-model loop's field (:mod:`lib.tracking.mismatch`)."""
    m, I, c, c_phi, a = plant[0], plant[1], plant[2], plant[3], plant[4]
    for q in range(Y.shape[0]):
        x, yy, phi, vx, vy, vp = Y[q, 0], Y[q, 1], Y[q, 2], Y[q, 3], Y[q, 4], Y[q, 5]
        mx, cx = model[0, q], model[1, q]
        tx = mx * ref[6, q] + cx * vx + k[2] * (ref[3, q] - vx) + k[0] * (ref[0, q] - x)     # (23)
        ty = mx * ref[7, q] + cx * vy + k[3] * (ref[4, q] - vy) + k[1] * (ref[1, q] - yy)
        F, beta = _position(tx, ty, phi)                                               # (25)-(26)
        psi = phi + beta
        Tq = T[q]
        out[q, 0], out[q, 1], out[q, 2] = Tq * vx, Tq * vy, Tq * vp
        out[q, 3] = Tq * ((F * math.cos(psi) - c * vx) / m)                             # (2)-(4)
        out[q, 4] = Tq * ((F * math.sin(psi) - c * vy) / m)
        out[q, 5] = Tq * ((F * math.sin(beta) * a - c_phi * vp) / I)


@numba.njit(cache=True)
def _paper_rows(t, Y, eight, R, Th, model, k, plant, fmax, bmax, out):  # pragma: no cover (compiled)
    """s' of the rows of Y (M, 6) under the paper's law: the path's position and derivatives
    (:func:`lib.trajectories.eight_position`, :func:`lib.trajectories.circle_position`), (23)
    with the model's m and c (``model``) and k = (kp_x, kp_y, kv_x, kv_y), (25)-(26) under the
    cap ``fmax`` and the angle limit ``bmax``, (2)-(4) of the plant (m, I, c, c_phi, a): the
    operations of :meth:`ClosedLoop.rates`, in their order."""
    s = Th * t
    if eight:
        c1, s1, c2, s2 = math.cos(s), math.sin(s), math.cos(2 * s), math.sin(2 * s)
        xd, yd, vxd, vyd, axd, ayd = (0.5 * R * s2, R * s1, R * Th * c2, R * Th * c1, -2 * R * Th**2 * s2,
                                      -R * Th**2 * s1)
    else:
        c, sn = math.cos(s), math.sin(s)
        xd, yd, vxd, vyd, axd, ayd = R * c, R * sn, -R * Th * sn, R * Th * c, -R * Th**2 * c, -R * Th**2 * sn
    mm, cm = model[0], model[1]
    m, I, c_lin, c_phi, a = plant[0], plant[1], plant[2], plant[3], plant[4]
    for q in range(Y.shape[0]):
        x, y, phi, vx, vy, vp = Y[q, 0], Y[q, 1], Y[q, 2], Y[q, 3], Y[q, 4], Y[q, 5]
        tx = mm * axd + cm * vx + k[2] * (vxd - vx) + k[0] * (xd - x)                       # (23)
        ty = mm * ayd + cm * vy + k[3] * (vyd - vy) + k[1] * (yd - y)
        F, beta = _position(tx, ty, phi)                                              # (25)-(26)
        F = min(F, fmax)                                                              # Limits.apply
        beta = min(max(beta, -bmax), bmax)
        psi = phi + beta
        out[q, 0], out[q, 1], out[q, 2] = vx, vy, vp
        out[q, 3] = (F * math.cos(psi) - c_lin * vx) / m                                # (2)-(4)
        out[q, 4] = (F * math.sin(psi) - c_lin * vy) / m
        out[q, 5] = (F * math.sin(beta) * a - c_phi * vp) / I


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
