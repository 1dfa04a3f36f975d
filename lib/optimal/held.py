"""The convex bound's achieved motions as motions of the full model (2)-(4) (Chapter 8): the
world-frame force of :func:`lib.optimal.bound.cap_bound`'s motion held on each node interval, with
the heading on the period-1 orbit it settles on under that force (eq. (4)), located by Newton's
method on the heading's period map (:func:`heading_orbit`), not waited for. The "convex" start of
:func:`lib.optimal.motion.periodic_motion` and the tracker's tests use these motions.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..dynamics.orbits import floquet_multipliers, newton
from ..machinery import checks
from ..machinery.summary import Summarised
from ..params import Body
from ..trajectories import heading_turns, make
from .bound import CapBound, _phi2, cap_bound

__all__ = ["HeldForceMotion", "held_force_motion", "heading_orbit", "HEADING_SUBSTEPS", "HEADING_TOL"]


#: RK4 steps a node interval of the heading under a held force (:func:`heading_orbit`): the period
#: map's error (order h^4, h = T / (16 N)) lies far below Newton's tolerance
HEADING_SUBSTEPS = 16
#: Newton's tolerance on the heading's period map (rad, rad/s); periods of transient before it
HEADING_TOL, HEADING_TRANSIENT = 1e-10, 4


def _heading_run(body: Body, Fw: np.ndarray, h: float, x: np.ndarray, record: bool = False):
    """(phi, phi') of rows x (M, 2) over one period under the world force Fw (N, 2) held on intervals
    of h (s): I phi'' + c_phi phi' = a (Fw_y cos phi - Fw_x sin phi), eq. (4) with F sin beta the
    force across the axis; RK4, HEADING_SUBSTEPS steps an interval, with its variational equation.
    Returns P(x) (M, 2), DP (M, 2, 2) and, with ``record``, every step's state (steps + 1, M, 2)."""
    dt, M = h / HEADING_SUBSTEPS, x.shape[0]
    J, grid = np.tile(np.eye(2), (M, 1, 1)), [x]

    def f(y, J, fx, fy):
        c, s = np.cos(y[:, 0]), np.sin(y[:, 0])
        A = np.zeros((M, 2, 2))
        A[:, 0, 1], A[:, 1, 0], A[:, 1, 1] = 1.0, -body.a * (fy * s + fx * c) / body.I, -body.c_phi / body.I
        return np.stack([y[:, 1], (body.a * (fy * c - fx * s) - body.c_phi * y[:, 1]) / body.I], -1), A @ J
    for fx, fy in Fw:
        for _ in range(HEADING_SUBSTEPS):
            k1, K1 = f(x, J, fx, fy)
            k2, K2 = f(x + dt / 2 * k1, J + dt / 2 * K1, fx, fy)
            k3, K3 = f(x + dt / 2 * k2, J + dt / 2 * K2, fx, fy)
            k4, K4 = f(x + dt * k3, J + dt * K3, fx, fy)
            x, J = x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4), J + dt / 6 * (K1 + 2 * K2 + 2 * K3 + K4)
            if record:
                grid.append(x)
    return x, J, (np.stack(grid) if record else None)


def heading_orbit(body: Body, bound: CapBound, objective: str = "rms") -> tuple[np.ndarray, np.ndarray, float, int]:
    """The heading's period-1 orbit without slip under the held world force of :func:`cap_bound`'s
    achieved motion (``objective`` "max": ``bound.F``; "rms": ``bound.F_rms``), with beta pointing
    the force where that force points (eq. (4)). Located, not waited for: Newton on the period map
    (:func:`lib.dynamics.orbits.newton`, the exact Jacobian of the RK4 map, tol :data:`HEADING_TOL`,
    the path's turns of the heading a period) from the heading along the force at t = 0 after
    :data:`HEADING_TRANSIENT` periods; RuntimeError if Newton does not converge.

    Returns
    -------
    grid : numpy.ndarray
        (nodes HEADING_SUBSTEPS + 1, 2) phi (rad), phi' (rad/s) at the RK4 steps over one period.
    multipliers : numpy.ndarray
        (2,) the orbit's Floquet multipliers (complex, decreasing modulus).
    residual : float
        Newton's residual (max-norm, rad and rad/s).
    turns : int
        Whole turns of the heading a period (the path's).
    """
    checks.instance("body", body, Body)
    checks.instance("bound", bound, CapBound)
    Fw = bound.F_rms if checks.one_of("objective", objective, ("max", "rms")) == "rms" else bound.F
    turns, h = heading_turns(make(bound.kind, bound.R, bound.Theta)), 2 * math.pi / bound.Theta / bound.nodes
    x = np.array([[math.atan2(Fw[0, 1], Fw[0, 0]), 0.0]])
    for _ in range(HEADING_TRANSIENT):
        x = _heading_run(body, Fw, h, x)[0] - [2 * math.pi * turns, 0.0]
    res = newton(lambda i, y, k: _heading_run(body, Fw, h, y)[:2], np.zeros(1, int), x, 1, turns=[turns],
                 tol=HEADING_TOL, max_iter=20)
    if not res.residual[0] <= HEADING_TOL:
        raise RuntimeError(f"heading_orbit: Newton found no period-1 orbit (residual {res.residual[0]:.3g})")
    return (_heading_run(body, Fw, h, res.x, record=True)[2][:, 0], floquet_multipliers(res.jacobian[0]),
            float(res.residual[0]), turns)


@dataclass(frozen=True, repr=False)
class HeldForceMotion(Summarised):
    """A periodic motion of the full model (2)-(4) whose world-frame force ``Fw`` (N, (N, 2)) is held
    on each node interval (:func:`held_force_motion`): C (m) and V (m/s) at the nodes ``t`` (s, (N,))
    as :func:`lib.optimal.bound.cap_bound`'s achieved motion (closed form between them); the heading
    on its period-1 orbit under that force (:func:`heading_orbit`: ``heading``
    (N S + 1, 2) (rad, rad/s) at its RK4 steps, its ``multipliers`` and Newton's ``residual``);
    F = |Fw| (N), beta the force's angle less phi (rad, continuous within an interval). It has what
    :mod:`lib.optimal.tracker` asks of a motion: period (s), kind, R (m), Theta (rad/s), F_max (N),
    beta_max (None), turns, ``state(t)``, ``inputs(t)``, the input breaks ``t``."""

    body: Body
    t: np.ndarray
    C: np.ndarray
    V: np.ndarray
    Fw: np.ndarray
    heading: np.ndarray
    multipliers: np.ndarray
    residual: float
    period: float
    kind: str
    R: float
    Theta: float
    F_max: float
    turns: int
    objective: str
    beta_max: None = None

    def _heading(self, t):
        """(interval k, phi, phi') at times t (s), any shape: cubic Hermite on the RK4 steps, with
        the rates of eq. (4) at both ends (the steps never straddle a node)."""
        t = np.asarray(t, dtype=float)
        laps = np.floor(t / self.period)
        dt = self.period / self.t.size / HEADING_SUBSTEPS
        x = (t - laps * self.period) / dt
        j = np.clip(np.floor(x).astype(int), 0, self.heading.shape[0] - 2)
        k, r, b = j // HEADING_SUBSTEPS, x - j, self.body
        (p0, w0), (p1, w1) = np.moveaxis(self.heading[j], -1, 0), np.moveaxis(self.heading[j + 1], -1, 0)
        fx, fy = self.Fw[k][..., 0], self.Fw[k][..., 1]
        a0, a1 = ((b.a * (fy * np.cos(p) - fx * np.sin(p)) - b.c_phi * w) / b.I for p, w in ((p0, w0), (p1, w1)))
        h00, h10, h01, h11 = 2 * r**3 - 3 * r**2 + 1, dt * (r**3 - 2 * r**2 + r), 3 * r**2 - 2 * r**3, dt * (r**3 - r**2)
        phi = h00 * p0 + h10 * w0 + h01 * p1 + h11 * w1 + 2 * np.pi * self.turns * laps
        return k, phi, h00 * w0 + h10 * a0 + h01 * w1 + h11 * a1

    def state(self, t) -> tuple[np.ndarray, np.ndarray]:
        """Configuration (m, m, rad) and rate (m/s, m/s, rad/s) at times t (s), t.shape + (3,)."""
        k, phi, dphi = self._heading(t)
        b, kap = self.body, self.body.c / self.body.m
        r = (np.asarray(t, dtype=float) % self.period - self.t[k])[..., None]
        p = b.m * self.V[k] + b.c * self.C[k]
        C = np.exp(-kap * r) * self.C[k] - np.expm1(-kap * r) / b.c * p + self.Fw[k] * _phi2(kap * r) / (b.m * kap**2)
        V = np.exp(-kap * r) * self.V[k] - np.expm1(-kap * r) / b.c * self.Fw[k]
        return np.concatenate([C, phi[..., None]], -1), np.concatenate([V, dphi[..., None]], -1)

    def inputs(self, t) -> tuple[np.ndarray, np.ndarray]:
        """F (N) and beta (rad) at times t (s), shape t.shape."""
        k, phi, _ = self._heading(t)
        fx, fy = self.Fw[k][..., 0], self.Fw[k][..., 1]
        return np.hypot(fx, fy), np.angle(np.exp(1j * (np.arctan2(fy, fx) - phi)))


def held_force_motion(body: Body, bound: CapBound, objective: str = "rms") -> HeldForceMotion:
    """:func:`lib.optimal.bound.cap_bound`'s achieved motion of ``objective`` ("max" or "rms") as a
    motion of the full model (2)-(4), its heading on the period-1 orbit that
    :func:`heading_orbit` locates under the held force (RuntimeError without one).

    Parameters
    ----------
    body : Body
        The body the bound was computed for.
    bound : CapBound
        The bound.
    objective : str
        ``"max"`` (the largest distance's motion) or ``"rms"``.

    Returns
    -------
    HeldForceMotion
        The motion, with its heading orbit's multipliers and residual.
    """
    grid, mult, res, turns = heading_orbit(body, bound, objective)
    rms = objective == "rms"
    return HeldForceMotion(body=body, t=bound.t, C=bound.C_rms if rms else bound.C, V=bound.V_rms if rms else bound.V,
                           Fw=bound.F_rms if rms else bound.F, heading=grid, multipliers=mult, residual=res,
                           period=2 * math.pi / bound.Theta, kind=bound.kind, R=bound.R, Theta=bound.Theta,
                           F_max=bound.F_max, turns=turns, objective=objective)


@lru_cache(maxsize=8)
def _convex_held(body: Body, kind: str, R: float, Theta: float, F_max: float, nodes: int) -> HeldForceMotion:
    """The "convex" start's motion: the RMS-optimal held-force motion of the cap's convex problem
    at ``nodes`` (at least 16) nodes (cached: the continuation and the multistart reuse it)."""
    return held_force_motion(body, cap_bound(body, R, Theta, F_max, kind=kind, nodes=max(nodes, 16)), "rms")
