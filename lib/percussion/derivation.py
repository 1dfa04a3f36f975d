"""The centre of percussion P and its equations of motion, derived with sympy from (2)-(4).

A point X = C + s e1 on the body axis (e1 = (cos phi, sin phi), e2 = (-sin phi, cos phi),
s in m, positive towards the force's point of application: the torque F a sin(beta) of
(4) puts that point at C + a e1). Its acceleration, from (2)-(4) with u1 = F cos beta,
u2 = F sin beta ((7)-(8)), carries u2 with the coefficient 1/m + s a / I_C; it vanishes at

    s_P = -I_C / (m a),

the centre of percussion with respect to the force's point. There

    P'' = (u1/m - s_P omega^2) e1 - (c/m) P' + s_P (c/m - c_phi/I_C) omega e2:

the lateral force has left, and the drag splits into a drag -(c/m) P' of P's own velocity
and a lateral term proportional to omega and to the mismatch c/m - c_phi/I_C of the two
drag rates; with c/m = c_phi/I_C it vanishes and P'' + (c/m) P' lies along the body axis.

With the thrust u1 as input the decoupling matrix of P'' is [e1/m, 0] (rank 1: static
feedback is singular). With u1 a state (an integrator, input nu = u1') P''' is affine in
(nu, u2) with the matrix ``extended`` whose determinant is -(c/m - c_phi/I_C) / m^2: regular
everywhere when the drag rates differ, singular everywhere when they are equal.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import sympy as sp

__all__ = ["PointDerivation", "derive_point"]


@dataclass(frozen=True)
class PointDerivation:
    """The sympy results of :func:`derive_point` (every expression in the symbols ``sym``).

    ``s_P``: P's position on the axis (m); ``lateral_u2``: the coefficient of u2 in X''.e2
    for a general s; ``accel``: P'' (2x1, world frame) in terms of (phi, omega, P', u1);
    ``accel_body``: (P''.e1, P''.e2); ``drag_lateral``: the lateral drag term (coefficient of
    e2 beyond the own drag); ``mismatch``: c/m - c_phi/I_C; ``static``: the 2x2 matrix of
    (u1, u2) in P''; ``extended``: the 2x2 matrix of (nu, u2) in P''' (body frame);
    ``extended_det``: its determinant."""

    sym: dict
    s_P: sp.Expr
    lateral_u2: sp.Expr
    accel: sp.Matrix
    accel_body: sp.Matrix
    drag_lateral: sp.Expr
    mismatch: sp.Expr
    static: sp.Matrix
    extended: sp.Matrix
    extended_det: sp.Expr


def _symbols() -> dict:
    m, I, a, c, cp = sp.symbols("m I_C a c c_varphi", positive=True)
    s = sp.Symbol("s", real=True)
    phi, om, u1, u2, nu = sp.symbols("varphi omega u_1 u_2 nu", real=True)
    vx, vy = sp.symbols("v_x v_y", real=True)          # C's velocity (world frame)
    return dict(m=m, I=I, a=a, c=c, c_phi=cp, s=s, phi=phi, omega=om, u1=u1, u2=u2, nu=nu, vx=vx, vy=vy)


def _accelerations(S: dict):
    """(C'', omega') from (2)-(4) with (7)-(8): m C'' = -c C' + u1 e1 + u2 e2, I omega' = -c_phi omega + a u2."""
    e1 = sp.Matrix([sp.cos(S["phi"]), sp.sin(S["phi"])])
    e2 = sp.Matrix([-sp.sin(S["phi"]), sp.cos(S["phi"])])
    vC = sp.Matrix([S["vx"], S["vy"]])
    aC = (-S["c"] * vC + S["u1"] * e1 + S["u2"] * e2) / S["m"]
    dom = (-S["c_phi"] * S["omega"] + S["a"] * S["u2"]) / S["I"]
    return e1, e2, vC, aC, dom


@lru_cache(maxsize=1)
def derive_point() -> PointDerivation:
    """Derive P (no drag assumption): the point of the axis whose acceleration is free of u2,
    its equation of motion with drag, and the decoupling matrices of P'' and P'''."""
    S = _symbols()
    e1, e2, vC, aC, dom = _accelerations(S)
    s, om = S["s"], S["omega"]
    aX = aC + s * dom * e2 - s * om**2 * e1                       # X = C + s e1
    lateral = sp.simplify(sp.diff(aX.dot(e2), S["u2"]))
    s_P = sp.solve(sp.Eq(lateral, 0), s)[0]
    vP = vC + s_P * om * e2
    aP = aX.subs(s, s_P).applyfunc(sp.simplify)
    k, mism = S["c"] / S["m"], S["c"] / S["m"] - S["c_phi"] / S["I"]
    # P'' + (c/m) P' in the body frame: what is left after P's own drag
    rest = (aP + k * vP).applyfunc(sp.simplify)
    body = sp.Matrix([sp.simplify(rest.dot(e1)), sp.simplify(rest.dot(e2))])
    drag_lat = sp.simplify(body[1])
    accel = (body[0] * e1 + body[1] * e2 - k * vP).applyfunc(sp.simplify)
    static = sp.Matrix([[sp.diff(aP.dot(e), u) for u in (S["u1"], S["u2"])] for e in (e1, e2)]).applyfunc(sp.simplify)
    extended = _extended_matrix(S, e1, e2, vP, s_P, accel)
    return PointDerivation(sym=S, s_P=s_P, lateral_u2=lateral, accel=accel, accel_body=body,
                           drag_lateral=drag_lat, mismatch=mism, static=static, extended=extended,
                           extended_det=sp.factor(sp.simplify(extended.det())))


def _extended_matrix(S, e1, e2, vP, s_P, accel) -> sp.Matrix:
    """The matrix of (nu, u2) in P''' (body frame), with u1' = nu, omega' from (4), phi' = omega
    and P'' from ``accel`` (P' a state: its rate is P'')."""
    vPx, vPy = sp.symbols("w_x w_y", real=True)
    # P'' written with P' as its own state (vP -> (vPx, vPy)):
    k = S["c"] / S["m"]
    body = accel + k * vP                                         # independent of vP
    aP = body - k * sp.Matrix([vPx, vPy])
    dom = (-S["c_phi"] * S["omega"] + S["a"] * S["u2"]) / S["I"]
    jerk = (aP.diff(S["phi"]) * S["omega"] + aP.diff(S["omega"]) * dom + aP.diff(S["u1"]) * S["nu"]
            + aP.diff(vPx) * aP[0] + aP.diff(vPy) * aP[1])
    return sp.Matrix([[sp.diff(jerk.dot(e), u) for u in (S["nu"], S["u2"])] for e in (e1, e2)]).applyfunc(sp.simplify)
