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
- at the end of each step the event functions are evaluated: the switching
  function mode * lat + eps_lat (watched falling through zero), the sliding
  exits ``r_+ + k lat`` (rising) and ``r_- + k lat`` (falling), and the kinks
  |tau| sin(psi -+ beta_max) and |tau|^2 - F_max^2 (either way). If one changed
  sign, the step is redone from its start with a shorter step: its root is
  first estimated on the step's cubic Hermite interpolant and bracketed by two
  real steps 1e-3 of the step either side, then the length is found by the
  Illinois method on the event function (a bisection when it stalls),
  until the first event is bracketed to 1e-11 s. The run then lands just past
  the event, so that no step straddles a switching or a kink,
  and the step's remainder follows with the new mode. No state is interpolated;
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

import numba
import numpy as np

__all__ = ["run_periods", "EPS_LAT", "N_EVENTS"]

#: the switching function is watched at mode * lat + EPS_LAT (N)
EPS_LAT = 1e-9
#: number of event functions per mode (switching or exits, two clip kinks, the cap)
N_EVENTS = 4
_TWO_PI = 2.0 * math.pi
#: events are bracketed to 1e-11 s: switchings and slide exits (a jump of the field) and kinks
#: (a jump of its derivative) alike. Kinks located to only 1e-8 s cost a factor 40 in the error
#: of a chaotic run after two periods (measured: 2.5e-6 against 6e-8 at 20 deg, 400 steps)
_T_TOL = 1e-11
_MAX_EVENTS_PER_STEP = 200

# layout of the parameter vector P
_M, _I, _A, _C, _CPHI, _KPX, _KPY, _KVX, _KVY, _R, _TH, _KSLIDE, _KIND = range(13)


@numba.njit(cache=True)
def _kin(P, t):
    """Position, velocity, acceleration and jerk of the reference (circle (27) or eight (28))."""
    R, th = P[_R], P[_TH]
    s = th * t
    if P[_KIND] == 0.0:
        c, sn = math.cos(s), math.sin(s)
        return (R * c, R * sn, -R * th * sn, R * th * c, -R * th**2 * c, -R * th**2 * sn,
                R * th**3 * sn, -R * th**3 * c)
    c1, s1, c2, s2 = math.cos(s), math.sin(s), math.cos(2 * s), math.sin(2 * s)
    return (0.5 * R * s2, R * s1, R * th * c2, R * th * c1, -2 * R * th**2 * s2, -R * th**2 * s1,
            -4 * R * th**3 * c2, -R * th**3 * c1)


@numba.njit(cache=True)
def _field(P, lim, mode, t, s, out, g):
    """Rates of state s under ``mode`` into ``out`` (6,), event functions into ``g`` (4,);
    ``lim`` = (beta_max, cos beta_max, sin beta_max, F_max)."""
    bmax, cb, sb, fmax = lim
    m, I, a, cc, cphi = P[_M], P[_I], P[_A], P[_C], P[_CPHI]
    xd, yd, vxd, vyd, axd, ayd, jxd, jyd = _kin(P, t)
    x, y, phi, vx, vy, w = s[0], s[1], s[2], s[3], s[4], s[5]
    tx = m * axd + cc * vx + P[_KVX] * (vxd - vx) + P[_KPX] * (xd - x)
    ty = m * ayd + cc * vy + P[_KVY] * (vyd - vy) + P[_KPY] * (yd - y)
    c, sn = math.cos(phi), math.sin(phi)
    lat, lon = ty * c - tx * sn, tx * c + ty * sn
    tn = math.hypot(tx, ty)
    F = min(tn, fmax)
    ksl = P[_KSLIDE]
    # the clip's edges and the cap: kinks of the smooth fields
    g[1] = lat * cb - lon * sb
    g[2] = lat * cb + lon * sb
    g[3] = tx * tx + ty * ty - fmax * fmax if fmax < math.inf else 1.0
    if mode != 0:
        # beta = clip(psi, +-beta_max), psi = atan2(lat, lon) the demand's angle to the axis,
        # continued by mode * 2 pi just across S; its cosine and sine without trigonometry
        if lon < 0 and mode * lat < 0:
            cbe, sbe = cb, mode * sb
        elif lon >= tn * cb and tn > 0:
            cbe, sbe = lon / tn, lat / tn
        else:
            cbe, sbe = cb, (sb if lat >= 0 else -sb)
        ax = (F * (c * cbe - sn * sbe) - cc * vx) / m
        ay = (F * (sn * cbe + c * sbe) - cc * vy) / m
        aw = (a * F * sbe - cphi * w) / I
        g[0] = mode * lat + EPS_LAT
    else:
        apx = (F * (c * cb - sn * sb) - cc * vx) / m
        apy = (F * (sn * cb + c * sb) - cc * vy) / m
        amx = (F * (c * cb + sn * sb) - cc * vx) / m
        amy = (F * (sn * cb - c * sb) - cc * vy) / m
        awp = (a * F * sb - cphi * w) / I
        awm = (-a * F * sb - cphi * w) / I
        rp = _lat_rate(P, s, apx, apy, tx, ty, vxd, vyd, axd, ayd, jxd, jyd, c, sn)
        rm = _lat_rate(P, s, amx, amy, tx, ty, vxd, vyd, axd, ayd, jxd, jyd, c, sn)
        lam = (rm + ksl * lat) / (rm - rp)
        ax = lam * apx + (1 - lam) * amx
        ay = lam * apy + (1 - lam) * amy
        aw = lam * awp + (1 - lam) * awm
        g[0] = rp + ksl * lat
        g[1] = rm + ksl * lat
        g[2] = 1.0  # while sliding beta is the Filippov average, not a clip: no clip kinks
    out[0], out[1], out[2], out[3], out[4], out[5] = vx, vy, w, ax, ay, aw
    return lat, lon


@numba.njit(cache=True)
def _lat_rate(P, s, ax, ay, tx, ty, vxd, vyd, axd, ayd, jxd, jyd, c, sn):
    m, cc = P[_M], P[_C]
    dtx = m * jxd + cc * ax + P[_KVX] * (axd - ax) + P[_KPX] * (vxd - s[3])
    dty = m * jyd + cc * ay + P[_KVY] * (ayd - ay) + P[_KPY] * (vyd - s[4])
    return dty * c - dtx * sn - s[5] * (tx * c + ty * sn)


@numba.njit(cache=True)
def _one_sided(P, lim, t, s):
    """(lon, rate of lat under beta = +beta_max, under beta = -beta_max)."""
    bmax, fmax = lim[0], lim[3]
    m, cc = P[_M], P[_C]
    xd, yd, vxd, vyd, axd, ayd, jxd, jyd = _kin(P, t)
    tx = m * axd + cc * s[3] + P[_KVX] * (vxd - s[3]) + P[_KPX] * (xd - s[0])
    ty = m * ayd + cc * s[4] + P[_KVY] * (vyd - s[4]) + P[_KPY] * (yd - s[1])
    c, sn = math.cos(s[2]), math.sin(s[2])
    F = min(math.hypot(tx, ty), fmax)
    rp = _lat_rate(P, s, (F * math.cos(s[2] + bmax) - cc * s[3]) / m, (F * math.sin(s[2] + bmax) - cc * s[4]) / m,
                   tx, ty, vxd, vyd, axd, ayd, jxd, jyd, c, sn)
    rm = _lat_rate(P, s, (F * math.cos(s[2] - bmax) - cc * s[3]) / m, (F * math.sin(s[2] - bmax) - cc * s[4]) / m,
                   tx, ty, vxd, vyd, axd, ayd, jxd, jyd, c, sn)
    return tx * c + ty * sn, rp, rm


@numba.njit(cache=True)
def _step(P, lim, mode, t, s, h, A, b, c, K, ys, out, g):
    """One explicit Runge-Kutta step of size h from (t, s) into ``out``; the event
    functions at its end into ``g``, the rates there into ``ys``. ``K[0]`` must hold the
    rates at (t, s) under ``mode`` already (the first stage, c[0] = 0, does not depend on
    h): the caller has them from the end of the step before, or from the field evaluated
    after an event, or from the first try of this step (``_advance``)."""
    n_st = c.size
    for i in range(1, n_st):
        for q in range(6):
            ys[q] = s[q]
        for j in range(i):
            if A[i, j] != 0.0:
                for q in range(6):
                    ys[q] += h * A[i, j] * K[j, q]
        _field(P, lim, mode, t + c[i] * h, ys, K[i], g)
    for q in range(6):
        acc = 0.0
        for i in range(n_st):
            if b[i] != 0.0:
                acc += b[i] * K[i, q]
        out[q] = s[q] + h * acc
    _field(P, lim, mode, t + h, out, ys, g)


@numba.njit(cache=True)
def _fired(mode, g0, g1, k):
    """Whether event k fired between values g0 and g1 (its direction depends on the mode)."""
    if mode != 0:
        if k == 0:
            return g0[0] > 0.0 and g1[0] <= 0.0
    else:
        if k == 0:
            return g0[0] <= 0.0 and g1[0] > 0.0
        if k == 1:
            return g0[1] > 0.0 and g1[1] <= 0.0
    return (g0[k] > 0.0) != (g1[k] > 0.0)


@numba.njit(cache=True)
def _initial_mode(P, lim, t, s, g, tmp):
    lat, lon = _field(P, lim, 1, t, s, tmp, g)
    return 1 if lat >= 0 else -1


@numba.njit(cache=True)
def _copy(y, g, y_to, g_to):
    """Copy a state (6,) and its event values into y_to, g_to."""
    for q in range(6):
        y_to[q] = y[q]
    for k in range(N_EVENTS):
        g_to[k] = g[k]


@numba.njit(cache=True)
def _hermite_root(P, lim, mode, t, dt, s, f0, y1, f1, g0, ev, yh, fh, gh):
    """Root in (0, dt) of event ``ev`` (as :func:`_fired` sees it from ``g0``) on the cubic
    Hermite interpolant of the step (t, s, f0) -> (t + dt, y1, f1), by bisection to 1e-10 dt:
    an estimate, to be bracketed by real steps (the interpolant's error is of the step's order
    four, not eight). ``f1`` must hold the rates at the step's end. Returns -1 if none is seen."""
    lo, hi = 0.0, 1.0
    found = False
    for _ in range(34):
        u = 0.5 * (lo + hi)
        u2, u3 = u * u, u * u * u
        h00, h10, h01, h11 = 2 * u3 - 3 * u2 + 1, u3 - 2 * u2 + u, -2 * u3 + 3 * u2, u3 - u2
        for q in range(6):
            yh[q] = h00 * s[q] + h10 * dt * f0[q] + h01 * y1[q] + h11 * dt * f1[q]
        _field(P, lim, mode, t + u * dt, yh, fh, gh)
        if _fired(mode, g0, gh, ev):
            hi = u
            found = True
        else:
            lo = u
    return hi * dt if found else -1.0


@numba.njit(cache=True)
def _first_fired(mode, g0, g1):
    """The first event (in the order of the event functions) that fired between g0 and g1, or -1."""
    for k in range(N_EVENTS):
        if _fired(mode, g0, g1, k):
            return k
    return -1


@numba.njit(cache=True)
def _locate(P, lim, mode, t, s, dt, first, A, b, c, K, ys, y1, y2, g0, g1, g2, yh, fh, gh, stats):
    """The time from t (s) to the first event within a step dt from state s, where the event
    ``first`` fired at the step's end (y1, g1): bracketed to _T_TOL. Returns it; y2, g2 hold
    the state and event functions at the bracket's end."""
    # bracket the first event in (lo, hi]
    lo, hi = 0.0, dt
    ev = first
    glo, ghi = g0[ev], g1[ev]
    _copy(y1, g1, y2, g2)
    # first on the step's cubic Hermite interpolant (one field evaluation per try), then
    # two real steps a little before and after its root narrow the bracket cheaply
    guess = _hermite_root(P, lim, mode, t, dt, s, K[0], y1, ys, g0, ev, yh, fh, gh)
    if 0.0 < guess < dt:
        for th in (guess - 1e-3 * dt, guess + 1e-3 * dt):
            if not lo < th < hi:
                continue
            _step(P, lim, mode, t, s, th, A, b, c, K, ys, y1, g1)
            stats[5] += 1
            hit = _first_fired(mode, g0, g1)
            if hit >= 0:
                hi = th
                _copy(y1, g1, y2, g2)
                if hit != ev:
                    ev = hit
                    glo = g0[ev]
                ghi = g1[ev]
                break
            lo = th
            glo = g1[ev]
    # then Illinois on the target event with real steps (a bisection when it stalls); a
    # secant try that lands next to the root is followed by a try just across it, 0.9 tol
    # away, which closes the bracket at once when the secant was accurate
    side = 0
    it = 0
    stall = 0
    nudge = 0
    while hi - lo > _T_TOL and it < 200:
        it += 1
        width = hi - lo
        secant = False
        if nudge == 1:
            th = lo + 0.9 * _T_TOL
        elif nudge == -1:
            th = hi - 0.9 * _T_TOL
        elif stall >= 2 or ghi == glo:
            th = 0.5 * (lo + hi)
            stall = 0
        else:
            th = (lo * ghi - hi * glo) / (ghi - glo)
            secant = True
            if not (lo < th < hi):
                th = 0.5 * (lo + hi)
                secant = False
        _step(P, lim, mode, t, s, th, A, b, c, K, ys, y1, g1)
        stats[5] += 1
        hit = -1
        for k in range(N_EVENTS):
            if _fired(mode, g0, g1, k):
                hit = k
                if k == ev:
                    break
        if hit >= 0:  # an event before th
            hi = th
            _copy(y1, g1, y2, g2)
            if hit != ev:  # another event comes first: follow it from here on
                ev = hit
                side = 0
                glo = g0[ev]
            ghi = g1[ev]
            if side == 1:
                glo *= 0.5
            side = 1
            nudge = -1 if secant else 0
        else:
            lo = th
            glo = g1[ev]
            if side == -1:
                ghi *= 0.5
            side = -1
            nudge = 1 if secant else 0
        stall = stall + 1 if hi - lo > 0.5 * width else 0
    return hi


@numba.njit(cache=True)
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


@numba.njit(cache=True)
def _advance(P, lim, mode, t0, s, n_steps, h, A, b, c, K, ys, y1, y2, g0, g1, g2, yh, fh, gh, stats):
    """Integrate s (in place) over n_steps steps of size h from t0; returns the final mode.
    stats: [crossings, slides, time sliding, events, failed, steps locating events]."""
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
            hi = _locate(P, lim, mode, t, s, dt, first, A, b, c, K, ys, y1, y2, g0, g1, g2, yh, fh, gh, stats)
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
    return mode


@numba.njit(cache=True, parallel=True)
def _run(P, bmax, fmax, S0, n_periods, n_steps, T, t0, lyap_from, d0, A, b, c, sections, modes, logs, stats):
    N = S0.shape[0]
    for q in numba.prange(N):
        n_st = c.size
        K = np.empty((n_st, 6))
        ys, y1, y2 = np.empty(6), np.empty(6), np.empty(6)
        g0, g1, g2, gh = np.empty(N_EVENTS), np.empty(N_EVENTS), np.empty(N_EVENTS), np.empty(N_EVENTS)
        yh, fh = np.empty(6), np.empty(6)
        s = S0[q].copy()
        s2 = np.empty(6)
        st2 = np.zeros(6)
        h = T / n_steps
        lim = (bmax[q], math.cos(bmax[q]), math.sin(bmax[q]), fmax[q])
        mode = _initial_mode(P, lim, t0, s, g0, ys)
        mode2 = 1
        for q6 in range(6):
            sections[q, 0, q6] = s[q6]
        for k in range(n_periods):
            ta = t0 + k * T
            if k == lyap_from:
                for q6 in range(6):
                    s2[q6] = s[q6] + d0 / math.sqrt(6.0)
                mode2 = _initial_mode(P, lim, ta, s2, g0, ys)
            mode = _advance(P, lim, mode, ta, s, n_steps, h, A, b, c, K, ys, y1, y2, g0, g1, g2, yh, fh, gh,
                            stats[q])
            if stats[q, 4] != 0.0:
                break
            if k >= lyap_from >= 0:
                mode2 = _advance(P, lim, mode2, ta, s2, n_steps, h, A, b, c, K, ys, y1, y2, g0, g1,
                                 g2, yh, fh, gh, st2)
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


def run_periods(P: np.ndarray, angle_limits: np.ndarray, force_limits: np.ndarray, S0: np.ndarray, n_periods: int,
                steps_per_period: int, period: float, t0: float, lyapunov_from: int, d0: float, A: np.ndarray,
                b: np.ndarray, c: np.ndarray):
    """Low-level entry (see :func:`lib.limits.runs.switched_runs` for the checked one): N runs
    of ``n_periods`` periods from states S0 (N, 6) at t0. Returns the states at the period
    ends (N, n_periods + 1, 6), the final modes (N,), log(d/d0) of the companion per
    period from ``lyapunov_from`` on (N, n_periods - lyapunov_from; -1 for none) and the
    statistics (N, 6): crossings, slides, time sliding (s), events, failure flag
    (1: an accumulation of events, 2: a non-finite state), real steps spent locating events.

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

    Returns
    -------
    tuple
        States (N, n_periods + 1, 6), final modes (N,), log-growths and statistics (N, 6).
    """
    N = S0.shape[0]
    sections = np.full((N, n_periods + 1, 6), np.nan)
    modes = np.zeros(N, dtype=np.int64)
    n_log = n_periods - lyapunov_from if lyapunov_from >= 0 else 0
    logs = np.full((N, max(n_log, 0)), np.nan)
    stats = np.zeros((N, 6))
    _run(np.ascontiguousarray(P, float), np.ascontiguousarray(angle_limits, float),
         np.ascontiguousarray(force_limits, float), np.ascontiguousarray(S0, float), int(n_periods),
         int(steps_per_period), float(period), float(t0), int(lyapunov_from), float(d0),
         np.ascontiguousarray(A, float), np.ascontiguousarray(b, float), np.ascontiguousarray(c, float),
         sections, modes, logs, stats)
    return sections, modes, logs, stats
