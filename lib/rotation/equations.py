"""The rotation equation of paper Sec. 6, derived with sympy: (4) with the allocation
(25)-(26) gives (32); on the circle (27) it becomes the autonomous (33), whose
equilibria p0^(k) the paper states in closed form; on the eight (28) it is (37).
The paper's printed forms are kept beside the derived ones for the errata.

Starting on the reference, z(0) = z_d(0) and dz(0) = dz_d(0), the position errors
of the closed loop stay exactly zero (they obey the homogeneous (24)), the demand
reduces to the feed-forward tau = M ddz_d + N(dz_d), and the heading obeys

    I_C phi'' + c_phi phi' = a (tau_y cos phi - tau_x sin phi).     (32)
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import sympy as sp

from ..symbolic import parameter_symbols

__all__ = ["RotationEquation", "derive_rotation_equation", "printed_eq33", "derive_eight_equation",
           "printed_eq37", "corrected_p0", "printed_p0"]


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
    """v_p' exactly as printed in (33): its cos p term carries the wrong sign.

    Returns
    -------
    sympy.Expr
        v_p' as printed (rad/s^2).
    """
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
    sin phi on both terms) or with the bracket where it belongs.

    Parameters
    ----------
    misplaced : bool
        Keep the misplaced bracket.

    Returns
    -------
    sympy.Expr
        The right side (rad/s^2).
    """
    phi, _, s = derive_eight_equation()
    m, a, c, R, Th, t = (s[k] for k in ("m", "a", "c", "R", "Theta", "t"))
    A = c * sp.cos(Th * t) - m * Th * sp.sin(Th * t)
    B = c * sp.cos(2 * Th * t) - 2 * m * Th * sp.sin(2 * Th * t)
    if misplaced:
        return a * Th * R * (A * sp.cos(phi) - B) * sp.sin(phi)
    return a * Th * R * (A * sp.cos(phi) - B * sp.sin(phi))


def corrected_p0(k: int):
    """Corrected closed form of the equilibria of (33), symbolic:
    p0^(k) = k pi + arctan(m Theta / c) - arcsin((-1)^k c_phi / (a R sqrt(m^2 Theta^2 + c^2))).

    Parameters
    ----------
    k : int
        The branch.

    Returns
    -------
    sympy.Expr
        p0^(k) (rad).
    """
    s = derive_rotation_equation().params
    m, a, c, cphi, R, Th = (s[n] for n in ("m", "a", "c", "c_phi", "R", "Theta"))
    return k * sp.pi + sp.atan(m * Th / c) - sp.asin((-1) ** k * cphi / (a * R * sp.sqrt(m**2 * Th**2 + c**2)))


def printed_p0(k: int, garbled: bool = True):
    """The printed p0^(k) = k pi - arctan(m Theta/c) - arcsin(c_phi / (a c R cos(k pi) sqrt(m^2 Theta^2/(c+1)))).
    With ``garbled=False`` the square root reads sqrt(m^2 Theta^2 / c^2 + 1), presumably what was meant.

    Parameters
    ----------
    k : int
        The branch.
    garbled : bool
        Keep the printed square root.

    Returns
    -------
    sympy.Expr
        p0^(k) as printed (rad).
    """
    s = derive_rotation_equation().params
    m, a, c, cphi, R, Th = (s[n] for n in ("m", "a", "c", "c_phi", "R", "Theta"))
    root = sp.sqrt(m**2 * Th**2 / (c + 1)) if garbled else sp.sqrt(m**2 * Th**2 / c**2 + 1)
    return k * sp.pi - sp.atan(m * Th / c) - sp.asin(cphi / (a * c * R * sp.cos(k * sp.pi) * root))
