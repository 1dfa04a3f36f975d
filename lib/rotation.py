"""The reduced rotation equation (32) on a reference, for many (R, Theta) points at once
(paper Sec. 6, Fig. 5): its integration, the steady state of the rotation error,
periodic orbits of its period map with their Floquet multipliers, and its largest
Lyapunov exponent.

Starting on the reference the position errors stay zero and the closed loop
reduces exactly to (32) in the heading (:mod:`lib.rotation_equations`). The field
is :func:`lib.rotation_field.rotation_rates`, in the phase s = Theta t so that all
points share one time grid; the batch integrator (:mod:`lib.integrators.batch`,
fixed-step 8th-order Dormand-Prince) or its compiled engine
(:mod:`lib.integrators.compiled`) advances all points together.

Units: R in m, Theta in rad/s, angles in rad, the phase s in rad; w = d phi / ds.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from .dynamics.orbits import Orbit, floquet_multipliers, newton_orbit
from .integrators import batch
from .params import Body
from .rotation_field import coefficients, rotation_rates, rotation_rates_dphi
from .trajectories import KINEMATICS, POSITIONS

__all__ = [
    "steps_per_period", "reduced_rotation", "classify_samples", "sampled_range", "rotation_sweep",
    "eight_rotation_sweep", "ENGINES", "rotation_period_map", "rotation_orbit", "RotationLyapunov",
    "rotation_lyapunov", "WINDING", "REGIMES", "verdict_steps", "rotation_verdicts", "RotationAttractor",
    "rotation_attractor",
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


def steps_per_period(body: Body, kind: str, R, Theta, h_lambda: float = 0.125) -> np.ndarray:
    """Fixed steps per reference period for each point: a power of two (>= 64)
    such that h Lambda <= ``h_lambda``, where Lambda = A + sqrt(B v_max + C a_max)
    bounds the moduli of the eigenvalues of the linearised equation (in s)."""
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
    from .integrators.compiled import rotation_period  # numba's import and compile cost seconds

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
    reference with p(0) = ``p0`` (rad) and dp/dt(0) = ``v0`` (rad/s) (scalars or arrays),
    decided by waiting: the classifier of the first edition of Fig. 5, kept for
    comparison (:func:`rotation_verdicts` decides every point instead and is what
    :func:`eight_rotation_sweep` uses).

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


def eight_rotation_sweep(body: Body, R, Theta, **options) -> pd.DataFrame:
    """Fig. 5: the verdict on the rotation error on the eight (28) and its steady-state
    range, started on the reference, for each pair (R_i (m), Theta_i (rad/s)): periodic,
    slipping, chaotic, quasiperiodic or undecided, decided by :func:`rotation_verdicts`
    (Newton on the period map of (32) and the largest Lyapunov exponent). See there for
    the options and the columns (including ``lost``)."""
    return rotation_verdicts(body, "eight", R, Theta, **options)


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
    """
    if kind not in ("eight", "circle"):
        raise ValueError(f"kind must be 'eight' or 'circle', got {kind!r}")
    if not isinstance(body, Body):
        raise TypeError(f"body must be a lib.params.Body, got {type(body).__name__}")
    R, Theta = _check_grid(R, Theta)
    n = int(steps) if steps is not None else int(steps_per_period(body, kind, R, Theta, h_lambda).max())
    if n < 1:
        raise ValueError(f"steps must be a positive integer, got {steps!r}")
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
    states (phi, w = d phi / ds) at phase s = 0."""
    R, Theta = _check_grid(R, Theta)
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
    """
    if not isinstance(periods, (int, np.integer)) or periods < 2:
        raise ValueError(f"periods must be an integer >= 2, got {periods!r}")
    if not isinstance(transient, (int, np.integer)) or transient < 0:
        raise ValueError(f"transient must be a non-negative integer, got {transient!r}")
    R, Theta = _check_grid(R, Theta)
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


# ====================================================================== decisive verdicts
#
# Each point's verdict is decided, not waited for: a short transient, then Newton on
# the period map for an orbit that the transient is shown to approach; failing that,
# the largest Lyapunov exponent with an honest error bar.

#: the verdicts of :func:`rotation_verdicts`
REGIMES = ("periodic", "slipping", "chaotic", "quasiperiodic", "undecided")


def verdict_steps(body: Body, kind: str, R, Theta, h_lambda: float = 0.125, h_damp: float = 1.0) -> np.ndarray:
    """Fixed steps per reference period for :func:`rotation_verdicts`: the smallest
    multiple of 32 (>= 64) with h omega <= ``h_lambda`` and h A <= ``h_damp``, where
    omega = sqrt(B v_max + C a_max) bounds the frequencies of the linearised equation
    (32) (in the phase s) and A is its damping. The damping only sets how fast a
    transient in w dies out, which the 8th-order scheme follows well beyond h A = 1,
    so this asks for about half the steps of :func:`steps_per_period` at the same
    accuracy of the attractor (about 1e-10 rad per period)."""
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
        self.H0 = _shape(kind)[0](0.0)[4]

    def flow(self, phi, w, A, B, C, periods, *, jac=False, renorm=False, track=False):
        H = self.H if track else None
        if self.engine == "numba":
            from .integrators.compiled import rotation_flow

            return rotation_flow(phi, w, A, B, C, periods, self.X1, self.Y1, self.X2, self.Y2, self.hA, self.hB,
                                 jac=jac, renorm=renorm, H=H, wind2pi=self.w2pi)
        return _flow_numpy(self, phi, w, A, B, C, periods, jac=jac, renorm=renorm, H=H)

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


def _wrap(a):
    """Angle a (rad) wrapped to [-pi, pi)."""
    return (np.asarray(a) + np.pi) % (2 * np.pi) - np.pi


def _candidates(hist, max_period: int, cand_tol: float):
    """Lags k <= ``max_period`` at which the last two section states ``hist`` (L, N, 2) (phi
    reduced by the reference's winding) repeat within ``cand_tol``, up to whole turns n of
    phi: returns (ok, n, defect), each (max_period, N), row k - 1 for lag k."""
    L, N = hist.shape[:2]
    K = min(max_period, L - 2)
    dd = np.full((max_period, N), np.inf)
    nn = np.zeros((max_period, N), int)
    for k in range(1, K + 1):
        worst = np.zeros(N)
        for end in (-1, -2):   # the last two section states both repeat (a chance return does not)
            dphi = hist[end, :, 0] - hist[end - k, :, 0]
            n = np.round(dphi / (2 * np.pi))
            d = np.maximum(np.abs(dphi - 2 * np.pi * n), np.abs(hist[end, :, 1] - hist[end - k, :, 1]))
            worst = np.maximum(worst, d)
            if end == -1:
                nn[k - 1] = n.astype(int)
        dd[k - 1] = worst
    return dd <= cand_tol, nn, dd


def _newton(eng: _Engine, A, B, C, x, k, nslip, tol: float, max_iter: int = 15, max_step: float = 1.0):
    """Newton on P^k(x) - x - (2 pi (n + winding k), 0) for each point (its own k, n), with the
    exact Jacobian of the compiled map. Returns x (N, 2), DP^k there (N, 2, 2), residual (N,)."""
    x = np.array(x, float)
    N = x.shape[0]
    J = np.tile(np.eye(2), (N, 1, 1))
    res = np.full(N, np.inf)
    prev = np.full(N, np.inf)
    todo = np.arange(N)
    for it in range(max_iter + 1):
        o = eng.flow(x[todo, 0], x[todo, 1], A[todo], B[todo], C[todo], k[todo], jac=True)
        G = np.column_stack([o["phi"] - x[todo, 0] - 2 * np.pi * (nslip[todo] + eng.winding * k[todo]),
                             o["w"] - x[todo, 1]])
        r = np.max(np.abs(G), axis=1)
        J[todo], res[todo] = o["J"], r
        stop = ~np.isfinite(r) | ((r <= tol) & ((r <= 1e-13) | (r > 0.5 * prev[todo]))) | (it == max_iter)
        prev[todo] = r
        go = ~stop
        if not go.any():
            break
        Jg, Gg = o["J"][go], G[go]
        a, b, c, d = Jg[:, 0, 0] - 1, Jg[:, 0, 1], Jg[:, 1, 0], Jg[:, 1, 1] - 1
        det = a * d - b * c
        with np.errstate(divide="ignore", invalid="ignore"):
            dx = np.column_stack([-(d * Gg[:, 0] - b * Gg[:, 1]) / det, -(-c * Gg[:, 0] + a * Gg[:, 1]) / det])
        scale = np.maximum(1.0, np.max(np.abs(dx), axis=1) / max_step)
        bad = ~np.all(np.isfinite(dx), axis=1)
        dx[bad] = 0.0
        todo_go = todo[go]
        x[todo_go] += dx / scale[:, None]
        res[todo_go[bad]] = np.nan
        todo = todo_go[~bad]
        if todo.size == 0:
            break
    return x, J, res


def _orbit_points(eng: _Engine, A, B, C, x, k):
    """The k section states of each orbit (phi reduced by the reference's winding), (K, N, 2),
    NaN past a point's own k."""
    o = eng.flow(x[:, 0], x[:, 1], A, B, C, k)
    sec = o["sec"]
    sec[:, :, 0] -= eng.w2pi * np.arange(1, sec.shape[0] + 1)[:, None]
    return sec


def _distance(state, pts):
    """Distance (max-norm, phi modulo 2 pi) from states (N, 2) to the nearest of the orbit points
    (K, N, 2), and the index of that point."""
    d = np.maximum(np.abs(_wrap(state[None, :, 0] - pts[:, :, 0])), np.abs(state[None, :, 1] - pts[:, :, 1]))
    d = np.where(np.isnan(d), np.inf, d)
    j = d.argmin(axis=0)
    return d[j, np.arange(d.shape[1])], j


def _try_orbits(eng, A, B, C, hist, opts, tried=None):
    """For points whose recent section states ``hist`` (L, N, 2) nearly repeat at some lag k:
    Newton for the period-k orbit (k = 1, 2, ... in turn, each point until one is reached),
    its Floquet multipliers, and whether the run reaches it: close to one of its k points
    and closing in over the last periods at a rate consistent with its slowest multiplier.
    ``tried`` (max_period, N), updated in place: the lag-k defect at which Newton last failed
    for each point; lag k is tried again only once the defect has halved.
    Returns a dict of arrays (N,): found (bool) and the orbit reached."""
    N = hist.shape[1]
    cand, nslip, defect = _candidates(hist, opts["max_period"], opts["candidate_tol"])
    if tried is not None:
        cand &= defect < 0.5 * tried
    out = dict(found=np.zeros(N, bool), k=np.zeros(N, int), n=np.zeros(N, int), x=np.full((N, 2), np.nan),
               mult=np.full((N, 2), np.nan + 0j), residual=np.full(N, np.nan), distance=np.full(N, np.nan),
               orbit_p=np.full(N, np.nan))
    L = hist.shape[0] - 1
    # an attracting orbit of period d found but not yet reached: its multiples k would
    # find the same orbit again; wait for the run to come closer instead
    waiting = np.zeros((cand.shape[0], N), bool)
    for kk in range(1, cand.shape[0] + 1):
        c = np.flatnonzero(cand[kk - 1] & ~out["found"] & ~waiting[kk - 1])
        if c.size == 0:
            continue
        k = np.full(c.size, kk)
        x, J, res = _newton(eng, A[c], B[c], C[c], hist[-1, c], k, nslip[kk - 1, c], opts["newton_tol"])
        ok = res <= opts["newton_tol"]
        mult = np.full((c.size, 2), np.nan + 0j)
        if ok.any():
            mult[ok] = floquet_multipliers(J[ok])
        att = ok & (np.abs(mult[:, 0]) < 1.0)
        waiting[kk - 1::kk, c[att]] = True
        if not att.any():
            if tried is not None:
                tried[kk - 1, c] = defect[kk - 1, c]
            continue
        a = c[att]
        pts = _orbit_points(eng, A[a], B[a], C[a], x[att], k[att])
        # the orbit's least period: a period-d orbit (d | k) is also a fixed point of P^k
        kmin, nmin = np.full(a.size, kk), nslip[kk - 1, a].copy()
        for d in range(kk - 1, 0, -1):
            if kk % d:
                continue
            dphi = pts[d - 1, :, 0] - x[att, 0]
            nd = np.round(dphi / (2 * np.pi))
            same = np.maximum(np.abs(dphi - 2 * np.pi * nd), np.abs(pts[d - 1, :, 1] - x[att, 1])) <= 1e-8
            kmin[same], nmin[same] = d, nd[same].astype(int)
        d_now, j_now = _distance(hist[-1, a], pts)
        m = min(L, kk * max(1, L // kk))
        d_then, _ = _distance(hist[L - m, a], pts)
        rho = np.abs(mult[att, 0])
        floor = opts["reach_floor"]
        shrink = (d_now < d_then) & (d_now <= 3.0 * d_then * rho ** (m / kk) + floor)
        reached = (d_now <= floor) | ((d_now <= opts["reach_tol"]) & shrink)
        g = a[reached]
        if tried is not None:
            tried[kk - 1, c] = defect[kk - 1, c]
        out["found"][g] = True
        out["k"][g], out["n"][g] = kmin[reached], nmin[reached]
        out["x"][g], out["mult"][g], out["residual"][g] = x[att][reached], mult[att][reached], res[att][reached]
        out["distance"][g] = d_now[reached]
        near = pts[j_now, np.arange(a.size)][reached]
        out["orbit_p"][g] = _wrap(near[:, 0] - eng.H0)
    return out


def _check_int(name, v, lo):
    if isinstance(v, bool) or not isinstance(v, (int, np.integer)):
        raise TypeError(f"{name} must be an integer, got {type(v).__name__}")
    if v < lo:
        raise ValueError(f"{name} must be >= {lo}, got {v!r}")
    return int(v)


def _check_pos(name, v):
    if isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating)):
        raise TypeError(f"{name} must be a number, got {type(v).__name__}")
    if not (np.isfinite(v) and v > 0):
        raise ValueError(f"{name} must be positive and finite, got {v!r}")
    return float(v)


_DEFAULTS = dict(transient=48, min_transient=8, chunk=8, max_period=8, lyapunov_periods=300, block=12,
                 min_lyapunov_periods=72, newton_tol=1e-10, candidate_tol=0.05, reach_tol=0.05, reach_floor=1e-9,
                 lyapunov_band=0.01, slip_band=1e-3, h_verdict=0.25)


def _verdict_options(options: dict) -> dict:
    unknown = set(options) - set(_DEFAULTS) - {"max_periods"}
    if unknown:
        raise TypeError(f"unknown option(s) {sorted(unknown)}; known: {sorted(set(_DEFAULTS) | {'max_periods'})}")
    o = dict(_DEFAULTS, **{k: v for k, v in options.items() if k != "max_periods"})
    for name in ("transient", "min_transient", "chunk", "lyapunov_periods", "min_lyapunov_periods"):
        o[name] = _check_int(name, o[name], 0 if name in ("lyapunov_periods", "min_lyapunov_periods") else 1)
    o["max_period"] = _check_int("max_period", o["max_period"], 1)
    o["block"] = _check_int("block", o["block"], 2)
    for name in ("newton_tol", "candidate_tol", "reach_tol", "reach_floor", "lyapunov_band", "slip_band",
                 "h_verdict"):
        o[name] = _check_pos(name, o[name])
    mp = options.get("max_periods")
    if mp is not None:  # a total budget of periods per point: the transient first
        mp = _check_int("max_periods", mp, 2)
        o["transient"] = min(o["transient"], mp)
        o["min_transient"] = min(o["min_transient"], o["transient"])
        o["lyapunov_periods"] = min(o["lyapunov_periods"], mp - o["transient"])
    o["min_transient"] = min(o["min_transient"], o["transient"])
    return o


def rotation_verdicts(body: Body, kind: str, R, Theta, *, p0=0.0, v0=0.0, h_lambda: float = 0.125,
                      steps: int | None = None, engine: str = "numba", **options) -> pd.DataFrame:
    """Decisive verdict on the rotation error p = phi - phi_d of the reduced rotation
    equation (32) on the reference ``kind`` (``"eight"`` (28) or ``"circle"`` (27)) at each
    point (R_i (m), Theta_i (rad/s)), started on the reference with p(0) = ``p0`` (rad),
    dp/dt(0) = ``v0`` (rad/s) (scalars or arrays).

    All points run together in the phase s = Theta t by the compiled fixed-step
    8th-order Dormand-Prince flow with its exact Jacobian
    (:func:`lib.integrators.compiled.rotation_flow`; ``engine="numpy"`` runs the same
    scheme vectorised in numpy); points leave the arrays as soon as they are decided.
    Two step sizes (``steps`` fixes both): the verdict is decided on the *verdict map*,
    :func:`verdict_steps` with h omega <= ``h_verdict`` (0.25), and every orbit found is
    then located again by Newton on the *fine map*, h omega <= ``h_lambda`` (0.125),
    which gives its point, multipliers and range (the range to about 1e-7 rad; the
    verdict map alone is good to about 1e-5 rad, which the verdict does not need).

    1. Transient: ``transient`` periods (48) in chunks of ``chunk`` (8). From
       ``min_transient`` (8) periods on, after every chunk, a point whose last section
       states (at s = 0 mod 2 pi) repeat within ``candidate_tol`` (rad) at some lag
       k <= ``max_period`` (8), up to n whole turns of p, is handed to Newton on
       P^k(x) - x - (2 pi (n + winding k), 0) (P the period map, its Jacobian exact).
       It is decided when Newton converges (residual <= ``newton_tol`` rad), all
       Floquet multipliers (eigenvalues of DP^k) lie inside the unit circle, and the
       run *reaches this orbit*: its state is within ``reach_tol`` (rad, phi modulo
       2 pi) of one of the orbit's k points and the distance has shrunk over the
       last periods, no slower than the slowest multiplier allows (or is below
       ``reach_floor``). Verdict ``periodic`` (n = 0) or ``slipping`` (n != 0).
    2. Otherwise the largest Lyapunov exponent: a tangent vector carried by the exact
       Jacobian, renormalised every period, over up to ``lyapunov_periods`` (300)
       periods; lambda (1/s) is the mean log growth per period divided by the period
       2 pi / Theta, its standard error from the means of blocks of ``block`` (12)
       periods (batch means, so that correlated periods do not shrink it). After every
       block from ``min_lyapunov_periods`` (72) on, a point that is not clearly
       expanding is handed to Newton again, and a clearly chaotic one (lambda T above
       the band and 5 standard errors) stops.
       At the end: ``chaotic`` when lambda T > max(3 SE, ``lyapunov_band``) (T the
       period, so the band is per period, 0.01); ``quasiperiodic`` when |lambda T| <=
       band and its SE <= band / 3; else ``undecided`` (with a reason).

    ``max_periods`` (option) caps the periods integrated per point (transient first).

    Returns a DataFrame, one row per point, in order: R (m), Theta (rad/s), regime;
    period (reference periods of the orbit, periodic/slipping; 0 otherwise); range (rad:
    max - min of p over the attracting orbit at every step, extremes refined by cubic
    Hermite interpolation (:func:`sampled_range`); over the Lyapunov run otherwise);
    floquet (largest multiplier modulus); lyapunov, lyapunov_stderr (1/s; for an orbit
    ln|mu_1| / (k T) with no error); slip, slip_stderr (turns of p per period: n / k on
    an orbit, the measured drift over the Lyapunov run with its batch-means error
    otherwise); lost (bool): the heading slips whole turns, i.e. the verdict is
    ``slipping``, or the motion is not periodic and its drift differs from zero by more
    than 3 standard errors plus ``slip_band`` (1e-3 turns per period); a bounded chaotic
    heading is not lost; orbit_p (rad, p at s = 0 mod 2 pi at the orbit point the run
    is nearest to: which orbit is reached), distance (rad, from the run's last state to
    that point), residual (rad, Newton's), periods (integrated), steps (per period of the fine map), verdict_steps (of the verdict map),
    reason (why undecided).
    """
    if kind not in ("eight", "circle"):
        raise ValueError(f"kind must be 'eight' or 'circle', got {kind!r}")
    if not isinstance(body, Body):
        raise TypeError(f"body must be a lib.params.Body, got {type(body).__name__}")
    if engine not in ENGINES:
        raise ValueError(f"engine must be one of {sorted(ENGINES)}, got {engine!r}")
    R, Theta = _check_grid(R, Theta)
    h_lambda = _check_pos("h_lambda", h_lambda)
    opts = _verdict_options(options)
    N = R.size
    try:
        p0 = np.broadcast_to(np.asarray(p0, dtype=float), (N,)).copy()
        v0 = np.broadcast_to(np.asarray(v0, dtype=float), (N,)).copy()
    except ValueError as e:
        raise ValueError(f"p0 and v0 must be scalars or arrays of length {N}") from e
    if not (np.all(np.isfinite(p0)) and np.all(np.isfinite(v0))):
        raise ValueError("initial p0 and v0 must be finite")
    n_pts, n_fine = _step_counts(body, kind, R, Theta, h_lambda, steps, opts)
    res = _verdict_core(body, kind, R, Theta, p0, v0, n_pts, opts, engine, n_fine)
    cols = {k: v for k, v in res.items() if k not in ("x", "mult")}
    frame = pd.DataFrame({"R": R, "Theta": Theta, **cols, "steps": n_fine, "verdict_steps": n_pts})
    return frame


def _step_counts(body, kind, R, Theta, h_lambda, steps, opts):
    """Steps per period of the verdict map (h omega <= ``h_verdict``) and of the fine map
    (h omega <= ``h_lambda``) on which orbits are located and measured; ``steps`` fixes both."""
    if steps is not None:
        n = np.full(R.size, _check_int("steps", steps, 8))
        return n, n
    n_fine = verdict_steps(body, kind, R, Theta, h_lambda)
    return np.minimum(verdict_steps(body, kind, R, Theta, opts["h_verdict"]), n_fine), n_fine


def _verdict_core(body, kind, R, Theta, p0, v0, n_pts, opts, engine, n_fine=None):
    """The verdicts of :func:`rotation_verdicts` as a dict of arrays, plus the orbit's point x
    (N, 2) and multipliers (N, 2) for periodic/slipping points: decided on the map of
    ``n_pts`` steps per period, each orbit then located again on the map of ``n_fine``
    steps (default: the same) for its point, multipliers and range."""
    N = R.size
    n_fine = n_pts if n_fine is None else n_fine
    out = dict(regime=np.full(N, "undecided", dtype=object), period=np.zeros(N, int), range=np.full(N, np.nan),
               floquet=np.full(N, np.nan), lyapunov=np.full(N, np.nan), lyapunov_stderr=np.full(N, np.nan),
               slip=np.full(N, np.nan), slip_stderr=np.full(N, np.nan), lost=np.zeros(N, bool),
               orbit_p=np.full(N, np.nan), distance=np.full(N, np.nan), residual=np.full(N, np.nan),
               periods=np.zeros(N, int), reason=np.full(N, "", dtype=object),
               x=np.full((N, 2), np.nan), mult=np.full((N, 2), np.nan + 0j))
    slip_n = np.zeros(N, int)
    HL = 2 * opts["max_period"] + 1         # section states kept for the candidates and the reach test

    for n in np.unique(n_pts):
        eng = _Engine(kind, int(n), engine)
        idx = np.flatnonzero(n_pts == n)
        A, B, C = coefficients(body, R[idx], Theta[idx])
        phi, w = _initial(kind, Theta[idx], p0[idx], v0[idx])
        hist = np.stack([phi, w], axis=-1)[None]
        t = 0
        state = dict(idx=idx, A=A, B=B, C=C, phi=phi, w=w, hist=hist,
                     tried=np.full((opts["max_period"], idx.size), np.inf))

        def keep(mask, extra=()):
            for key in ("idx", "A", "B", "C", "phi", "w") + tuple(extra):
                state[key] = state[key][mask]
            state["hist"] = state["hist"][:, mask]
            state["tried"] = state["tried"][:, mask]

        def advance(c, **kw):
            s = state
            o = _flow_with(eng, s, c, s["J"]) if kw.get("renorm") else \
                eng.flow(s["phi"], s["w"], s["A"], s["B"], s["C"], c)
            sec = o["sec"]
            sec[:, :, 0] -= eng.w2pi * np.arange(1, c + 1)[:, None]
            s["phi"], s["w"] = o["phi"] - eng.w2pi * c, o["w"]
            s["hist"] = np.concatenate([s["hist"], sec])[-HL:]
            return o

        def decide(r, t):
            f = np.flatnonzero(r["found"])
            if f.size == 0:
                return
            g = state["idx"][f]
            k, nn = r["k"][f], r["n"][f]
            out["regime"][g] = np.where(nn == 0, "periodic", "slipping")
            out["period"][g], slip_n[g] = k, nn
            out["slip"][g], out["slip_stderr"][g] = nn / k, 0.0
            out["lost"][g] = nn != 0
            out["x"][g], out["mult"][g] = r["x"][f], r["mult"][f]
            mod = np.abs(r["mult"][f, 0])
            out["floquet"][g] = mod
            out["lyapunov"][g] = np.log(mod) * Theta[g] / (2 * np.pi * k)
            out["orbit_p"][g], out["distance"][g], out["residual"][g] = r["orbit_p"][f], r["distance"][f], r["residual"][f]
            out["periods"][g] = t
            m = np.ones(state["idx"].size, bool)
            m[f] = False
            keep(m, extra=("J", "lo", "hi", "pb", "logs") if "J" in state else ())

        # 1. transient, with Newton on the points that nearly repeat
        while t < opts["transient"] and state["idx"].size:
            c = min(opts["chunk"], opts["transient"] - t)
            advance(c)
            t += c
            if t >= opts["min_transient"]:
                decide(_try_orbits(eng, state["A"], state["B"], state["C"], state["hist"], opts, state["tried"]), t)

        # 2. the largest Lyapunov exponent of the rest, and their drift
        L, Bk = opts["lyapunov_periods"], opts["block"]
        nb_max = L // Bk
        if state["idx"].size and nb_max < 2:
            out["reason"][state["idx"]] = "no attracting orbit reached within the period budget"
            out["periods"][state["idx"]] = t
        if state["idx"].size == 0 or nb_max < 2:
            continue
        M = state["idx"].size
        state["J"] = np.tile(np.array([[1.0, 0.0], [1.0, 0.0]]) / np.sqrt(2.0), (M, 1, 1))
        state["lo"], state["hi"] = np.full(M, np.inf), np.full(M, -np.inf)
        state["pb"] = np.empty((M, nb_max + 1))
        state["pb"][:, 0] = state["phi"]
        state["logs"] = np.empty((M, nb_max))
        for b in range(nb_max):
            o = advance(Bk, renorm=True)
            t += Bk
            state["J"] = o["J"]
            state["lo"], state["hi"] = np.minimum(state["lo"], o["pmin"]), np.maximum(state["hi"], o["pmax"])
            state["pb"][:, b + 1] = state["phi"]
            state["logs"][:, b] = o["logs"].mean(axis=0)
            nb = b + 1
            if t - opts["transient"] < opts["min_lyapunov_periods"] and nb < nb_max:
                continue
            lam = state["logs"][:, :nb].mean(axis=1)
            se = state["logs"][:, :nb].std(axis=1, ddof=1) / np.sqrt(nb)
            band = opts["lyapunov_band"]
            # contracting (or unresolved) points: Newton again from where the run now is
            trymask = lam < 3 * se
            if trymask.any():
                sub = np.flatnonzero(trymask)
                tr = state["tried"][:, sub]
                r = _try_orbits(eng, state["A"][sub], state["B"][sub], state["C"][sub], state["hist"][:, sub], opts, tr)
                state["tried"][:, sub] = tr
                found = np.zeros(state["idx"].size, bool)
                found[sub] = r["found"]
                full = {key: (np.zeros(state["idx"].size, bool) if key == "found" else
                              np.zeros((state["idx"].size,) + np.shape(v)[1:], np.asarray(v).dtype))
                        for key, v in r.items()}
                for key in r:
                    full[key][sub] = r[key]
                lam, se = lam[~found], se[~found]
                decide(full, t)
            if state["idx"].size == 0:
                break
            final = nb == nb_max
            chaotic = (lam > band) & (lam > (3 if final else 5) * se)
            done = chaotic | final
            if not done.any():
                continue
            g = state["idx"][done]
            T = 2 * np.pi / Theta[g]
            lam_d, se_d = lam[done], se[done]
            out["lyapunov"][g], out["lyapunov_stderr"][g] = lam_d / T, se_d / T
            quasi = ~chaotic[done] & (np.abs(lam_d) <= band) & (se_d <= band / 3)
            out["regime"][g] = np.where(chaotic[done], "chaotic", np.where(quasi, "quasiperiodic", "undecided"))
            und = ~chaotic[done] & ~quasi
            out["reason"][g[und]] = np.where(
                lam_d[und] < -np.maximum(3 * se_d[und], band),
                f"contracting, but no attracting orbit of period <= {opts['max_period']} reached",
                "Lyapunov exponent not resolved from zero")
            pb = state["pb"][done, :nb + 1]
            inc = np.diff(pb, axis=1) / (2 * np.pi * Bk)
            drift = (pb[:, -1] - pb[:, 0]) / (2 * np.pi * Bk * nb)
            dse = inc.std(axis=1, ddof=1) / np.sqrt(nb)
            out["slip"][g], out["slip_stderr"][g] = drift, dse
            out["lost"][g] = np.abs(drift) > 3 * dse + opts["slip_band"]
            out["range"][g] = state["hi"][done] - state["lo"][done]
            out["periods"][g] = t
            keep(~done, extra=("J", "lo", "hi", "pb", "logs"))
            if state["idx"].size == 0:
                break

    # each attracting orbit on the fine map (n_fine steps per period): Newton from the
    # orbit found on the verdict map, its multipliers, and its range sampled at every
    # step (Hermite-refined extremes)
    orb = np.flatnonzero(np.isin(out["regime"], ("periodic", "slipping")))
    for n in np.unique(n_fine[orb]):
        eng = _Engine(kind, int(n), engine)
        for k in np.unique(out["period"][orb]):
            g = orb[(n_fine[orb] == n) & (out["period"][orb] == k)]
            if g.size == 0:
                continue
            A, B, C = coefficients(body, R[g], Theta[g])
            kk = np.full(g.size, int(k))
            if np.any(n_pts[g] != n):
                x, J, res = _newton(eng, A, B, C, out["x"][g], kk, slip_n[g], opts["newton_tol"])
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
                g, A, B, C, kk, x, mult, res = g[ok], A[ok], B[ok], C[ok], kk[ok], x[ok], mult[ok], res[ok]
                out["x"][g], out["mult"][g], out["residual"][g] = x, mult, res
                mod = np.abs(mult[:, 0])
                out["floquet"][g] = mod
                out["lyapunov"][g] = np.log(mod) * Theta[g] / (2 * np.pi * kk)
                if g.size == 0:
                    continue
            p, dp = eng.record(out["x"][g, 0], out["x"][g, 1], A, B, C, int(k))
            out["range"][g] = sampled_range(p, cyclic=slip_n[g] == 0, dy=dp, h=eng.h)
    return out


def _flow_with(eng: _Engine, s: dict, c: int, J):
    """The Lyapunov flow: ``c`` periods carrying the tangent vector (first column of J)."""
    if eng.engine == "numba":
        from .integrators.compiled import rotation_flow

        return rotation_flow(s["phi"], s["w"], s["A"], s["B"], s["C"], c, eng.X1, eng.Y1, eng.X2, eng.Y2,
                             eng.hA, eng.hB, J=J, renorm=True, H=eng.H, wind2pi=eng.w2pi)
    return _flow_numpy(eng, s["phi"], s["w"], s["A"], s["B"], s["C"], c, renorm=True, H=eng.H, J0=J)


@dataclass(frozen=True)
class RotationAttractor:
    """The attracting orbit of the heading that the run from one start reaches
    (:func:`rotation_attractor`).

    ``regime`` ("periodic" or "slipping"), ``period`` k (reference periods), ``slip`` n
    (whole turns of p per k periods); ``states`` (k, 2): (p (rad), dp/dt (rad/s)) at
    t = 0, T, ..., (k - 1) T (mod k T) on the orbit, starting with the point the run is
    nearest to at its end; ``multipliers`` (2,) complex, the Floquet multipliers
    (eigenvalues of DP^k), by decreasing modulus; ``t`` (s) and ``p`` (rad): the orbit
    over its k periods at every integration step (t from 0 to k T, p continuous);
    ``range`` (rad), ``residual`` (rad, Newton's), ``periods`` (integrated before
    the verdict)."""

    regime: str
    period: int
    slip: int
    states: np.ndarray
    multipliers: np.ndarray
    t: np.ndarray
    p: np.ndarray
    range: float
    residual: float
    periods: int


def rotation_attractor(body: Body, kind: str, R: float, Theta: float, *, p0: float = 0.0, v0: float = 0.0,
                       h_lambda: float = 0.125, steps: int | None = None, **options) -> RotationAttractor:
    """The attracting periodic orbit of the heading error p = phi - phi_d of (32) on the
    reference ``kind`` at one point (R (m), Theta (rad/s)) that the run from p(0) = ``p0``
    (rad), dp/dt(0) = ``v0`` (rad/s) reaches, as decided by :func:`rotation_verdicts`
    (same options). On the eight (28) the rotation equation (37) is symmetric and has two
    mirror-image period-1 orbits; which one a start reaches is reported by
    ``states[0, 0]``. Raises ValueError if the run reaches no attracting orbit (the
    verdict is then chaotic, quasiperiodic or undecided)."""
    for name, v in (("R", R), ("Theta", Theta), ("p0", p0), ("v0", v0)):
        if isinstance(v, bool) or not np.isscalar(v) or not isinstance(v, (int, float, np.integer, np.floating)):
            raise TypeError(f"{name} must be a real scalar, got {type(v).__name__}")
    R_, Th = _check_grid([R], [Theta])
    if not (np.isfinite(p0) and np.isfinite(v0)):
        raise ValueError("initial p0 and v0 must be finite")
    if kind not in ("eight", "circle"):
        raise ValueError(f"kind must be 'eight' or 'circle', got {kind!r}")
    if not isinstance(body, Body):
        raise TypeError(f"body must be a lib.params.Body, got {type(body).__name__}")
    h_lambda = _check_pos("h_lambda", h_lambda)
    opts = _verdict_options(options)
    n_pts, n_fine = _step_counts(body, kind, R_, Th, h_lambda, steps, opts)
    n = int(n_fine[0])
    res = _verdict_core(body, kind, R_, Th, np.array([float(p0)]), np.array([float(v0)]), n_pts, opts, "numba",
                        n_fine)
    regime = res["regime"][0]
    if regime not in ("periodic", "slipping"):
        raise ValueError(f"no attracting orbit is reached at R = {R} m, Theta = {Theta} rad/s from p0 = {p0}: "
                         f"the verdict is {regime} {res['reason'][0]}".rstrip())
    k = int(res["period"][0])
    eng = _Engine(kind, n, "numba")
    A, B, C = coefficients(body, R_, Th)
    x = res["x"][:1].copy()
    pts = _orbit_points(eng, A, B, C, x, np.array([k]))[:k, 0]          # P(x), ..., P^k(x) ~ x + shift
    pts = np.concatenate([x, pts[:-1]])
    # start at the orbit point nearest to the run's end (the one reported by orbit_p)
    j = int(np.argmin(np.abs(_wrap(pts[:, 0] - eng.H0 - res["orbit_p"][0]))))
    x0 = pts[j:j + 1].copy()
    x0[0, 0] = eng.H0 + _wrap(x0[0, 0] - eng.H0)
    p, dp = eng.record(x0[:, 0], x0[:, 1], A, B, C, k)
    p = np.concatenate([[x0[0, 0] - eng.H0], p[0]])
    t = np.arange(p.size) * eng.h / Th[0]
    states = np.roll(pts, -j, axis=0)
    H1_0 = _shape(kind)[0](0.0)[5]
    states = np.column_stack([_wrap(states[:, 0] - eng.H0), (states[:, 1] - H1_0) * Th[0]])
    return RotationAttractor(regime=regime, period=k, slip=int(round(res["slip"][0] * k)), states=states,
                             multipliers=res["mult"][0], t=t, p=p, range=float(res["range"][0]),
                             residual=float(res["residual"][0]), periods=int(res["periods"][0]))
