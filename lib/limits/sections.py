"""The long-run regime under an angle limit (and a force cap) by the adaptive, event-located
reference integrator (:class:`lib.integrators.switched.SwitchedLoop`), one run at a time
(paper Sec. 5, Chapter 4): the stroboscopic section of the period map
(:func:`stroboscopic_section`, :func:`section_sweep`) and the regime read from it, its
period and the largest Lyapunov exponent (:func:`sweep_angle_limit`, :func:`classify`).
The compiled path, many runs at once, decides Chapter 4's verdicts
(:func:`lib.limits.verdicts.limit_verdicts`); :mod:`lib.limits` re-exports these names.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..machinery import checks
from ..angles import state_difference
from ..dynamics import verdicts as dv
from ..dynamics.lyapunov import largest_lyapunov
from ..dynamics.sections import section_period
from ..integrators.switched import SwitchedLoop
from ..machinery.parallel import map_in_processes
from ..params import PAPER_DZ0, PAPER_Z0, Body, Gains
from .runs import _check_parts, _limits_arrays, error_state
from ..trajectories import Reference

__all__ = ["stroboscopic_section", "Regime", "classify", "section_sweep", "sweep_angle_limit"]


def stroboscopic_section(loop: SwitchedLoop, s0, n_transient: int, n_points: int, **kw) -> np.ndarray:
    """Poincaré section of the period-T map: the error state (see :func:`error_state`)
    at t = k T for k = n_transient, ..., n_transient + n_points - 1, T the
    reference period. Returns an array of shape (n_points, 6).

    Parameters
    ----------
    loop : SwitchedLoop
        The switched closed loop.
    s0 : array_like
        Start state (6,) (m, rad, m/s, rad/s).
    n_transient : int
        Periods dropped.
    n_points : int
        Section points.
    **kw
        Tolerances of :meth:`lib.integrators.switched.SwitchedLoop.integrate`.

    Returns
    -------
    numpy.ndarray
        Error states (n_points, 6).
    """
    if n_points < 1 or n_transient < 0:
        raise ValueError("need n_points >= 1 and n_transient >= 0")
    T = loop.period
    k = np.arange(n_transient, n_transient + n_points)
    seg = loop.integrate(s0, 0.0, float(k[-1] * T), t_eval=k * T, **kw)
    return error_state(loop.ref, seg.t, seg.y)


@dataclass(frozen=True, eq=False)
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

    def __eq__(self, other: object) -> bool:
        """Field by field; the section compared as an array, a NaN equal to a NaN."""
        if not isinstance(other, Regime):
            return NotImplemented
        def same(a, b) -> bool:
            if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
                return np.array_equal(a, b, equal_nan=True)
            return a == b or (isinstance(a, float) and isinstance(b, float) and np.isnan(a) and np.isnan(b))
        return all(same(getattr(self, f), getattr(other, f)) for f in self.__dataclass_fields__)

    __hash__ = None


def classify(period: int, lyapunov: float, stderr: float, *, zero_band: float = 0.01) -> str:
    """Verdict of the adaptive reference path (:func:`sweep_angle_limit`, which does not
    locate orbits) from a section period (:func:`section_period`, 0 = none found) and the
    largest Lyapunov exponent (1/s) with its standard error, by the book's rule
    (:func:`lib.dynamics.verdicts.classify`, band ``zero_band``; the section's closure is
    not tested on this path): "chaotic"; otherwise "periodic-k" when the section has
    period k; otherwise "quasi-periodic" when the exponent is known to be within the band
    of zero; otherwise "undecided" (the estimate is too noisy to decide).

    Parameters
    ----------
    period : int
        Section period (0: none found).
    lyapunov : float
        Largest Lyapunov exponent (1/s).
    stderr : float
        Its standard error (1/s).
    zero_band : float
        The band of zero (1/s).

    Returns
    -------
    str
        The verdict.
    """
    regime = dv.classify([lyapunov], [stderr], [0.0], band=zero_band, return_tol=1.0, max_period=8)[0][0]
    if regime == "chaotic":
        return "chaotic"
    if period > 0:
        return f"periodic-{period}"
    return "quasi-periodic" if regime == "quasiperiodic" else "undecided"


def _section_one(args):
    body, gains, ref, bmax, force_limit, n_transient, n_points, rtol, atol, s0 = args
    loop = SwitchedLoop(body, gains, ref, bmax, force_limit)
    return stroboscopic_section(loop, s0, n_transient, n_points, rtol=rtol, atol=atol)


def _start(z0, dz0) -> np.ndarray:
    """The start state (z0, dz0) of a sweep, the paper's Table by default, checked."""
    return np.concatenate([checks.array("z0", PAPER_Z0 if z0 is None else z0, shape=(3,)),
                           checks.array("dz0", PAPER_DZ0 if dz0 is None else dz0, shape=(3,))])


def _check_sweep(body, gains, ref, angle_limits, force_limit, **numbers) -> np.ndarray:
    """Check a sweep's parts, limits and options (``n_*`` integers, the rest positive
    numbers) by :mod:`lib.machinery.checks`; returns the angle limits (rad) as a 1-D array."""
    _check_parts(body, gains, ref)
    if force_limit is not None:
        checks.number("force_limit", force_limit, positive=True)
    for name, v in numbers.items():
        if name.startswith("n_"):
            checks.integer(name, v, minimum=0 if name == "n_transient" else 1)
        else:
            checks.number(name, v, positive=True)
    return _limits_arrays(angle_limits, None)[0]


def section_sweep(body: Body, gains: Gains, ref: Reference, angle_limits, *, force_limit=None,
                  n_transient: int = 20, n_points: int = 24, rtol: float = 1e-8, atol: float = 1e-8,
                  z0=None, dz0=None, workers: int = 1, progress: bool | None = None) -> list[np.ndarray]:
    """Bifurcation data: the stroboscopic section (:func:`stroboscopic_section`,
    ``n_points`` error states after ``n_transient`` periods) for each angle limit (rad),
    from the paper's initial state unless ``z0``/``dz0`` are given; ``workers``
    processes share the sweep.

    Parameters
    ----------
    body : Body
        The body.
    gains : Gains
        The gains of (23).
    ref : Circle or Eight
        The reference.
    angle_limits : float or array_like
        beta_max (rad), in (0, pi].
    force_limit : float, optional
        F_max (N), > 0.
    n_transient, n_points : int
        Periods dropped (>= 0) and section points (>= 1).
    rtol, atol : float
        Tolerances, > 0.
    z0, dz0 : array_like, optional
        Start, default the paper's Table.
    workers : int
        Spawned processes (>= 1).
    progress : bool, optional
        A progress bar over the limits (default None: only when run interactively).

    Returns
    -------
    list of numpy.ndarray
        One section (n_points, 6) per angle limit.
    """
    angles = _check_sweep(body, gains, ref, angle_limits, force_limit, n_transient=n_transient,
                          n_points=n_points, rtol=rtol, atol=atol)
    s0 = _start(z0, dz0)
    items = [(body, gains, ref, float(b), force_limit, n_transient, n_points, rtol, atol, s0) for b in angles]
    return map_in_processes(_section_one, items, workers, progress)


def sweep_angle_limit(body: Body, gains: Gains, ref: Reference, angle_limits, *, force_limit=None,
                      n_transient: int = 30, n_points: int = 40, n_lyap: int = 40, tol: float = 1e-4,
                      rtol: float = 1e-10, atol: float = 1e-10, d0: float = 1e-5, z0=None, dz0=None,
                      workers: int = 1, progress: bool | None = None) -> list[Regime]:
    """Classify the long-run regime for each angle limit (rad).

    For each limit: ``n_transient`` periods are discarded, ``n_points`` section
    points recorded (their period found by :func:`section_period` with ``tol``),
    and the largest Lyapunov exponent estimated over ``n_lyap`` periods starting
    from the end of the section.

    Parameters
    ----------
    body : Body
        The body.
    gains : Gains
        The gains of (23).
    ref : Circle or Eight
        The reference.
    angle_limits : float or array_like
        beta_max (rad), in (0, pi].
    force_limit : float, optional
        F_max (N), > 0; None for no cap.
    n_transient, n_points, n_lyap : int
        Periods dropped (>= 0), section points (>= 1), Lyapunov periods (>= 1).
    tol : float
        Section period tolerance (the error state's units), > 0.
    rtol, atol : float
        Tolerances of the adaptive integrator, > 0.
    d0 : float
        Initial separation of the Lyapunov companion, > 0.
    z0, dz0 : array_like, optional
        Start (m, m, rad; m/s, m/s, rad/s), default the paper's Table.
    workers : int
        Spawned processes (>= 1).
    progress : bool, optional
        A progress bar over the limits (default None: only when run interactively).

    Returns
    -------
    list of Regime
        One per angle limit, in order.
    """
    angles = _check_sweep(body, gains, ref, angle_limits, force_limit, n_transient=n_transient,
                          n_points=n_points, n_lyap=n_lyap, tol=tol, rtol=rtol, atol=atol, d0=d0)
    s0 = _start(z0, dz0)
    items = [(body, gains, ref, float(b), force_limit, n_transient, n_points, n_lyap, tol, rtol, atol, d0, s0)
             for b in angles]
    return map_in_processes(_regime_one, items, workers, progress)


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
