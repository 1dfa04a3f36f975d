"""The compiled engine of the batch integrator for the reduced rotation equation: the
fixed-step scheme of :func:`lib.integrators.batch.steps` (8th-order Dormand-Prince)
run over one reference period, one point per parallel numba loop, on the field
:func:`lib.rotation.field.rotation_rates_cs` compiled from its one definition, at the cos and sin
of each stage's heading taken from its step's (:func:`lib.integrators.trig.cos_sin_near`). About
ten times faster than the vectorised numpy engine on the Fig. 5 grid (see
``benchmarks/bench_eight_sweep.py``); the tests check the two agree to rounding.
"""

from __future__ import annotations

from pathlib import Path

import numba
import numpy as np

from ..machinery.cache import source_stamp
from ..rotation.field import rotation_rates_cs
from .trig import cos_sin_near

__all__ = ["rotation_period", "rotation_flow", "overdamped_period"]

# the field given cos and sin of the stage's heading, which cos_sin_near takes from the step's
_rates = numba.njit(rotation_rates_cs)
_near = numba.njit(cos_sin_near)


def rotation_period(phi, w, A, B, C, h, X1, Y1, X2, Y2, hA, hB):
    """One period of n fixed steps for N points: the unit reference's derivatives
    X1.. are tabulated at the stage phases, shape (n, stages). Returns ((phi, w) at
    every step end, each (n, N)), final phi, final w).

    Parameters
    ----------
    phi, w : numpy.ndarray
        Heading (rad) and w = d phi / ds, (N,).
    A, B, C : numpy.ndarray
        The coefficients of (32), (N,).
    h : float
        The phase step.
    X1, Y1, X2, Y2 : numpy.ndarray
        The unit reference's derivatives at the stage phases, (n, stages).
    hA, hB : numpy.ndarray
        The tableau times the step.

    Returns
    -------
    tuple
        ((phi, w) at every step end, each (n, N)), final phi, final w.
    """
    phi, w = np.array(phi, dtype=float), np.array(w, dtype=float)
    out = np.empty((X1.shape[0], phi.size))
    out_w = np.empty_like(out)
    _kernel(phi, w, np.ascontiguousarray(A, float), np.ascontiguousarray(B, float),
            np.ascontiguousarray(C, float), X1, Y1, X2, Y2, hA, hB, out, out_w)
    return (out, out_w), phi, w


# ---------------------------------------------------------------- the period map with its Jacobian


def rotation_flow(phi, w, A, B, C, periods, X1, Y1, X2, Y2, hA, hB, *, J=None, jac: bool = True,
                  renorm: bool = False, H=None, wind2pi: float = 0.0):
    """``periods`` (int, or one per point) reference periods of the reduced rotation
    equation (32) in the phase form of :func:`lib.rotation.field.rotation_rates`, for N
    points in parallel, by the fixed-step scheme of :func:`rotation_period` (the unit
    reference's derivatives tabulated at the stage phases, (n steps, stages); ``hA``,
    ``hB`` the tableau times the step). With ``jac`` the variational equation (its
    phi-derivative from :func:`lib.rotation.field.rotation_rates_cs`) is run with the
    same stages, so J is the exact Jacobian of the discrete map. ``J`` (N, 2, 2) is the
    initial variational matrix (identity by default). With ``renorm`` its first column
    is a tangent vector renormalised every period (for the largest Lyapunov exponent); the
    second column is then not integrated (returned as given).
    With ``H`` (n,), the reference heading at the step ends (rad), the extremes of
    p = phi - phi_d over every step are tracked (the heading winds ``wind2pi`` rad per period).

    Returns a dict: phi, w (N,) final; J (N, 2, 2); sec (P, N, 2) the raw (phi, w) at the end
    of each period (P = max periods; NaN past a point's own count); logs (P, N) the log
    growth of the tangent vector per period (with ``renorm``); pmin, pmax (N,) (with ``H``).

    Parameters
    ----------
    phi, w : numpy.ndarray
        Heading (rad) and w = d phi / ds, (N,).
    A, B, C : numpy.ndarray
        The coefficients of (32), (N,).
    periods : int or numpy.ndarray
        Periods, one or per point.
    X1, Y1, X2, Y2 : numpy.ndarray
        The unit reference's derivatives at the stage phases, (n, stages).
    hA, hB : numpy.ndarray
        The tableau times the step.
    J : numpy.ndarray, optional
        Initial variational matrix (N, 2, 2).
    jac, renorm : bool
        Run the variational equation; renormalise its first column every period.
    H : numpy.ndarray, optional
        The reference heading at the step ends (rad), (n,).
    wind2pi : float
        The heading's winding per period (rad).

    Returns
    -------
    dict
        phi, w, J, sec, logs, pmin, pmax (see above).
    """
    phi = np.array(phi, dtype=float, ndmin=1)
    w = np.array(w, dtype=float, ndmin=1)
    N = phi.size
    per = np.broadcast_to(np.asarray(periods, dtype=np.int64), (N,)).copy()
    P = int(per.max()) if N else 0
    Jf = np.tile(np.array([1.0, 0.0, 0.0, 1.0]), (N, 1)) if J is None else \
        np.ascontiguousarray(np.asarray(J, dtype=float).reshape(N, 4))
    if renorm:
        Jf[:, 1] = 0.0
        Jf[:, 3] = 0.0
    logs = np.full((P if renorm else 1, N), np.nan)
    sec = np.full((P, N, 2), np.nan)
    track = H is not None
    Hc = np.zeros(X1.shape[0]) if H is None else np.ascontiguousarray(H, dtype=float)
    pmin = np.full(N, np.inf)
    pmax = np.full(N, -np.inf)
    _flow_kernel(phi, w, Jf, np.ascontiguousarray(A, float), np.ascontiguousarray(B, float),
                 np.ascontiguousarray(C, float), per, X1, Y1, X2, Y2, hA, hB, bool(jac or renorm),
                 bool(renorm), track, Hc, float(wind2pi), logs, sec, pmin, pmax)
    return dict(phi=phi, w=w, J=Jf.reshape(N, 2, 2), sec=sec, logs=logs if renorm else None,
                pmin=pmin if track else None, pmax=pmax if track else None)


@numba.njit(cache=True)
def _overdamped_rate(cp, sp, j, A, B, C, X1, Y1, X2, Y2, X3, Y3, corrected):
    """phi_s of the overdamped heading, or with the first inertia correction
    (:func:`lib.rotation.slow_eight._rate`), at the heading of cos cp and sin sp: the torque T of
    :func:`lib.rotation.field.rotation_rates` at rest (w = 0), its derivative along the path T_s
    (the same field one derivative up) and in phi (:func:`lib.rotation.field.rotation_rates_dphi`),
    their formulas written out to share the one cos and sin, term by term in the same order, so
    the values are those of the separate definitions to the last bit."""
    T = (B * Y1[j] + C * Y2[j]) * cp - (B * X1[j] + C * X2[j]) * sp - A * 0.0
    if not corrected:
        return T / A
    Ts = (B * Y2[j] + C * Y3[j]) * cp - (B * X2[j] + C * X3[j]) * sp - A * 0.0
    Tphi = -(B * Y1[j] + C * Y2[j]) * sp - (B * X1[j] + C * X2[j]) * cp
    return T / A - (Ts + Tphi * T / A) / A**2


# Numba keys a cached function on its own file, not on the functions it calls from other modules
# (the field, the stages' cos and sin), so each kernel is made in a closure over ``stamp``, the hash
# of those modules and this one (as lib.integrators.switched_compiled._make_run is): numba keys a
# closure on its cells too, so an edit of any of them compiles the kernels again.

def _make_period_kernel(stamp: int):
    """The kernel of :func:`rotation_period`, closed over ``stamp``."""

    @numba.njit(cache=True, parallel=True)
    def _kernel(phi, w, A, B, C, X1, Y1, X2, Y2, hA, hB, out, out_w):
        if stamp < 0:  # never: the closure's cell, which numba's cache keys on
            return
        n, stages = X1.shape
        for q in numba.prange(phi.size):
            kp = np.empty(stages)
            kw = np.empty(stages)
            f, v, a_, b_, c_ = phi[q], w[q], A[q], B[q], C[q]
            for j in range(n):
                c0, s0 = np.cos(f), np.sin(f)
                for i in range(stages):
                    dp, ws = 0.0, v
                    for l in range(i):
                        dp += hA[i, l] * kp[l]
                        ws += hA[i, l] * kw[l]
                    cp, sp = _near(c0, s0, f, dp)
                    kp[i], kw[i], _ = _rates(cp, sp, ws, a_, b_, c_, X1[j, i], Y1[j, i], X2[j, i], Y2[j, i])
                for i in range(stages):
                    f += hB[i] * kp[i]
                    v += hB[i] * kw[i]
                out[j, q] = f
                out_w[j, q] = v
            phi[q], w[q] = f, v

    return _kernel


def _make_flow_kernel(stamp: int):
    """The kernel of :func:`rotation_flow`, closed over ``stamp``."""

    @numba.njit(cache=True, parallel=True)
    def _flow_kernel(phi, w, J, A, B, C, periods, X1, Y1, X2, Y2, hA, hB, jac, renorm, track, H, wind2pi,
                     logs, sec, pmin, pmax):
        """``periods[q]`` periods for point q of (phi, w) and, with ``jac``, of the variational
        matrix J[q] = (V00, V01, V10, V11), V = d(phi, w) / d(phi0, w0), by the same stages.
        With ``renorm`` only the first column of V is carried: a tangent vector, renormalised
        after every period, the log of its growth stored in logs[period, q]. The states at the
        end of every period go to sec[period, q] (raw phi, w); with ``track`` pmin/pmax hold the
        extremes of p = phi - H - wind2pi * period over every step end."""
        if stamp < 0:  # never: the closure's cell, which numba's cache keys on
            return
        n, stages = X1.shape
        full = jac and not renorm
        for q in numba.prange(phi.size):
            kp = np.empty(stages)
            kw = np.empty(stages)
            k0 = np.empty(stages)
            k1 = np.empty(stages)
            k2 = np.empty(stages)
            k3 = np.empty(stages)
            f, v, a_, b_, c_ = phi[q], w[q], A[q], B[q], C[q]
            j0, j1, j2, j3 = J[q, 0], J[q, 1], J[q, 2], J[q, 3]
            lo, hi = pmin[q], pmax[q]
            for per in range(periods[q]):
                for j in range(n):
                    cf, sf = np.cos(f), np.sin(f)
                    for i in range(stages):
                        dp, ws = 0.0, v
                        s0, s1, s2, s3 = j0, j1, j2, j3
                        for l in range(i):
                            c = hA[i, l]
                            dp += c * kp[l]
                            ws += c * kw[l]
                            if jac:
                                s0 += c * k0[l]
                                s2 += c * k2[l]
                                if full:
                                    s1 += c * k1[l]
                                    s3 += c * k3[l]
                        cp, sp = _near(cf, sf, f, dp)
                        if jac:
                            kp[i], kw[i], d = _rates(cp, sp, ws, a_, b_, c_, X1[j, i], Y1[j, i], X2[j, i], Y2[j, i])
                            k0[i] = s2
                            k2[i] = d * s0 - a_ * s2
                            if full:
                                k1[i] = s3
                                k3[i] = d * s1 - a_ * s3
                        else:
                            kp[i], kw[i], _ = _rates(cp, sp, ws, a_, b_, c_, X1[j, i], Y1[j, i], X2[j, i], Y2[j, i])
                    for i in range(stages):
                        f += hB[i] * kp[i]
                        v += hB[i] * kw[i]
                    if jac:
                        for i in range(stages):
                            j0 += hB[i] * k0[i]
                            j2 += hB[i] * k2[i]
                            if full:
                                j1 += hB[i] * k1[i]
                                j3 += hB[i] * k3[i]
                    if track:
                        p = f - H[j] - wind2pi * per
                        lo = min(lo, p)
                        hi = max(hi, p)
                sec[per, q, 0] = f
                sec[per, q, 1] = v
                if renorm:
                    norm = np.sqrt(j0 * j0 + j2 * j2)
                    logs[per, q] = np.log(norm)
                    j0 /= norm
                    j2 /= norm
            phi[q], w[q] = f, v
            J[q, 0], J[q, 1], J[q, 2], J[q, 3] = j0, j1, j2, j3
            pmin[q], pmax[q] = lo, hi

    return _flow_kernel


def _make_overdamped_kernel(stamp: int):
    """The kernel of :func:`overdamped_period`, closed over ``stamp``."""

    @numba.njit(cache=True, parallel=True)
    def _overdamped_kernel(phi, A, B, C, X1, Y1, X2, Y2, X3, Y3, n, corrected, out):
        if stamp < 0:  # never: the closure's cell, which numba's cache keys on
            return
        h = 2 * np.pi / n
        for q in numba.prange(phi.size):
            x, a_, b_, c_ = phi[q], A[q], B[q], C[q]
            for i in range(n):
                j = 2 * i
                c0, s0 = np.cos(x), np.sin(x)
                k1 = _overdamped_rate(c0, s0, j, a_, b_, c_, X1, Y1, X2, Y2, X3, Y3, corrected)
                cp, sp = _near(c0, s0, x, 0.5 * h * k1)
                k2 = _overdamped_rate(cp, sp, j + 1, a_, b_, c_, X1, Y1, X2, Y2, X3, Y3, corrected)
                cp, sp = _near(c0, s0, x, 0.5 * h * k2)
                k3 = _overdamped_rate(cp, sp, j + 1, a_, b_, c_, X1, Y1, X2, Y2, X3, Y3, corrected)
                cp, sp = _near(c0, s0, x, h * k3)
                k4 = _overdamped_rate(cp, sp, j + 2, a_, b_, c_, X1, Y1, X2, Y2, X3, Y3, corrected)
                x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
            out[q] = x

    return _overdamped_kernel


def _sources_stamp() -> int:
    """A hash of the modules the kernels compile in (as a 60-bit integer)."""
    here = Path(__file__)
    return source_stamp(here, here.parents[1] / "rotation" / "field.py", here.with_name("trig.py"))


_STAMP = _sources_stamp()
_kernel = _make_period_kernel(_STAMP)
_flow_kernel = _make_flow_kernel(_STAMP)
_overdamped_kernel = _make_overdamped_kernel(_STAMP)


def overdamped_period(phi, A, B, C, forcing, n: int, corrected: bool) -> np.ndarray:
    """The first-order heading of :mod:`lib.rotation.slow_eight` over one period: ``n`` classical RK4
    steps of phi_s = T / A (or with the first inertia correction), one point per parallel
    numba loop, from ``phi`` (rad) with coefficients ``A, B, C`` (broadcast with ``phi``);
    ``forcing`` is the unit eight's six derivatives (X', Y', X'', Y'', X''', Y''') at the
    2 n + 1 half-step phases. The same arithmetic as the vectorised numpy steps, point by
    point, but for the cos and sin of the stages' headings, taken from the step's
    (:func:`lib.integrators.trig.cos_sin_near`): they differ in the last bit.

    Parameters
    ----------
    phi : array_like
        Headings at the phase 0 (rad).
    A, B, C : array_like
        :func:`lib.rotation.field.coefficients`, broadcast with ``phi``.
    forcing : tuple of numpy.ndarray
        Six arrays of length 2 n + 1.
    n : int
        RK4 steps per period.
    corrected : bool
        With the first inertia correction.

    Returns
    -------
    numpy.ndarray
        The headings after one period (rad), of the broadcast shape.
    """
    phi, A, B, C = (np.ascontiguousarray(x, dtype=float) for x in np.broadcast_arrays(phi, A, B, C))
    f = [np.ascontiguousarray(x, dtype=float) for x in forcing]
    out = np.empty(phi.size)
    _overdamped_kernel(phi.ravel(), A.ravel(), B.ravel(), C.ravel(), *f, np.int64(n), np.bool_(corrected), out)
    return out.reshape(phi.shape)
