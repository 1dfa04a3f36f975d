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

from .control import wrap_angle
from .params import Body
from .symbolic import parameter_symbols

__all__ = [
    "RotationEquation", "derive_rotation_equation", "printed_eq33", "derive_eight_equation",
    "printed_eq37", "circle_equilibria", "circle_critical_radius", "circle_eigenvalues",
    "circle_jacobian", "circle_rotation_rhs", "circle_final_state", "circle_slipping_coexists",
    "steps_per_period", "reduced_rotation", "classify_samples", "sampled_range", "rotation_sweep", "eight_rotation_sweep",
    "eight_heading_fourier", "heading_series", "PAPER_HEADING_SERIES", "ENGINES", "corrected_p0",
    "printed_p0", "plot_fig5", "plot_circle_map", "ERRATA",
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
    return float(wrap_angle(gamma - math.asin(k))), float(wrap_angle(gamma + math.pi + math.asin(k)))


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


# ---------------------------------------------------------------- the reduced rotation ODE

_C = None


def _tableau():
    """Butcher tableau of the 8th-order Dormand-Prince method (scipy's ``DOP853``),
    used here with a fixed step so that every grid point lands on the same phases."""
    global _C
    if _C is None:
        from scipy.integrate import DOP853
        n = DOP853.n_stages
        _C = (np.array(DOP853.A[:n, :n]), np.array(DOP853.B), np.array(DOP853.C[:n]))
    return _C


def _shape(kind: str):
    """Unit reference (R = 1 m, theta = 1 rad/s) of ``kind``: with s = Theta t,
    x_d = R X(s), y_d = R Y(s), phi_d = H(s). Returns a function of s giving
    (X', Y', X'', Y'', H, H') and the winding of H per period (turns)."""
    from .trajectories import make

    ref = make(kind, 1.0, 1.0)

    def at(s):
        s = np.asarray(s, dtype=float)
        dz, ddz, z = ref.dz(s), ref.ddz(s), ref.z(s)
        return dz[..., 0], dz[..., 1], ddz[..., 0], ddz[..., 1], z[..., 2], dz[..., 2]

    winding = int(round((ref.z(2 * np.pi)[2] - ref.z(0.0)[2]) / (2 * np.pi)))
    return at, winding


def _check_grid(R, Theta):
    R = np.atleast_1d(np.asarray(R, dtype=float))
    Theta = np.atleast_1d(np.asarray(Theta, dtype=float))
    if R.ndim != 1 or Theta.ndim != 1:
        raise ValueError(f"R and Theta must be 1-D arrays (one grid point per pair), got shapes {R.shape}, {Theta.shape}")
    if R.size == 0:
        raise ValueError("R and Theta must not be empty")
    if R.shape != Theta.shape:
        raise ValueError(f"R and Theta must have equal length, got {R.size} and {Theta.size}")
    if not (np.all(np.isfinite(R)) and np.all(np.isfinite(Theta))):
        raise ValueError("R and Theta must be finite")
    if np.any(R <= 0):
        raise ValueError(f"R must be positive (m), got min {R.min()!r}")
    if np.any(Theta <= 0):
        raise ValueError(f"Theta must be positive (rad/s), got min {Theta.min()!r}")
    return R, Theta


def _coefficients(body: Body, R, Theta):
    """Coefficients of the rotation equation in the phase s = Theta t, w = dphi/ds:

        w' = -A w + B (Y' cos phi - X' sin phi) + C (Y'' cos phi - X'' sin phi),

    A = c_phi / (I Theta), B = a R c / (I Theta), C = a R m / I  (eq. (32) divided by I Theta^2)."""
    A = body.c_phi / (body.I * Theta)
    B = body.a * R * body.c / (body.I * Theta)
    C = body.a * R * body.m / body.I
    return A, B, C


def steps_per_period(body: Body, kind: str, R, Theta, h_lambda: float = 0.125) -> np.ndarray:
    """Fixed steps per reference period for each point: a power of two (>= 64)
    such that h Lambda <= ``h_lambda``, where Lambda = A + sqrt(B v_max + C a_max)
    bounds the moduli of the eigenvalues of the linearised equation (in s)."""
    at, _ = _shape(kind)
    s = np.linspace(0, 2 * np.pi, 721)
    X1, Y1, X2, Y2, _, _ = at(s)
    vmax, amax = np.hypot(X1, Y1).max(), np.hypot(X2, Y2).max()
    A, B, C = _coefficients(body, np.asarray(R, float), np.asarray(Theta, float))
    lam = A + np.sqrt(B * vmax + C * amax)
    need = 2 * np.pi * lam / h_lambda
    return np.maximum(64, 2 ** np.ceil(np.log2(need))).astype(int)


def reduced_rotation(body: Body, kind: str, R: float, Theta: float, periods: int, *, steps: int | None = None,
                     p0: float = 0.0, v0: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Integrate the reduced rotation equation (32) on the reference ``kind`` from
    p(0) = ``p0`` (rad), dp/dt(0) = ``v0`` (rad/s), p = phi - phi_d, for ``periods``
    reference periods. Returns (t (s), p (rad)) at every step (and t = 0).

    This is the exact closed loop (23), (25)-(26) when the position starts on the
    reference (the position errors then stay zero)."""
    R_, Th_ = _check_grid(R, Theta)
    n = int(steps or steps_per_period(body, kind, R_, Th_)[0])
    at, winding = _shape(kind)
    phi, w = _run(body, kind, R_, Th_, n, periods, np.array([p0]), np.array([v0]), record=True)
    s = np.arange(phi.shape[0]) * 2 * np.pi / n
    H = at(s)[4]
    return s / Theta, phi[:, 0] - H


def _forcing(kind: str, n: int):
    """Stage phases of one period and the unit reference there, for n steps per period."""
    Aa, Bb, Cc = _tableau()
    at, winding = _shape(kind)
    h = 2 * np.pi / n
    X1, Y1, X2, Y2, _, _ = at((np.arange(n)[:, None] + Cc[None, :]) * h)
    _, _, _, _, H, H1 = at(np.arange(1, n + 1) * h)
    return h, X1, Y1, X2, Y2, (H, H1), winding


def _period(phi, w, A, B, C, h, X1, Y1, X2, Y2):
    """One reference period of fixed DOP853 steps for all points; returns ((phi, w)
    at every step end, each of shape (n, N)), final phi, final w)."""
    Aa, Bb, Cc = _tableau()
    n, stages = X1.shape
    hA = Aa * h
    hB = Bb * h
    KP = np.empty((stages,) + phi.shape)
    KW = np.empty_like(KP)
    out = np.empty((n,) + phi.shape)
    out_w = np.empty_like(out)
    for j in range(n):
        for i in range(stages):
            if i == 0:
                ps, ws = phi, w
            else:
                ps = phi + hA[i, :i] @ KP[:i]
                ws = w + hA[i, :i] @ KW[:i]
            KP[i] = ws
            KW[i] = (B * Y1[j, i] + C * Y2[j, i]) * np.cos(ps) - (B * X1[j, i] + C * X2[j, i]) * np.sin(ps) - A * ws
        phi = phi + hB @ KP
        w = w + hB @ KW
        out[j] = phi
        out_w[j] = w
    return (out, out_w), phi, w


def _period_compiled_impl(phi, w, A, B, C, h, X1, Y1, X2, Y2, hA, hB, out, out_w):
    """Same scheme as :func:`_period`, one point at a time in compiled loops."""
    n, stages = X1.shape
    for q in _prange(phi.size):
        kp = np.empty(stages)
        kw = np.empty(stages)
        f, v, a_, b_, c_ = phi[q], w[q], A[q], B[q], C[q]
        for j in range(n):
            for i in range(stages):
                ps, ws = f, v
                for l in range(i):
                    ps += hA[i, l] * kp[l]
                    ws += hA[i, l] * kw[l]
                kp[i] = ws
                kw[i] = ((b_ * Y1[j, i] + c_ * Y2[j, i]) * math.cos(ps)
                         - (b_ * X1[j, i] + c_ * X2[j, i]) * math.sin(ps) - a_ * ws)
            for i in range(stages):
                f += hB[i] * kp[i]
                v += hB[i] * kw[i]
            out[j, q] = f
            out_w[j, q] = v
        phi[q], w[q] = f, v


_COMPILED = None


def _prange(n):  # the plain-Python stand-in; rebound to numba.prange before compiling
    return range(n)


def _period_compiled(phi, w, A, B, C, h, X1, Y1, X2, Y2):
    """:func:`_period` compiled with numba (the default engine; see the benchmark)."""
    global _COMPILED, _prange
    if _COMPILED is None:
        import numba

        _prange = numba.prange
        _COMPILED = numba.njit(cache=True, parallel=True)(_period_compiled_impl)
    Aa, Bb, _ = _tableau()
    phi, w = np.array(phi, dtype=float), np.array(w, dtype=float)
    out = np.empty((X1.shape[0], phi.size))
    out_w = np.empty_like(out)
    _COMPILED(phi, w, np.ascontiguousarray(A, float), np.ascontiguousarray(B, float),
              np.ascontiguousarray(C, float), h, X1, Y1, X2, Y2, Aa * h, Bb * h, out, out_w)
    return (out, out_w), phi, w


ENGINES = {"numba": _period_compiled, "numpy": _period}


def _initial(kind, Theta, p0, v0):
    at, _ = _shape(kind)
    _, _, _, _, H0, H10 = at(0.0)
    return H0 + p0, H10 + v0 / Theta


def _run(body, kind, R, Theta, n, periods, p0, v0, record=False):
    """Fixed-step DOP853 in s for all points at once; with ``record`` the states at every step."""
    h, X1, Y1, X2, Y2, H, winding = _forcing(kind, n)
    A, B, C = _coefficients(body, R, Theta)
    phi, w = _initial(kind, Theta, p0, v0)
    outs = [phi[None].copy()]
    for _ in range(periods):
        (out, _), phi, w = _period(phi, w, A, B, C, h, X1, Y1, X2, Y2)
        outs.append(out)
    return np.concatenate(outs), w


def classify_samples(P: np.ndarray, tol: float = 1e-9, dP: np.ndarray | None = None) -> dict:
    """Classify the steady state from the rotation error sampled over the last periods.

    ``P`` has shape (L_max + 1, N, n): for N points, the last L_max + 1 reference
    periods of p (rad) at n equally spaced phases each (oldest first). For each lag
    L = 1..L_max the defect is d_L = max_j |p_j - p_{j-L periods} - 2 pi k_L|, with
    k_L the whole number of turns slipped in L periods. The smallest L with
    d_L <= ``tol`` is the period (in reference periods); k_L = 0 makes the point
    ``periodic``, k_L != 0 ``slipping``; if no lag qualifies it is ``irregular``
    (the smallest defect is reported). Returns arrays: regime, period, slip
    (turns per reference period), defect, range (max - min of p over the last
    ``period`` periods; with the phase derivatives ``dP`` = dp/ds at the same
    samples, the extremes are refined by cubic Hermite interpolation, see
    :func:`sampled_range`).
    """
    P = np.asarray(P, dtype=float)
    if P.ndim != 3 or P.shape[0] < 2 or P.shape[2] < 1:
        raise ValueError(f"P must have shape (L_max + 1 >= 2, N, n >= 1), got {P.shape}")
    Lmax, N = P.shape[0] - 1, P.shape[1]
    last = P[-1]
    defects = np.empty((Lmax, N))
    turns = np.empty((Lmax, N))
    for L in range(1, Lmax + 1):
        d = last - P[-1 - L]
        k = np.round(d[:, -1] / (2 * np.pi))
        turns[L - 1] = k
        defects[L - 1] = np.abs(d - 2 * np.pi * k[:, None]).max(axis=1)
    ok = defects <= tol
    any_ok = ok.any(axis=0)
    Lidx = np.where(any_ok, ok.argmax(axis=0), defects.argmin(axis=0))
    cols = np.arange(N)
    k = turns[Lidx, cols]
    period = Lidx + 1
    regime = np.where(~any_ok, "irregular", np.where(k == 0, "periodic", "slipping"))
    rng = np.empty(N)
    for L in np.unique(period):
        sel = period == L
        window = P[-L:, sel, :].transpose(1, 0, 2).reshape(sel.sum(), -1)
        dwin = None if dP is None else dP[-L:, sel, :].transpose(1, 0, 2).reshape(sel.sum(), -1)
        rng[sel] = sampled_range(window, cyclic=(k[sel] == 0), dy=dwin, h=2 * np.pi / P.shape[2])
    return dict(regime=regime, period=period, slip=k / period, defect=defects[Lidx, cols], range=rng)


def sampled_range(y, cyclic=True, dy=None, h: float = 1.0) -> np.ndarray:
    """max - min of each row of ``y`` (samples at equal phase steps ``h``).

    Without ``dy`` the extreme samples are refined by the parabola through them
    and their neighbours (error O(h^3)); with the derivatives ``dy`` (per unit
    phase) at the samples, by the cubic Hermite interpolant on the two
    intervals beside each extreme sample (error O(h^4)), so that the range is
    that of the continuous signal, not of its sampling. ``cyclic`` (per row) lets
    neighbours wrap around, as for whole periods of a periodic signal;
    otherwise extremes at the ends are not refined."""
    y = np.atleast_2d(np.asarray(y, dtype=float))
    n = y.shape[1]
    if n < 3:
        return y.max(axis=1) - y.min(axis=1)
    cyclic = np.broadcast_to(np.asarray(cyclic, bool), y.shape[:1])
    rows = np.arange(y.shape[0])

    def parabola(j, sign):
        ym, y0, yp = y[rows, (j - 1) % n], y[rows, j], y[rows, (j + 1) % n]
        curv = ym - 2 * y0 + yp
        ok = (cyclic | ((j > 0) & (j < n - 1))) & (sign * curv < 0)
        with np.errstate(divide="ignore", invalid="ignore"):
            val = y0 - (ym - yp) ** 2 / (8 * curv)
        return np.where(ok, val, y0)

    def hermite(j, sign):
        best = y[rows, j] * sign
        for a in (j - 1, j):
            b = a + 1
            ok = cyclic | ((a >= 0) & (b <= n - 1))
            a, b = a % n, b % n
            y0, y1 = y[rows, a] * sign, y[rows, b] * sign
            d0, d1 = dy[rows, a] * h * sign, dy[rows, b] * h * sign
            c1, c2, c3 = d0, 3 * (y1 - y0) - 2 * d0 - d1, 2 * (y0 - y1) + d0 + d1
            disc = np.maximum(c2**2 - 3 * c1 * c3, 0.0)
            for root in ((-c2 + np.sqrt(disc)), (-c2 - np.sqrt(disc))):
                with np.errstate(divide="ignore", invalid="ignore"):
                    t = np.where(np.abs(c3) > 1e-300, root / (3 * c3), -c1 / (2 * c2))
                inside = ok & np.isfinite(t) & (t > 0) & (t < 1)
                t = np.where(inside, t, 0.0)
                val = y0 + t * (c1 + t * (c2 + t * c3))
                best = np.where(inside, np.maximum(best, val), best)
        return best * sign

    if dy is None:
        return parabola(y.argmax(axis=1), 1) - parabola(y.argmin(axis=1), -1)
    dy = np.atleast_2d(np.asarray(dy, dtype=float))
    return hermite(y.argmax(axis=1), 1) - hermite(y.argmin(axis=1), -1)


def rotation_sweep(body: Body, kind: str, R, Theta, *, p0=0.0, v0=0.0, tol: float = 1e-9,
                   min_periods: int = 4, max_periods: int = 200, max_lag: int = 4,
                   h_lambda: float = 0.125, steps: int | None = None, engine: str = "numba") -> pd.DataFrame:
    """Steady state of the rotation error p = phi - phi_d on the reference ``kind``
    (``"eight"`` or ``"circle"``) for every grid point (R_i, Theta_i), started on the
    reference with p(0) = ``p0`` (rad) and dp/dt(0) = ``v0`` (rad/s) (scalars or arrays).

    All points are integrated together (numpy-vectorised over points), by a fixed-step
    8th-order Dormand-Prince scheme in the phase s = Theta t, so every point covers
    the same number of reference periods, with a power-of-two number of steps per
    period (:func:`steps_per_period`, or ``steps``). ``engine`` is ``"numba"``
    (compiled loops, the default) or ``"numpy"`` (vectorised over points; same
    scheme, same results to rounding, slower: see ``benchmarks/bench_eight_sweep.py``). After each period from
    ``min_periods`` on, :func:`classify_samples` is applied to the last ``max_lag + 1``
    periods; a point whose defect is <= ``tol`` (rad) is finished, the others go on
    to at most ``max_periods``.

    Returns a DataFrame, one row per point, in order: R (m), Theta (rad/s), range
    (rad), regime, period (reference periods), slip (turns per period), defect
    (rad, the convergence measure), periods (integrated), steps (per period).
    """
    if kind not in ("eight", "circle"):
        raise ValueError(f"kind must be 'eight' or 'circle', got {kind!r}")
    if not isinstance(body, Body):
        raise TypeError(f"body must be a lib.params.Body, got {type(body).__name__}")
    R, Theta = _check_grid(R, Theta)
    N = R.size
    p0 = np.broadcast_to(np.asarray(p0, dtype=float), (N,)).copy()
    v0 = np.broadcast_to(np.asarray(v0, dtype=float), (N,)).copy()
    if not (np.all(np.isfinite(p0)) and np.all(np.isfinite(v0))):
        raise ValueError("initial p0 and v0 must be finite")
    for name, v, lo in (("min_periods", min_periods, 1), ("max_lag", max_lag, 1)):
        if not isinstance(v, (int, np.integer)) or v < lo:
            raise ValueError(f"{name} must be an integer >= {lo}, got {v!r}")
    if not isinstance(max_periods, (int, np.integer)) or max_periods < max(min_periods, max_lag + 1):
        raise ValueError(f"max_periods must be an integer >= min_periods and > max_lag, got {max_periods!r}")
    if engine not in ENGINES:
        raise ValueError(f"engine must be one of {sorted(ENGINES)}, got {engine!r}")
    step_period = ENGINES[engine]
    if not (np.isfinite(tol) and tol > 0):
        raise ValueError(f"tol must be positive, got {tol!r}")
    n_pts = (np.full(N, int(steps)) if steps is not None
             else steps_per_period(body, kind, R, Theta, h_lambda))
    cols = {k: np.empty(N, dtype=object if k == "regime" else float)
            for k in ("range", "regime", "period", "slip", "defect", "periods")}
    for n in np.unique(n_pts):
        idx = np.flatnonzero(n_pts == n)
        h, X1, Y1, X2, Y2, (H, H1), winding = _forcing(kind, int(n))
        A, B, C = _coefficients(body, R[idx], Theta[idx])
        phi, w = _initial(kind, Theta[idx], p0[idx], v0[idx])
        P = np.zeros((max_lag + 1, idx.size, int(n)))
        dP = np.zeros_like(P)
        for k in range(1, max_periods + 1):
            (out, out_w), phi, w = step_period(phi, w, A, B, C, h, X1, Y1, X2, Y2)
            P, dP = np.roll(P, -1, axis=0), np.roll(dP, -1, axis=0)
            P[-1] = (out - H[:, None] - 2 * np.pi * winding * (k - 1)).T
            dP[-1] = (out_w - H1[:, None]).T
            if k < max(min_periods, max_lag + 1) and k < max_periods:
                continue
            c = classify_samples(P[-(min(k, max_lag) + 1):], tol, dP[-(min(k, max_lag) + 1):])
            done = (c["defect"] <= tol) | (k == max_periods)
            for key in ("range", "regime", "period", "slip", "defect"):
                cols[key][idx[done]] = c[key][done]
            cols["periods"][idx[done]] = k
            keep = ~done
            if not keep.any():
                break
            idx, phi, w, A, B, C = idx[keep], phi[keep], w[keep], A[keep], B[keep], C[keep]
            P, dP = P[:, keep], dP[:, keep]
    frame = pd.DataFrame({"R": R, "Theta": Theta, **cols, "steps": n_pts})
    return frame.astype({"period": int, "periods": int, "range": float, "slip": float, "defect": float})


def eight_rotation_sweep(body: Body, R, Theta, **options) -> pd.DataFrame:
    """Fig. 5: steady-state range of the rotation error on the eight (28), started on
    the reference, for each pair (R_i (m), Theta_i (rad/s)). See :func:`rotation_sweep`
    for the options and the columns."""
    return rotation_sweep(body, "eight", R, Theta, **options)


# ---------------------------------------------------------------- the circle: global behaviour

def _circle_arrays(body, R, theta, *arrays):
    if not isinstance(body, Body):
        raise TypeError(f"body must be a lib.params.Body, got {type(body).__name__}")
    out = np.broadcast_arrays(*(np.atleast_1d(np.asarray(a, dtype=float)) for a in (R, theta) + arrays))
    out = [np.ravel(a).copy() for a in out]
    if out[0].size == 0:
        raise ValueError("empty input arrays")
    if not all(np.all(np.isfinite(a)) for a in out):
        raise ValueError("inputs must be finite")
    if np.any(out[0] <= 0) or np.any(out[1] <= 0):
        raise ValueError("R (m) and theta (rad/s) must be positive")
    return out


def circle_final_state(body: Body, R, theta, p0=0.0, v0=0.0, t_end: float = 300.0,
                       t_max: float = 5000.0, rtol: float = 1e-9, atol: float = 1e-9) -> pd.DataFrame:
    """Integrate the corrected (33) from p(0) = ``p0`` (rad), p'(0) = ``v0`` (rad/s)
    for all broadcast (R, theta, p0, v0) together (one stacked ``solve_ivp`` per
    stage) and classify the end state.

    ``settled``: within 1e-4 of the stable equilibrium (mod 2 pi) and at rest;
    ``slipping``: p changed by more than a whole turn over the second half of
    the run; otherwise the run is extended, doubling its length, up to ``t_max``
    s, after which the point is ``undecided``. Returns a DataFrame with R, theta,
    p0, v0, p_end, v_end, t_end (s) and regime."""
    from scipy.integrate import solve_ivp

    R, theta, p0, v0 = _circle_arrays(body, R, theta, p0, v0)
    N = R.size
    ps = np.full(N, np.nan)
    for i in range(N):
        try:
            ps[i] = circle_equilibria(body, float(R[i]), float(theta[i]))[0]
        except ValueError:
            pass
    p, v = p0.copy(), v0.copy()
    t_used = np.zeros(N)
    regime = np.full(N, "undecided", dtype=object)
    todo = np.arange(N)
    span = float(t_end)
    while todo.size and t_used[todo[0]] + span <= t_max + 1e-9:
        Rr, th = R[todo], theta[todo]
        n = todo.size

        def rhs(t, y):
            return np.concatenate([y[n:], circle_rotation_rhs(body, Rr, th, y[:n], y[n:])])

        sol = solve_ivp(rhs, (0.0, span), np.concatenate([p[todo], v[todo]]), method="DOP853",
                        rtol=rtol, atol=atol, t_eval=[span / 2, span])
        mid, p[todo], v[todo] = sol.y[:n, 0], sol.y[:n, -1], sol.y[n:, -1]
        t_used[todo] += span
        gap = np.abs(np.remainder(p[todo] - ps[todo] + np.pi, 2 * np.pi) - np.pi)
        settled = (gap < 1e-4) & (np.abs(v[todo]) < 1e-4)
        slipping = ~settled & (np.abs(p[todo] - mid) > 2 * np.pi)
        regime[todo[settled]] = "settled"
        regime[todo[slipping]] = "slipping"
        todo = todo[~(settled | slipping)]
        span *= 2
    return pd.DataFrame({"R": R, "theta": theta, "p0": p0, "v0": v0, "p_end": p, "v_end": v,
                         "t_end": t_used, "regime": regime.astype(str)})


def circle_slipping_coexists(body: Body, R, theta, t_end: float = 400.0) -> np.ndarray:
    """Whether a slipping (running) motion of the corrected (33) coexists with the
    stable equilibrium, for each broadcast (R (m), theta (rad/s)) with R > R_crit.

    Test: follow the branch of the saddle's unstable manifold that leaves towards
    decreasing p (the direction of the constant drag torque -c_phi theta). If it
    passes the next saddle, p_saddle - 2 pi, the motion runs on for ever and a
    running periodic orbit exists; if it falls into the stable equilibrium, every
    motion not on the saddle's stable manifold settles. (This is the homoclinic
    bifurcation of the damped driven pendulum, Strogatz 2015, Sec. 8.5.)
    """
    from scipy.integrate import solve_ivp

    R, theta = _circle_arrays(body, R, theta)
    N = R.size
    ps = np.empty(N)
    y0 = np.empty(2 * N)
    for i in range(N):
        _, sad = circle_equilibria(body, float(R[i]), float(theta[i]))
        J = circle_jacobian(body, float(R[i]), float(theta[i]), sad)
        lam, vec = np.linalg.eig(J)
        u = np.real(vec[:, np.argmax(lam.real)])
        u = -u if u[0] > 0 else u
        ps[i] = sad
        y0[i], y0[N + i] = sad + 1e-6 * u[0] / np.hypot(*u), 1e-6 * u[1] / np.hypot(*u)

    def rhs(t, y):
        p, v = y[:N], y[N:]
        return np.concatenate([v, circle_rotation_rhs(body, R, theta, p, v)])

    sol = solve_ivp(rhs, (0.0, t_end), y0, method="DOP853", rtol=1e-10, atol=1e-12, dense_output=True)
    pmin = np.full(N, np.inf)
    for chunk in np.array_split(np.linspace(0, t_end, 40001), 10):
        pmin = np.minimum(pmin, sol.sol(chunk)[:N].min(axis=1))
    return pmin < ps - 2 * np.pi


# ---------------------------------------------------------------- the eight's tangent angle

#: The paper's 3-term approximation of the eight's tangent angle (Sec. 6):
#: phi_d ~ pi - 2.26 cos s - 0.24 cos 3s + 0.16 cos 5s, s = Theta t.
PAPER_HEADING_SERIES = {0: math.pi, 1: -2.26, 3: -0.24, 5: 0.16}


def eight_heading_fourier(n_harmonics: int = 9, n_samples: int = 4096) -> np.ndarray:
    """Cosine Fourier coefficients a_0..a_{n_harmonics} of the eight's continuous
    tangent angle phi_d(s) = pi + atan2(-cos s, -cos 2s) (rad), s = Theta t, by FFT.

    phi_d is even in s, so phi_d = a_0 + sum_k a_k cos(k s); the half-period
    symmetry phi_d(s + pi) - pi = -(phi_d(s) - pi) leaves only odd k."""
    if not isinstance(n_harmonics, (int, np.integer)) or n_harmonics < 0:
        raise ValueError(f"n_harmonics must be a non-negative integer, got {n_harmonics!r}")
    at, _ = _shape("eight")
    s = 2 * np.pi * np.arange(n_samples) / n_samples
    H = at(s)[4]
    c = np.fft.rfft(H) / n_samples
    a = 2 * c.real
    a[0] = c[0].real
    return a[: n_harmonics + 1]


def heading_series(coefficients: dict, s) -> np.ndarray:
    """Evaluate a cosine series {k: a_k} at phases s (rad)."""
    s = np.asarray(s, dtype=float)
    return sum(a * np.cos(k * s) for k, a in coefficients.items())


# ---------------------------------------------------------------- errata (Sec. 6)

def corrected_p0(k: int):
    """Corrected closed form of the equilibria of (33), symbolic:
    p0^(k) = k pi + arctan(m Theta / c) - arcsin((-1)^k c_phi / (a R sqrt(m^2 Theta^2 + c^2)))."""
    s = derive_rotation_equation().params
    m, a, c, cphi, R, Th = (s[n] for n in ("m", "a", "c", "c_phi", "R", "Theta"))
    return k * sp.pi + sp.atan(m * Th / c) - sp.asin((-1) ** k * cphi / (a * R * sp.sqrt(m**2 * Th**2 + c**2)))


def printed_p0(k: int, garbled: bool = True):
    """The printed p0^(k) = k pi - arctan(m Theta/c) - arcsin(c_phi / (a c R cos(k pi) sqrt(m^2 Theta^2/(c+1)))).
    With ``garbled=False`` the square root reads sqrt(m^2 Theta^2 / c^2 + 1), presumably what was meant."""
    s = derive_rotation_equation().params
    m, a, c, cphi, R, Th = (s[n] for n in ("m", "a", "c", "c_phi", "R", "Theta"))
    root = sp.sqrt(m**2 * Th**2 / (c + 1)) if garbled else sp.sqrt(m**2 * Th**2 / c**2 + 1)
    return k * sp.pi - sp.atan(m * Th / c) - sp.asin(cphi / (a * c * R * sp.cos(k * sp.pi) * root))


def _table_values():
    s = derive_rotation_equation().params
    b = Body()
    return {s["m"]: b.m, s["I"]: b.I, s["a"]: b.a, s["c"]: b.c, s["c_phi"]: b.c_phi, s["R"]: 2.0,
            s["Theta"]: sp.pi / 4}


def _check_eq33():
    from .errata import Verdict

    eq = derive_rotation_equation()
    diff = sp.simplify(printed_eq33() - eq.rhs)
    s = eq.params
    corrected = printed_eq33() + 2 * s["a"] * s["m"] * s["Theta"] ** 2 * s["R"] / s["I"] * sp.cos(eq.p)
    return Verdict(printed_holds=diff == 0, corrected_holds=sp.simplify(corrected - eq.rhs) == 0,
                   detail=f"printed minus derived v_p' = {sp.sstr(diff)}")


def _check_p0():
    from .errata import Verdict

    eq = derive_rotation_equation()
    at_rest = eq.rhs.subs(eq.v_p, 0)
    corrected_ok = all(sp.simplify(sp.expand_trig(at_rest.subs(eq.p, corrected_p0(k)))) == 0 for k in (0, 1))
    vals = _table_values()
    res_printed = [float(sp.N(at_rest.subs(eq.p, printed_p0(k)).subs(vals))) for k in (0, 1)]
    res_corr = [float(sp.N(at_rest.subs(eq.p, corrected_p0(k)).subs(vals))) for k in (0, 1)]
    return Verdict(printed_holds=max(abs(r) for r in res_printed) < 1e-9,
                   corrected_holds=corrected_ok and max(abs(r) for r in res_corr) < 1e-12,
                   detail=(f"residual of the derived (33) at rest, Table values, k = 0, 1: printed p0 "
                           f"{res_printed[0]:.3g}, {res_printed[1]:.3g} rad/s^2; corrected p0 zero symbolically"))


def _check_eq37():
    from .errata import Verdict

    _, torque, _ = derive_eight_equation()
    diff = sp.simplify(sp.expand(printed_eq37(True) - torque))
    return Verdict(printed_holds=diff == 0,
                   corrected_holds=sp.simplify(sp.expand(printed_eq37(False) - torque)) == 0,
                   detail=f"printed minus derived right side is nonzero: {sp.sstr(sp.factor(diff))}")


def _check_fourier_digits():
    """The printed coefficients of the tangent angle's 3-term series against the
    computed ones rounded to the printed two decimals, compared as whole hundredths."""
    from .errata import Verdict

    a = eight_heading_fourier(5)
    computed = {k: int(round(100 * a[k])) for k in (1, 3, 5)}
    printed = {k: int(round(100 * PAPER_HEADING_SERIES[k])) for k in (1, 3, 5)}
    corrected = {1: -226, 3: -23, 5: 16}
    return Verdict(printed_holds=printed == computed, corrected_holds=corrected == computed,
                   detail=(f"computed a1, a3, a5 = {a[1]:.4f}, {a[3]:.4f}, {a[5]:.4f}; in hundredths "
                           f"{computed}, printed {printed}"))


def _errata():
    from .errata import Erratum

    sec = "chapters/05_stability"
    return [
        Erratum(
            key="eq33-cos-sign",
            where="Eq. (33), the $\\cos p$ term of $\\dot v_p$",
            printed=r"$-\frac{am\Theta^2R}{I}\cos p$",
            corrected=r"$+\frac{am\Theta^2R}{I}\cos p$",
            verified_by="sympy derivation of (33) from (4), (25)-(26), (27) "
                        "(`lib.stability.derive_rotation_equation`); simulation converges to the "
                        "corrected p0 (`tests/test_stability.py::test_simulated_circle_converges_to_stable_equilibrium`)",
            section=sec, check=_check_eq33),
        Erratum(
            key="eq33-p0",
            where="Sec. 6, the equilibria $p_0^{(k)}$ of (33)",
            printed=r"$k\pi - \arctan\frac{m\Theta}{c} - \arcsin\left(c_\varphi / acR\cos k\pi\sqrt{\frac{m^2\Theta^2}{c+1}}\right)$",
            corrected=r"$k\pi + \arctan\frac{m\Theta}{c} - \arcsin\frac{(-1)^k c_\varphi}{aR\sqrt{m^2\Theta^2+c^2}}$",
            verified_by="sympy substitution into the derived (33) (`lib.stability.corrected_p0`); "
                        "`tests/test_stability.py::test_equilibria_solve_derived_equation`",
            section=sec, check=_check_p0),
        Erratum(
            key="eq37-bracket",
            where="Eq. (37), right side",
            printed=r"$a\Theta R((c\cos\Theta t - m\Theta\sin\Theta t)\cos\varphi - (c\cos 2\Theta t - 2m\Theta\sin 2\Theta t))\sin\varphi$",
            corrected=r"$a\Theta R((c\cos\Theta t - m\Theta\sin\Theta t)\cos\varphi - (c\cos 2\Theta t - 2m\Theta\sin 2\Theta t)\sin\varphi)$",
            verified_by="sympy derivation of (37) from (32) and (28) (`lib.stability.derive_eight_equation`); "
                        "the reduced equation against the full closed loop "
                        "(`tests/test_stability.py::test_reduced_rotation_matches_full_closed_loop`)",
            section=sec, check=_check_eq37),
        Erratum(
            key="fourier-a3",
            where="Sec. 6, the 3-term series of the eight's tangent angle",
            printed=r"$-0.24\cos 3\Theta t$",
            corrected=r"$-0.23\cos 3\Theta t$ (the computed $a_3$ rounded to two decimals, as $a_1$ and $a_5$ are)",
            verified_by="FFT of the continuous tangent angle (`lib.stability.eight_heading_fourier`), "
                        "compared with the printed digits as whole hundredths "
                        "(`lib.stability._check_fourier_digits`)",
            section=sec, check=_check_fourier_digits),
    ]


ERRATA = _errata()


# ---------------------------------------------------------------- figures of Chapter 5

def plot_fig5(frame: pd.DataFrame, ax=None):
    """Fig. 5: steady-state range (rad) of the rotation error over (R, Theta), one
    square per periodic point; slipping points as empty circles, irregular as crosses.
    Returns the figure."""
    import matplotlib.pyplot as plt

    if ax is None:
        fig, ax = plt.subplots(figsize=(7, 5))
    fig = ax.figure
    per = frame[frame.regime == "periodic"]
    sc = ax.scatter(per.R, per.Theta, c=per["range"], marker="s", s=22, cmap="viridis", linewidths=0)
    fig.colorbar(sc, ax=ax, label="range of $p$ (rad)")
    slip = frame[frame.regime == "slipping"]
    ax.scatter(slip.R, slip.Theta, facecolors="none", edgecolors="C3", s=30, label="slipping")
    irr = frame[frame.regime == "irregular"]
    ax.scatter(irr.R, irr.Theta, marker="x", color="k", s=14, lw=0.8, label="irregular")
    ax.set(xlabel="R (m)", ylabel=r"$\Theta$ (rad/s)")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=2)
    return fig


def plot_circle_map(frame: pd.DataFrame, body: Body, coexists=None, ax=None):
    """Where the circle's rotation error settles or slips (``frame`` from
    :func:`circle_final_state`), with the analytic boundary R_crit(theta) of (36)
    and, if given, the points where slipping coexists with the stable equilibrium."""
    import matplotlib.pyplot as plt

    if ax is None:
        fig, ax = plt.subplots(figsize=(7, 5))
    for regime, style in (("settled", dict(color="C0", marker=".")), ("slipping", dict(color="C3", marker="x"))):
        sel = frame[frame.regime == regime]
        ax.scatter(sel.R, sel.theta, s=12, label=f"{regime} (from the reference)", **style)
    if coexists is not None:
        sel = frame[np.asarray(coexists, bool)]
        ax.scatter(sel.R, sel.theta, s=60, facecolors="none", edgecolors="k",
                   label="slipping coexists with $p_s$")
    th = np.linspace(frame.theta.min(), frame.theta.max(), 300)
    ax.plot([circle_critical_radius(body, x) for x in th], th, "k", lw=2, label=r"$R_{crit}(\theta)$, (36)")
    ax.set(xlabel="R (m)", ylabel=r"$\theta$ (rad/s)")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=2, fontsize=8)
    return ax.figure
