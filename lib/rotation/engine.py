"""The reduced rotation (32) as a period map for the verdicts (:mod:`lib.rotation.verdicts`):
the forcing of one reference tabulated at n steps per period, the compiled fixed-step
8th-order Dormand-Prince flow with its exact Jacobian and renormalised tangent vector
(:func:`lib.integrators.compiled.rotation_flow`, or the same scheme in numpy), the period
map seen by :mod:`lib.dynamics.verdicts`, the range of p over an orbit, and each orbit the
verdicts found located again on the fine map (``_on_fine_map``).

Units: R in m, Theta in rad/s, angles in rad, the phase s = Theta t in rad; w = d phi / ds.
"""

from __future__ import annotations

import numpy as np

from ..angles import wrap_angle
from ..dynamics import verdicts as dv
from ..dynamics.orbits import floquet_multipliers
from ..integrators import batch
from ..integrators.compiled import rotation_flow
from ..machinery import checks
from ..params import Body
from .reduced import ENGINES, _forcing, _shape, _unit_forcing, steps_per_period
from ..dynamics.sampled import sampled_range
from .field import coefficients, rotation_rates, rotation_rates_dphi

__all__ = ["verdict_steps", "RotationMap", "orbit_range", "check_domain", "MAX_DAMPING_PERIODS", "MAX_STEPS"]


def verdict_steps(body: Body, kind: str, R, Theta, h_lambda: float = 0.125, h_damp: float = 1.0) -> np.ndarray:
    """Fixed steps per reference period for :func:`lib.rotation.verdicts.rotation_verdicts`: the smallest
    multiple of 32 (>= 64) with h omega <= ``h_lambda`` and h A <= ``h_damp``, where
    omega = sqrt(B v_max + C a_max) bounds the frequencies of the linearised equation
    (32) (in the phase s) and A is its damping. The damping only sets how fast a
    transient in w dies out, which the 8th-order scheme follows well beyond h A = 1,
    so this asks for about half the steps of :func:`lib.rotation.reduced.steps_per_period` at the same
    accuracy of the attractor (about 1e-10 rad per period).

    Parameters
    ----------
    body : Body
        The body.
    kind : str
        ``"eight"`` or ``"circle"``.
    R, Theta : array_like
        Radii (m) and rates (rad/s).
    h_lambda : float
        Bound on h omega.
    h_damp : float
        Bound on h A.

    Returns
    -------
    numpy.ndarray
        Steps per period (int), one per point.
    """
    at, _ = _shape(kind)
    s = np.linspace(0, 2 * np.pi, 721)
    X1, Y1, X2, Y2, _, _ = at(s)
    vmax, amax = np.hypot(X1, Y1).max(), np.hypot(X2, Y2).max()
    A, B, C = coefficients(body, np.asarray(R, float), np.asarray(Theta, float))
    need = np.maximum(2 * np.pi * np.sqrt(B * vmax + C * amax) / h_lambda, 2 * np.pi * A / h_damp)
    return np.maximum(64, 32 * np.ceil(need / 32)).astype(int)


class _Engine:
    """One run of the verdicts at n steps per period: the forcing tabulated once, the
    flow (:func:`lib.integrators.compiled.rotation_flow`, or its numpy twin) with it."""

    def __init__(self, kind: str, n: int, engine: str):
        self.kind, self.n, self.engine = kind, n, engine
        self.h, self.X1, self.Y1, self.X2, self.Y2, (self.H, self.H1), self.winding = _forcing(kind, n)
        tab = batch.dop853()
        self.hA, self.hB = tab.A * self.h, tab.b * self.h
        self.w2pi = 2 * np.pi * self.winding
        self.H0, self.H1_0 = _shape(kind)[0](0.0)[4:6]

    def flow(self, phi, w, A, B, C, periods, *, jac=False, renorm=False):
        if self.engine == "numba":
            return rotation_flow(phi, w, A, B, C, periods, self.X1, self.Y1, self.X2, self.Y2, self.hA, self.hB,
                                 jac=jac, renorm=renorm, wind2pi=self.w2pi)
        return _flow_numpy(self, phi, w, A, B, C, periods, jac=jac, renorm=renorm)

    def flow_with(self, s: dict, c: int, J):
        """The Lyapunov flow: ``c`` periods of the states ``s`` carrying the tangent vector (first
        column of J), renormalised every period, with the range of p on the way."""
        if self.engine == "numba":
            return rotation_flow(s["phi"], s["w"], s["A"], s["B"], s["C"], c, self.X1, self.Y1, self.X2, self.Y2,
                                 self.hA, self.hB, J=J, renorm=True, H=self.H, wind2pi=self.w2pi)
        return _flow_numpy(self, s["phi"], s["w"], s["A"], s["B"], s["C"], c, renorm=True, H=self.H, J0=J)

    def record(self, phi, w, A, B, C, k: int):
        """p (rad) and dp/ds at every step end over k periods from (phi, w) (N, k n)."""
        ps, dps = [], []
        for j in range(k):
            (out, out_w), phi, w = ENGINES[self.engine](phi, w, A, B, C, self.h, self.X1, self.Y1, self.X2,
                                                        self.Y2, self.kind)
            ps.append((out - self.H[:, None] - self.w2pi * j).T)
            dps.append((out_w - self.H1[:, None]).T)
        return np.concatenate(ps, axis=1), np.concatenate(dps, axis=1)


def _flow_numpy(eng: _Engine, phi, w, A, B, C, periods, *, jac=False, renorm=False, H=None, J0=None):
    """:func:`lib.integrators.compiled.rotation_flow` by the numpy batch integrator (same scheme)."""
    phi, w = np.array(phi, float, ndmin=1), np.array(w, float, ndmin=1)
    N = phi.size
    per = np.broadcast_to(np.asarray(periods, int), (N,))
    P = int(per.max())
    jac = jac or renorm

    def rates(s, Y):
        X1, Y1, X2, Y2 = _unit_forcing(eng.kind, s)
        dphi, dw = rotation_rates(Y[0], Y[1], A, B, C, X1, Y1, X2, Y2)
        if not jac:
            return np.stack([dphi, dw])
        d = rotation_rates_dphi(Y[0], B, C, X1, Y1, X2, Y2)
        return np.stack([dphi, dw, Y[4], Y[5], d * Y[2] - A * Y[4], d * Y[3] - A * Y[5]])

    Y = np.concatenate([np.stack([phi, w]), np.tile(np.array([1.0, 0, 0, 1.0])[:, None], (1, N))]) if jac \
        else np.stack([phi, w])
    if J0 is not None:
        Y[2:] = np.asarray(J0, float).reshape(N, 4).T
    if renorm:
        Y[3] = Y[5] = 0.0
    sec = np.full((P, N, 2), np.nan)
    logs = np.full((P, N), np.nan) if renorm else None
    lo, hi = np.full(N, np.inf), np.full(N, -np.inf)
    for q in range(P):
        act = per > q
        for j, (_, Yn) in enumerate(batch.steps(rates, Y, 0.0, eng.h, eng.n, batch.dop853())):
            if H is not None:
                p = Yn[0] - H[j] - eng.w2pi * q
                lo, hi = np.where(act, np.minimum(lo, p), lo), np.where(act, np.maximum(hi, p), hi)
        Yn = Yn.copy()
        sec[q, act] = Yn[:2, act].T
        if renorm:
            norm = np.hypot(Yn[2], Yn[4])
            logs[q, act] = np.log(norm[act])
            Yn[2], Yn[4] = Yn[2] / norm, Yn[4] / norm
        Y = np.where(act, Yn, Y)
    J = Y[2:].reshape(2, 2, N).transpose(2, 0, 1).copy() if jac else np.tile(np.eye(2), (N, 1, 1))
    return dict(phi=Y[0].copy(), w=Y[1].copy(), J=J, sec=sec, logs=logs,
                pmin=lo if H is not None else None, pmax=hi if H is not None else None)


class RotationMap:
    """The period map of the reduced rotation at rows with coefficients A, B, C (a
    :class:`lib.dynamics.verdicts.PeriodMap`): the state (phi, w) at s = 0 mod 2 pi, phi
    reduced by the reference's winding (so that a periodic heading error is a fixed point);
    :meth:`step` with the exact Jacobian of the discrete map."""

    turn_axis = 0

    def __init__(self, eng: _Engine, A, B, C):
        self.eng, self.A, self.B, self.C = eng, A, B, C

    def _run(self, idx, x, k, jac: bool):
        k = np.broadcast_to(np.asarray(k, dtype=int), (len(idx),))
        o = self.eng.flow(x[:, 0], x[:, 1], self.A[idx], self.B[idx], self.C[idx], k, jac=jac)
        return np.column_stack([o["phi"] - self.eng.w2pi * k, o["w"]]), o

    def advance(self, idx, x, k):
        """The states of rows ``idx`` k periods after x (N, 2)."""
        return self._run(idx, x, k, False)[0]

    def step(self, idx, x, k):
        """The states of rows ``idx`` k periods after x (N, 2), and the exact Jacobian of the
        discrete map (N, 2, 2)."""
        y, o = self._run(idx, x, k, True)
        return y, o["J"]


def orbit_range(eng: _Engine, x, A, B, C, k: int, slip) -> tuple[np.ndarray, np.ndarray]:
    """Range (rad) of p over k periods from the orbit points x (N, 2), sampled at every
    step, the extremes refined by cubic Hermite interpolation. A periodic orbit's samples
    wrap around (p(kT) = p(0)); a slipping orbit's window [0, kT] includes its start, where
    its extreme often lies (p runs on by 2 pi n).

    And, on the eight, the distance (rad, max-norm of (p, dp/ds), p modulo 2 pi) from the
    orbit to its mirror image: (37) is unchanged by p(t) -> -p(t + T/2) (the eight
    reflected in its x axis half a period later), so with every orbit its mirror image is
    an orbit too, with the same multipliers; at distance 0 the orbit is its own image,
    otherwise the two are distinct coexisting attractors (NaN on the circle).

    Parameters
    ----------
    eng : _Engine
        The compiled engine of the points.
    x : array_like
        Orbit points (N, 2).
    A, B, C : array_like
        The coefficients of (32).
    k : int
        Period.
    slip : array_like
        Turns per k periods (N,).

    Returns
    -------
    range : numpy.ndarray
        Range of p (rad), (N,).
    mirror : numpy.ndarray
        Distance to the mirror image (rad), (N,).
    """
    p, dp = eng.record(x[:, 0], x[:, 1], A, B, C, k)
    N, n = x.shape[0], eng.n
    mirror = np.full(N, np.nan)
    if eng.kind == "eight" and n % 2 == 0:
        p0, dp0 = x[:, 0] - eng.H0, x[:, 1] - eng.H1_0
        half = np.arange(k) * n + n // 2 - 1              # samples at t = j T + T / 2
        d = np.maximum(np.abs(wrap_angle(p0[:, None] + p[:, half])), np.abs(dp0[:, None] + dp[:, half]))
        mirror = d.min(axis=1)
    out = np.empty(N)
    cyc = np.asarray(slip) == 0
    if cyc.any():
        out[cyc] = sampled_range(p[cyc], cyclic=True, dy=dp[cyc], h=eng.h)
    if (~cyc).any():
        p0, dp0 = x[~cyc, 0] - eng.H0, x[~cyc, 1] - eng.H1_0
        out[~cyc] = sampled_range(np.column_stack([p0, p[~cyc]]), cyclic=False,
                                  dy=np.column_stack([dp0, dp[~cyc]]), h=eng.h)
    return out, mirror


#: the most reference periods the heading's damping time I_C / c_phi may last where the rotation's
#: verdicts are meant to hold (:data:`lib.machinery.domain.MAX_DAMPING_PERIODS`)
MAX_DAMPING_PERIODS = checks.MAX_DAMPING_PERIODS
#: the most fixed steps a reference period may need (:data:`lib.machinery.domain.MAX_STEPS`)
MAX_STEPS = checks.MAX_STEPS


def check_domain(body: Body, kind: str, R, Theta, h_lambda: float = 0.125) -> np.ndarray:
    """Refuse points outside the domain of the rotation's verdicts, naming the first one and
    the bound it breaks, and return the steps per period of the others
    (:func:`lib.rotation.reduced.steps_per_period`).

    Parameters
    ----------
    body : Body
        The body.
    kind : str
        ``"eight"`` or ``"circle"``.
    R, Theta : numpy.ndarray
        Radii (m) and rates (rad/s), 1-D, of equal length, already checked.
    h_lambda : float
        The bound on h Lambda.

    Returns
    -------
    numpy.ndarray
        Steps per period (int), one per point.

    Raises
    ------
    ValueError
        If a rate makes the heading's damping time longer than :data:`MAX_DAMPING_PERIODS`
        periods, or a point needs more than :data:`MAX_STEPS` steps a period.
    """
    checks.heading_damping(body, Theta)
    steps = steps_per_period(body, kind, R, Theta, h_lambda)
    A, _, _ = coefficients(body, R, Theta)
    checks.steps_domain(steps, 2 * np.pi * A / h_lambda, R, Theta)
    return steps


#: Newton on the reduced rotation's period map (exact Jacobian): polished below its
#: tolerance while the residual still halves
_NEWTON = dict(max_iter=15, max_step=1.0, polish=1e-13)


def _on_fine_map(body, kind, R, Theta, n_pts, n_fine, opts, engine, out) -> None:
    """Each attracting orbit on the fine map (``n_fine`` steps per period): Newton from the
    orbit found on the verdict map, its multipliers, and its range sampled at every step
    (Hermite-refined extremes). An orbit that does not survive is undecided."""
    orb = np.flatnonzero(np.isin(out["regime"], ("periodic", "slipping")))
    for n in np.unique(n_fine[orb]):
        eng = _Engine(kind, int(n), engine)
        for k in np.unique(out["period"][orb]):
            g = orb[(n_fine[orb] == n) & (out["period"][orb] == k)]
            if g.size == 0:
                continue
            A, B, C = coefficients(body, R[g], Theta[g])
            if np.any(n_pts[g] != n):
                rmap = RotationMap(eng, A, B, C)
                x, J, res, _, _ = dv.newton(rmap.step, np.arange(g.size), out["x"][g], int(k), turn_axis=0,
                                         turns=out["slip_n"][g], tol=opts["newton_tol"], **_NEWTON)
                ok = res <= opts["newton_tol"]
                mult = np.full((g.size, 2), np.nan + 0j)
                if ok.any():
                    mult[ok] = floquet_multipliers(J[ok])
                ok &= np.abs(mult[:, 0]) < 1.0
                bad = g[~ok]
                out["regime"][bad] = "undecided"
                out["reason"][bad] = "the orbit of the verdict map is not an attracting orbit of the fine map"
                out["period"][bad], out["lost"][bad] = 0, False
                for key in ("floquet", "lyapunov", "slip", "slip_stderr", "orbit_p", "distance"):
                    out[key][bad] = np.nan
                g, A, B, C, x, mult, res = g[ok], A[ok], B[ok], C[ok], x[ok], mult[ok], res[ok]
                out["x"][g], out["mult"][g], out["residual"][g] = x, mult, res
                mod = np.abs(mult[:, 0])
                out["floquet"][g] = mod
                out["lyapunov"][g] = np.log(mod) * Theta[g] / (2 * np.pi * k)
                if g.size == 0:
                    continue
            out["range"][g], out["mirror"][g] = orbit_range(eng, out["x"][g], A, B, C, int(k), out["slip_n"][g])
