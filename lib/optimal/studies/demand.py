"""The price of exactness: the peak force (N) that *exact* tracking needs over one period, at
every point of Fig. 5's grid (:data:`lib.rotation.verdicts.FIG5_GRID`), for C and for the
centre of percussion P.

C exactly on the path (the paper's law in steady state, any heading): the force is fixed by
(2)-(3), m C_d'' + c C_d' = F (cos(phi + beta), sin(phi + beta)), so in the phase s = Theta t
of the circle (27) or the eight (28), C_d = R X(s),

    F_C(s) = R Theta |m Theta X''(s) + c X'(s)|,

on the circle the constant R Theta sqrt(m^2 Theta^2 + c^2): :func:`lib.optimal.bound.exact_peak_force`
(a dense search and Newton on the closed form).

P exactly on the path under Chapter 7's law (:mod:`lib.percussion`): with w = P_d'' + k P_d'
(k = c/m), the heading runs on the attracting orbit of the zero dynamics eps phi' = w . e2 and
the force is (:mod:`lib.percussion.zero_dynamics`, :func:`lib.percussion.percussion_steady`)

    u1 = m (w . e1 + s_P phi'^2),   u2 = (I_C phi'' + c_phi phi') / a,
    phi'' = (w' . e2 - (w . e1) phi') / eps,   F_P = |(u1, u2)|.

The orbit is found by Newton on the heading's exact period map
(:class:`lib.percussion.engine.HeadingMap`) at :data:`DENSE_STEPS` Magnus steps a period,
started at the orbit point of the verdict (:func:`lib.percussion.percussion_fig5_map`).

Each peak of P is an extreme, not a sample: F is sampled at :data:`DENSE_STEPS` points a period
along the orbit, the :data:`CANDIDATES` largest sampled local maxima are refined by golden-section
search on the continuous function over the two steps around each (the heading between samples
integrated from the sample by classical Runge-Kutta, :data:`RK4_SUBSTEPS` substeps), and the
largest refined value is returned. Its relative error is that of the Magnus orbit: about 1e-8 on
Fig. 5's grid for the eight (against 4096 steps), at most 3e-7 on the circle at R = 4 m,
Theta = 1.5 rad/s (against the closed form). The map of P over the 10^4 points takes about 10 s
of CPU, plus about 1 s for the verdicts when ``frame`` is not given.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from ...angles import wrap_angle
from ...machinery import checks
from ...params import Body
from ...percussion.engine import HeadingEngine, coefficients
from ...percussion.point import centre_of_percussion, lateral_drag_speed
from ...percussion.sweep import heading_sweep
from ...rotation.verdicts import FIG5_GRID
from ...trajectories import POSITIONS
from ..bound import exact_peak_force

__all__ = ["DENSE_STEPS", "CANDIDATES", "GOLDEN_ITERATIONS", "RK4_SUBSTEPS", "exact_force_map",
           "exact_force_maps"]

#: Magnus steps (and samples of F) per period of the dense search along the orbit of P
DENSE_STEPS = 2048
#: sampled local maxima refined per point
CANDIDATES = 4
#: golden-section iterations of the refinement; the bracket of two steps (2 * 2 pi / DENSE_STEPS
#: in phase) shrinks by 0.618^36 to about 2e-10, which moves F by a relative (2e-10)^2 F''/F
GOLDEN_ITERATIONS = 36
#: classical Runge-Kutta substeps of the heading from a sample to a point of its bracket (P)
RK4_SUBSTEPS = 4
_NEWTON_TOL = 1e-10          # rad: |period map(x) - x| accepted as the orbit
_NEWTON_PASSES = 8
_CHUNK = 1600                # points per block of the P search: its (chunk, DENSE_STEPS) arrays stay below 32 MB
_FRAME_COLUMNS = ("R", "Theta", "regime", "lost", "orbit_p", "period")
_INV_PHI = (math.sqrt(5.0) - 1.0) / 2.0


# --------------------------------------------------------------------------- checks


def _check_points(R, Theta) -> tuple[np.ndarray, np.ndarray]:
    R = checks.array("R", R, positive=True, nonempty=True)
    Theta = checks.array("Theta", Theta, positive=True, nonempty=True)
    try:
        R, Theta = np.broadcast_arrays(R, Theta)
    except ValueError as e:
        raise ValueError(f"R and Theta must broadcast together, got shapes {R.shape} and {Theta.shape}") from e
    return R, Theta


def _check_frame(frame, R: np.ndarray, Theta: np.ndarray) -> pd.DataFrame | None:
    if frame is None:
        return None
    checks.instance("frame", frame, pd.DataFrame)
    missing = [c for c in _FRAME_COLUMNS if c not in frame.columns]
    if missing:
        raise ValueError(f"frame must be a frame of lib.percussion.heading_sweep, missing columns {missing}")
    if len(frame) != R.size:
        raise ValueError(f"frame must have one row per point ({R.size}), got {len(frame)} rows")
    fR, fT = frame["R"].to_numpy(float), frame["Theta"].to_numpy(float)
    if not (np.allclose(fR, R.ravel(), rtol=1e-12, atol=0) and np.allclose(fT, Theta.ravel(), rtol=1e-12, atol=0)):
        raise ValueError("frame must be computed on the same points: its R and Theta columns differ from R, Theta")
    return frame


# --------------------------------------------------------------------------- shared search


def _golden_max(f, lo: np.ndarray, hi: np.ndarray, iterations: int = GOLDEN_ITERATIONS) -> np.ndarray:
    """The largest value of f (vectorised over rows, f(s) -> values) found by golden-section
    search on the brackets [lo, hi] (one per row), with the bracket ends' values included."""
    a, b = lo.copy(), hi.copy()
    best = np.maximum(f(a), f(b))
    c, d = b - _INV_PHI * (b - a), a + _INV_PHI * (b - a)
    fc, fd = f(c), f(d)
    for _ in range(iterations):
        left = fc >= fd                      # the maximum is in [a, d]
        best = np.maximum(best, np.maximum(fc, fd))
        a, b = np.where(left, a, c), np.where(left, d, b)
        new = np.where(left, b - _INV_PHI * (b - a), a + _INV_PHI * (b - a))
        fn = f(new)
        c, fc, d, fd = (np.where(left, new, d), np.where(left, fn, fd),
                        np.where(left, c, new), np.where(left, fc, fn))
    return np.maximum(best, np.maximum(fc, fd))


def _candidates(values: np.ndarray, k: int = CANDIDATES) -> np.ndarray:
    """Column indices (N, k) of the k largest local maxima of each cyclic row of ``values``
    (rows with fewer repeat their largest)."""
    peak = (values >= np.roll(values, 1, axis=1)) & (values >= np.roll(values, -1, axis=1))
    rows, cols = np.nonzero(peak)
    order = np.lexsort((-values[rows, cols], rows))
    rows, cols = rows[order], cols[order]
    rank = np.arange(rows.size) - np.searchsorted(rows, rows)
    keep = rank < k
    out = np.repeat(np.argmax(values, axis=1)[:, None], k, axis=1)
    out[rows[keep], rank[keep]] = cols[keep]
    return out


# --------------------------------------------------------------------------- P on the path


def _force_P(body: Body, kind: str, R, Theta, s, phi) -> np.ndarray:
    """F (N) with P on the path at phase s and heading phi (broadcast), from the zero dynamics."""
    k, eps, sP = body.c / body.m, lateral_drag_speed(body), centre_of_percussion(body)
    _, _, X1, Y1, X2, Y2, X3, Y3 = POSITIONS[kind](1.0, 1.0, s)
    a2, a1 = R * Theta**2, k * R * Theta
    wx, wy = a2 * X2 + a1 * X1, a2 * Y2 + a1 * Y1
    dwx, dwy = a2 * Theta * X3 + k * a2 * X2, a2 * Theta * Y3 + k * a2 * Y2
    c, sn = np.cos(phi), np.sin(phi)
    wa, wl = wx * c + wy * sn, wy * c - wx * sn
    om = wl / eps
    dom = ((dwy * c - dwx * sn) - wa * om) / eps
    u1 = body.m * (wa + sP * om**2)
    u2 = (body.I * dom + body.c_phi * om) / body.a
    return np.hypot(u1, u2)


def _slope(kind: str, cA, cV, s, phi):
    """d phi / ds of the zero dynamics (:mod:`lib.percussion.engine`'s alpha cos phi - beta sin phi)."""
    _, _, X1, Y1, X2, Y2, _, _ = POSITIONS[kind](1.0, 1.0, s)
    return (cA * Y2 + cV * Y1) * np.cos(phi) - (cA * X2 + cV * X1) * np.sin(phi)


def _heading_at(kind: str, cA, cV, s0, phi0, s):
    """The heading at phase s on the solution through (s0, phi0): RK4 in RK4_SUBSTEPS substeps."""
    dt = (s - s0) / RK4_SUBSTEPS
    x, phi = s0.copy(), phi0.copy()
    for _ in range(RK4_SUBSTEPS):
        k1 = _slope(kind, cA, cV, x, phi)
        k2 = _slope(kind, cA, cV, x + dt / 2, phi + dt / 2 * k1)
        k3 = _slope(kind, cA, cV, x + dt / 2, phi + dt / 2 * k2)
        k4 = _slope(kind, cA, cV, x + dt, phi + dt * k3)
        phi = phi + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        x = x + dt
    return phi


def _orbit(eng: HeadingEngine, cA, cV, x, where: str) -> dict:
    """One recorded period of the attracting orbit of the period map, found by Newton with the
    map's exact derivative from the start headings x (rad, at s = 0)."""
    x = np.asarray(x, float).copy()
    o = eng.flow(x, cA, cV, 1)
    x = x - wrap_angle(o["phi"] - x) / (np.exp(o["logs"][0]) - 1.0)
    rec = None
    todo = np.arange(x.size)
    for _ in range(_NEWTON_PASSES):
        o = eng.flow(x[todo], cA[todo], cV[todo], 1, record=True)
        d = wrap_angle(o["phi"] - x[todo])
        if rec is None:
            rec = o["p"].copy()
        else:
            rec[todo] = o["p"]
        ok = np.abs(d) <= _NEWTON_TOL
        x[todo[~ok]] -= d[~ok] / (np.exp(o["logs"][0, ~ok]) - 1.0)
        todo = todo[~ok]
        if todo.size == 0:
            return dict(phi=rec + eng.H[None, :])
    raise RuntimeError(f"Newton on the heading's period map did not converge to {_NEWTON_TOL:g} rad at "
                       f"{todo.size} point(s) {where}")


def _peak_force_P(body: Body, kind: str, R: np.ndarray, Theta: np.ndarray, x0: np.ndarray) -> np.ndarray:
    """The peak of F_P (N) over the attracting orbit through (near) x0 (rad at s = 0), 1-D."""
    eng = HeadingEngine(kind, DENSE_STEPS)
    h = eng.h
    s = np.arange(1, DENSE_STEPS + 1) * h
    out = np.empty(R.size)
    for lo in range(0, R.size, _CHUNK):
        sl = slice(lo, min(lo + _CHUNK, R.size))
        Rc, Tc = R[sl], Theta[sl]
        cA, cV = coefficients(body, Rc, Tc)
        where = f"(first at R = {Rc[0]:.6g} m, Theta = {Tc[0]:.6g} rad/s)"
        phi = _orbit(eng, cA, cV, x0[sl], where)["phi"]
        F = _force_P(body, kind, Rc[:, None], Tc[:, None], s[None, :], phi)
        idx = _candidates(F)
        n_c = idx.shape[1]
        s0, phi0 = s[idx].ravel(), np.take_along_axis(phi, idx, 1).ravel()
        rc, tc, ac, vc = (np.repeat(v, n_c) for v in (Rc, Tc, cA, cV))

        def f(x):
            return _force_P(body, kind, rc, tc, x, _heading_at(kind, ac, vc, s0, phi0, x))

        best = _golden_max(f, s0 - h, s0 + h).reshape(idx.shape).max(axis=1)
        out[sl] = np.maximum(best, F.max(axis=1))
    return out


def _held(frame: pd.DataFrame) -> np.ndarray:
    """Rows where the zero dynamics hold the heading on an attracting orbit of period 1."""
    return ((frame["regime"].to_numpy() == "periodic") & ~frame["lost"].to_numpy(bool)
            & (frame["period"].to_numpy() == 1) & np.isfinite(frame["orbit_p"].to_numpy(float)))


# --------------------------------------------------------------------------- public


def exact_force_map(body: Body, R, Theta, *, kind: str = "eight", point: str = "C",
                    frame: pd.DataFrame | None = None) -> np.ndarray:
    """The peak force (N) over one period that exact tracking of the path needs, at each
    (R, Theta) (broadcast).

    ``point="C"``: C exactly on the circle (27) or eight (28), any heading: the peak of
    |m C_d'' + c C_d'| (paper (2)-(3)), by :func:`lib.optimal.bound.exact_peak_force`.
    ``point="P"``: the centre of percussion P exactly on the path under Chapter 7's law, the
    heading on the zero dynamics' attracting orbit: the peak of F = |(u1, u2)| along that
    orbit (see the module's docstring); NaN where the zero dynamics do not hold the heading on an orbit of period 1 (regime not ``"periodic"``, or
    lost). Each peak of P is a refined extreme (dense search of :data:`DENSE_STEPS` samples a
    period, then golden-section search on the continuous function).

    Parameters
    ----------
    body : Body
        The body (m, I_C, a, c, c_phi).
    R : array_like
        Size of the path (m), > 0.
    Theta : array_like
        Rate of the reference (rad/s), > 0, broadcastable with ``R``.
    kind : str
        ``"eight"`` (28, default) or ``"circle"`` (27).
    point : str
        ``"C"`` (centre of mass) or ``"P"`` (centre of percussion).
    frame : pandas.DataFrame, optional
        For ``point="P"``: the verdicts of :func:`lib.percussion.heading_sweep` (e.g.
        :func:`lib.percussion.percussion_fig5_map`) of the same body and ``kind`` at the
        broadcast points in C order (columns R, Theta, regime, lost, orbit_p, period); None
        computes them. Checked, and unused, for ``point="C"``.

    Returns
    -------
    numpy.ndarray
        The peak force (N), the broadcast shape of ``R`` and ``Theta``.

    Raises
    ------
    TypeError, ValueError
        Naming the bad argument.
    RuntimeError
        If Newton does not find the orbit at a point the verdict holds.
    """
    checks.instance("body", body, Body)
    R, Theta = _check_points(R, Theta)
    checks.one_of("kind", kind, ("eight", "circle"))
    checks.one_of("point", point, ("C", "P"))
    frame = _check_frame(frame, R, Theta)
    Rf, Tf = R.ravel().copy(), Theta.ravel().copy()
    if point == "C":
        return np.asarray(exact_peak_force(body, Rf, Tf, kind=kind), float).reshape(R.shape)
    if frame is None:
        frame = heading_sweep(body, Rf, Tf, kind=kind)
    held = _held(frame)
    out = np.full(Rf.size, np.nan)
    if held.any():
        eng0 = HeadingEngine(kind, 2)
        x0 = eng0.H0 + frame["orbit_p"].to_numpy(float)[held]
        out[held] = _peak_force_P(body, kind, Rf[held], Tf[held], x0)
    return out.reshape(R.shape)


def exact_force_maps(body: Body, n: int = FIG5_GRID["n"], *, frame: pd.DataFrame | None = None) -> pd.DataFrame:
    """The peak force that exact tracking of the eight (28) needs, for C and for P, on the
    n x n grid of Fig. 5 (:data:`lib.rotation.verdicts.FIG5_GRID`, Theta varying slowest, as
    :func:`lib.percussion.percussion_fig5_map` lays it out).

    Parameters
    ----------
    body : Body
        The body.
    n : int
        Points per side (>= 2); default ``FIG5_GRID["n"]``.
    frame : pandas.DataFrame, optional
        :func:`lib.percussion.percussion_fig5_map` of ``body`` with the same ``n`` (so the map
        of the verdicts is computed once); None computes it.

    Returns
    -------
    pandas.DataFrame
        n^2 rows: R (m), Theta (rad/s), F_C (N), F_P (N; NaN where the heading is not held),
        ratio = F_P / F_C.
    """
    checks.instance("body", body, Body)
    n = checks.integer("n", n, minimum=2)
    R, Th = np.meshgrid(np.linspace(*FIG5_GRID["R"], n), np.linspace(*FIG5_GRID["Theta"], n))
    R, Th = R.ravel(), Th.ravel()
    frame = _check_frame(frame, R, Th)
    F_C = exact_force_map(body, R, Th, kind="eight", point="C")
    F_P = exact_force_map(body, R, Th, kind="eight", point="P", frame=frame)
    return pd.DataFrame({"R": R, "Theta": Th, "F_C": F_C, "F_P": F_P, "ratio": F_P / F_C})
