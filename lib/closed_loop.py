"""The closed loop: the body (2)-(4) driven by the computed-torque law (23) through an
allocation (:mod:`lib.allocation`), as one vector field vectorised over points.

This is the single closed-loop right-hand side behind the smooth integrator
(:func:`lib.simulate.simulate`) and the batch integrator
(:func:`lib.weighting.batch.closed_loop_batch`); the switched integrator
(:mod:`lib.integrators.switched`) uses a scalar fast path of the same equations,
tested against this one at random states.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from .machinery import checks
from .allocation import Allocation, Allocator, Limits
from .control import computed_torque_from
from .model import config_accel
from .params import Body, Gains

__all__ = ["ClosedLoop", "reference_of"]

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
