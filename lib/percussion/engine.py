"""The heading's period map under the law for P, exactly as a linear flow.

With P on the path, the zero dynamics in the phase s = Theta t read (Chapter 7)

    d phi / ds = alpha(s) cos phi - beta(s) sin phi,
    alpha = (R/eps)(Theta Y'' + k Y'),  beta = (R/eps)(Theta X'' + k X'),

(X, Y the unit path, primes d/ds). With x = (cos(phi/2), sin(phi/2)) this is the direction of
the *linear* flow x' = S(s) x, S = (1/2)[[beta, alpha], [alpha, -beta]] (symmetric, traceless):
the heading is twice the angle of a vector carried by a linear periodic system. So the period
map is a Moebius map of the circle (the projective action of the monodromy matrix in SL(2, R)):
it has an attracting and a repelling fixed point (hyperbolic, |trace| > 2), or none
(elliptic, |trace| < 2: the heading drifts, quasi-periodically or on a neutral cycle); chaos
cannot occur.

The flow is integrated by the fourth-order Magnus method (two Gauss points, one commutator);
each step's exp(Omega) is exact (Omega^2 = d I), so the step is stable however stiff the
heading's relaxation (|w| / eps up to hundreds per second). Its Jacobian is exact too:
d phi_end / d phi_start = det(E) / |E x|^2 = 1 / |E x|^2 per step. The steps run in one compiled
loop (``_flow_kernel``), point by point; ``tests/test_percussion_sweep.py`` checks it against
the step written out in numpy.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from ..params import Body
from ..trajectories import KINEMATICS, POSITIONS
from .point import _eps

__all__ = ["WINDING", "HeadingEngine", "HeadingMap", "coefficients"]

#: turns of the reference heading per period
WINDING = {"eight": 0, "circle": 1}
_G = np.array([0.5 - np.sqrt(3) / 6, 0.5 + np.sqrt(3) / 6])


def coefficients(body: Body, R, Theta) -> tuple[np.ndarray, np.ndarray]:
    """(cA, cV) with alpha = cA Y'' + cV Y', beta = cA X'' + cV X': cA = R Theta / eps,
    cV = R k / eps (dimensionless per unit phase).

    Parameters
    ----------
    body : Body
        The body, checked by the caller (its eps = :func:`lib.percussion.point.lateral_drag_speed`
        and k = c/m).
    R : array_like
        Sizes of the path (m).
    Theta : array_like
        Rates of the reference (rad/s), broadcastable with ``R``.

    Returns
    -------
    cA : numpy.ndarray
        R Theta / eps (dimensionless), the broadcast shape of ``R`` and ``Theta``.
    cV : numpy.ndarray
        R (c/m) / eps (dimensionless), the shape of ``R``.
    """
    eps = _eps(body)                           # a checked body: the kernel, not the public face
    R, Theta = np.asarray(R, float), np.asarray(Theta, float)
    return R * Theta / eps, R * (body.c / body.m) / eps


class HeadingEngine:
    """The tabulated unit path of ``kind`` at n Magnus steps per period, and the flow."""

    def __init__(self, kind: str, n: int):
        self.kind, self.n, self.h = kind, int(n), 2 * np.pi / n
        s = (np.arange(n)[:, None] + _G[None, :]) * self.h
        _, _, self.X1, self.Y1, self.X2, self.Y2, _, _ = POSITIONS[kind](1.0, 1.0, s)
        ends = np.arange(1, n + 1) * self.h
        _, _, self.eX1, self.eY1, self.eX2, self.eY2, _, _ = POSITIONS[kind](1.0, 1.0, ends)
        z, dz, _ = KINEMATICS[kind](1.0, 1.0, ends)
        self.H, self.H1 = z[:, 2], dz[:, 2]
        self.H0 = float(KINEMATICS[kind](1.0, 1.0, 0.0)[0][2])
        self.w2pi = 2 * np.pi * WINDING[kind]

    def rate(self, phi, cA, cV, j):
        """d phi / ds at the end of step j (N,)."""
        al = cA * self.eY2[j] + cV * self.eY1[j]
        be = cA * self.eX2[j] + cV * self.eX1[j]
        return al * np.cos(phi) - be * np.sin(phi)

    def flow(self, phi, cA, cV, periods: int, *, record: bool = False) -> dict:
        """``periods`` periods from phi (N,) (rad, at s = 0): the sections (periods, N) (phi less
        the reference's winding), log d phi/d phi0 per period (periods, N), the end state, and
        with ``record`` p = phi - H and dp/ds at every step end (N, periods n)."""
        th = np.array(phi, dtype=float, ndmin=1) / 2
        N, periods = th.size, int(periods)
        cA, cV = (np.ascontiguousarray(np.broadcast_to(np.asarray(v, float), (N,))) for v in (cA, cV))
        sec, logs = np.empty((periods, N)), np.empty((periods, N))
        n_rec = periods * self.n if record else 0
        p, dp = np.empty((N, n_rec)), np.empty((N, n_rec))
        _flow_kernel(th, cA, cV, periods, self.h, self.X1, self.Y1, self.X2, self.Y2, self.eX1, self.eY1,
                     self.eX2, self.eY2, self.H, self.H1, self.w2pi, record, sec, logs, p, dp)
        out = dict(phi=sec[-1].copy() if periods else 2 * th, sec=sec, logs=logs)
        if record:
            out["p"], out["dp"] = p, dp
        return out


_SQRT3_24 = math.sqrt(3) / 24


@numba.njit(cache=True)
def _flow_kernel(th, cA, cV, periods, h, X1, Y1, X2, Y2, eX1, eY1, eX2, eY2, H, H1, w2pi, record, sec, logs,
                 p, dp):
    """:meth:`HeadingEngine.flow`'s steps: for each point q, ``periods`` periods of the Magnus
    step from th[q] (half the heading, advanced in place); sec, logs (periods, N) and, with
    ``record``, p, dp (N, periods n) filled. The unit vector x = (cos th, sin th) is carried
    from step to step (E x normalised) and th advanced by the angle from x to E x, so that a
    step takes no sine or cosine of the heading."""
    n = X1.shape[0]
    for q in range(th.size):
        t, a_, v_ = th[q], cA[q], cV[q]
        x1, x2 = math.cos(t), math.sin(t)
        for per in range(periods):
            lj = 0.0
            for j in range(n):
                a1, a2 = a_ * Y2[j, 0] + v_ * Y1[j, 0], a_ * Y2[j, 1] + v_ * Y1[j, 1]
                b1, b2 = a_ * X2[j, 0] + v_ * X1[j, 0], a_ * X2[j, 1] + v_ * X1[j, 1]
                P, Q = h / 4 * (b1 + b2), h / 4 * (a1 + a2)
                Rr = _SQRT3_24 * h * h * (b2 * a1 - a2 * b1)
                d = P * P + Q * Q - Rr * Rr
                r = math.sqrt(abs(d))
                if d >= 0:                 # exp(Omega) = c0 I + c1 Omega, Omega^2 = d I
                    c0, c1 = math.cosh(r), (math.sinh(r) / r if r > 0 else 1.0)
                else:
                    c0, c1 = math.cos(r), math.sin(r) / r
                y1 = c0 * x1 + c1 * (P * x1 + (Q + Rr) * x2)
                y2 = c0 * x2 + c1 * ((Q - Rr) * x1 - P * x2)
                t += math.atan2(x1 * y2 - x2 * y1, x1 * y1 + x2 * y2)
                s2 = y1 * y1 + y2 * y2
                lj -= math.log(s2)         # log d phi_end / d phi_start = -2 log |E x|
                nrm = math.sqrt(s2)
                x1, x2 = y1 / nrm, y2 / nrm
                if record:
                    k = per * n + j
                    p[q, k] = 2 * t - H[j] - w2pi * per
                    al = a_ * eY2[j] + v_ * eY1[j]
                    be = a_ * eX2[j] + v_ * eX1[j]
                    # cos and sin of the heading 2 th from x
                    dp[q, k] = al * (x1 * x1 - x2 * x2) - be * (2 * x1 * x2) - H1[j]
            sec[per, q] = 2 * t - w2pi * (per + 1)
            logs[per, q] = lj
        th[q] = t


class HeadingMap:
    """The period map of the zero dynamics at rows with coefficients (cA, cV), a
    :class:`lib.dynamics.verdicts.PeriodMap`: the state (phi,) at s = 0 mod 2 pi, less the
    reference's winding; :meth:`step` with the exact Jacobian of the discrete map."""

    turn_axis = 0

    def __init__(self, eng: HeadingEngine, cA, cV):
        self.eng, self.cA, self.cV = eng, np.asarray(cA, float), np.asarray(cV, float)

    def step(self, idx, x, k):
        """P^k(x) (M, 1) of rows ``idx`` and its Jacobian (M, 1, 1); k one or one per row."""
        idx = np.asarray(idx)
        x = np.asarray(x, float)
        k = np.broadcast_to(np.asarray(k, int), (idx.size,))
        y, J = np.empty_like(x), np.empty((idx.size, 1, 1))
        for kk in np.unique(k):
            r = np.flatnonzero(k == kk)
            o = self.eng.flow(x[r, 0], self.cA[idx[r]], self.cV[idx[r]], int(kk))
            y[r, 0] = o["phi"] if kk else x[r, 0]
            J[r, 0, 0] = np.exp(o["logs"].sum(axis=0)) if kk else 1.0
        return y, J

    def advance(self, idx, x, k):
        """P^k(x) (M, 1)."""
        return self.step(idx, x, k)[0]
