"""One step of the compiled switched integrator and the location of the first event within
it (numba), for :mod:`lib.integrators.switched_compiled`.

A step of an explicit Runge-Kutta method (8th-order Dormand-Prince by default) is taken
over a fixed interval; if an event function changed sign over it (``_fired``), the
first event is located to ``T_TOL`` = 1e-11 s and the run lands just past it, so that no
step straddles a switching or a kink. Two locators do that (``run_periods``'s ``dense``):

- **dense** (the default). A step that straddles an event mixes both sides' fields in its
  stages, so no interpolant of it is accurate there. Its cubic Hermite interpolant gives a
  rough estimate; a real step to 1e-3 of the step before it is smooth, and its 7th-order
  dense output (scipy's ``DOP853``: three more stages, once an event), continued a little
  past its end, is the one-sided flow through the event. The event's time is found on that
  continuation by the Illinois method to 5e-13 s, with no new stage per try. One real step
  then lands T_TOL / 2 past it. It stands if the event fired there and the root lies within
  T_TOL before the landing, as a Newton step from the landing puts it (the event function's
  real value over its slope on the continuation: an error of second order in the distance);
  otherwise one more real step lands just past that root. An event that still escapes (a
  grazing one, another event first, a rough estimate that misses) goes to the **bracket**
  locator from the real bracket found so far: about 3 % of the events, measured on the
  eight's sweep. About 2.4 real steps an event instead of 10.
- **bracket**: the root is first estimated on the step's cubic Hermite interpolant and
  bracketed by two real steps 1e-3 of the step either side, then the length is found by
  the Illinois method with real steps (a bisection when it stalls) until the first event
  is bracketed to T_TOL. About ten real steps an event.

No state is interpolated: every landing state comes from a real step from the step's start.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from .switched_field import _TH, N_EVENTS, _field, _field_cs
from .trig import cos_sin_near

# a stage's cos and sin of the reference's phase and of the heading, from its step's
_near = numba.njit(cos_sin_near)

# the constants these kernels pass to one another are typed values (np.int64, np.bool_), not
# literals, which numba would compile into a copy of the callee each (switched_compiled: _LITERALS)

__all__ = ["T_TOL"]

#: events are placed within 1e-11 s, switchings and slide exits (a jump of the field) and kinks
#: (a jump of its derivative) alike. Kinks located to only 1e-8 s cost a factor 40 in the error
#: of a chaotic run after two periods (measured 2.5e-6 against 6e-8 at 20 deg, 400 steps)
T_TOL = 1e-11
#: the root on the dense output is found to this (s), far inside T_TOL
_DENSE_TOL = 0.05 * T_TOL
#: the real steps around the Hermite estimate, as a fraction of the step
_MARGIN = 1e-3


@numba.njit
def _step(P, lim, mode, t, s, h, A, b, c, K, ys, out, g):
    """One explicit Runge-Kutta step of size h from (t, s) into ``out``; the event
    functions at its end into ``g``, the rates there into ``ys``. ``K[0]`` must hold the
    rates at (t, s) under ``mode`` already (the first stage, c[0] = 0, does not depend on
    h): the caller has them from the end of the step before, or from the field evaluated
    after an event, or from the first try of this step (``_advance``). The stages' cos and
    sin of the reference's phase and of the heading come from the start's
    (:func:`lib.integrators.trig.cos_sin_near`): one libm sincos of each angle a step."""
    n_st = c.size
    th, p0 = P[_TH], s[2]
    k0 = th * t
    ck0, sk0, cp0, sp0 = math.cos(k0), math.sin(k0), math.cos(p0), math.sin(p0)
    for i in range(1, n_st):
        for q in range(6):
            ys[q] = s[q]
        for j in range(i):
            if A[i, j] != 0.0:
                for q in range(6):
                    ys[q] += h * A[i, j] * K[j, q]
        ck, sk = _near(ck0, sk0, k0, th * (t + c[i] * h) - k0)
        cp, sp = _near(cp0, sp0, p0, ys[2] - p0)
        _field_cs(P, lim, mode, ck, sk, cp, sp, ys, K[i], g)
    for q in range(6):
        acc = 0.0
        for i in range(n_st):
            if b[i] != 0.0:
                acc += b[i] * K[i, q]
        out[q] = s[q] + h * acc
    ck, sk = _near(ck0, sk0, k0, th * (t + h) - k0)
    cp, sp = _near(cp0, sp0, p0, out[2] - p0)
    _field_cs(P, lim, mode, ck, sk, cp, sp, out, ys, g)


@numba.njit
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


@numba.njit
def _first_fired(mode, g0, g1):
    """The first event (in the order of the event functions) that fired between g0 and g1, or -1."""
    for k in range(N_EVENTS):
        if _fired(mode, g0, g1, k):
            return k
    return -1


@numba.njit
def _hit(mode, g0, g1, ev):
    """The event that fired between g0 and g1: ``ev`` if it did, else the last that did, or -1."""
    hit = -1
    for k in range(N_EVENTS):
        if _fired(mode, g0, g1, k):
            hit = k
            if k == ev:
                break
    return hit


@numba.njit
def _copy(y, g, y_to, g_to):
    """Copy a state (6,) and its event values into y_to, g_to."""
    for q in range(6):
        y_to[q] = y[q]
    for k in range(N_EVENTS):
        g_to[k] = g[k]


@numba.njit
def _hermite_root(P, lim, mode, t, dt, s, f0, y1, f1, g0, ev, yh, fh, gh, n_bisect):
    """Root in (0, dt) of event ``ev`` (as :func:`_fired` sees it from ``g0``) on the cubic
    Hermite interpolant of the step (t, s, f0) -> (t + dt, y1, f1), by ``n_bisect``
    bisections (34: to 1e-10 dt):
    an estimate, to be bracketed by real steps (the interpolant's error is of the step's order
    four, not eight). ``f1`` must hold the rates at the step's end. Returns -1 if none is seen."""
    lo, hi = 0.0, 1.0
    found = False
    for _ in range(n_bisect):
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


@numba.njit
def _dense_coefficients(P, lim, mode, t, s, dt, y1, K, AX, CX, D, F, yh, gh):
    """The coefficients F (7, 6) of the 7th-order dense output of the DOP853 step (t, s, dt)
    -> y1 whose stages are K[0:12] and end rates K[12] (scipy's ``DOP853._dense_output_impl``):
    three more stages K[13:16] with the rows AX (3, 16) at the nodes CX (3,), and D (4, 16)."""
    for r in range(3):
        st = 13 + r
        for q in range(6):
            acc = 0.0
            for j in range(st):
                if AX[r, j] != 0.0:
                    acc += AX[r, j] * K[j, q]
            yh[q] = s[q] + dt * acc
        _field(P, lim, mode, t + CX[r] * dt, yh, K[st], gh)
    for q in range(6):
        dy = y1[q] - s[q]
        F[0, q] = dy
        F[1, q] = dt * K[0, q] - dy
        F[2, q] = 2.0 * dy - dt * (K[12, q] + K[0, q])
        for r in range(4):
            acc = 0.0
            for j in range(16):
                if D[r, j] != 0.0:
                    acc += D[r, j] * K[j, q]
            F[3 + r, q] = dt * acc


@numba.njit
def _dense_state(F, s, u, out):
    """The dense output at the fraction u of the step from s (scipy's ``Dop853DenseOutput``)."""
    for q in range(6):
        out[q] = 0.0
    for i in range(7):
        f = F[6 - i]
        w = u if i % 2 == 0 else 1.0 - u
        for q in range(6):
            out[q] = (out[q] + f[q]) * w
    for q in range(6):
        out[q] += s[q]


@numba.njit
def _illinois(P, lim, mode, t, s, lo, hi, glo, ghi, ev, tol, dense, F, dt, A, b, c, K, ys, yt, gt,
              y2, g2, g0, stats):
    """Narrow the bracket (lo, hi] (s from t) of the first event to ``tol``: the Illinois
    method on event ``ev`` (a bisection when it stalls), each try a real step from (t, s), or
    with ``dense`` the step's dense output F of length dt (no new stage). A secant try that
    lands next to the root is followed by a try just across it, 0.9 tol away, which closes the
    bracket at once when the secant was accurate. A try where another event fired first
    follows that one. Real tries that fired are copied into y2, g2 (the state at hi).
    Returns (lo, hi, ev)."""
    side = 0
    it = 0
    stall = 0
    nudge = 0
    while hi - lo > tol and it < 200:
        it += 1
        width = hi - lo
        secant = False
        if nudge == 1:
            th = lo + 0.9 * tol
        elif nudge == -1:
            th = hi - 0.9 * tol
        elif stall >= 2 or ghi == glo:
            th = 0.5 * (lo + hi)
            stall = 0
        else:
            th = (lo * ghi - hi * glo) / (ghi - glo)
            secant = True
            if not (lo < th < hi):
                th = 0.5 * (lo + hi)
                secant = False
        if dense:
            _dense_state(F, s, th / dt, yt)
            _field(P, lim, mode, t + th, yt, ys, gt)
        else:
            _step(P, lim, mode, t, s, th, A, b, c, K, ys, yt, gt)
            stats[5] += 1
        hit = _hit(mode, g0, gt, ev)
        if hit >= 0:  # an event before th
            hi = th
            if not dense:
                _copy(yt, gt, y2, g2)
            if hit != ev:  # another event comes first: follow it from here on
                ev = hit
                side = 0
                glo = g0[ev]
            ghi = gt[ev]
            if side == 1:
                glo *= 0.5
            side = 1
            nudge = -1 if secant else 0
        else:
            lo = th
            glo = gt[ev]
            if side == -1:
                ghi *= 0.5
            side = -1
            nudge = 1 if secant else 0
        stall = stall + 1 if hi - lo > 0.5 * width else 0
    return lo, hi, ev


@numba.njit
def _dense_landing(P, lim, mode, t, s, dt, first, A, b, c, K, ys, y1, y2, g0, g1, g2, yh, fh, gh, AX, CX, D,
                   F, stats):
    """The dense locator (module docstring) for the step (t, s, dt) -> (y1, g1, end rates ys)
    where event ``first`` fired. Returns (lo, hi, glo, ghi, ev, done): done if the event is
    located (hi, with y2, g2 there), else the bracket (lo, hi] of event ev, its values glo,
    ghi, for the bracket locator, with y2, g2 at hi."""
    _copy(y1, g1, y2, g2)  # the step's end: the bracket's end until a real step fires earlier
    ev = first
    # a rough estimate on the step's cubic Hermite interpolant (the step straddles the event,
    # so no interpolant of it is accurate there), then a real step to just before it
    guess = _hermite_root(P, lim, mode, t, dt, s, K[0], y1, ys, g0, ev, yh, fh, gh, np.int64(16))
    ta, tb = guess - _MARGIN * dt, min(guess + _MARGIN * dt, dt)
    if not (0.0 < ta and guess < dt):
        stats[6] += 1
        return 0.0, dt, g0[ev], g2[ev], ev, False
    _step(P, lim, mode, t, s, ta, A, b, c, K, ys, y1, g1)
    stats[5] += 1
    hit = _first_fired(mode, g0, g1)
    if hit >= 0:
        _copy(y1, g1, y2, g2)
        stats[6] += 1
        return 0.0, ta, g0[hit], g1[hit], hit, False
    ga = (g1[0], g1[1], g1[2], g1[3])
    # that step is smooth: its dense output, continued past its end, is the one-sided flow
    # through the event. The event's time on it, by Illinois, with no new stage per try
    for q in range(6):
        K[12, q] = ys[q]
    _dense_coefficients(P, lim, mode, t, s, ta, y1, K, AX, CX, D, F, yh, gh)
    _dense_state(F, s, tb / ta, yh)
    _field(P, lim, mode, t + tb, yh, fh, gh)
    ev = _hit(mode, g0, gh, ev)
    if ev < 0:  # the continuation does not reach the event by tb
        stats[6] += 1
        return ta, dt, ga[first], g2[first], first, False
    lo, hi, ev = _illinois(P, lim, mode, t, s, ta, tb, ga[ev], gh[ev], ev, _DENSE_TOL, np.bool_(True), F, ta, A, b,
                           c, K, ys, yh, gh, y2, g2, g0, stats)
    # the event function's slope there, on the continuation over 1e-6 of the step
    th, tq = hi, hi - 1e-6 * dt
    _dense_state(F, s, th / ta, yh)
    _field(P, lim, mode, t + th, yh, fh, gh)
    gth = gh[ev]
    _dense_state(F, s, tq / ta, yh)
    _field(P, lim, mode, t + tq, yh, fh, gh)
    slope = (gth - gh[ev]) / (th - tq)
    # one real step just past it (T_TOL / 2); it stands if the event fired there and the root
    # lies within T_TOL before, as the slope and the real value of the event function put it
    # (a Newton step from the landing: its error is of second order in the distance, far
    # below T_TOL). Else one more real step, to that root and T_TOL / 2 past it
    root = hi
    lo_r, glo_r, hi_r = ta, ga[ev], dt  # the real bracket so far: not fired at ta; fired at dt (y2)
    for _ in range(2):
        th = min(root + 0.5 * T_TOL, hi_r)
        _step(P, lim, mode, t, s, th, A, b, c, K, ys, y1, g1)
        stats[5] += 1
        hit = _hit(mode, g0, g1, ev)
        if hit >= 0:
            _copy(y1, g1, y2, g2)
            hi_r = th
            if hit != ev:  # another event first: from the bracket (ta, th]
                stats[6] += 1
                return ta, th, ga[hit], g1[hit], hit, False
        else:
            lo_r, glo_r = th, g1[ev]
        if slope == 0.0:
            break
        root = th - g1[ev] / slope
        if hit >= 0 and th - T_TOL < root <= th:
            return th, th, 0.0, 0.0, ev, True
        if not lo_r < root < hi_r:
            break
    stats[6] += 1
    return lo_r, hi_r, glo_r, g2[ev], ev, False


@numba.njit
def _locate(P, lim, mode, t, s, dt, first, A, b, c, K, ys, y1, y2, g0, g1, g2, yh, fh, gh, dense, AX, CX, D, F,
            stats):
    """The time from t (s) to the first event within a step dt from state s, where the event
    ``first`` fired at the step's end (y1, g1, with the end rates in ys): bracketed to T_TOL,
    on the dense output first if ``dense``. Returns it; y2, g2 hold the state and event
    functions there."""
    lo, hi = 0.0, dt
    ev = first
    if dense:
        lo, hi, glo, ghi, ev, done = _dense_landing(P, lim, mode, t, s, dt, first, A, b, c, K, ys, y1, y2, g0, g1,
                                                    g2, yh, fh, gh, AX, CX, D, F, stats)
        if done:
            return hi
    else:
        glo, ghi = g0[ev], g1[ev]
        _copy(y1, g1, y2, g2)
        # first on the step's cubic Hermite interpolant (one field evaluation per try), then
        # two real steps a little before and after its root narrow the bracket cheaply
        guess = _hermite_root(P, lim, mode, t, dt, s, K[0], y1, ys, g0, ev, yh, fh, gh, np.int64(34))
        if 0.0 < guess < dt:
            for th in (guess - _MARGIN * dt, guess + _MARGIN * dt):
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
    lo, hi, ev = _illinois(P, lim, mode, t, s, lo, hi, glo, ghi, ev, T_TOL, np.bool_(False), F, dt, A, b, c, K, ys,
                           y1, g1, y2, g2, g0, stats)
    return hi
