"""Stability of the uncontrolled rotation (paper Sec. 6, eqs. (32)-(37), Fig. 5).

Starting on the reference, z(0) = z_d(0) and dz(0) = dz_d(0), the position
errors of the closed loop (23), (25)-(26) stay exactly zero (they obey the
homogeneous linear equation (24)), the demand reduces to the feed-forward
tau = M ddz_d + N(dz_d), and the heading phi obeys the single non-autonomous
equation (32),

    I_C phi'' + c_phi phi' = a (tau_y cos phi - tau_x sin phi).

For the circle (27) it becomes the autonomous pendulum-like equation (33) in
the rotation error p = phi - theta t - pi/2, solved here in closed form
(:func:`circle_equilibria`, :func:`circle_critical_radius`,
:func:`circle_eigenvalues`). For the eight (28) it stays time-periodic and is
integrated numerically for whole grids of (R, Theta) at once
(:func:`rotation_sweep`, :func:`eight_rotation_sweep`).

Units: R in m, theta (Theta) in rad/s, angles in rad, times in s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import pandas as pd
import sympy as sp

from .params import Body
from .symbolic import parameter_symbols

__all__ = [
    "RotationEquation", "derive_rotation_equation", "printed_eq33", "derive_eight_equation",
    "printed_eq37", "circle_equilibria", "circle_critical_radius", "circle_eigenvalues",
    "circle_jacobian", "circle_rotation_rhs",
]


# ---------------------------------------------------------------- symbolic: (32) -> (33), (37)

def _symbols():
    p = parameter_symbols()
    R = sp.Symbol("R", positive=True)
    Th = sp.Symbol("Theta", positive=True)
    t = sp.Symbol("t", real=True)
    return p, R, Th, t


@dataclass(frozen=True)
class RotationEquation:
    """The rotation equation on the reference in first-order form p' = v_p, v_p' = ``rhs``.

    ``p`` and ``v_p`` are sympy symbols (rad, rad/s); ``rhs`` is v_p' (rad/s^2);
    ``params`` maps Body field names to symbols, plus ``R`` and ``Theta``.
    """

    p: sp.Symbol
    v_p: sp.Symbol
    rhs: sp.Expr
    params: dict


def _eq32_torque(tau_x, tau_y, phi, a):
    """a F sin(beta) with F, beta from (25)-(26): F cos(phi+beta) = tau_x, F sin(phi+beta) = tau_y.

    F sin(beta) = F sin((phi + beta) - phi) is expanded by sympy and the two
    products replaced by tau_x, tau_y, which gives the right side of (32).
    """
    F, psi = sp.symbols("F psi", real=True)  # psi = phi + beta
    expr = sp.expand(sp.expand_trig(a * F * sp.sin(psi - phi)))
    return expr.subs({F * sp.cos(psi): tau_x, F * sp.sin(psi): tau_y})


@lru_cache(maxsize=None)
def derive_rotation_equation() -> RotationEquation:
    """Derive (33) from the model: (4) with (25)-(26) gives (32); on the circle (27)
    with zero position error tau_x = m xdd_d + c xd_d, tau_y = m ydd_d + c yd_d;
    then phi = p + Theta t + pi/2.
    """
    p_, R, Th, t = _symbols()
    m, I, a, c, cphi = p_["m"], p_["I"], p_["a"], p_["c"], p_["c_phi"]
    xd, yd = R * sp.cos(Th * t), R * sp.sin(Th * t)
    tau_x = m * xd.diff(t, 2) + c * xd.diff(t)
    tau_y = m * yd.diff(t, 2) + c * yd.diff(t)
    p, v = sp.symbols("p v_p", real=True)
    phi = p + Th * t + sp.pi / 2
    torque = _eq32_torque(tau_x, tau_y, phi, a)
    # I phi'' + c_phi phi' = torque with phi' = v + Theta, phi'' = v'
    rhs = (torque - cphi * (v + Th)) / I
    rhs = sp.expand(sp.simplify(sp.expand_trig(sp.expand(rhs))))
    if rhs.has(t):
        raise RuntimeError("the circle's rotation equation should be autonomous in p")
    params = dict(p_, R=R, Theta=Th)
    return RotationEquation(p=p, v_p=v, rhs=rhs, params=params)


def printed_eq33() -> sp.Expr:
    """v_p' exactly as printed in (33): its cos p term carries the wrong sign."""
    eq = derive_rotation_equation()
    s = eq.params
    m, I, a, c, cphi, R, Th = (s[k] for k in ("m", "I", "a", "c", "c_phi", "R", "Theta"))
    p, v = eq.p, eq.v_p
    return (-cphi / I * v - a * c * Th * R / I * sp.sin(p) - a * m * Th**2 * R / I * sp.cos(p)
            - cphi * Th / I)


@lru_cache(maxsize=None)
def derive_eight_equation() -> tuple[sp.Symbol, sp.Expr, dict]:
    """Right side of (37), a (tau_y cos phi - tau_x sin phi), on the eight (28) with zero position error.

    Returns (phi, torque, params); the equation is I_C phi'' + c_phi phi' = torque.
    """
    p_, R, Th, t = _symbols()
    m, a, c = p_["m"], p_["a"], p_["c"]
    xd, yd = R / 2 * sp.sin(2 * Th * t), R * sp.sin(Th * t)
    tau_x = m * xd.diff(t, 2) + c * xd.diff(t)
    tau_y = m * yd.diff(t, 2) + c * yd.diff(t)
    phi = sp.Symbol("varphi", real=True)
    return phi, _eq32_torque(tau_x, tau_y, phi, a), dict(p_, R=R, Theta=Th, t=t)


def printed_eq37(misplaced: bool = True) -> sp.Expr:
    """Right side of (37) as printed (``misplaced=True``: the closing bracket puts
    sin phi on both terms) or with the bracket where it belongs."""
    phi, _, s = derive_eight_equation()
    m, a, c, R, Th, t = (s[k] for k in ("m", "a", "c", "R", "Theta", "t"))
    A = c * sp.cos(Th * t) - m * Th * sp.sin(Th * t)
    B = c * sp.cos(2 * Th * t) - 2 * m * Th * sp.sin(2 * Th * t)
    if misplaced:
        return a * Th * R * (A * sp.cos(phi) - B) * sp.sin(phi)
    return a * Th * R * (A * sp.cos(phi) - B * sp.sin(phi))


# ---------------------------------------------------------------- the circle in closed form

def _check_circle_args(body: Body, R=None, theta=None) -> None:
    if not isinstance(body, Body):
        raise TypeError(f"body must be a lib.params.Body, got {type(body).__name__}")
    for name, v in (("R", R), ("theta", theta)):
        if v is None:
            continue
        if isinstance(v, bool) or not np.isscalar(v) or not np.isfinite(v):
            raise ValueError(f"{name} must be a finite real number, got {v!r}")
    if R is not None and R <= 0:
        raise ValueError(f"circle radius R must be positive, got {R!r} m")
    if theta is not None and theta <= 0:
        raise ValueError(f"angular rate theta must be positive (rad/s), got {theta!r}")


def circle_critical_radius(body: Body, theta: float) -> float:
    """Critical radius of (36), R_crit = c_phi / (a sqrt(m^2 theta^2 + c^2)) (m).

    Equilibria of (33) exist iff R >= R_crit; for R > R_crit there are two per
    turn, one stable and one saddle. ``theta`` > 0 in rad/s.
    """
    _check_circle_args(body, None, theta)
    return body.c_phi / (body.a * math.hypot(body.m * theta, body.c))


def circle_equilibria(body: Body, R: float, theta: float) -> tuple[float, float]:
    """The two equilibria (stable, saddle) of the corrected (33), p = phi - theta t - pi/2 (rad).

    With gamma = arctan(m theta / c) and k = R_crit / R <= 1, (33) at rest reads
    sin(p - gamma) = -k, so p_stable = gamma - arcsin k and
    p_saddle = gamma + pi + arcsin k, both wrapped to (-pi, pi].
    Raises ValueError when R < R_crit (no equilibrium: the rotation slips for ever).
    """
    _check_circle_args(body, R, theta)
    r_crit = circle_critical_radius(body, theta)
    if R < r_crit:
        raise ValueError(f"no equilibrium: R = {R!r} m is below the critical radius "
                         f"R_crit = {r_crit:.6g} m of (36) at theta = {theta!r} rad/s")
    k = min(r_crit / R, 1.0)
    gamma = math.atan(body.m * theta / body.c)
    wrap = lambda x: math.pi - (math.pi - x) % (2 * math.pi)  # noqa: E731
    return wrap(gamma - math.asin(k)), wrap(gamma + math.pi + math.asin(k))


def circle_jacobian(body: Body, R: float, theta: float, p0: float) -> np.ndarray:
    """Jacobian of (33) (corrected) at (p0, 0): the matrix of the linearisation (34)."""
    k21 = -body.a * R * theta / body.I * (body.c * math.cos(p0) + body.m * theta * math.sin(p0))
    return np.array([[0.0, 1.0], [k21, -body.c_phi / body.I]])


def circle_eigenvalues(body: Body, R: float, theta: float) -> np.ndarray:
    """Eigenvalues (1/s) of the linearisation (34) at the stable equilibrium:
    the roots of (35), lambda^2 + c_phi/I lambda + theta/I sqrt(a^2 R^2 (m^2 theta^2 + c^2) - c_phi^2).
    Complex array of two values, sorted by real part."""
    p_s, _ = circle_equilibria(body, R, theta)
    k0 = theta / body.I * math.sqrt(max(body.a**2 * R**2 * (body.m**2 * theta**2 + body.c**2)
                                        - body.c_phi**2, 0.0))
    lam = np.roots([1.0, body.c_phi / body.I, k0]).astype(complex)
    return lam[np.argsort(lam.real)]


def circle_rotation_rhs(body: Body, R, theta, p, v_p) -> np.ndarray:
    """Right side of the corrected (33): returns v_p' (rad/s^2); vectorised over arrays."""
    p, v_p = np.asarray(p, dtype=float), np.asarray(v_p, dtype=float)
    return (-body.c_phi / body.I * v_p - body.a * body.c * theta * R / body.I * np.sin(p)
            + body.a * body.m * theta**2 * R / body.I * np.cos(p) - body.c_phi * theta / body.I)
