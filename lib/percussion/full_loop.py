"""The full closed loop under the law for P on Fig. 5's grid: seven states, from the paper's start.

Chapter 7 decides Fig. 5 under the law for P on the zero dynamics alone (P exactly on the path,
:mod:`lib.percussion.sweep`). Here the whole loop runs instead: C's configuration and rate and the
thrust state xi (7 states, :func:`lib.percussion.law.closed_loop_rates` without limits), from the
paper's start (C at (1, 0) m, phi = pi/2, at rest, xi = 0.5 N), P asked to follow the eight (28).
In the coordinates (e, e', e'', phi) the loop is a cascade: P's error obeys the designed linear
equation and drives the first-order heading, so the loop's attractor is expected to be the zero
dynamics' orbit with P on the path; this module computes it rather than assuming it.

Each point runs on its own compiled fixed-step RK4 (:class:`FullLoopMap`): the heading's
relaxation rate |v| / eps (v = P'' + k P') reaches hundreds per second at the grid's far corner
and, from the paper's start, during the error's transient at every point; a point's step count a
period is chosen so that h times the largest rate (the heading's bound, :func:`steps_per_period`,
plus the error equation's fastest root) stays below ``h_rate`` (0.25 by default; RK4's real
stability bound is 2.79). Measured on the 10 x 10 sample, at 2 some runs blow up numerically, at 1
the orbits' headings are off by 0.02 rad, at 0.5 by 2e-4 rad, at 0.25 and 0.125 by 9e-5 rad (the
zero dynamics' own resolution). The verdict is the book's
orbit procedure (:func:`lib.dynamics.verdicts.find_orbits`: lag candidates, Newton on
P^k(x) = x + 2 pi n e_phi with a difference Jacobian, Floquet multipliers, the reach test), as
:func:`lib.optimal.loop.loop_verdict` applies it to one loop; a point without an orbit reached is
``undecided`` (no Lyapunov exponent is computed here, so ``chaotic`` is never said). ``held`` is
:func:`lib.dynamics.verdicts.held`: periodic, the heading not lost, P tracked (its error on the
orbit within ``position_tol`` R).
"""

from __future__ import annotations

import math

import numba
import numpy as np
import pandas as pd

from ..allocation import Limits
from ..angles import wrap_angle
from ..dynamics import verdicts as dv
from ..machinery import checks
from ..params import PAPER_DZ0, PAPER_Z0, Body, Gains
from ..rotation.verdicts import FIG5_GRID
from ..trajectories import eight_kinematics
from .law import error_polynomial
from .point import centre_of_percussion, lateral_drag_speed, point_accel, point_state

__all__ = ["FULL_LOOP_OPTIONS", "THRUST0", "MAX_STEPS", "grid_sample", "compiled_rates", "limited_field",
           "steps_per_period", "start_error", "FullLoopMap", "full_loop_verdicts", "compare_with_zero_dynamics"]

#: the thrust state at the start (N), as Chapter 7 starts the law for P
THRUST0 = 0.5

#: the procedure's options (state units m, rad, m/s, rad/s, N); periods in rounds of ``chunk``
#: up to ``max_periods``, searched for an orbit of period <= ``max_period`` after each round;
#: ``h_rate`` the bound on h times the largest rate; ``position_tol`` the tracking tolerance in units of R
FULL_LOOP_OPTIONS = dict(chunk=6, max_periods=30, max_period=4, candidate_tol=1e-3, newton_tol=1e-8,
                         reach_tol=1e-4, reach_floor=1e-8, fd_step=1e-6, newton_iter=12, h_rate=0.25,
                         min_steps=64, position_tol=0.1)
#: the most RK4 steps a period a point may need (:func:`steps_per_period`; the Fig. 5 grid needs
#: at most 6808 at the default h_rate)
MAX_STEPS = 2**16
_MINIMA = dict(chunk=3, max_periods=3, max_period=1, newton_iter=1, min_steps=8)


@numba.njit(cache=True)
def _field(t, y, out, R, Th, p, q, fc, ac, taw, circle):
    """The 7 states' rates (out, in place) and the applied F (N) on the eight (28) at (R, Th) or the circle
    (27); model p = (m, I, a, c, c_phi, s_P, eps, k2x, k1x, k0x, k2y, k1y, k0y), plant q = (m, I, a, c, c_phi);
    cap ``fc`` (N), angle limit ``ac`` (rad), T_aw ``taw`` (s, 0: none) of law.closed_loop_rates."""
    m, I, a, c, cphi, s, eps, k = p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[3] / p[0]
    st = Th * t
    s1, c1, s2, c2 = math.sin(st), math.cos(st), math.sin(2 * st), math.cos(2 * st)
    if circle:
        Pd, dPd = (R * c1, R * s1), (-R * Th * s1, R * Th * c1)
        ddPd, dddPd = (-R * Th * Th * c1, -R * Th * Th * s1), (R * Th ** 3 * s1, -R * Th ** 3 * c1)
    else:
        Pd, dPd = (0.5 * R * s2, R * s1), (R * Th * c2, R * Th * c1)
        ddPd, dddPd = (-2 * R * Th * Th * s2, -R * Th * Th * s1), (-4 * R * Th ** 3 * c2, -R * Th ** 3 * c1)
    phi, om, xi = y[2], y[5], y[6]
    cp, sp = math.cos(phi), math.sin(phi)
    P = (y[0] + s * cp, y[1] + s * sp)
    dP = (y[3] - s * sp * om, y[4] + s * cp * om)
    along = xi / m - s * om * om
    ddP = (along * cp - eps * om * sp - k * dP[0], along * sp + eps * om * cp - k * dP[1])
    g0 = dddPd[0] + p[7] * (ddPd[0] - ddP[0]) + p[8] * (dPd[0] - dP[0]) + p[9] * (Pd[0] - P[0]) + k * ddP[0]
    g1 = dddPd[1] + p[10] * (ddPd[1] - ddP[1]) + p[11] * (dPd[1] - dP[1]) + p[12] * (Pd[1] - P[1]) + k * ddP[1]
    r1 = g0 * cp + g1 * sp + eps * om * om
    r2 = -g0 * sp + g1 * cp - along * om
    dom = r2 / eps
    u2 = (I * dom + cphi * om) / a
    F = math.hypot(xi, u2)
    clipped = F > fc or (ac < math.pi and abs(math.atan2(u2, xi)) > ac)   # no angle to take without a limit
    if clipped:
        F, beta = min(F, fc), min(max(math.atan2(u2, xi), -ac), ac)
        fx, fy, lat = F * math.cos(phi + beta), F * math.sin(phi + beta), F * math.sin(beta)
    else:
        fx, fy, lat = xi * cp - u2 * sp, xi * sp + u2 * cp, u2
    out[0], out[1], out[2] = y[3], y[4], om
    out[3] = (fx - q[3] * y[3]) / q[0]
    out[4] = (fy - q[3] * y[4]) / q[0]
    out[5] = (q[2] * lat - q[4] * om) / q[1]
    out[6] = m * (r1 + 2 * s * om * dom)
    if clipped and taw > 0:
        out[6] += m * 2 * s * om * (out[5] - (a * u2 - cphi * om) / I) + (F * math.cos(beta) - xi) / taw
    return F


@numba.njit(cache=True)
def _rows_field(t, Y, out, R, Th, p, q, fc, ac, taw, circle):
    """``_field`` on every row of Y (M, 7), into out (M, 7)."""
    for i in range(Y.shape[0]):
        _field(t, Y[i], out[i], R, Th, p, q, fc, ac, taw, circle)


def limited_field(body: Body, gains: Gains, ref, limits: Limits | None = None, anti_windup: float | None = None):
    """The compiled field of the law for P under limits, for fixed-step loops on many rows: the rates
    of :func:`lib.percussion.law.closed_loop_rates` (the body both plant and model), its limits and
    anti-windup, to rounding (``tests/test_percussion_full_loop.py``).

    Parameters
    ----------
    body, gains : Body, Gains
        The body and the gains (:func:`lib.percussion.law.error_polynomial`).
    ref : Reference
        The eight or the circle (:func:`lib.trajectories.make`).
    limits, anti_windup : Limits, float, optional
        The limits on the applied force, and T_aw (s) > 0; None for none.

    Returns
    -------
    callable
        ``rates(t, Y)``: t (s) a float, Y (..., 7) the states; the rates, of Y's shape.
    """
    args = _limited_args(body, gains, ref, limits, anti_windup)
    def rates(t, Y):
        out = np.empty_like(Y := np.ascontiguousarray(Y, dtype=float))
        _rows_field(float(t), Y.reshape(-1, 7), out.reshape(-1, 7), *args)
        return out
    return rates


def _limited_args(body, gains, ref, limits, anti_windup) -> tuple:  # _rows_field's (R, Th, p, q, fc, ac, taw, circle)
    checks.one_of("ref (its path's kind)", getattr(ref, "_kind", None), ("eight", "circle"))
    limits = checks.instance("limits", Limits() if limits is None else limits, Limits)
    fc, ac = (d if v is None else float(v) for v, d in ((limits.force, math.inf), (limits.angle, math.pi)))
    taw = 0.0 if anti_windup is None else checks.number("anti_windup", anti_windup, positive=True, unit="s")
    return float(ref.R), float(ref.theta), _params(body, gains), _plant(body), fc, ac, taw, ref._kind == "circle"


@numba.njit(cache=True)
def _periods(x, R, Th, steps, p, pl, k, fmax, emax):
    """Advance each row of x (M, 7) in place by k[q] periods of the eight by RK4 with steps[q]
    steps a period; fmax[q] the largest F (N) and emax[q] the largest distance of the model's P
    from the path (m) seen at a step's start (running)."""
    d, free = 7, (math.inf, math.pi, 0.0, np.bool_(False))  # no limit, no anti-windup, the eight (typed)
    k1, k2, k3, k4, yy = np.empty(d), np.empty(d), np.empty(d), np.empty(d), np.empty(d)
    for q in range(x.shape[0]):
        n = steps[q]
        h = 2 * math.pi / Th[q] / n
        y = x[q]
        for j in range(k[q] * n):
            t = (j % n) * h
            f = _field(t, y, k1, R[q], Th[q], p, pl, *free)
            if f > fmax[q] or f != f:
                fmax[q] = f
            ex = y[0] + p[5] * math.cos(y[2]) - 0.5 * R[q] * math.sin(2 * Th[q] * t)
            ey = y[1] + p[5] * math.sin(y[2]) - R[q] * math.sin(Th[q] * t)
            emax[q] = max(emax[q], math.hypot(ex, ey))
            for i in range(d):
                yy[i] = y[i] + 0.5 * h * k1[i]
            _field(t + 0.5 * h, yy, k2, R[q], Th[q], p, pl, *free)
            for i in range(d):
                yy[i] = y[i] + 0.5 * h * k2[i]
            _field(t + 0.5 * h, yy, k3, R[q], Th[q], p, pl, *free)
            for i in range(d):
                yy[i] = y[i] + h * k3[i]
            _field(t + h, yy, k4, R[q], Th[q], p, pl, *free)
            for i in range(d):
                y[i] += h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i])
            if not math.isfinite(y[2]) or abs(y[6]) > 1e12:
                y[:] = math.nan
                fmax[q] = math.nan
                break


def _params(body: Body, gains: Gains) -> np.ndarray:
    return np.r_[body.m, body.I, body.a, body.c, body.c_phi, centre_of_percussion(body), lateral_drag_speed(body),
                 error_polynomial(body, gains).ravel()].astype(float)


def _plant(body: Body) -> np.ndarray:
    return np.array([body.m, body.I, body.a, body.c, body.c_phi], dtype=float)


def grid_sample(n_side: int = 10, n: int = FIG5_GRID["n"]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """An n_side x n_side subgrid of Fig. 5's n x n grid (:data:`lib.rotation.verdicts.FIG5_GRID`),
    corners included, evenly spread: the points' R (m), Theta (rad/s) and their rows in the
    n^2-row frame of the map (Theta varying slowest).

    Parameters
    ----------
    n_side : int
        Points per side of the sample, 2 <= n_side <= n.
    n : int
        Points per side of the full grid.

    Returns
    -------
    R, Theta : numpy.ndarray
        (n_side^2,) each.
    rows : numpy.ndarray
        (n_side^2,) row numbers in the full map's frame.
    """
    n = checks.integer("n", n, minimum=2)
    n_side = checks.integer("n_side", n_side, minimum=2)
    if n_side > n:
        raise ValueError(f"n_side must be at most n = {n}, got {n_side}")
    pick = np.round(np.linspace(0, n - 1, n_side)).astype(int)
    r_all, t_all = np.linspace(*FIG5_GRID["R"], n), np.linspace(*FIG5_GRID["Theta"], n)
    iT, iR = (a.ravel() for a in np.meshgrid(pick, pick, indexing="ij"))
    return r_all[iR], t_all[iT], iT * n + iR


def compiled_rates(body: Body, gains: Gains, R: float, Theta: float, t: float, y, model: Body | None = None
                   ) -> tuple[np.ndarray, float]:
    """The compiled field of :class:`FullLoopMap` at one state: the law for P on the eight, no limits.

    Parameters
    ----------
    body, gains : Body, Gains
        The plant and the gains (the error polynomial of :func:`lib.percussion.law.error_polynomial`).
    R, Theta : float
        The eight's size (m) and rate (rad/s).
    t : float
        Time (s).
    y : array_like
        State (x, y, phi, x', y', phi', xi) (m, m, rad, m/s, m/s, rad/s, N).
    model : Body, optional
        The law's model of the body (default the plant).

    Returns
    -------
    rates : numpy.ndarray
        (7,) the state's rates.
    F : float
        The force magnitude (N).
    """
    out, law = np.empty(7), _params(body if model is None else model, gains)
    F = _field(float(t), np.asarray(y, dtype=float).copy(), out, float(R), float(Theta), law, _plant(body),
               math.inf, math.pi, 0.0, False)
    return out, float(F)


def _error_drive(body: Body, gains: Gains, R, Theta, x0) -> np.ndarray:
    """max over t >= 0 of |e''(t)| + k |e'(t)| (m/s^2) for P's error from the start x0 (7,) on the
    eight at each point: the designed linear equation solved through its eigenvectors, sampled
    every 0.01 s over the slowest root's 30 time constants."""
    co = error_polynomial(body, gains)
    z, dz, xi = x0[:3], x0[3:6], x0[6]
    P, dP = point_state(body, z, dz)
    ddP = point_accel(body, z[2], dz[2], dP, xi)
    zd, dzd, ddzd = eight_kinematics(R, Theta, 0.0)
    e0 = np.stack([zd[:, :2] - P, dzd[:, :2] - dP, ddzd[:, :2] - ddP], -1)          # (N, 2, 3)
    k, worst = body.c / body.m, np.zeros(R.size)
    for j in range(2):
        A = np.array([[0, 1, 0], [0, 0, 1], [-co[j, 2], -co[j, 1], -co[j, 0]]])
        lam, V = np.linalg.eig(A)
        t = np.arange(0.0, 30 / np.abs(lam.real).min(), 0.01)
        c = np.linalg.solve(V, e0[:, j].T)                                           # (3, N)
        x = np.einsum("ij,tj,jn->tin", V, np.exp(np.outer(t, lam)), c).real           # (t, 3, N)
        worst = np.maximum(worst, (np.abs(x[:, 2]) + k * np.abs(x[:, 1])).max(axis=0))
    return worst


def start_error(body: Body, R, Theta, x0=None) -> np.ndarray:
    """P's distance from the path's point P_d(0) at the start (m), per point of the eight.

    Parameters
    ----------
    body : Body
        The body.
    R, Theta : array_like
        The points (m, rad/s).
    x0 : array_like, optional
        The start (7,) or its first six entries; default the paper's.

    Returns
    -------
    numpy.ndarray
        (N,) |P(0) - P_d(0)| (m).
    """
    R, Theta = np.atleast_1d(np.asarray(R, float)), np.atleast_1d(np.asarray(Theta, float))
    x0 = np.r_[PAPER_Z0, PAPER_DZ0] if x0 is None else np.asarray(x0, float)
    P, _ = point_state(body, x0[:3], x0[3:6])
    zd = eight_kinematics(R, Theta, 0.0)[0]
    return np.hypot(zd[:, 0] - P[0], zd[:, 1] - P[1])


def steps_per_period(body: Body, gains: Gains, R, Theta, h_rate: float = 1.0, min_steps: int = 64,
                     x0=None) -> np.ndarray:
    """RK4 steps a period of the eight (2 pi / Theta) so that h times the largest rate stays below
    ``h_rate``: the heading's relaxation rate |v| / eps, v = P'' + k P' = w - (e'' + k e'), with
    |w| <= R Theta^2 max|X''| + R k Theta max|X'| on the unit eight (max|X''| <= sqrt(5),
    max|X'| <= sqrt(2)) and e'' + k e' bounded on P's designed error from the start ``x0``, plus
    the error equation's fastest root (1/s).

    Parameters
    ----------
    body, gains : Body, Gains
        The body and the gains.
    R, Theta : array_like
        The points (m, rad/s).
    h_rate : float
        The bound on h times the rate, > 0.
    min_steps : int
        The fewest steps a period.
    x0 : array_like, optional
        The start (7,); default the paper's with the thrust :data:`THRUST0`.

    Returns
    -------
    numpy.ndarray
        (N,) int steps a period, multiples of 8.
    """
    R, Theta = np.atleast_1d(np.asarray(R, float)), np.atleast_1d(np.asarray(Theta, float))
    x0 = np.r_[PAPER_Z0, PAPER_DZ0, THRUST0] if x0 is None else np.asarray(x0, float)
    eps, k = abs(lateral_drag_speed(body)), body.c / body.m
    co = error_polynomial(body, gains)
    fastest = max(np.abs(np.roots(np.r_[1.0, c])).max() for c in co)
    w = R * (math.sqrt(5) * Theta**2 + math.sqrt(2) * k * Theta)
    rate = (w + _error_drive(body, gains, R, Theta, x0)) / eps + fastest
    need = np.ceil(rate * 2 * np.pi / Theta / h_rate / 8) * 8
    return np.maximum(need, min_steps).astype(np.int64)


class FullLoopMap:
    """The period map of the 7-state loop at many points (:class:`lib.dynamics.verdicts.PeriodMap`):
    row i has its own (R, Theta) and step count; the law uses ``model`` (default the plant)."""

    turn_axis = 2

    def __init__(self, body: Body, gains: Gains, R, Theta, steps, model: Body | None = None,
                 fd_step: float = FULL_LOOP_OPTIONS["fd_step"]):
        self.R, self.Theta = np.asarray(R, float), np.asarray(Theta, float)
        self.steps = np.asarray(steps, np.int64)
        self.p, self.plant = _params(body if model is None else model, gains), _plant(body)
        self.fd_step = fd_step

    def advance(self, idx, x, k, fmax=None, emax=None) -> np.ndarray:
        """x (M, d) of the rows ``idx`` after k periods; ``fmax``, ``emax`` (M,) updated in place
        with the largest force (N) and distance of the model's P from the path (m) on the way."""
        idx = np.asarray(idx)
        x = np.array(x, dtype=float, order="C")
        k = np.broadcast_to(np.asarray(k, dtype=np.int64), (x.shape[0],)).copy()
        f = np.zeros(x.shape[0]) if fmax is None else fmax
        e = np.zeros(x.shape[0]) if emax is None else emax
        _periods(x, self.R[idx], self.Theta[idx], self.steps[idx], self.p, self.plant, k, f, e)
        return x

    def step(self, idx, x, k):
        """(P^k(x), DP^k) with a forward-difference Jacobian."""
        return dv.difference_jacobian(self, idx, x, k, self.fd_step)


def _orbit_rows(fmap, live, hist, o, out):
    """find_orbits on the live rows; fills ``out`` for the rows decided; returns their mask."""
    r = dv.find_orbits(fmap.step, fmap, live, hist, max_period=o["max_period"], candidate_tol=o["candidate_tol"],
                       newton_tol=o["newton_tol"], reach_tol=o["reach_tol"], reach_floor=o["reach_floor"],
                       newton_options=dict(max_iter=o["newton_iter"], stall_after=2))
    f = np.flatnonzero(r["found"])
    g = live[f]
    out["regime"][g] = dv.orbit_regime(r["n"][f])
    out["period"][g], out["turns"][g], out["lost"][g] = r["k"][f], r["n"][f], r["n"][f] != 0
    out["floquet"][g], out["orbit"][g] = r["rho"][f], r["near"][f]
    out["status"][live] = r["status"]
    return r["found"]


def full_loop_verdicts(body: Body, gains: Gains, R, Theta, *, thrust0: float = THRUST0, model: Body | None = None,
                       **options) -> pd.DataFrame:
    """The verdict on the 7-state loop under the law for P at each point (R_i, Theta_i) of the
    eight (28), from the paper's start (the module's docstring).

    Parameters
    ----------
    body, gains : Body, Gains
        The plant (and the law's model) and the gains.
    R, Theta : array_like
        The points (m, rad/s), > 0, 1-D, equal lengths.
    thrust0 : float
        The thrust state at the start (N).
    model : Body, optional
        The law's model of the body (default the plant: a wrong model when it differs).
    **options
        Keys of :data:`FULL_LOOP_OPTIONS`.

    Returns
    -------
    pandas.DataFrame
        One row a point: R, Theta, steps (RK4 steps a period), regime, period, turns, lost,
        tracked, held, floquet (largest |multiplier| of the orbit's map), orbit_p (the heading
        error phi - phi_d at t = 0 on the orbit, rad), P_error (the largest distance of the
        model's P from the path over one period of the orbit, m), F_run (the largest force from
        the start until the orbit is reached, N), F_orbit (the largest on one period of the orbit,
        N; all three at the steps' starts), periods, reason.
    """
    checks.instance("body", body, Body)
    checks.instance("gains", gains, Gains)
    o = checks.options(options, FULL_LOOP_OPTIONS, minima=_MINIMA)
    R = checks.array("R", R, ndim=1, positive=True)
    Theta = checks.array("Theta", Theta, ndim=1, positive=True)
    if R.shape != Theta.shape:
        raise ValueError(f"R and Theta must have equal lengths, got {R.size} and {Theta.size}")
    thrust0 = checks.number("thrust0", thrust0, unit="N")
    if model is not None:
        checks.instance("model", model, Body)
    N = R.size
    steps = steps_per_period(body, gains, R, Theta, o["h_rate"], o["min_steps"], np.r_[PAPER_Z0, PAPER_DZ0, thrust0])
    by_r = checks.scale_culprit(body, R, Theta) == "R"
    checks.within_budget({"R": np.where(by_r, steps, 0), "Theta": np.where(by_r, 0, steps)}, MAX_STEPS,
                         what="a period would need", unit="RK4 steps",
                         values={"R": (R, "m"), "Theta": (Theta, "rad/s")},
                         fix="keep R and Theta near the body's scales, or raise the option h_rate")
    fmap = FullLoopMap(body, gains, R, Theta, steps, model, o["fd_step"])
    out = dict(regime=np.full(N, "undecided", dtype=object), period=np.zeros(N, int), turns=np.zeros(N, int),
               lost=np.zeros(N, bool), floquet=np.full(N, np.nan), orbit=np.full((N, 7), np.nan),
               status=np.full(N, "", dtype=object), periods=np.zeros(N, int))
    fmax = np.zeros(N)
    live = np.arange(N)
    x = np.tile(np.r_[PAPER_Z0, PAPER_DZ0, thrust0], (N, 1))
    hist, t = x[None], 0
    keep = 2 * o["max_period"] + 2
    while live.size and t < o["max_periods"]:
        secs = []
        for _ in range(min(o["chunk"], o["max_periods"] - t)):
            f = fmax[live].copy()
            x = fmap.advance(live, x, 1, f)
            fmax[live] = f
            secs.append(x)
            t += 1
        hist = np.concatenate([hist, np.stack(secs)])[-keep:]
        out["periods"][live] = t
        ok = np.isfinite(hist[-1]).all(axis=1)
        done = np.zeros(live.size, bool)
        if ok.any():
            done[ok] = _orbit_rows(fmap, live[ok], hist[:, ok], o, out)
        out["status"][live[~ok]] = "diverged"
        done |= ~ok
        live, x, hist = live[~done], x[~done], hist[:, ~done]
    return _frame(fmap, R, Theta, steps, fmax, out, o)


def _frame(fmap, R, Theta, steps, fmax, out, o) -> pd.DataFrame:
    """The verdicts' frame, with the orbit's measures."""
    N = R.size
    orb = np.isfinite(out["orbit"]).all(axis=1)
    P_err, f_orb, orbit_p = np.full(N, np.nan), np.full(N, np.nan), np.full(N, np.nan)
    if orb.any():
        z = out["orbit"][orb]
        orbit_p[orb] = wrap_angle(z[:, 2] - eight_kinematics(R[orb], Theta[orb], 0.0)[0][:, 2])
        f, e = np.zeros(orb.sum()), np.zeros(orb.sum())
        fmap.advance(np.flatnonzero(orb), z, out["period"][orb], f, e)
        f_orb[orb], P_err[orb] = f, e
    tracked = orb & (P_err <= o["position_tol"] * R)
    reason = np.where(out["regime"] == "undecided",
                      np.where(out["status"] == "diverged", "diverged",
                               "no attracting orbit reached in " + out["periods"].astype(str) + " periods ("
                               + out["status"].astype(str) + ")"), "")
    return pd.DataFrame(dict(R=R, Theta=Theta, steps=steps, regime=out["regime"], period=out["period"],
                             turns=out["turns"], lost=out["lost"], tracked=tracked,
                             held=dv.held(out["regime"], out["lost"], tracked), floquet=out["floquet"],
                             orbit_p=orbit_p, P_error=P_err, F_run=fmax, F_orbit=f_orb, periods=out["periods"],
                             reason=reason))


def compare_with_zero_dynamics(full: pd.DataFrame, zero: pd.DataFrame) -> dict:
    """The full loop's verdicts beside the zero dynamics' at the same points.

    Parameters
    ----------
    full : pandas.DataFrame
        :func:`full_loop_verdicts` at some points.
    zero : pandas.DataFrame
        :func:`lib.percussion.heading_sweep` at the same points, in the same order.

    Returns
    -------
    dict
        points, held_full, held_zero (counts), same_verdict (points whose regime and held agree),
        orbit_gap (the largest |difference| of the two orbits' heading errors at t = 0, wrapped,
        rad, over the points held by both), P_error_max (m), F_run_max, F_orbit_max (N).
    """
    if len(full) != len(zero) or not (np.allclose(full.R, zero.R) and np.allclose(full.Theta, zero.Theta)):
        raise ValueError("full and zero must hold the same points in the same order")
    held_z = dv.held(zero.regime, zero.lost)
    both = full.held.to_numpy() & held_z
    gap = np.abs(wrap_angle(full.orbit_p.to_numpy()[both] - zero.orbit_p.to_numpy()[both]))
    same = (full.regime.to_numpy() == zero.regime.to_numpy()) & (full.held.to_numpy() == held_z)
    return dict(points=len(full), held_full=int(full.held.sum()), held_zero=int(held_z.sum()),
                same_verdict=int(same.sum()), orbit_gap=float(gap.max()) if gap.size else math.nan,
                P_error_max=float(full.P_error.max()), F_run_max=float(full.F_run.max()),
                F_orbit_max=float(full.F_orbit.max()))
