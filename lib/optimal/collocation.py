"""The CasADi transcription behind :mod:`lib.optimal.motion`: direct collocation of the
model (2)-(4) over one period, solved by IPOPT.

The model's right-hand side is written here a second time, for CasADi symbols
(:func:`casadi_accel`); it is a second statement of eqs. (2)-(4), checked against the one
numeric definition :func:`lib.model.config_accel` at random states by
``tests/test_optimal_motion.py``.

Transcription: the period T is cut into ``nodes`` intervals of length h = T / nodes; on
interval k the state X = (x, y, phi, x', y', phi') (m, m, rad, m/s, m/s, rad/s) is a
polynomial of degree ``degree`` through the interval's start X_k and the states at the
``degree`` Gauss-Legendre points, the inputs u_k = (F_k (N), beta_k (rad)) are constant. The
collocation equations ask X' = f(X, u_k) at the Legendre points, continuity asks the
polynomial's end to be X_{k+1}, and periodicity closes the chain: X_nodes = X_0 + (0, 0,
2 pi n, 0, 0, 0). The objective is the mean over the period of |C - C_d|^2 (m^2) by the
collocation quadrature (Gauss-Legendre weights, exact for polynomials of degree 2 degree - 1).
Inputs being constant per interval, the solution is exactly reproducible by integrating
them (:func:`lib.optimal.motion.verify_motion`); Legendre collocation of degree d is of
order 2 d at the interval ends (superconvergence), so the return error of that integration
falls like h^(2 d).

The NLP depends on the body, ``nodes`` and ``degree`` only; the path (C_d at the
collocation points), the step h and the turn 2 pi n are parameters, the limits are bounds,
so one compiled solver (cached) serves every path, rate, limit and start. The starts of
:func:`lib.optimal.motion.periodic_motion`, the bounds and the largest distance's search live here
too; the entry manoeuvre onto a motion, the same intervals left open, is :mod:`lib.optimal.entry`.
"""

from __future__ import annotations

import math

from dataclasses import dataclass
from functools import lru_cache
from typing import TYPE_CHECKING

import numpy as np
from scipy.optimize import minimize_scalar

from ..angles import wrap_angle
from ..params import Body
from ..percussion import paper_steady
from ..trajectories import POSITIONS, make

if TYPE_CHECKING:  # imported where used: casadi loads in about 1 s, most pages never call it
    import casadi as ca

__all__ = ["Tableau", "tableau", "casadi_accel", "accel_function", "Transcription", "transcription", "ACCEPTED",
           "IPOPT_OPTIONS", "FREE_ANGLE", "HARMONICS"]

#: IPOPT return statuses accepted as a solution
ACCEPTED = ("Solve_Succeeded", "Solved_To_Acceptable_Level")
#: IPOPT options; silent, a tolerance well below the collocation error at the default mesh, an
#: iteration cap (a start that does not converge within it is reported, not used), and a failure
#: returned as a status for the caller to judge rather than raised
IPOPT_OPTIONS = {"ipopt.print_level": 0, "print_time": False, "ipopt.sb": "yes", "ipopt.max_iter": 400,
                 "error_on_fail": False,
                 "ipopt.tol": 1e-10, "ipopt.constr_viol_tol": 1e-10}
#: the state's length; x, y, phi, x', y', phi'
NX = 6
#: the bound on |beta| (rad) when no angle limit is given; beta is then free, but bounded a
#: little beyond +-pi to keep the NLP bounded (every force direction stays reachable)
FREE_ANGLE = math.pi + 1.0
#: harmonics of the paper's steady heading kept for the "paper" start (it is smooth)
HARMONICS = 64
#: dense samples per interval for the largest distance, before its refinement
DENSE = 16


@dataclass(frozen=True)
class Tableau:
    """Collocation on [0, 1]: ``tau`` (d + 1,) the points (0 then the d Legendre points);
    ``C`` (d + 1, d) the derivative of the Lagrange basis at the Legendre points
    (column j: p'(tau_j) = sum_r C[r, j] X_r); ``D`` (d + 1,) the basis at 1; ``B`` (d,) the
    quadrature weights at the Legendre points (sum 1); ``basis`` (d + 1, d + 1) the basis
    polynomials' coefficients, highest power first (row r for X_r)."""

    tau: np.ndarray
    C: np.ndarray
    D: np.ndarray
    B: np.ndarray
    basis: np.ndarray

    def weights(self, s) -> np.ndarray:
        """The Lagrange basis at s in [0, 1] (any shape): shape s.shape + (d + 1,)."""
        s = np.asarray(s, dtype=float)[..., None]
        w = np.zeros(s.shape[:-1] + (self.basis.shape[0],))
        for c in self.basis.T:             # Horner on every basis polynomial at once, as numpy.polyval
            w = w * s + c
        return w


@lru_cache(maxsize=8)
def tableau(degree: int) -> Tableau:
    """The Gauss-Legendre collocation tableau of ``degree`` points (unvalidated kernel).

    Parameters
    ----------
    degree : int
        Number of Legendre points per interval (1 to 5).

    Returns
    -------
    Tableau
        Its points, derivative matrix, end weights, quadrature weights and basis.
    """
    import casadi as ca
    tau = np.concatenate([[0.0], np.asarray(ca.collocation_points(degree, "legendre"), dtype=float)])
    d = degree
    basis = np.empty((d + 1, d + 1))
    C, D, B = np.empty((d + 1, d)), np.empty(d + 1), np.empty(d)
    for r in range(d + 1):
        p = np.poly1d([1.0])
        for s in range(d + 1):
            if s != r:
                p *= np.poly1d([1.0, -tau[s]]) / (tau[r] - tau[s])
        basis[r] = p.coeffs
        D[r] = p(1.0)
        dp = np.polyder(p)
        C[r] = dp(tau[1:])
        if r > 0:
            B[r - 1] = np.polyint(p)(1.0)
    for arr in (tau, C, D, B, basis):
        arr.setflags(write=False)
    return Tableau(tau=tau, C=C, D=D, B=B, basis=basis)


def casadi_accel(body: Body, z, dz, F, beta):
    """Accelerations of eqs. (2)-(4) for CasADi symbols: the second statement of
    :func:`lib.model.config_accel` (checked against it at random states by the tests).

    m x'' + c x' = F cos(phi + beta), m y'' + c y' = F sin(phi + beta),
    I_C phi'' + c_phi phi' = F a sin(beta).

    Parameters
    ----------
    body : Body
        The body (m (kg), I_C (kg m^2), a (m), c (N s/m), c_phi (N m s)).
    z, dz : casadi.SX or casadi.MX
        Configuration (x (m), y (m), phi (rad)) and its rate (m/s, m/s, rad/s), 3-vectors.
    F, beta : casadi.SX or casadi.MX
        Force magnitude (N) and its angle to the body axis (rad), scalars.

    Returns
    -------
    casadi.SX or casadi.MX
        (x'' (m/s^2), y'' (m/s^2), phi'' (rad/s^2)), a 3-vector.
    """
    import casadi as ca
    psi = z[2] + beta
    return ca.vertcat((F * ca.cos(psi) - body.c * dz[0]) / body.m,
                      (F * ca.sin(psi) - body.c * dz[1]) / body.m,
                      (F * body.a * ca.sin(beta) - body.c_phi * dz[2]) / body.I)


def accel_function(body: Body) -> ca.Function:
    """:func:`casadi_accel` as a CasADi function (z (3), dz (3), u = (F, beta) (2)) -> ddz (3).

    Parameters
    ----------
    body : Body
        The body.

    Returns
    -------
    casadi.Function
        ``accel(z, dz, u)``; units as :func:`casadi_accel`.
    """
    import casadi as ca
    z, dz, u = ca.SX.sym("z", 3), ca.SX.sym("dz", 3), ca.SX.sym("u", 2)
    return ca.Function("accel", [z, dz, u], [casadi_accel(body, z, dz, u[0], u[1])])


@dataclass(frozen=True)
class Transcription:
    """The compiled NLP of one (body, nodes, degree).

    Decision vector: per interval k a block of ``block`` = 6 (d + 1) + 2 entries, X_k, the d
    collocation states, then F_k, beta_k; blocks in order of k. Parameters: h (s), the turn
    2 pi n (rad), then C_d at the collocation points, x then y per (k, j), k major.
    ``solver`` is the IPOPT ``nlpsol``; ``ng`` the number of (equality) constraints."""

    nodes: int
    degree: int
    block: int
    ng: int
    solver: ca.Function

    def unpack(self, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """States (nodes, d + 1, 6) and inputs (nodes, 2) from a decision vector."""
        blk = np.asarray(w, dtype=float).reshape(self.nodes, self.block)
        return blk[:, :-2].reshape(self.nodes, self.degree + 1, NX), blk[:, -2:].copy()

    def pack(self, X: np.ndarray, u: np.ndarray) -> np.ndarray:
        """The decision vector of states (nodes, d + 1, 6) and inputs (nodes, 2)."""
        return np.concatenate([np.asarray(X, float).reshape(self.nodes, -1), np.asarray(u, float)], axis=1).ravel()


def _interval(body: Body, tab: Tableau) -> ca.Function:
    """One interval's residuals and cost: (X (6, d+1), u (2), X_next (6), h, Cd (2, d)) ->
    (g (6 (d + 1)), cost = sum_j B_j |C_j - Cd_j|^2)."""
    import casadi as ca
    d = len(tab.B)
    X, u, Xn = ca.SX.sym("X", NX, d + 1), ca.SX.sym("u", 2), ca.SX.sym("Xn", NX)
    h, Cd = ca.SX.sym("h"), ca.SX.sym("Cd", 2, d)
    g, cost = [], 0
    for j in range(1, d + 1):
        xj = X[:, j]
        rate = ca.vertcat(xj[3:], casadi_accel(body, xj[:3], xj[3:], u[0], u[1]))
        slope = sum(tab.C[r, j - 1] * X[:, r] for r in range(d + 1))
        g.append(h * rate - slope)
        e = xj[:2] - Cd[:, j - 1]
        cost += tab.B[j - 1] * ca.dot(e, e)
    g.append(sum(tab.D[r] * X[:, r] for r in range(d + 1)) - Xn)
    return ca.Function("interval", [X, u, Xn, h, Cd], [ca.vertcat(*g), cost])


@lru_cache(maxsize=4)
def transcription(body: Body, nodes: int, degree: int) -> Transcription:
    """The collocation NLP and its IPOPT solver for ``nodes`` intervals of ``degree``
    Legendre points (cached: the book's settings share one).

    Parameters
    ----------
    body : Body
        The body.
    nodes : int
        Intervals per period.
    degree : int
        Legendre points per interval.

    Returns
    -------
    Transcription
        The solver; call it with x0, lbx, ubx, lbg = ubg = 0 and p (see :class:`Transcription`).
    """
    import casadi as ca
    tab = tableau(degree)
    d, N = degree, nodes
    block = NX * (d + 1) + 2
    w = ca.SX.sym("w", N * block)
    p = ca.SX.sym("p", 2 + 2 * d * N)
    W = ca.reshape(w, block, N)
    Xs = W[:NX * (d + 1), :]
    U = W[NX * (d + 1):, :]
    X0 = Xs[:NX, :]
    shift = ca.vertcat(0, 0, p[1], 0, 0, 0)
    Xnext = ca.horzcat(X0[:, 1:], X0[:, 0] + shift)
    Cd = ca.reshape(p[2:], 2 * d, N)
    f = _interval(body, tab)
    fm = f.map(N)
    g, cost = fm(ca.reshape(Xs, NX, (d + 1) * N), U, Xnext, ca.repmat(p[0], 1, N), ca.reshape(Cd, 2, d * N))
    nlp = {"x": w, "p": p, "f": ca.sum2(cost) / N, "g": ca.vec(g)}
    solver = ca.nlpsol("periodic_motion", "ipopt", nlp, IPOPT_OPTIONS)
    return Transcription(nodes=N, degree=d, block=block, ng=int(nlp["g"].numel()), solver=solver)


# The starts of :func:`lib.optimal.motion.periodic_motion` (states at the collocation times,
# inputs on the intervals) and the bounds of the decision vector.

def _force(body: Body, kind: str, R: float, Theta: float, t) -> tuple[np.ndarray, np.ndarray]:
    """The force that keeps C on the path, w = m C_d'' + c C_d' (N), and its rate (N/s), (..., 2)."""
    _, _, vx, vy, ax, ay, jx, jy = POSITIONS[kind](R, Theta, np.asarray(t, dtype=float))
    w = body.m * np.stack([ax, ay], -1) + body.c * np.stack([vx, vy], -1)
    dw = body.m * np.stack([jx, jy], -1) + body.c * np.stack([ax, ay], -1)
    return w, dw


@lru_cache(maxsize=16)
def _paper_heading(body: Body, kind: str, R: float, Theta: float) -> np.ndarray:
    """The paper's steady heading error p = phi - phi_d (rad) as complex Fourier coefficients
    c_k (k = 0 .. HARMONICS) of p(t) = c_0 + 2 Re sum_k c_k exp(i k Theta t) (cached: the book
    asks for it under several limits)."""
    p = paper_steady(body, kind, R, Theta).p[:-1]
    return np.fft.rfft(p)[:HARMONICS + 1] / len(p)


def _fourier(coeffs: np.ndarray, Theta: float, t) -> tuple[np.ndarray, np.ndarray]:
    """The series of :func:`_paper_heading` and its rate (rad/s) at times t (s)."""
    k = np.arange(len(coeffs))
    e = np.exp(1j * np.multiply.outer(np.asarray(t, dtype=float), k * Theta))
    mult = np.where(k == 0, 1.0, 2.0)
    return (mult * coeffs * e).sum(-1).real, (mult * 1j * k * Theta * coeffs * e).sum(-1).real


def _path_start(body, kind, R, Theta, t_col, t_mid, heading):
    """A start with C on the path: states at the collocation times ``t_col`` (nodes, d + 1),
    inputs at the interval mid-times ``t_mid`` (the force w of the path, its angle to the
    heading), the heading (phi, phi') given by ``heading(t)``."""
    ref = make(kind, R, Theta)
    z, dz, _ = ref.kinematics(t_col)
    phi, dphi = heading(t_col)
    X = np.concatenate([z[..., :2], phi[..., None], dz[..., :2], dphi[..., None]], axis=-1)
    w, _ = _force(body, kind, R, Theta, t_mid)
    u = np.stack([np.hypot(w[:, 0], w[:, 1]), wrap_angle(np.arctan2(w[:, 1], w[:, 0]) - heading(t_mid)[0])], -1)
    return X, u


def _start(name, body, kind, R, Theta, turns, t_col, t_mid, shift):
    """The (states, inputs) of a named start (see :func:`periodic_motion`): ``"paper"`` the
    paper's steady heading; ``"force"`` the heading along w = m C_d'' + c C_d' turned by
    ``shift`` (rad), continuous, with a linear drift added if w's winding over a period is not
    the path's turn n (never on the book's paths)."""
    T = 2 * np.pi / Theta
    ref = make(kind, R, Theta)
    if name == "paper":
        coeffs = _paper_heading(body, kind, R, Theta)

        def heading(t):
            p, dp = _fourier(coeffs, Theta, t)
            zd, dzd, _ = ref.kinematics(t)
            return zd[..., 2] + p, dzd[..., 2] + dp
        return _path_start(body, kind, R, Theta, t_col, t_mid, heading)
    tt = np.linspace(0.0, T, 257)
    w, _ = _force(body, kind, R, Theta, tt)
    ang = np.unwrap(np.arctan2(w[:, 1], w[:, 0]))
    slip = 2 * np.pi * (turns - round((ang[-1] - ang[0]) / (2 * np.pi))) / T

    def heading(t):
        w, dw = _force(body, kind, R, Theta, t)
        raw = np.arctan2(w[..., 1], w[..., 0])
        near = np.interp(t, tt, ang)            # the unwrapped branch; t lies in [0, T)
        phi = raw + 2 * np.pi * np.round((near - raw) / (2 * np.pi)) + slip * t + shift
        rate = (w[..., 0] * dw[..., 1] - w[..., 1] * dw[..., 0]) / (w ** 2).sum(-1) + slip
        return phi, rate
    return _path_start(body, kind, R, Theta, t_col, t_mid, heading)


def _bounds(tr, F_max, beta_max):
    lo = np.full((tr.nodes, tr.block), -np.inf)
    hi = np.full((tr.nodes, tr.block), np.inf)
    b = FREE_ANGLE if beta_max is None else beta_max
    lo[:, -2], hi[:, -2] = 0.0, np.inf if F_max is None else F_max
    lo[:, -1], hi[:, -1] = -b, b
    return lo.ravel(), hi.ravel()


def _clip(u, F_max, beta_max):
    b = FREE_ANGLE if beta_max is None else beta_max
    return np.stack([np.clip(u[:, 0], 0.0, np.inf if F_max is None else F_max), np.clip(u[:, 1], -b, b)], -1)


def _guess_start(g, t_col, t_mid):
    z, dz = g.state(t_col)
    F, beta = g.inputs(t_mid)
    return np.concatenate([z, dz], -1), np.stack([F, beta], -1)


def _max_error(motion, ref) -> float:
    """Largest |C - C_d| (m): DENSE samples per interval, the largest refined by a bounded search."""
    n = motion.nodes * DENSE
    t = np.arange(n) * (motion.period / n)

    def dist(tt):
        return np.linalg.norm(motion.state(tt)[0][..., :2] - ref.z(tt)[..., :2], axis=-1)

    d = dist(t)
    i = int(np.argmax(d))
    dt = motion.period / n
    res = minimize_scalar(lambda s: -float(dist(s)), bounds=(t[i] - dt, t[i] + dt), method="bounded",
                          options={"xatol": 1e-9 * motion.period})
    return max(float(d[i]), -float(res.fun))
