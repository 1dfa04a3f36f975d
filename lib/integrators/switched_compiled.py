"""The compiled switched integrator: the closed loop with an angle limit (and an optional
force cap), integrated in numba with a fixed step, event location and Filippov
sliding, for many runs at once (one run per parallel loop).

It integrates the same system as :class:`lib.integrators.switched.SwitchedLoop`
(see that module for the switching surface S = {lat = 0, lon < 0}, the one-sided
fields continued across S, the sliding field and the kinks), with the same
modes (+1 / -1 smooth on a side, 0 sliding), by a different scheme:

- every reference period T is cut into ``steps_per_period`` equal steps of an
  explicit Runge-Kutta method (8th-order Dormand-Prince by default), so that the
  discrete period map is exactly T-periodic, as the flow's is;
- at the end of each step the event functions are evaluated
  (:mod:`lib.integrators.switched_field`): the switching function mode * lat + eps_lat
  (watched falling through zero), the sliding exits ``r_+ + k lat`` (rising) and
  ``r_- + k lat`` (falling), and the kinks |tau| sin(psi -+ beta_max) and
  |tau|^2 - F_max^2 (either way). If one changed sign, the first event is located to
  1e-11 s (:mod:`lib.integrators.switched_events`: on the dense output of a smooth step
  ending just before it, then one real step; or by real steps only) and the run lands just
  past it, so that no step straddles a switching or a kink, and the step's remainder
  follows with the new mode. No state is interpolated;
- the mode after a crossing of S is decided as in ``SwitchedLoop``: cross if the
  far side's field carries on through S, slide if both fields point into S.

eps_lat = 1e-9 N makes the crossing unambiguous: a run lands 1e-9 N beyond S,
and a run leaving a slide with |lat| below it cannot be caught by the surface
it just left. The largest Lyapunov exponent is estimated as
:func:`lib.dynamics.lyapunov.largest_lyapunov` does (Benettin: a companion run
at distance d0, renormalised every period), inside the compiled loop.

``tests/test_limits.py`` checks this integrator against ``SwitchedLoop`` at tight
tolerance (crossings, slides and kinks) and its exponents against the slow path.
"""

from __future__ import annotations

import math
from pathlib import Path

import numba
import numpy as np

from ..machinery.cache import source_stamp
from .switched_events import T_TOL, _copy, _first_fired, _locate, _step
from .switched_field import EPS_LAT, N_EVENTS, _field, _kin, _one_sided  # noqa: F401 (_kin: the tests')

__all__ = ["run_periods", "dop853_dense", "EPS_LAT", "N_EVENTS", "T_TOL"]

_MAX_EVENTS_PER_STEP = 200

# _LITERALS: a compiled function called with a constant (a literal 1, True) is compiled again for
# that constant, beside its compilation for a typed value: a second copy of the same arithmetic
# (measured: about 2 s of the switched kernel's 12 s of compilation on a fresh clone, the same
# speed after). The constants passed between these kernels are typed values (np.int64, np.bool_)


@numba.njit
def _initial_mode(P, lim, t, s, g, tmp):
    lat, lon = _field(P, lim, np.int64(1), t, s, tmp, g)  # typed, not a literal (_LITERALS)
    return 1 if lat >= 0 else -1


@numba.njit
def _new_mode(P, lim, mode, t, s, g0, g2, stats):
    """The mode after an event at time t (s), state s: the event that fired at the landing
    point decides (the switching and exit events take precedence)."""
    ev = _first_fired(mode, g0, g2)
    if mode != 0 and ev == 0:
        lon, rp, rm = _one_sided(P, lim, t, s)
        far = rm if mode == 1 else rp
        near = rp if mode == 1 else rm
        if lon >= 0 or mode * far < 0:
            if lon < 0:
                stats[0] += 1
            return -mode
        if mode * near < 0:
            stats[1] += 1
            return 0
        return mode  # a grazing touch, both fields carry the run back: keep the mode
    if mode == 0 and ev == 0:
        return 1
    if mode == 0 and ev == 1:
        return -1
    return mode


@numba.njit
def _advance(P, lim, mode, t0, s, n_steps, h, A, b, c, K, ys, y1, y2, g0, g1, g2, yh, fh, gh, dense, AX, CX, D,
             F, stats, rec, r0, every):
    """Integrate s (in place) over n_steps steps of size h from t0; returns the final mode.
    stats: [crossings, slides, time sliding, events, failed, steps locating events, dense
    estimates rejected]; ``dense``: the locator (:mod:`lib.integrators.switched_events`).
    With ``every`` > 0 the state at the end of every ``every``-th step goes to row
    r0 + (j + 1) / every of ``rec`` (the run itself is not changed)."""
    # K[0] holds the rates at (t, s) under the mode at every step's start (see _step): from the
    # field evaluated here or after an event, or from the end of the step before when that
    # step ended at the same time to the bit (t + dt == t_end), else evaluated again
    _field(P, lim, mode, t0, s, K[0], g0)
    t_k0 = t0
    for j in range(n_steps):
        t = t0 + j * h
        t_end = t0 + (j + 1) * h
        if t_k0 != t:
            _field(P, lim, mode, t, s, K[0], gh)
        n_ev = 0
        while True:
            dt = t_end - t
            if dt <= 1e-13 * (1.0 + abs(t_end)):
                break
            _step(P, lim, mode, t, s, dt, A, b, c, K, ys, y1, g1)
            first = _first_fired(mode, g0, g1)
            if first < 0:
                if mode == 0:
                    stats[2] += dt
                _copy(y1, g1, s, g0)
                for q in range(6):
                    K[0, q] = ys[q]
                t_k0 = t + dt
                t = t_end
                break
            hi = _locate(P, lim, mode, t, s, dt, first, A, b, c, K, ys, y1, y2, g0, g1, g2, yh, fh, gh, dense, AX, CX,
                         D, F, stats)
            if mode == 0:
                stats[2] += hi
            t += hi
            for q in range(6):
                s[q] = y2[q]
            stats[3] += 1
            n_ev += 1
            if n_ev > _MAX_EVENTS_PER_STEP:
                stats[4] = 1.0
                return mode
            mode = _new_mode(P, lim, mode, t, s, g0, g2, stats)
            _field(P, lim, mode, t, s, K[0], g0)
            t_k0 = t
        for q in range(6):
            if not math.isfinite(s[q]):
                stats[4] = 2.0
                return mode
        if every > 0 and (j + 1) % every == 0:
            for q in range(6):
                rec[r0 + (j + 1) // every, q] = s[q]
    return mode


def _sources_stamp() -> int:
    """A hash of the four modules whose kernels ``_run`` compiles in (as a 60-bit integer)."""
    return source_stamp(*(Path(__file__).with_name(name)
                          for name in ("switched_field.py", "switched_events.py", "switched_compiled.py", "trig.py")))


def _make_run(stamp: int):
    """The runs' kernel, cached on disk by numba. Numba keys a cached function on its own
    file and bytecode, not on the functions it calls from other modules, so only this one is
    cached, and it closes over ``stamp``, the hash of the modules it calls into: numba keys
    a closure on its cells too, so an edit of any of them compiles it again."""

    @numba.njit(cache=True, parallel=True)
    def _run(P, bmax, fmax, S0, n_periods, n_steps, T, t0, lyap_from, d0, A, b, c, dense, AX, CX, D, sections,
             modes, logs, stats, rec_from, rec_every, samples):
        if stamp < 0:
            return
        N = S0.shape[0]
        for q in numba.prange(N):
            K = np.empty((max(c.size, 16), 6))  # the stages, and for the dense output the end rates and three more
            F = np.empty((7, 6))
            ys, y1, y2 = np.empty(6), np.empty(6), np.empty(6)
            g0, g1, g2, gh = np.empty(N_EVENTS), np.empty(N_EVENTS), np.empty(N_EVENTS), np.empty(N_EVENTS)
            yh, fh = np.empty(6), np.empty(6)
            s = S0[q].copy()
            s2 = np.empty(6)
            st2 = np.zeros(stats.shape[1])
            h = T / n_steps
            lim = (bmax[q], math.cos(bmax[q]), math.sin(bmax[q]), fmax[q])
            mode = _initial_mode(P, lim, t0, s, g0, ys)
            mode2 = 1
            for q6 in range(6):
                sections[q, 0, q6] = s[q6]
            per = n_steps // rec_every if rec_every > 0 else 0       # samples a period
            for k in range(n_periods):
                ta = t0 + k * T
                every = rec_every if 0 <= rec_from <= k else 0
                if every > 0 and k == rec_from:
                    for q6 in range(6):
                        samples[q, 0, q6] = s[q6]
                if k == lyap_from:
                    for q6 in range(6):
                        s2[q6] = s[q6] + d0 / math.sqrt(6.0)
                    mode2 = _initial_mode(P, lim, ta, s2, g0, ys)
                mode = _advance(P, lim, mode, ta, s, n_steps, h, A, b, c, K, ys, y1, y2, g0, g1, g2, yh, fh, gh, dense,
                                AX, CX, D, F, stats[q], samples[q], (k - rec_from) * per, every)
                if stats[q, 4] != 0.0:
                    break
                if k >= lyap_from >= 0:
                    mode2 = _advance(P, lim, mode2, ta, s2, n_steps, h, A, b, c, K, ys, y1, y2, g0, g1, g2, yh,
                                     fh, gh, dense, AX, CX, D, F, st2, samples[q], np.int64(0), np.int64(0))
                    if st2[4] != 0.0:
                        stats[q, 4] = st2[4]
                        break
                    d = 0.0
                    for q6 in range(6):
                        d += (s2[q6] - s[q6]) ** 2
                    d = math.sqrt(d)
                    logs[q, k - lyap_from] = math.log(d / d0)
                    for q6 in range(6):
                        s2[q6] = s[q6] + (s2[q6] - s[q6]) * d0 / d
                    mode2 = _initial_mode(P, lim, ta + T, s2, g0, ys)
                for q6 in range(6):
                    sections[q, k + 1, q6] = s[q6]
                modes[q] = mode


    return _run


_run = _make_run(_sources_stamp())


def run_periods(P: np.ndarray, angle_limits: np.ndarray, force_limits: np.ndarray, S0: np.ndarray, n_periods: int,
                steps_per_period: int, period: float, t0: float, lyapunov_from: int, d0: float, A: np.ndarray,
                b: np.ndarray, c: np.ndarray, *, dense_output: tuple | None = None, record: tuple | None = None):
    """Low-level entry (see :func:`lib.limits.runs.switched_runs` for the checked one): N runs
    of ``n_periods`` periods from states S0 (N, 6) at t0. Returns the states at the period
    ends (N, n_periods + 1, 6), the final modes (N,), log(d/d0) of the companion per
    period from ``lyapunov_from`` on (N, n_periods - lyapunov_from; -1 for none) and the
    statistics (N, 7): crossings, slides, time sliding (s), events, failure flag
    (1: an accumulation of events, 2: a non-finite state), real steps spent locating events,
    dense estimates rejected (:mod:`lib.integrators.switched_events`). With ``record`` = (k, S)
    also the states S times a period (at the ends of every ``steps_per_period / S``-th step of
    the same run) from the start of period k on (N, (n_periods - k) S + 1, 6), else None.

    Parameters
    ----------
    P : numpy.ndarray
        The packed parameters of body, gains and reference.
    angle_limits, force_limits : numpy.ndarray
        beta_max (rad) and F_max (N, inf for none), (N,).
    S0 : numpy.ndarray
        Start states (N, 6).
    n_periods, steps_per_period : int
        Periods and fixed steps per period.
    period, t0 : float
        The reference period and the start time (s).
    lyapunov_from : int
        First period of the companion (-1 for none).
    d0 : float
        The companion's initial separation.
    A, b, c : numpy.ndarray
        The Runge-Kutta tableau.
    dense_output : tuple, optional
        (A_extra (3, 16), C_extra (3,), D (4, 16)) of DOP853's dense output
        (:func:`dop853_dense`): events are located on it first; None, by real steps only.
    record : tuple, optional
        (first period k, samples per period S), S dividing ``steps_per_period``: the run's
        states S times a period from period k on.

    Returns
    -------
    tuple
        States (N, n_periods + 1, 6), final modes (N,), log-growths, statistics (N, 7) and the
        recorded states (or None).
    """
    N = S0.shape[0]
    sections = np.full((N, n_periods + 1, 6), np.nan)
    modes = np.zeros(N, dtype=np.int64)
    n_log = n_periods - lyapunov_from if lyapunov_from >= 0 else 0
    logs = np.full((N, max(n_log, 0)), np.nan)
    stats = np.zeros((N, 7))
    if record is None:
        rec_from, rec_every, samples = -1, 0, np.zeros((N, 1, 6))
    else:
        rec_from, per = (int(v) for v in record)
        if not (0 <= rec_from < n_periods and per >= 1 and steps_per_period % per == 0):
            raise ValueError(f"record must be (k, S), 0 <= k < n_periods ({n_periods}), S dividing "
                             f"steps_per_period ({steps_per_period}), got {record!r}")
        rec_every, samples = steps_per_period // per, np.full((N, (n_periods - rec_from) * per + 1, 6), np.nan)
    if dense_output is None:
        AX, CX, D = np.zeros((3, 16)), np.zeros(3), np.zeros((4, 16))
    else:
        AX, CX, D = (np.asarray(x, float) for x in dense_output)
        if c.size != 12 or AX.shape != (3, 16) or CX.shape != (3,) or D.shape != (4, 16):
            raise ValueError("dense_output is DOP853's (12 stages): A_extra (3, 16), C_extra (3,), D (4, 16)")
    # C-contiguous and writable (copied if need be): numba compiles a read-only array (a
    # broadcast, a view of one) as another type, a second kernel of the same arithmetic
    P, bmax, fmax, S0, A, b, c, AX, CX, D = (np.require(x, float, "CW") for x in (
        P, angle_limits, force_limits, S0, A, b, c, AX, CX, D))
    _run(P, bmax, fmax, S0, int(n_periods), int(steps_per_period), float(period), float(t0), int(lyapunov_from),
         float(d0), A, b, c, dense_output is not None, AX, CX, D, sections, modes, logs, stats, rec_from, rec_every,
         samples)
    return sections, modes, logs, stats, (None if record is None else samples)


def dop853_dense() -> tuple:
    """The coefficients of the 7th-order dense output of scipy's ``DOP853`` (its three extra
    stages and its interpolant), for :func:`run_periods`'s ``dense_output``.

    Returns
    -------
    tuple
        (A_extra (3, 16), C_extra (3,), D (4, 16)).
    """
    from scipy.integrate import DOP853

    return np.array(DOP853.A_EXTRA), np.array(DOP853.C_EXTRA), np.array(DOP853.D)
