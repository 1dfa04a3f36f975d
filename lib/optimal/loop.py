"""Any closed loop of the body under the paper's limits, decided and measured one way.

Chapter 8 sets four controllers side by side under each limit setting: the paper's law, the
weighted law of Chapter 6, the law for P of Chapter 7 and the controller of the optimal motion.
Each is a periodically forced vector field ``rates(t, s)``, vectorised over rows of states. This
module turns such a field into the book's period map (:class:`FlowMap`, a
:class:`lib.dynamics.verdicts.PeriodMap`), decides its long-run regime with the book's one
procedure for orbits (:func:`lib.dynamics.verdicts.find_orbits`: lag candidates, Newton on
P^k(x) = x + 2 pi n e_phi with a difference Jacobian, Floquet multipliers, the reach test), and
measures a run's steady errors and inputs (:func:`steady_measures`), extremes refined between
samples (:func:`lib.dynamics.sampled.sampled_extremes`).

A run on which no attracting orbit is located is ``undecided`` here with its reason: this module
does not compute Lyapunov exponents, so it never says ``chaotic``; Chapter 4's verdicts do that
for the paper's law.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Callable

import numba
import numpy as np
from scipy.integrate import solve_ivp

from .. import closed_loop
from ..closed_loop import _weighted_rows
from ..angles import wrap_angle
from ..dynamics import verdicts as dv
from ..dynamics.sampled import sampled_extremes
from ..integrators.batch import RK4, fixed_steps, integrate, nonfinite_message
from ..integrators.smooth import SimulationError
from ..machinery import checks
from ..machinery.cache import source_stamp
from ..percussion import full_loop
from ..percussion.full_loop import _rows_field
from .floquet import multiplier_tolerance, multipliers_agree
from .verdict import BLOWUP, ORBIT_SHIFT_TOL       # a state beyond BLOWUP has blown up

__all__ = ["FlowMap", "LoopVerdict", "loop_verdict", "halved_verdict", "run_periods", "steady_measures",
           "LOOP_OPTIONS", "rows_period_end"]

Rates = Callable[[float, np.ndarray], np.ndarray]

#: the procedure's settings here (state units; m, rad, m/s, rad/s); periods run before the orbit
#: search, section states kept, longest period tried, and the tolerances of
#: :func:`lib.dynamics.verdicts.find_orbits`; the integration's tolerances
#: (``steps`` = 0; adaptive DOP853 at rtol, atol; ``steps`` > 0; classical RK4 with that many
#: fixed steps a period, the batch integrator of Chapter 6, whose cost does not grow where a
#: clipped angle chatters across its switching surface)
LOOP_OPTIONS = dict(transient=24, history=12, max_period=4, candidate_tol=1e-3, newton_tol=1e-8, reach_tol=1e-4,
                    reach_floor=1e-8, fd_step=1e-6, newton_iter=12, rtol=1e-10, atol=1e-10, steps=0)
_INTEGER_OPTIONS = dict(transient=1, history=3, max_period=1, newton_iter=1, steps=0)


def _beyond(t: float) -> str:
    """What ``_fixed`` says of a stage's state beyond :data:`BLOWUP` at t (s)."""
    return f"a state beyond {BLOWUP:g} at t = {t:.6g} s"


def _blew_up(what) -> SimulationError:
    return SimulationError(f"the closed loop blew up: {what}")


def _fixed(rates: Rates, x: np.ndarray, t0: float, t1: float, steps: int):
    """Classical RK4 with ``steps`` fixed steps from t0 to t1, every step recorded: (t, states (n, M, d))."""
    def f(t, y):
        if np.max(np.abs(y)) > BLOWUP:
            raise FloatingPointError(_beyond(t))
        return rates(t, y)
    try:
        return integrate(f, x, t0, t1, (t1 - t0) / steps, RK4)
    except FloatingPointError as err:
        raise _blew_up(err) from None


def _make_rows_steps(stamp: int, law: int):
    """The kernel of :func:`rows_period_end` for one compiled field (``law`` 0: the law for P's,
    ``lib.percussion.full_loop._rows_field``; 1: the weighted law's, ``lib.closed_loop._weighted_rows``),
    cached on disk by numba; it closes over ``stamp``, the hash of the field's file (numba keys a
    cached kernel on its own file only), and over ``law``, whose other branch numba prunes."""

    @numba.njit(cache=True)
    def run(Y, n, h, hA, c, b, hb, blowup, rec, args):  # pragma: no cover (compiled)
        """n steps of h (s) of the explicit tableau (hA = h A, c, b, hb = h / b_den) from t = 0 on
        every row of Y (M, d), in place, with the stage sums of :func:`lib.integrators.batch.steps`
        in their order (zero coefficients skipped); the state at each step's start into rec[k] for
        k < len(rec). Returns (0, 0, 0), or (1, t, row) where a stage's state exceeds ``blowup`` in
        magnitude, or (2, t, row) where a step ends non-finite."""
        M, d, S = Y.shape[0], Y.shape[1], c.size
        K = np.empty((S, M, d))
        yi = np.empty((M, d))
        for k in range(n if stamp >= 0 else 0):
            t = k * h
            if k < rec.shape[0]:
                rec[k] = Y
            for i in range(S):
                for r in range(M):
                    for col in range(d):
                        v = Y[r, col]
                        for j in range(i):
                            if hA[i, j] != 0:
                                v = v + hA[i, j] * K[j, r, col]
                        if abs(v) > blowup:
                            return 1, t + c[i] * h, r
                        yi[r, col] = v
                if law == 0:
                    _rows_field(t + c[i] * h, yi, K[i], *args)
                else:
                    _weighted_rows(t + c[i] * h, yi, K[i], *args)
            for r in range(M):
                for col in range(d):
                    acc = b[0] * K[0, r, col]
                    for j in range(1, S):
                        if b[j] != 0:
                            acc = acc + b[j] * K[j, r, col]
                    Y[r, col] = Y[r, col] + hb * acc
                    if not np.isfinite(Y[r, col]):
                        return 2, (k + 1) * h, r
        return 0, 0.0, 0
    return run


_ROWS_STEPS = {"percussion": _make_rows_steps(source_stamp(Path(full_loop.__file__)), 0),
               "weighted": _make_rows_steps(source_stamp(Path(closed_loop.__file__)), 1)}


def rows_period_end(law: str, args: tuple) -> Callable:
    """``period_end(x, n, h, blowup, rec=None)`` of a compiled field (:class:`FlowMap`): the
    classical RK4 (:data:`lib.integrators.batch.RK4`) compiled on the law for P's field under
    limits (``law`` "percussion", ``args`` those of ``lib.percussion.full_loop._rows_field``) or
    the weighted law's (``"weighted"``, those of ``lib.closed_loop._weighted_rows``); ``rec``
    (n, M, d), where given, receives the state at each step's start.

    Parameters
    ----------
    law : str
        ``"percussion"`` or ``"weighted"``.
    args : tuple
        The field's arguments after (t, Y, out).

    Returns
    -------
    callable
        (x (M, d), n, h (s), blowup, rec=None) -> (end (M, d), code, t, row).
    """
    kernel = _ROWS_STEPS[checks.one_of("law", law, tuple(_ROWS_STEPS))]

    def period_end(x, n, h, blowup, rec=None):
        Y = np.array(x, dtype=float, order="C").reshape(-1, np.shape(x)[-1])
        r = np.empty((0,) + Y.shape) if rec is None else rec
        status = kernel(Y, n, h, h * RK4.A, RK4.c, RK4.b, h / RK4.b_den, blowup, r, args)
        return (Y.reshape(np.shape(x)), *status)
    return period_end


def _integrate(rates: Rates, x: np.ndarray, t0: float, t1: float, rtol: float, atol: float, dense: bool = False):
    """solve_ivp (DOP853) of all rows of x (M, d) together from t0 to t1."""
    M, d = x.shape

    def f(t, y):
        out = rates(t, y.reshape(M, d)).reshape(-1)
        if not np.all(np.isfinite(out)) or np.max(np.abs(y)) > BLOWUP:
            raise SimulationError(f"the closed loop blew up at t = {t:.6g} s (a state beyond {BLOWUP:g} "
                                  "or a rate not finite)")
        return out

    sol = solve_ivp(f, (t0, t1), x.reshape(-1), method="DOP853", rtol=rtol, atol=atol, dense_output=dense)
    if sol.status != 0:
        raise SimulationError(f"the closed loop could not be integrated past t = {sol.t[-1]:.6g} s: {sol.message}")
    return sol


class FlowMap:
    """The period map of a T-periodic field: ``advance(idx, x, k)`` integrates the rows x (M, d)
    over k periods each (adaptive DOP853, all rows at once), the heading (column ``turn_axis``)
    continuous. A :class:`lib.dynamics.verdicts.PeriodMap`; one field for every row (``idx`` unused).
    With fixed ``steps``, ``period_end(x, n, h, blowup, rec=None)`` (optional, e.g.
    :func:`rows_period_end`) is a compiled run of the same RK4 steps, n of h (s) from t = 0, used
    by :meth:`end` and :meth:`one` (which passes ``rec`` (n, M, d) for the states at each step's
    start): it returns the end (M, d) and a status (code, t, row), code 1 where a stage's state
    exceeds ``blowup`` and 2 where a step ends non-finite (0 otherwise), which both raise as
    ``_fixed`` does."""

    def __init__(self, rates: Rates, period: float, *, turn_axis: int = 2, rtol: float = 1e-10,
                 atol: float = 1e-10, steps: int = 0, period_end: Callable | None = None):
        self.rates, self.period, self.turn_axis = rates, float(period), turn_axis
        self.rtol, self.atol, self.steps, self.period_end = rtol, atol, steps, period_end

    def end(self, x: np.ndarray) -> np.ndarray:
        """The rows x (M, d) at t = 0 after one period."""
        if not (self.steps and self.period_end is not None):
            return self.one(x)[0]
        y, code, t, row = self.period_end(x, *fixed_steps(0.0, self.period, self.period / self.steps), BLOWUP)
        if code:
            raise _blew_up(_beyond(t) if code == 1 else nonfinite_message(t, row))
        return y

    def one(self, x: np.ndarray, samples: int = 0):
        """One period from the rows x (M, d) at t = 0: the end (M, d) and, with ``samples`` > 0
        (adaptive) or always (fixed steps), the times and states at equal steps over the period
        (the end left out)."""
        if self.steps and self.period_end is not None:
            n, h = fixed_steps(0.0, self.period, self.period / self.steps)
            rec = np.empty((n,) + np.shape(x))
            y, code, t, row = self.period_end(x, n, h, BLOWUP, rec)
            if code:
                raise _blew_up(_beyond(t) if code == 1 else nonfinite_message(t, row))
            return y, np.arange(n) * h, rec
        if self.steps:
            t, y = _fixed(self.rates, x, 0.0, self.period, self.steps)
            return y[-1], t[:-1], y[:-1]
        sol = _integrate(self.rates, x, 0.0, self.period, self.rtol, self.atol, dense=samples > 0)
        end = sol.y[:, -1].reshape(x.shape)
        if not samples:
            return end, None, None
        t = np.arange(samples) * (self.period / samples)
        return end, t, sol.sol(t).T.reshape(samples, *x.shape)

    def advance(self, idx, x, k) -> np.ndarray:
        x = np.array(x, dtype=float)
        k = np.broadcast_to(np.asarray(k, dtype=int), (x.shape[0],))
        for j in range(int(k.max(initial=0))):
            go = k > j
            x[go] = self.end(x[go])
        return x


@dataclass(frozen=True)
class LoopVerdict:
    """The regime of one closed loop from one start (:func:`loop_verdict`).

    ``regime`` a word of :data:`lib.dynamics.verdicts.REGIMES` (``periodic``, ``slipping`` or
    ``undecided``); ``period`` (periods of the forcing) and ``turns`` (whole turns the heading
    gains on the path's per ``period`` periods of the orbit); ``orbit`` (d,) the orbit's state at t = 0 (NaN without one); ``multipliers``
    (d,) its Floquet multipliers; ``floquet`` the largest modulus; ``distance`` of the run's last
    section state from the orbit (state units); ``reason`` why no orbit, where there is none;
    ``section`` (L, d) the run's section states (t = j T). From :func:`halved_verdict` (on the
    finer of two RK4 maps): ``steps`` the coarser map's fixed steps a period (the finer has
    twice as many; 0 from :func:`loop_verdict` alone), ``orbit_shift`` how far the orbit moved
    between them (max-norm, state units, heading modulo 2 pi; NaN without an orbit on both) and
    ``floquet_change`` how far the largest |multiplier| moved."""

    regime: str
    period: int
    turns: int
    orbit: np.ndarray
    multipliers: np.ndarray
    floquet: float
    distance: float
    reason: str
    section: np.ndarray
    steps: int = 0
    orbit_shift: float = math.nan
    floquet_change: float = math.nan


def run_periods(flow: FlowMap, s0, n_periods: int, *, samples: int = 0, record: int = 1):
    """Run one start s0 (d,) of ``flow`` over ``n_periods`` periods: the section states (n + 1, d)
    at t = j T and the states at equal steps over the last ``record`` periods (t from the first
    of them, (n_rec,); states (n_rec, d)): ``samples`` a period on the adaptive integrator's dense
    output, or the fixed steps themselves.

    Parameters
    ----------
    flow : FlowMap
        The closed loop's period map.
    s0 : array_like
        The start (d,) at t = 0.
    n_periods : int
        Periods run.
    samples : int
        Samples a period with the adaptive integrator (0: none).
    record : int
        The last periods recorded.

    Returns
    -------
    section : numpy.ndarray
        (n_periods + 1, d) the states at t = j T.
    t, states : numpy.ndarray or None
        The recorded times (s) and states (n_rec, d), None when nothing is recorded.
    """
    x = np.asarray(s0, dtype=float)[None, :]
    sec, ts, ys = [x[0].copy()], [], []
    for j in range(n_periods):
        keep = j >= n_periods - record
        end, t, y = flow.one(x, samples) if keep else (flow.end(x), None, None)
        if keep and t is not None:
            ts.append(t + (len(ts)) * flow.period)
            ys.append(y[:, 0])
        x = end
        sec.append(x[0].copy())
    if not ts:
        return np.array(sec), None, None
    return np.array(sec), np.concatenate(ts), np.concatenate(ys)


def loop_verdict(rates: Rates, period: float, s0, *, reference_turns: int = 0, period_end: Callable | None = None,
                 **options) -> LoopVerdict:
    """The long-run regime of the closed loop s' = rates(t, s) (T = ``period`` s) from s0 (d,), by
    the book's orbit procedure (:func:`lib.dynamics.verdicts.find_orbits`) on :class:`FlowMap`:
    ``transient`` periods, then the last ``history`` section states searched for an orbit of
    period k <= ``max_period`` (up to whole turns of the heading, column 2), Newton with a
    difference Jacobian (step ``fd_step``), Floquet multipliers, the reach test. Options and
    defaults: :data:`LOOP_OPTIONS`. A state that blows up gives ``undecided`` with the time.
    The heading's turns are counted against the path's: ``reference_turns`` (1 on the circle (27),
    whose tangent turns once a period; 0 on the eight) are taken off the orbit's, so that an orbit
    on which the heading follows the circle is ``periodic`` and one that gains turns on it
    ``slipping``.

    Parameters
    ----------
    rates : callable
        (t (s), s (M, d)) -> s' (M, d), T-periodic in t.
    period : float
        T (s), > 0.
    s0 : array_like
        The start (d,), heading in column 2.
    reference_turns : int
        Whole turns of the path's heading per period.
    period_end : callable, optional
        With fixed ``steps``: the same steps over a period compiled (:class:`FlowMap`).
    **options
        Keys of :data:`LOOP_OPTIONS`.

    Returns
    -------
    LoopVerdict
    """
    o = checks.options(options, LOOP_OPTIONS, minima=_INTEGER_OPTIONS)
    if not callable(rates):
        raise TypeError(f"rates must be a callable (t, s) -> s', got {type(rates).__name__}")
    if period_end is not None and not callable(period_end):
        raise TypeError(f"period_end must be None or a callable (x, n, h, blowup), got {type(period_end).__name__}")
    period = checks.number("period", period, positive=True, unit="s")
    s0 = checks.array("s0", s0, ndim=1)
    reference_turns = checks.integer("reference_turns", reference_turns)
    d = s0.size
    nan = np.full(d, np.nan)
    flow = FlowMap(rates, period, rtol=o["rtol"], atol=o["atol"], steps=o["steps"], period_end=period_end)
    try:
        sec, _, _ = run_periods(flow, s0, o["transient"] + o["history"], record=0)
    except SimulationError as err:
        return LoopVerdict("undecided", 0, 0, nan, nan + 0j, np.nan, np.nan, f"diverged: {err}", np.empty((0, d)))
    hist = sec[-o["history"]:, None, :]
    try:
        orb = dv.find_orbits(lambda i, x, k: dv.difference_jacobian(flow, i, x, k, o["fd_step"]), flow,
                             np.arange(1), hist, max_period=o["max_period"], candidate_tol=o["candidate_tol"],
                             newton_tol=o["newton_tol"], reach_tol=o["reach_tol"], reach_floor=o["reach_floor"],
                             newton_options=dict(max_iter=o["newton_iter"], stall_after=2))
    except SimulationError as err:
        return LoopVerdict("undecided", 0, 0, nan, nan + 0j, np.nan, np.nan, f"orbit search diverged: {err}", sec)
    if not orb["found"][0]:
        status = orb["status"][0] or "no candidate"
        return LoopVerdict("undecided", 0, 0, nan, nan + 0j, float(orb["floquet"][0]), np.nan,
                           f"no attracting orbit reached after {o['transient'] + o['history']} periods ({status})",
                           sec)
    k = int(orb["k"][0])
    n = int(orb["n"][0]) - k * reference_turns
    regime = str(dv.orbit_regime(np.array([n]))[0])
    return LoopVerdict(regime, k, n, orb["x"][0], orb["mult"][0], float(np.abs(orb["mult"][0]).max()),
                       float(orb["distance"][0]), "", sec)


def _orbit_shift(flow: FlowMap, a: LoopVerdict, b: LoopVerdict) -> float:
    """How far a's orbit point lies from the nearest point of b's cycle (b.period points on
    ``flow``, b's map): max-norm, state units, the heading (column ``flow.turn_axis``) modulo
    2 pi; NaN unless both have an orbit."""
    if not (np.isfinite(a.orbit).all() and np.isfinite(b.orbit).all()):
        return math.nan
    pts = [b.orbit]
    for _ in range(1, b.period):
        pts.append(flow.end(pts[-1][None])[0])
    diff = a.orbit - np.array(pts)
    diff[:, flow.turn_axis] = wrap_angle(diff[:, flow.turn_axis])
    return float(np.abs(diff).max(axis=1).min())


def _disagreement(a: LoopVerdict, b: LoopVerdict, shift: float, steps: int) -> str:
    """Why the verdicts a (``steps`` RK4 steps a period) and b (twice as many) do not make one
    verdict, or "" when they do."""
    when = f"when the step was halved from {steps} to {2 * steps} RK4 steps a period"
    if (a.regime, a.period, a.turns) != (b.regime, b.period, b.turns):
        said = [f"{v.regime} (period {v.period}, {v.turns} turns)" if v.period else f"{v.regime} ({v.reason})"
                for v in (a, b)]
        return f"the verdict changed {when}: {said[0]}, then {said[1]}"
    if shift > ORBIT_SHIFT_TOL:
        return f"the orbit moved by {shift:.3g} (more than {ORBIT_SHIFT_TOL:g}) {when}"
    if b.regime != "undecided" and not multipliers_agree(a.floquet, b.floquet):
        return (f"|mu_1| moved from {a.floquet:.3g} to {b.floquet:.3g} (more than "
                f"{multiplier_tolerance(a.floquet, b.floquet):.3g}) {when}")
    return ""


def halved_verdict(rates: Rates, period: float, s0, *, steps: int, max_steps: int | None = None,
                   reference_turns: int = 0, period_end: Callable | None = None, **options) -> LoopVerdict:
    """:func:`loop_verdict` taken on two classical RK4 maps, ``steps`` and twice as many fixed
    steps a period, the steps doubled while the two disagree, up to ``max_steps`` for the finer.

    The two agree when they give the same regime, period and turns and, where they find an
    orbit, the orbit moves by at most :data:`lib.optimal.verdict.ORBIT_SHIFT_TOL` (max-norm,
    state units; to the nearest point of the finer map's cycle, the heading modulo 2 pi) and its
    largest |Floquet multiplier| agrees (:func:`lib.optimal.floquet.multipliers_agree`, relative), the
    tolerances of the optimal tracker's verdict. For a method of order p the finer map's error is
    about the shift / (2^p - 1): the shift itself where RK4 keeps only p = 1 across the kinks and
    the chattering of a clipped input (Chapter 8's loops: the shift halves with the step), a
    fifteenth of it on a smooth field. A distance measured along the finer map's orbit is then
    good to about 1e-4 m, below the last of three significant digits of distances of 0.1 m and
    more, and the reach test, which measures each run against its own map's orbit, is not moved
    by the step. Where the last pair tried still disagrees the verdict is ``undecided``, its
    reason saying what changed when the step was halved. The result is the finer map's verdict,
    with ``steps`` (the coarser map's), ``orbit_shift`` and ``floquet_change``.

    Parameters
    ----------
    rates, period, s0, reference_turns, period_end, **options
        As in :func:`loop_verdict` (not ``steps``).
    steps : int
        The coarser map's fixed steps a period at first, >= 1.
    max_steps : int, optional
        The most steps a period of the finer map, >= 2 ``steps`` and at most
        :data:`lib.machinery.domain.MAX_STEPS` (default 2 ``steps``: one pair, no doubling).

    Returns
    -------
    LoopVerdict
    """
    steps = checks.integer("steps", steps, minimum=1)
    max_steps = checks.integer("max_steps", 2 * steps if max_steps is None else max_steps, minimum=2 * steps)
    if max_steps > checks.MAX_STEPS:
        raise ValueError(f"max_steps must be at most {checks.MAX_STEPS} fixed steps a period, got {max_steps}")

    def verdict(n):
        return loop_verdict(rates, period, s0, reference_turns=reference_turns, period_end=period_end,
                            steps=n, **options)

    coarse = verdict(steps)
    while True:
        fine = verdict(2 * steps)
        flow = FlowMap(rates, period, steps=2 * steps, period_end=period_end)
        try:
            shift = _orbit_shift(flow, coarse, fine)
        except SimulationError:
            shift = math.inf
        change = abs(coarse.floquet - fine.floquet) if fine.regime != "undecided" else math.nan
        reason = _disagreement(coarse, fine, shift, steps)
        if not reason or 4 * steps > max_steps:
            break
        coarse, steps = fine, 2 * steps
    return replace(fine, regime="undecided" if reason else fine.regime, reason=reason or fine.reason,
                   steps=steps, orbit_shift=shift, floquet_change=change)


def steady_measures(t, states, F, beta, path_z, *, F_cap: float | None = None,
                    beta_max: float | None = None) -> dict:
    """The steady errors and inputs over one period sampled at equal steps (the last sample one
    step before the period closes): the largest and the RMS distance |C - C_d| (m), the peak
    force F (N) and the peak |beta| (rad), and the range of the heading error p = phi - phi_d
    (rad, continuous). Largest values are refined between samples by parabolas
    (:func:`lib.dynamics.sampled.sampled_extremes`, cyclic; error O(h^3) for a smooth signal, and
    the sampled value itself at a kink). A parabola through a force held at its cap would
    overshoot it: the peaks are taken no higher than ``F_cap`` and ``beta_max``, which the applied
    inputs never exceed.

    Parameters
    ----------
    t : array_like
        Sample times (s), (n,), equal steps over one period.
    states : array_like
        (n, 6): x, y, phi and rates.
    F, beta : array_like
        Applied inputs (N, rad), (n,).
    path_z : array_like
        The path's z_d at t, (n, 3) (x_d, y_d, phi_d).
    F_cap, beta_max : float, optional
        The limits the inputs obey (N, rad), None for none.

    Returns
    -------
    dict
        max_error, rms_error (m), F_peak (N), beta_peak (rad), p_range (rad).
    """
    states, path_z = np.asarray(states, dtype=float), np.asarray(path_z, dtype=float)
    dist = np.hypot(states[:, 0] - path_z[:, 0], states[:, 1] - path_z[:, 1])
    p = np.unwrap(states[:, 2] - path_z[:, 2])
    top = lambda y: float(max(sampled_extremes(np.asarray(y, dtype=float)[None, :])[1][0], np.max(y)))  # noqa: E731
    pmin, pmax = sampled_extremes(p[None, :], cyclic=False)
    F_peak, beta_peak = top(F), top(np.abs(beta))
    if F_cap is not None:
        F_peak = min(F_peak, float(F_cap))
    if beta_max is not None:
        beta_peak = min(beta_peak, float(beta_max))
    return dict(max_error=top(dist), rms_error=float(np.sqrt(np.mean(dist**2))), F_peak=F_peak,
                beta_peak=beta_peak, p_range=float(pmax[0] - pmin[0]))
