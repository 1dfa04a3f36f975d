"""Chapter 7's smaller claims, each computed: the steady motion's extremes, the lock radius
against the paper's (36), the circle of the report's row, and the run under the force cap.

- :func:`steady_extremes`: the peak force and the force's largest angle from the axis over one
  period of a steady motion (:func:`lib.percussion.paper_steady`,
  :func:`lib.percussion.percussion_steady`), as extremes: the largest sample refined by the
  parabola through it and its neighbours (error O(h^3)) at two resolutions, their difference
  reported; the angle reaches pi exactly where the thrust u1 is reversed and the lateral force
  u2 changes sign.
- :func:`lock_ratio`: R_lock / R_crit, the smallest locked circle of P over the paper's (36) for
  C, in sympy; it equals |rho - 1| with rho = (c/m) / (c_phi/I_C), so the lock radius is the
  smaller iff c/m < 2 c_phi/I_C, at every Theta.
- :func:`paper_circle_of_p`: the circle that P runs while C runs the paper's circle, and the
  steady motion of the law for P asked to follow it.
- :func:`cap_windup`: the law for P on a path under a force cap, integrated until its thrust
  state runs away, with the times and sizes that show it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import sympy as sp
from scipy.integrate import solve_ivp

from ..allocation import Limits
from ..dynamics.sampled import sampled_extremes
from ..machinery import checks
from ..params import PAPER_DZ0, PAPER_Z0, Body, Gains
from ..rotation.circle import circle_equilibria
from ..trajectories import Reference, position_kinematics
from .compare import paper_steady, percussion_steady
from .law import closed_loop_rates, error_polynomial
from .point import centre_of_percussion
from .zero_dynamics import CircleSteadyMotion, circle_steady_motion

__all__ = ["SteadyExtremes", "steady_extremes", "lock_ratio", "paper_circle_of_p", "CapWindup", "cap_windup"]


@dataclass(frozen=True)
class SteadyExtremes:
    """Extremes over one period of a steady motion: ``F_peak`` (N) and ``F_change`` (N, its change
    from half the samples); ``beta_peak`` (rad) the largest |beta| (pi when the force points
    backwards along the axis) and ``beta_change`` (rad); ``thrust_min`` (N) the smallest
    u1 = F cos beta (refined as the peak is); ``reversed_time`` (s) the time a period with u1 < 0
    (the share of samples); ``backward`` the sign changes of u2 while u1 < 0 (each one a passage
    of beta through pi)."""

    F_peak: float
    F_change: float
    beta_peak: float
    beta_change: float
    thrust_min: float
    reversed_time: float
    backward: int


def _peaks(F, beta, period):
    F, beta = np.asarray(F, float), np.asarray(beta, float)
    u1, u2 = F * np.cos(beta), F * np.sin(beta)
    rev = u1 < 0
    both = rev & np.roll(rev, -1)
    backward = int(np.count_nonzero(both & (np.sign(u2) != np.sign(np.roll(u2, -1)))))
    b = math.pi if backward else float(sampled_extremes(np.abs(beta)[None, :])[1][0])
    return (float(sampled_extremes(F[None, :])[1][0]), b, float(sampled_extremes(u1[None, :])[0][0]),
            float(rev.mean() * period), backward)


def steady_extremes(body: Body, law: str, kind: str, R: float, Theta: float, steps: int = 2048) -> SteadyExtremes:
    """The extremes of the force over one period of a steady motion (the module's docstring).

    Parameters
    ----------
    body : Body
        The body.
    law : str
        ``"paper"`` (C on the path, :func:`lib.percussion.paper_steady`) or ``"percussion"``
        (P on the path, :func:`lib.percussion.percussion_steady`).
    kind : str
        ``"eight"`` or ``"circle"``.
    R, Theta : float
        The path's size (m) and rate (rad/s).
    steps : int
        Samples a period (even, >= 16); the change is measured against steps / 2.

    Returns
    -------
    SteadyExtremes
    """
    checks.one_of("law", law, ("paper", "percussion"))
    steps = checks.integer("steps", steps, minimum=16)
    if steps % 2:
        raise ValueError(f"steps must be even, got {steps}")
    period = 2 * math.pi / Theta
    res = []
    for n in (steps // 2, steps):
        if law == "paper":
            sm = paper_steady(body, kind, R, Theta, record_steps=n)
            res.append(_peaks(sm.F[:-1], sm.beta[:-1], period))
        else:
            sm = percussion_steady(body, kind, R, Theta, steps=n)
            res.append(_peaks(sm.F, sm.beta, period))
    (F0, b0, *_), (F1, b1, umin, trev, back) = res
    return SteadyExtremes(F1, abs(F1 - F0), b1, abs(b1 - b0), umin, trev, back)


def lock_ratio() -> tuple[sp.Expr, sp.Expr]:
    """R_lock / R_crit in sympy: P's smallest locked circle, |eps| / sqrt(Theta^2 + (c/m)^2)
    (:func:`lib.percussion.circle_lock_radius`), over the paper's (36) for C,
    c_phi / (a sqrt(m^2 Theta^2 + c^2)) (:func:`lib.rotation.circle.circle_critical_radius`).

    Returns
    -------
    ratio : sympy.Expr
        The ratio simplified, free of Theta.
    rho : sympy.Expr
        (c/m) / (c_phi/I_C), in whose terms the ratio is |rho - 1|.
    """
    m, I, a, c, cp, th = sp.symbols("m I_C a c c_varphi Theta", positive=True)
    s = -I / (m * a)
    eps = s * (c / m - cp / I)
    lock = sp.Abs(eps) / sp.sqrt(th**2 + (c / m) ** 2)
    crit = cp / (a * sp.sqrt(m**2 * th**2 + c**2))
    return sp.simplify(lock / crit), (c / m) / (cp / I)


def paper_circle_of_p(body: Body, R: float, Theta: float) -> tuple[float, CircleSteadyMotion]:
    """The circle P runs while C runs the paper's circle (27) of radius R (m) at Theta (rad/s) on
    the stable equilibrium of the paper's law (:func:`lib.rotation.circle.circle_equilibria`),
    R_P = sqrt(R^2 - 2 R s_P sin p + s_P^2), and the law for P's steady motion on it
    (:func:`lib.percussion.circle_steady_motion`).

    Parameters
    ----------
    body : Body
        The body.
    R, Theta : float
        C's circle (m) and rate (rad/s).

    Returns
    -------
    R_P : float
        P's circle (m).
    motion : CircleSteadyMotion
        The law for P's steady motion with P on it (its ``radius_C`` is C's circle, m).
    """
    p0 = circle_equilibria(body, R, Theta)[0]
    s = centre_of_percussion(body)
    R_P = math.sqrt(R**2 - 2 * R * s * math.sin(p0) + s**2)
    return R_P, circle_steady_motion(body, R_P, Theta)


@dataclass(frozen=True)
class CapWindup:
    """The law for P under a force cap (:func:`cap_windup`): ``t_end`` (s) where the run stopped,
    ``ran_away`` whether |xi| reached the threshold there; ``t_over`` (s) the first time the thrust
    state xi exceeds the cap (NaN if never), ``xi_over`` (N) its largest value before ``t_stop``
    - 0.5 s; ``xi_end`` (N) and ``omega_end`` (rad/s) at the end; ``F_applied`` (N) the largest
    applied force (at the solver's steps)."""

    t_end: float
    ran_away: bool
    t_over: float
    xi_over: float
    xi_end: float
    omega_end: float
    F_applied: float


def cap_windup(body: Body, gains: Gains, ref: Reference, cap: float, t_end: float, *, thrust0: float = 0.5,
               threshold: float = 1e6, rtol: float = 1e-8) -> CapWindup:
    """The law for P (no anti-windup) from the paper's start under a force cap, integrated by
    DOP853 until ``t_end`` or until |xi| reaches ``threshold`` (N).

    Parameters
    ----------
    body, gains : Body, Gains
        The body and the gains.
    ref : Reference
        The path of P.
    cap : float
        The force cap (N), > 0.
    t_end : float
        The horizon (s), > 0.
    thrust0 : float
        xi at the start (N).
    threshold : float
        |xi| (N) at which the run is stopped as run away.
    rtol : float
        The solver's rtol (and atol, in state units).

    Returns
    -------
    CapWindup
    """
    cap = checks.number("cap", cap, positive=True, unit="N")
    t_end = checks.number("t_end", t_end, positive=True, unit="s")
    coeffs, lim, kin = error_polynomial(body, gains), Limits(force=cap), position_kinematics(ref)

    def both(t, y):
        k = np.array(kin(t))
        return closed_loop_rates(body, coeffs, (k[0:2], k[2:4], k[4:6], k[6:8]), y, lim)

    def away(t, y):
        return abs(y[6]) - threshold
    away.terminal = True
    sol = solve_ivp(lambda t, y: both(t, y)[0], (0.0, t_end), np.r_[PAPER_Z0, PAPER_DZ0, thrust0],
                    method="DOP853", rtol=rtol, atol=rtol, events=away, dense_output=True)
    xi, t = sol.y[6], sol.t
    over = np.flatnonzero(np.abs(xi) > cap)
    early = t <= t[-1] - 0.5
    F = np.array([float(both(tt, yy)[1]) for tt, yy in zip(t, sol.y.T)])
    return CapWindup(float(t[-1]), sol.status == 1, float(t[over[0]]) if over.size else math.nan,
                     float(xi[early].max()) if early.any() else math.nan, float(xi[-1]), float(sol.y[5, -1]),
                     float(F.max()))
