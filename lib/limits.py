"""The force and angle limits of paper Sec. 5 (Chapter 4): the long-run regime of the
closed loop under an angle limit, decided from a stroboscopic section and the
largest Lyapunov exponent, for one angle limit or a sweep of them.

The closed loop with an angle limit is integrated by the switched integrator
(:class:`lib.integrators.switched.SwitchedLoop`); the verdict tools are generic
(:mod:`lib.dynamics`). They are re-exported here, where Chapter 4 uses them.
"""

from __future__ import annotations

from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass

import numpy as np

from .angles import state_difference, wrap_angle
from .dynamics.lyapunov import LyapunovEstimate, largest_lyapunov
from .dynamics.sections import distinct_points, section_margin, section_period
from .integrators.switched import Segments, SwitchedLoop
from .params import PAPER_DZ0, PAPER_Z0, Body, Gains
from .trajectories import Reference

__all__ = [
    "error_state", "stroboscopic_section", "Regime", "classify", "section_sweep", "sweep_angle_limit",
    # re-exported from where they are defined
    "SwitchedLoop", "Segments", "largest_lyapunov", "LyapunovEstimate", "distinct_points", "section_period",
    "section_margin", "state_difference",
]


def error_state(ref: Reference, t, y) -> np.ndarray:
    """Tracking errors of states ``y`` (n, 6) at times ``t``: columns
    [e_x (m), e_y (m), de_x (m/s), de_y (m/s), p (rad), dp (rad/s)] with
    e = z_d - z as in (24) and the rotation error p = phi - phi_d wrapped to (-pi, pi]."""
    t = np.asarray(t, dtype=float)
    y = np.atleast_2d(np.asarray(y, dtype=float))
    zd, dzd = ref.z(t), ref.dz(t)
    p = y[:, 2] - zd[:, 2]
    p = wrap_angle(p)
    return np.column_stack([zd[:, 0] - y[:, 0], zd[:, 1] - y[:, 1], dzd[:, 0] - y[:, 3], dzd[:, 1] - y[:, 4],
                            p, y[:, 5] - dzd[:, 2]])


def stroboscopic_section(loop: SwitchedLoop, s0, n_transient: int, n_points: int, **kw) -> np.ndarray:
    """Poincaré section of the period-T map: the error state (see :func:`error_state`)
    at t = k T for k = n_transient, ..., n_transient + n_points - 1, T the
    reference period. Returns an array of shape (n_points, 6)."""
    if n_points < 1 or n_transient < 0:
        raise ValueError("need n_points >= 1 and n_transient >= 0")
    T = loop.period
    k = np.arange(n_transient, n_transient + n_points)
    seg = loop.integrate(s0, 0.0, float(k[-1] * T), t_eval=k * T, **kw)
    return error_state(loop.ref, seg.t, seg.y)



@dataclass(frozen=True)
class Regime:
    """Long-run behaviour at one angle limit: the stroboscopic section, its period
    (:func:`section_period`; 0 means none up to 8) and whether it was still
    converging, the largest Lyapunov exponent (1/s) with its standard error, the
    verdict, and the crossings of and time sliding on the switching surface."""

    angle_limit: float
    section: np.ndarray
    period: int
    converging: bool
    lyapunov: float
    lyapunov_stderr: float
    verdict: str
    n_crossings: int
    t_sliding: float


def classify(period: int, lyapunov: float, stderr: float, *, zero_band: float = 0.01) -> str:
    """Verdict from a section period (:func:`section_period`, 0 = none found) and the
    largest Lyapunov exponent (1/s) with its standard error.

    "chaotic" when the exponent exceeds both ``zero_band`` and three standard
    errors; otherwise "periodic-k" when the section has period k; otherwise
    "quasi-periodic" when the exponent is known to be within ``zero_band`` of
    zero (|lambda| and its standard error both below ``zero_band``); otherwise
    "undecided" (the estimate is too noisy to decide).
    """
    if lyapunov > max(zero_band, 3 * stderr):
        return "chaotic"
    if period > 0:
        return f"periodic-{period}"
    if abs(lyapunov) < zero_band and stderr < zero_band:
        return "quasi-periodic"
    return "undecided"


def _map(fn, items, workers: int):
    if workers <= 1 or len(items) <= 1:
        return [fn(x) for x in items]
    with ProcessPoolExecutor(max_workers=workers) as ex:
        return list(ex.map(fn, items))


def _section_one(args):
    body, gains, ref, bmax, force_limit, n_transient, n_points, rtol, atol, s0 = args
    loop = SwitchedLoop(body, gains, ref, bmax, force_limit)
    return stroboscopic_section(loop, s0, n_transient, n_points, rtol=rtol, atol=atol)


def section_sweep(body: Body, gains: Gains, ref: Reference, angle_limits, *, force_limit=None,
                  n_transient: int = 20, n_points: int = 24, rtol: float = 1e-8, atol: float = 1e-8,
                  z0=None, dz0=None, workers: int = 1) -> list[np.ndarray]:
    """Bifurcation data: the stroboscopic section (:func:`stroboscopic_section`,
    ``n_points`` error states after ``n_transient`` periods) for each angle limit (rad),
    from the paper's initial state unless ``z0``/``dz0`` are given; ``workers``
    processes share the sweep."""
    s0 = np.concatenate([np.asarray(PAPER_Z0 if z0 is None else z0, dtype=float),
                         np.asarray(PAPER_DZ0 if dz0 is None else dz0, dtype=float)])
    items = [(body, gains, ref, float(b), force_limit, n_transient, n_points, rtol, atol, s0)
             for b in np.atleast_1d(np.asarray(angle_limits, dtype=float))]
    return _map(_section_one, items, workers)


def sweep_angle_limit(body: Body, gains: Gains, ref: Reference, angle_limits, *, force_limit=None,
                      n_transient: int = 30, n_points: int = 40, n_lyap: int = 40, tol: float = 1e-4,
                      rtol: float = 1e-10, atol: float = 1e-10, d0: float = 1e-5, z0=None, dz0=None,
                      workers: int = 1) -> list[Regime]:
    """Classify the long-run regime for each angle limit (rad).

    For each limit: ``n_transient`` periods are discarded, ``n_points`` section
    points recorded (their period found by :func:`section_period` with ``tol``),
    and the largest Lyapunov exponent estimated over ``n_lyap`` periods starting
    from the end of the section.
    """
    s0 = np.concatenate([np.asarray(PAPER_Z0 if z0 is None else z0, dtype=float),
                         np.asarray(PAPER_DZ0 if dz0 is None else dz0, dtype=float)])
    items = [(body, gains, ref, float(b), force_limit, n_transient, n_points, n_lyap, tol, rtol, atol, d0, s0)
             for b in np.atleast_1d(np.asarray(angle_limits, dtype=float))]
    return _map(_regime_one, items, workers)


def _regime_one(args) -> Regime:
    body, gains, ref, bmax, force_limit, n_transient, n_points, n_lyap, tol, rtol, atol, d0, s0 = args
    loop = SwitchedLoop(body, gains, ref, bmax, force_limit)
    T = loop.period
    k = np.arange(n_transient, n_transient + n_points)
    seg = loop.integrate(s0, 0.0, float(k[-1] * T), t_eval=k * T, rtol=rtol, atol=atol)
    sec = error_state(ref, seg.t, seg.y)
    period, converging = section_period(sec, tol)
    t_start = float(k[-1] * T)

    def flow(x, t0, t1, mode=None):
        return loop.flow(x, t_start + t0, t_start + t1, mode, rtol=rtol, atol=atol)

    lyap = largest_lyapunov(flow, (seg.y_end, seg.mode_end), T, n_lyap, d0=d0, difference=state_difference)
    verdict = classify(period, lyap.value, lyap.stderr)
    return Regime(angle_limit=bmax, section=sec, period=period, converging=converging, lyapunov=lyap.value,
                  lyapunov_stderr=lyap.stderr, verdict=verdict, n_crossings=seg.n_crossings,
                  t_sliding=seg.t_sliding)
