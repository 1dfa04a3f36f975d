"""The smooth integrator: adaptive :func:`scipy.integrate.solve_ivp` with tolerances
grouped in :class:`Integration`, and a blow-up or a failure turned into a
:class:`SimulationError` that names the time and the variable.

The default is the 8th-order Dormand-Prince method (``DOP853``) at rtol = atol =
1e-10: the closed loop is smooth when no limit is active, so a high-order method
at tight tolerances reaches the 1e-8 agreement with the analytic error solution
of (24) that the tests demand, in a few thousand steps.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np
from scipy.integrate import solve_ivp

from ..machinery import checks

__all__ = ["Integration", "SimulationError", "integrate", "SWITCHING"]

#: how a discontinuity of the field (an angle limit) is integrated
SWITCHING = ("auto", "stepsize", "events")


class SimulationError(RuntimeError):
    """The integration failed or the solution became non-finite or blew up."""


#: the methods of :func:`scipy.integrate.solve_ivp`, by the names it documents
METHODS = ("BDF", "DOP853", "LSODA", "RK23", "RK45", "Radau")


@dataclass(frozen=True)
class Integration:
    """How to integrate: ``method`` of :func:`scipy.integrate.solve_ivp`, relative and
    absolute tolerances ``rtol`` and ``atol``, ``max_step`` (s), the magnitude
    ``blowup`` of a state that counts as blown up, and ``switching``: ``"stepsize"``
    leaves an angle limit's discontinuity to the step-size control, ``"events"``
    locates it (:mod:`lib.integrators.switched`), and ``"auto"`` (the default) locates
    it wherever the event-located loop applies (an angle limit below pi on the paper's
    position-only law, the plant its own model: :func:`lib.simulate.simulate`), since
    the step-size control crawls along a sliding motion. Validated on construction.
    """

    method: str = "DOP853"
    rtol: float = 1e-10
    atol: float = 1e-10
    max_step: float = math.inf
    blowup: float = 1e8
    switching: str = "auto"

    def accuracy(self, scale: float) -> float:
        """The error the book takes a run of a smooth, contracting loop to hold: ten times the
        per-step tolerance at the state's ``scale``, 10 (atol + rtol scale), in the state's unit.
        A value a run gives below it is round-off for this method, and the page prints this bound
        instead (:func:`lib.machinery.kinds.within_accuracy`); Chapter 3 checks it against the
        closed form of (24).

        Parameters
        ----------
        scale : float
            The magnitude of the state's components concerned (m, rad), > 0.

        Returns
        -------
        float
            The accuracy, in the unit of ``scale``.
        """
        return 10.0 * (self.atol + self.rtol * checks.number("scale", scale, positive=True))

    def __post_init__(self) -> None:
        for name in ("rtol", "atol", "max_step", "blowup"):
            v = getattr(self, name)
            if isinstance(v, bool) or not np.isscalar(v) or not v > 0 or math.isnan(v):
                raise ValueError(f"Integration.{name} must be a positive number, got {v!r}")
        if self.switching not in SWITCHING:
            raise ValueError(f"switching must be one of {SWITCHING}, got {self.switching!r}")
        if self.method not in METHODS:
            raise ValueError(f"Integration.method must be one of scipy's solve_ivp methods {METHODS}, "
                             f"got {self.method!r}")


def integrate(rhs: Callable, s0, t_end: float, t_eval, integration: Integration,
              names: tuple[str, ...]) -> tuple[np.ndarray, np.ndarray]:
    """Integrate s' = rhs(t, s) from s0 at t = 0 to ``t_end`` (s), sampled at ``t_eval``.

    A state whose magnitude exceeds ``integration.blowup`` raises
    :class:`SimulationError` naming the time and the largest variable (``names``);
    so does a failure of the solver. Returns (t, s) with s of shape (n, len(s0)).

    Parameters
    ----------
    rhs : callable
        (t, s) -> s'.
    s0 : array_like
        Start state.
    t_end : float
        End time (s).
    t_eval : array_like
        Output times (s).
    integration : Integration
        Method, tolerances, blow-up bound.
    names : tuple of str
        The state's variable names, for messages.

    Returns
    -------
    t : numpy.ndarray
        Times (s), (n,).
    s : numpy.ndarray
        States, (n, len(s0)).
    """
    def blew_up(t, s):
        return integration.blowup - np.max(np.abs(s))

    blew_up.terminal = True
    sol = solve_ivp(rhs, (0.0, t_end), s0, method=integration.method, t_eval=t_eval, rtol=integration.rtol,
                    atol=integration.atol, max_step=integration.max_step, events=blew_up)
    if sol.status == 1:
        s = sol.y_events[0][0]
        raise SimulationError(f"closed loop blew up at t = {sol.t_events[0][0]:.6g} s: "
                              f"|{names[int(np.argmax(np.abs(s)))]}| reached {integration.blowup:g}")
    if sol.status != 0:
        raise SimulationError(f"integration failed: {sol.message}")
    return sol.t, sol.y.T
