"""The reduced rotation equation (32) on a reference, for many (R, Theta) points at once
(paper Sec. 6, Fig. 5): its integration, the steady state of the rotation error,
periodic orbits of its period map with their Floquet multipliers, and its largest
Lyapunov exponent. The decisive verdicts of Fig. 5 built on these are in
:mod:`lib.rotation.verdicts`.

Starting on the reference the position errors stay zero and the closed loop
reduces exactly to (32) in the heading (:mod:`lib.rotation.equations`). The field
is :func:`lib.rotation.field.rotation_rates`, in the phase s = Theta t so that all
points share one time grid; the batch integrator (:mod:`lib.integrators.batch`,
fixed-step 8th-order Dormand-Prince) or its compiled engine
(:mod:`lib.integrators.compiled`) advances all points together.

Units: R in m, Theta in rad/s, angles in rad, the phase s in rad; w = d phi / ds.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..machinery import checks
from ..dynamics.orbits import MapWithJacobian, Orbit, newton_orbit
from ..integrators import batch
from ..params import Body
from .field import coefficients, rotation_rates, rotation_rates_dphi
from ..dynamics.sampled import classify_samples, sampled_extremes, sampled_range  # re-exported
from .slow_eight import SlowEight, slow_eight_prediction  # re-exported: Chapter 5's slow eights
from ..trajectories import KINEMATICS, POSITIONS

__all__ = [
    "check_grid", "steps_per_period", "reduced_rotation", "classify_samples", "sampled_range", "sampled_extremes", "rotation_sweep",
    "ENGINES", "rotation_period_map", "rotation_orbit", "RotationLyapunov",
    "rotation_lyapunov", "WINDING", "SlowEight", "slow_eight_prediction",
]


#: turns of the reference heading per period
WINDING = {"eight": 0, "circle": 1}


def _shape(kind: str):
    """Unit reference (R = 1 m, theta = 1 rad/s) of ``kind``: with s = Theta t,
    x_d = R X(s), y_d = R Y(s), phi_d = H(s). Returns a function of s giving
    (X', Y', X'', Y'', H, H') and the winding of H per period (turns)."""
    kin = KINEMATICS[kind]

    def at(s):
        z, dz, ddz = kin(1.0, 1.0, np.asarray(s, dtype=float))
        return dz[..., 0], dz[..., 1], ddz[..., 0], ddz[..., 1], z[..., 2], dz[..., 2]

    return at, WINDING[kind]


def _unit_forcing(kind: str, s):
    """(X', Y', X'', Y'') of the unit reference at the phase s (scalar or array)."""
    _, _, vx, vy, ax, ay, _, _ = POSITIONS[kind](1.0, 1.0, s)
    return vx, vy, ax, ay


def check_grid(R, Theta) -> tuple[np.ndarray, np.ndarray]:
    """The points (R_i (m), Theta_i (rad/s)) of a sweep as two equal 1-D float arrays,
    by :mod:`lib.machinery.checks` (a NaN or a non-positive entry is named by its index);
    a length-1 R or Theta is broadcast to the other's length. Every sweep over the
    (R, Theta) plane checks its grid with it (Chapters 5 and 7).

    Parameters
    ----------
    R, Theta : array_like
        Radii (m) and rates (rad/s), 1-D, > 0, of equal lengths (or one of length 1).

    Returns
    -------
    tuple of numpy.ndarray
        R and Theta, 1-D float arrays of one length.

    Raises
    ------
    ValueError
        Naming the array and the index of a NaN or non-positive entry, or the shapes.
    """
    R = np.atleast_1d(checks.array("R", R))
    Theta = np.atleast_1d(checks.array("Theta", Theta))
    if R.ndim != 1 or Theta.ndim != 1:
        raise ValueError(f"R and Theta must be 1-D arrays (one grid point per pair), got shapes {R.shape}, {Theta.shape}")
    if R.size == 0:
        raise ValueError("R and Theta must not be empty")
    if R.shape != Theta.shape:
        if min(R.size, Theta.size) != 1:
            raise ValueError(f"R and Theta must have equal lengths (or length 1), got {R.size} and {Theta.size}")
        R, Theta = np.broadcast_arrays(R, Theta)          # one radius or one rate for every point
    return checks.array("R", R, positive=True), checks.array("Theta", Theta, positive=True)



def steps_per_period(body: Body, kind: str, R, Theta, h_lambda: float = 0.125) -> np.ndarray:
    """Fixed steps per reference period for each point: a power of two (>= 64)
    such that h Lambda <= ``h_lambda``, where Lambda = A + sqrt(B v_max + C a_max)
    bounds the moduli of the eigenvalues of the linearised equation (in s).

    Parameters
    ----------
    body : Body
        The body.
    kind : str
        ``"eight"`` or ``"circle"``.
    R, Theta : array_like
        Radii (m) and rates (rad/s), 1-D.
    h_lambda : float
        The bound on h Lambda.

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
    lam = A + np.sqrt(B * vmax + C * amax)
    need = 2 * np.pi * lam / h_lambda
    return np.maximum(64, 2 ** np.ceil(np.log2(need))).astype(int)


def reduced_rotation(body: Body, kind: str, R: float, Theta: float, periods: int, *, steps: int | None = None,
                     p0: float = 0.0, v0: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Integrate the reduced rotation equation (32) on the reference ``kind`` from
    p(0) = ``p0`` (rad), dp/dt(0) = ``v0`` (rad/s), p = phi - phi_d, for ``periods``
    reference periods. Returns (t (s), p (rad)) at every step (and t = 0).

    This is the exact closed loop (23), (25)-(26) when the position starts on the
    reference (the position errors then stay zero).

    Parameters
    ----------
    body : Body
        The body.
    kind : str
        ``"eight"`` or ``"circle"``.
    R : float
        Radius (m).
    Theta : float
        Rate (rad/s).
    periods : int
        Reference periods.
    steps : int, optional
        Steps per period (default :func:`steps_per_period`).
    p0, v0 : float
        Start (rad, rad/s).

    Returns
    -------
    t : numpy.ndarray
        Times (s).
    p : numpy.ndarray
        The rotation error (rad).
    """
    R_, Th_ = check_grid(R, Theta)
    n = int(steps or steps_per_period(body, kind, R_, Th_)[0])
    at, winding = _shape(kind)
    phi, w = _run(body, kind, R_, Th_, n, periods, np.array([p0]), np.array([v0]), record=True)
    s = np.arange(phi.shape[0]) * 2 * np.pi / n
    H = at(s)[4]
    return s / Theta, phi[:, 0] - H


def _forcing(kind: str, n: int):
    """Stage phases of one period and the unit reference there, for n steps per period."""
    Cc = batch.dop853().c
    at, winding = _shape(kind)
    h = 2 * np.pi / n
    X1, Y1, X2, Y2, _, _ = at((np.arange(n)[:, None] + Cc[None, :]) * h)
    _, _, _, _, H, H1 = at(np.arange(1, n + 1) * h)
    return h, X1, Y1, X2, Y2, (H, H1), winding


def _period(phi, w, A, B, C, h, X1, Y1, X2, Y2, kind):
    """One reference period for all points by the batch integrator (numpy engine);
    returns ((phi, w) at every step end, each of shape (n, N)), final phi, final w)."""
    n = X1.shape[0]

    def rates(s, Y):
        return np.stack(rotation_rates(Y[0], Y[1], A, B, C, *_unit_forcing(kind, s)))

    out = np.empty((n,) + np.shape(phi))
    out_w = np.empty_like(out)
    for j, (_, Y) in enumerate(batch.steps(rates, np.stack([phi, w]), 0.0, h, n, batch.dop853())):
        out[j], out_w[j] = Y
    return (out, out_w), out[-1].copy(), out_w[-1].copy()


def _period_compiled(phi, w, A, B, C, h, X1, Y1, X2, Y2, kind):
    """:func:`_period` by the compiled engine (numba; the default, see the benchmark)."""
    # imported here, not at the top: lib.integrators.compiled imports lib.rotation.field, whose package's
    # __init__ imports this module, so a top-level import would meet compiled half initialised whenever it
    # is imported first (tests/test_layout.py: the cycle through a package)
    from ..integrators.compiled import rotation_period

    tab = batch.dop853()
    return rotation_period(phi, w, A, B, C, h, X1, Y1, X2, Y2, tab.A * h, tab.b * h)


ENGINES = {"numba": _period_compiled, "numpy": _period}


def _initial(kind, Theta, p0, v0):
    at, _ = _shape(kind)
    _, _, _, _, H0, H10 = at(0.0)
    return H0 + p0, H10 + v0 / Theta


def _run(body, kind, R, Theta, n, periods, p0, v0, record=False):
    """Fixed-step DOP853 in s for all points at once; with ``record`` the states at every step."""
    h, X1, Y1, X2, Y2, H, winding = _forcing(kind, n)
    A, B, C = coefficients(body, R, Theta)
    phi, w = _initial(kind, Theta, p0, v0)
    outs = [phi[None].copy()]
    for _ in range(periods):
        (out, _), phi, w = _period(phi, w, A, B, C, h, X1, Y1, X2, Y2, kind)
        outs.append(out)
    return np.concatenate(outs), w


def rotation_sweep(body: Body, kind: str, R, Theta, *, p0=0.0, v0=0.0, tol: float = 1e-9,
                   min_periods: int = 4, max_periods: int = 200, max_lag: int = 4,
                   h_lambda: float = 0.125, steps: int | None = None, engine: str = "numba") -> pd.DataFrame:
    """Steady state of the rotation error p = phi - phi_d on the reference ``kind``
    (``"eight"`` or ``"circle"``) for every grid point (R_i, Theta_i), started on the
    reference with p(0) = ``p0`` (rad) and dp/dt(0) = ``v0`` (rad/s) (scalars or arrays),
    decided by waiting: the classifier of the first edition of Fig. 5, kept for
    comparison (:func:`lib.rotation.verdicts.rotation_verdicts` decides every point
    instead and is what :func:`lib.rotation.verdicts.eight_rotation_sweep` uses).

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

    Parameters
    ----------
    body : Body
        The body.
    kind : str
        ``"eight"`` or ``"circle"``.
    R, Theta : array_like
        Radii (m) and rates (rad/s), 1-D, > 0.
    p0, v0 : float or array_like
        Start (rad, rad/s).
    tol : float
        Defect tolerance (rad).
    min_periods, max_periods, max_lag : int
        Periods integrated at least and at most, and the longest lag tried.
    h_lambda : float
        Step bound (see :func:`steps_per_period`).
    steps : int, optional
        Steps per period.
    engine : str
        ``"numba"`` or ``"numpy"``.

    Returns
    -------
    pandas.DataFrame
        One row per point (columns above).
    """
    checks.one_of("kind", kind, ("eight", "circle"))
    checks.instance("body", body, Body)
    R, Theta = check_grid(R, Theta)
    N = R.size
    p0 = np.broadcast_to(checks.array("p0", p0), (N,)).copy()
    v0 = np.broadcast_to(checks.array("v0", v0), (N,)).copy()
    min_periods = checks.integer("min_periods", min_periods, minimum=1)
    max_lag = checks.integer("max_lag", max_lag, minimum=1)
    max_periods = checks.integer("max_periods", max_periods, minimum=max(min_periods, max_lag + 1))
    step_period = ENGINES[checks.one_of("engine", engine, sorted(ENGINES))]
    tol = checks.number("tol", tol, positive=True)
    h_lambda = checks.number("h_lambda", h_lambda, positive=True)
    checks.heading_damping(body, Theta)               # the verdicts' domain, before any run
    n_dom = steps_per_period(body, kind, R, Theta, h_lambda)
    checks.steps_domain(n_dom, 2 * np.pi * coefficients(body, R, Theta)[0] / h_lambda, R, Theta)
    n_pts = np.full(N, checks.integer("steps", steps, minimum=8)) if steps is not None else n_dom
    cols = {k: np.empty(N, dtype=object if k == "regime" else float)
            for k in ("range", "regime", "period", "slip", "defect", "periods")}
    for n in np.unique(n_pts):
        idx = np.flatnonzero(n_pts == n)
        h, X1, Y1, X2, Y2, (H, H1), winding = _forcing(kind, int(n))
        A, B, C = coefficients(body, R[idx], Theta[idx])
        phi, w = _initial(kind, Theta[idx], p0[idx], v0[idx])
        P = np.zeros((max_lag + 1, idx.size, int(n)))
        dP = np.zeros_like(P)
        for k in range(1, max_periods + 1):
            (out, out_w), phi, w = step_period(phi, w, A, B, C, h, X1, Y1, X2, Y2, kind)
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


def rotation_period_map(body: Body, kind: str, R, Theta, *, steps: int | None = None,
                        h_lambda: float = 0.125) -> MapWithJacobian:
    """The period map of the reduced rotation equation (32) on the reference ``kind``
    (``"eight"`` or ``"circle"``) for the points (R_i (m), Theta_i (rad/s)), all with
    the same number of fixed steps per period (``steps``, or the largest that
    :func:`steps_per_period` asks for).

    The returned function maps states x = (phi, w) of shape (N, 2) at phase
    s = 0 (mod 2 pi) to the states one reference period later, with the Jacobian
    d x(2 pi) / d x(0) (N, 2, 2); phi is the heading (rad) and w = d phi / ds. Its
    attribute ``winding`` is the number of turns the reference heading makes per
    period (0 on the eight, 1 on the circle).

    Parameters
    ----------
    body : Body
        The body.
    kind : str
        ``"eight"`` or ``"circle"``.
    R, Theta : array_like
        Radii (m) and rates (rad/s), 1-D, > 0.
    steps : int, optional
        Steps per period (>= 1).
    h_lambda : float
        Step bound when ``steps`` is not given.

    Returns
    -------
    callable
        x (N, 2) -> (x one period later (N, 2), Jacobian (N, 2, 2)).
    """
    checks.one_of("kind", kind, ("eight", "circle"))
    checks.instance("body", body, Body)
    R, Theta = check_grid(R, Theta)
    n = (checks.integer("steps", steps, minimum=1) if steps is not None
         else int(steps_per_period(body, kind, R, Theta, h_lambda).max()))
    A, B, C = coefficients(body, R, Theta)
    h = 2 * np.pi / n

    def rates(s, Y):  # Y = (phi, w, V00, V01, V10, V11), V = d(phi, w) / d(phi0, w0)
        X1, Y1, X2, Y2 = _unit_forcing(kind, s)
        dphi, dw = rotation_rates(Y[0], Y[1], A, B, C, X1, Y1, X2, Y2)
        d = rotation_rates_dphi(Y[0], B, C, X1, Y1, X2, Y2)
        return np.stack([dphi, dw, Y[4], Y[5], d * Y[2] - A * Y[4], d * Y[3] - A * Y[5]])

    def step(x):
        x = np.asarray(x, dtype=float)
        if x.shape != (R.size, 2):
            raise ValueError(f"states must have shape ({R.size}, 2), got {x.shape}")
        Y = np.concatenate([x.T, np.tile(np.eye(2).reshape(4, 1), (1, R.size))])
        for _, Y in batch.steps(rates, Y, 0.0, h, n, batch.dop853()):
            pass
        return Y[:2].T.copy(), np.moveaxis(Y[2:].reshape(2, 2, -1), -1, 0)

    winding = WINDING[kind]
    step.winding = winding  # turns of the reference heading per period (eight 0, circle 1)
    return step


def rotation_orbit(body: Body, kind: str, R, Theta, *, k: int = 1, slip: int = 0, p0=0.0, v0=0.0,
                   transient: int = 10, steps: int | None = None, tol: float = 1e-11) -> Orbit:
    """Locate a period-``k`` orbit of the heading on the reference ``kind`` at each point
    (R_i (m), Theta_i (rad/s)), starting Newton from the state reached after
    ``transient`` periods from p(0) = ``p0`` (rad), dp/dt(0) = ``v0`` (rad/s) (the start
    on the reference by default). ``slip`` is the number of whole turns the heading
    error gains per k periods (0 for a repeating motion). The orbit's ``x`` are the
    states (phi, w = d phi / ds) at phase s = 0.

    Parameters
    ----------
    body : Body
        The body.
    kind : str
        ``"eight"`` or ``"circle"``.
    R, Theta : array_like
        Radii (m) and rates (rad/s), 1-D, > 0.
    k : int
        Period (reference periods).
    slip : int
        Whole turns per k periods.
    p0, v0 : float or array_like
        Start (rad, rad/s).
    transient : int
        Periods before Newton starts.
    steps : int, optional
        Steps per period.
    tol : float
        Newton's tolerance (rad).

    Returns
    -------
    Orbit
        The orbit points x (N, 2), the Jacobian there, residuals, convergence and iterations.
    """
    R, Theta = check_grid(R, Theta)
    step = rotation_period_map(body, kind, R, Theta, steps=steps)
    phi, w = _initial(kind, Theta, np.broadcast_to(np.asarray(p0, float), R.shape),
                      np.broadcast_to(np.asarray(v0, float), R.shape))
    x = np.column_stack([phi, w])
    winding = step.winding
    for _ in range(transient):
        x, _ = step(x)
    x[:, 0] -= 2 * np.pi * winding * transient
    shift = np.array([2 * np.pi * (winding * k + slip), 0.0])
    return newton_orbit(step, x, k, shift, tol=tol)


@dataclass(frozen=True)
class RotationLyapunov:
    """Largest Lyapunov exponent of the reduced rotation equation at N points:
    ``value`` (N,) in 1/s, ``stderr`` (N,) its standard error over the periods
    averaged, and ``periods`` the number of periods averaged."""

    value: np.ndarray
    stderr: np.ndarray
    periods: int


def rotation_lyapunov(body: Body, kind: str, R, Theta, *, periods: int = 200, transient: int = 50,
                      p0=0.0, v0=0.0, steps: int | None = None) -> RotationLyapunov:
    """Largest Lyapunov exponent (1/s) of the heading on the reference ``kind`` at each point
    (R_i (m), Theta_i (rad/s)), from p(0) = ``p0``, dp/dt(0) = ``v0`` (the reference start
    by default): after ``transient`` periods a tangent vector is carried by the exact
    Jacobian of the period map (:func:`rotation_period_map`) and renormalised every
    period; the exponent is the mean of the ``periods`` logarithmic growth rates
    divided by the period 2 pi / Theta, and its standard error that of the mean (the
    rates of successive periods are treated as independent, which is what makes the
    error small only for long runs).

    Parameters
    ----------
    body : Body
        The body.
    kind : str
        ``"eight"`` or ``"circle"``.
    R, Theta : array_like
        Radii (m) and rates (rad/s), 1-D, > 0.
    periods : int
        Periods averaged (>= 2).
    transient : int
        Periods dropped (>= 0).
    p0, v0 : float or array_like
        Start (rad, rad/s).
    steps : int, optional
        Steps per period.

    Returns
    -------
    RotationLyapunov
        value and stderr (1/s) and the periods averaged, one per point.
    """
    periods = checks.integer("periods", periods, minimum=2)
    transient = checks.integer("transient", transient, minimum=0)
    R, Theta = check_grid(R, Theta)
    step = rotation_period_map(body, kind, R, Theta, steps=steps)
    phi, w = _initial(kind, Theta, np.broadcast_to(np.asarray(p0, float), R.shape),
                      np.broadcast_to(np.asarray(v0, float), R.shape))
    x = np.column_stack([phi, w])
    for _ in range(transient):
        x, _ = step(x)
    u = np.tile(np.array([1.0, 1.0]) / np.sqrt(2.0), (R.size, 1))
    logs = np.empty((periods, R.size))
    for i in range(periods):
        x, J = step(x)
        u = np.einsum("nij,nj->ni", J, u)
        norm = np.linalg.norm(u, axis=1)
        logs[i] = np.log(norm)
        u = u / norm[:, None]
    rates = logs * (Theta / (2 * np.pi))
    return RotationLyapunov(value=rates.mean(axis=0), stderr=rates.std(axis=0, ddof=1) / np.sqrt(periods),
                            periods=int(periods))
