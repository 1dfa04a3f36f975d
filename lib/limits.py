"""Force and angle limits (end of paper Sec. 5): an event-located integrator for
the discontinuous closed loop, stroboscopic (Poincaré) sections, a largest
Lyapunov exponent estimate and a classification of the long-run regime.

Why a special integrator
------------------------
With an angle limit |beta| <= beta_max < pi, the position-only allocation
(25)-(26) clips the force angle. When the demanded force (tau_x, tau_y) points
straight behind the body, the clipped angle jumps from +beta_max to -beta_max:
the right-hand side of the closed loop is discontinuous on the switching
surface

    S = {lat = 0, lon < 0},   lat = e1 x tau = tau_y cos(phi) - tau_x sin(phi),
                              lon = e1 . tau = tau_x cos(phi) + tau_y sin(phi)

(e1 the body axis). The rate of ``lat`` depends on the accelerations of x and y,
which jump across S, so solutions can *slide* along S. :class:`SwitchedLoop`
integrates such a system as Filippov {cite}`filippov1988` prescribes: smooth
segments on either side, integrated with a smooth continuation of the side's
vector field and ended by event location on lat = 0; at S, a crossing if both
one-sided fields cross S in the same direction, otherwise sliding with the
convex combination of the two fields that keeps the solution on S, until one
of them turns away from S. Each side's field is continuous but has kinks,
where the clip starts or stops binding (|psi| = beta_max) and where the force
cap F <= F_max does; these are located as events too and the integrator
restarted there, since a step straddling a kink loses the method's order
without its error estimate noticing. Event states are integrated from the last
step point, not interpolated, so that the global error follows the tolerance
across crossings and slides (``tests/test_limits.py`` measures it).

Lyapunov exponents follow Benettin et al. {cite}`benettin1980` with two
trajectories renormalised once per period.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np
from scipy.integrate import solve_ivp

from .control import wrap_angle
from .params import Body, Gains
from .trajectories import Circle, Eight, Reference

__all__ = [
    "SwitchedLoop", "Segments", "reference_kinematics", "error_state", "stroboscopic_section",
    "largest_lyapunov", "LyapunovEstimate", "distinct_points", "classify", "Regime", "sweep_angle_limit",
    "section_sweep", "section_period", "section_margin", "state_difference",
]

TWO_PI = 2.0 * math.pi


# ------------------------------------------------------------------ reference


def reference_kinematics(ref: Reference) -> Callable[[float], tuple]:
    """Scalar function t -> (x_d, y_d, vx_d, vy_d, ax_d, ay_d, jx_d, jy_d) of the
    reference position (m), velocity (m/s), acceleration (m/s^2) and jerk (m/s^3).

    The jerk is needed for the rate of the switching function. For the circle
    (27) and the eight (28) all four are exact; for another reference the jerk
    is a fourth-order central difference of ``ref.ddz``.
    """
    if isinstance(ref, Circle):
        R, th = ref.R, ref.theta

        def kin(t: float) -> tuple:
            s = th * t
            c, sn = math.cos(s), math.sin(s)
            return (R * c, R * sn, -R * th * sn, R * th * c, -R * th**2 * c, -R * th**2 * sn,
                    R * th**3 * sn, -R * th**3 * c)
        return kin
    if isinstance(ref, Eight):
        R, th = ref.R, ref.theta

        def kin(t: float) -> tuple:
            s = th * t
            c1, s1, c2, s2 = math.cos(s), math.sin(s), math.cos(2 * s), math.sin(2 * s)
            return (0.5 * R * s2, R * s1, R * th * c2, R * th * c1, -2 * R * th**2 * s2, -R * th**2 * s1,
                    -4 * R * th**3 * c2, -R * th**3 * c1)
        return kin

    def kin(t: float) -> tuple:
        h = 1e-3
        z, dz, ddz = ref.z(t), ref.dz(t), ref.ddz(t)
        j = (ref.ddz(t - 2 * h) - 8 * ref.ddz(t - h) + 8 * ref.ddz(t + h) - ref.ddz(t + 2 * h)) / (12 * h)
        return (z[0], z[1], dz[0], dz[1], ddz[0], ddz[1], j[0], j[1])
    return kin


# ------------------------------------------------------------------ the switched loop


@dataclass(frozen=True)
class Segments:
    """Output of :meth:`SwitchedLoop.integrate`.

    ``t`` (s) shape (n,), ``y`` states [x, y, phi, xdot, ydot, phidot] shape (n, 6),
    ``mode`` at each sample (+1 / -1: smooth on the side lat > 0 / lat < 0;
    0: sliding on the switching surface), ``F`` (N) and ``beta`` (rad) the applied
    force (while sliding, ``beta`` is the Filippov average angle
    (2 lambda - 1) beta_max of the chattering between +-beta_max), the final
    state ``y_end`` and mode ``mode_end`` at ``t_end``, and counts of surface
    crossings and sliding episodes.
    """

    t: np.ndarray
    y: np.ndarray
    mode: np.ndarray
    F: np.ndarray
    beta: np.ndarray
    t_end: float
    y_end: np.ndarray
    mode_end: int
    n_crossings: int
    n_slides: int
    t_sliding: float


class SwitchedLoop:
    """Closed loop (2)-(4), (23), (25)-(26) with |beta| <= ``angle_limit`` (rad,
    in (0, pi)) and optionally F <= ``force_limit`` (N), integrated with event
    location at the switching surface and Filippov sliding (see the module
    docstring). The state is s = [x, y, phi, xdot, ydot, phidot] (SI units).

    ``k_slide`` (1/s) pulls a sliding solution back onto the surface
    (lat' = -k_slide lat) against the drift of the integration error.
    """

    def __init__(self, body: Body, gains: Gains, ref: Reference, angle_limit: float,
                 force_limit: float | None = None, *, k_slide: float = 5.0) -> None:
        if not isinstance(body, Body) or not isinstance(gains, Gains):
            raise TypeError("body and gains must be lib.params.Body and lib.params.Gains")
        if not all(callable(getattr(ref, k, None)) for k in ("z", "dz", "ddz")):
            raise TypeError(f"ref must be a reference with z, dz and ddz methods, got {type(ref).__name__}")
        if (isinstance(angle_limit, bool) or not np.isscalar(angle_limit) or not np.isfinite(angle_limit)
                or not 0 < angle_limit < math.pi):
            raise ValueError(f"angle_limit must be a number in (0, pi) rad, got {angle_limit!r}")
        if force_limit is not None and (isinstance(force_limit, bool) or not np.isscalar(force_limit)
                                        or not np.isfinite(force_limit) or force_limit <= 0):
            raise ValueError(f"force_limit must be a positive finite force in N, got {force_limit!r}")
        self.body, self.gains, self.ref = body, gains, ref
        self.bmax = float(angle_limit)
        self.fmax = math.inf if force_limit is None else float(force_limit)
        self.k_slide = float(k_slide)
        self._kin = reference_kinematics(ref)
        self.period = float(getattr(ref, "period", math.nan))

    # -- pieces of the vector field (scalar, for speed) --

    def _tau(self, t: float, s) -> tuple:
        b, g = self.body, self.gains
        xd, yd, vxd, vyd, axd, ayd, jxd, jyd = self._kin(t)
        x, y, phi, vx, vy, w = s
        tx = b.m * axd + b.c * vx + g.kv[0] * (vxd - vx) + g.kp[0] * (xd - x)
        ty = b.m * ayd + b.c * vy + g.kv[1] * (vyd - vy) + g.kp[1] * (yd - y)
        return tx, ty, (vxd, vyd, axd, ayd, jxd, jyd)

    def _accel(self, s, F: float, beta: float) -> tuple:
        b = self.body
        phi, vx, vy, w = s[2], s[3], s[4], s[5]
        return ((F * math.cos(phi + beta) - b.c * vx) / b.m,
                (F * math.sin(phi + beta) - b.c * vy) / b.m,
                (b.a * F * math.sin(beta) - b.c_phi * w) / b.I)

    def lateral(self, t: float, s) -> float:
        """Switching function lat = tau_y cos(phi) - tau_x sin(phi) (N)."""
        tx, ty, _ = self._tau(t, s)
        return ty * math.cos(s[2]) - tx * math.sin(s[2])

    def _lat_rate(self, t: float, s, ax: float, ay: float, tx: float, ty: float, kin) -> float:
        b, g = self.body, self.gains
        vxd, vyd, axd, ayd, jxd, jyd = kin
        x, y, phi, vx, vy, w = s
        dtx = b.m * jxd + b.c * ax + g.kv[0] * (axd - ax) + g.kp[0] * (vxd - vx)
        dty = b.m * jyd + b.c * ay + g.kv[1] * (ayd - ay) + g.kp[1] * (vyd - vy)
        c, sn = math.cos(phi), math.sin(phi)
        return dty * c - dtx * sn - w * (tx * c + ty * sn)

    def _side(self, t: float, s, sigma: int) -> tuple:
        """(F, beta) of the smooth field of side ``sigma``, continued across the surface."""
        tx, ty, kin = self._tau(t, s)
        c, sn = math.cos(s[2]), math.sin(s[2])
        lat, lon = ty * c - tx * sn, tx * c + ty * sn
        psi = math.atan2(lat, lon)
        if lon < 0 and sigma * lat < 0:  # just across the surface: continue side sigma's field
            psi += sigma * TWO_PI
        beta = min(max(psi, -self.bmax), self.bmax)
        return min(math.hypot(tx, ty), self.fmax), beta

    def one_sided_rates(self, t: float, s) -> tuple[float, float]:
        """Rates of ``lat`` under the fields with beta = +beta_max and beta = -beta_max."""
        tx, ty, kin = self._tau(t, s)
        F = min(math.hypot(tx, ty), self.fmax)
        out = []
        for beta in (self.bmax, -self.bmax):
            ax, ay, _ = self._accel(s, F, beta)
            out.append(self._lat_rate(t, s, ax, ay, tx, ty, kin))
        return out[0], out[1]

    def _sliding(self, t: float, s) -> tuple:
        """(F, lambda, accelerations) of the Filippov sliding field."""
        tx, ty, kin = self._tau(t, s)
        F = min(math.hypot(tx, ty), self.fmax)
        ap = self._accel(s, F, self.bmax)
        am = self._accel(s, F, -self.bmax)
        rp = self._lat_rate(t, s, ap[0], ap[1], tx, ty, kin)
        rm = self._lat_rate(t, s, am[0], am[1], tx, ty, kin)
        lat = ty * math.cos(s[2]) - tx * math.sin(s[2])
        lam = (rm + self.k_slide * lat) / (rm - rp)
        return F, lam, tuple(lam * p + (1 - lam) * m for p, m in zip(ap, am))

    def rhs(self, t: float, s, mode: int) -> np.ndarray:
        """Vector field of ``mode`` (+1, -1: smooth side; 0: sliding)."""
        if mode == 0:
            acc = self._sliding(t, s)[2]
        else:
            acc = self._accel(s, *self._side(t, s, mode))
        return np.array([s[3], s[4], s[5], acc[0], acc[1], acc[2]])

    def inputs(self, t: float, s, mode: int) -> tuple[float, float]:
        """Applied (F (N), beta (rad)); while sliding, beta is the Filippov average."""
        if mode == 0:
            F, lam, _ = self._sliding(t, s)
            return F, (2 * lam - 1) * self.bmax
        return self._side(t, s, mode)

    def initial_mode(self, t: float, s) -> int:
        """Mode of a state: the side of the surface it lies on, or 0 if it lies on
        the surface (|lat| < 1e-12 N behind the body) where the flow slides."""
        tx, ty, _ = self._tau(t, s)
        c, sn = math.cos(s[2]), math.sin(s[2])
        lat, lon = ty * c - tx * sn, tx * c + ty * sn
        if abs(lat) < 1e-12 and lon < 0:
            rp, rm = self.one_sided_rates(t, s)
            if rp < 0 < rm:
                return 0
            return 1 if rp > 0 else -1
        return 1 if lat >= 0 else -1

    # -- integration --

    def _kink_functions(self, t: float, s) -> tuple[float, ...]:
        """Where the smooth field of a side has a kink (continuous, with a jump in its
        derivative): |tau| sin(psi -+ beta_max) = 0 at the edges of the angle clip
        (psi the demand angle to the body axis), and |tau|^2 - F_max^2 = 0 at the
        force cap (only when a cap is set)."""
        tx, ty, _ = self._tau(t, s)
        c, sn = math.cos(s[2]), math.sin(s[2])
        lat, lon = ty * c - tx * sn, tx * c + ty * sn
        cb, sb = math.cos(self.bmax), math.sin(self.bmax)
        out = (lat * cb - lon * sb, lat * cb + lon * sb)
        if math.isfinite(self.fmax):
            out += (tx * tx + ty * ty - self.fmax**2,)
        return out

    def integrate(self, s0, t0: float, t1: float, t_eval=None, *, mode: int | None = None,
                  rtol: float = 1e-9, atol: float = 1e-9, method: str = "DOP853",
                  max_step: float = np.inf, max_segments: int = 200_000) -> Segments:
        """Integrate from (t0, s0) to t1 (s), sampling at ``t_eval`` (default: t0 and t1).

        ``mode`` is the starting mode (default :meth:`initial_mode`). Every
        non-smooth point is located as an event and the integrator restarted
        there, so that no step straddles one: the switching surface (a jump of
        the field), the exits from sliding, and the kinks of the smooth fields
        (:meth:`_kink_functions`). A step across a kink would cost the
        high-order method its order without its error estimate noticing, and
        the global error would stop following the tolerance. An event just
        crossed is watched only in the opposite direction on restart, so that
        the restart is not caught by the same root. Raises ``RuntimeError`` if
        more than ``max_segments`` smooth pieces are needed (a Zeno-like
        accumulation of switchings).
        """
        s = np.asarray(s0, dtype=float)
        if s.shape != (6,) or not np.all(np.isfinite(s)):
            raise ValueError(f"s0 must be a finite state of shape (6,), got {s0!r}")
        if not t1 > t0:
            raise ValueError(f"need t1 > t0, got t0 = {t0!r}, t1 = {t1!r}")
        tev = np.array([t0, t1]) if t_eval is None else np.asarray(t_eval, dtype=float)
        if tev.ndim != 1 or tev.size == 0 or tev[0] < t0 or tev[-1] > t1 or np.any(np.diff(tev) <= 0):
            raise ValueError("t_eval must be a non-empty increasing 1-D array within [t0, t1]")
        mode = self.initial_mode(t0, s) if mode is None else int(mode)
        ts, ys, ms = [], [], []
        t = float(t0)
        i_next = 0  # index of the next sample time in tev
        n_cross = n_slide = 0
        t_slide = 0.0
        just_crossed: tuple[int, int] | None = None  # (kink index, direction of its crossing)
        muted: set[int] = set()  # kinks grazed at the start of this segment
        for _ in range(max_segments):
            fun, events, n_switch = self._segment(mode, t, s, just_crossed, muted)
            sol = solve_ivp(fun, (t, t1), s, method=method, rtol=rtol, atol=atol, max_step=max_step,
                            events=events, dense_output=True)
            if sol.status == -1:
                raise RuntimeError(f"integration failed at t = {t:.6g} s: {sol.message}")
            if sol.status == 1:
                k = min((i for i, te in enumerate(sol.t_events) if te.size), key=lambda i: sol.t_events[i][0])
                if k >= n_switch and sol.t_events[k][0] - t <= _GRAZE * max(1.0, abs(t)):
                    # a kink function touching zero where the segment starts (a double root):
                    # run this segment without it; a kink grazed for so short a time costs nothing
                    muted.add(events[k].index)
                    continue
                t_new, s_new = _polish_event(fun, events[k], float(sol.t[-2]), sol.y[:, -2],
                                             float(sol.t_events[k][0]), method, rtol, atol)
                i_end = int(np.searchsorted(tev, t_new, side="left"))  # samples before the event
            else:
                k, t_new, s_new, i_end = -1, float(t1), sol.y[:, -1], tev.size
            if i_end > i_next:
                tt = tev[i_next:i_end]
                ts.append(tt)
                ys.append(np.asarray(sol.sol(tt), dtype=float).reshape(6, -1).T)
                ms.append(np.full(tt.size, mode))
                i_next = i_end
            if mode == 0:
                t_slide += t_new - t
            t, s = t_new, np.asarray(s_new, dtype=float)
            muted = set()
            if sol.status == 0:
                break
            if k >= n_switch:  # a kink: same field on, restarted; watch this kink the other way only
                just_crossed = (events[k].index, -events[k].start_sign)
                continue
            just_crossed = None
            mode, crossed, slid = self._after_event(t, s, mode, k)
            n_cross += crossed
            n_slide += slid
        else:
            raise RuntimeError(f"more than {max_segments} switching segments before t = {t1} s "
                               f"(stopped at t = {t:.6g} s)")
        t_all = np.concatenate(ts)
        y_all = np.concatenate(ys) if ys else np.empty((0, 6))
        m_all = np.concatenate(ms).astype(int)
        FB = np.array([self.inputs(ti, yi, mi) for ti, yi, mi in zip(t_all, y_all, m_all)]).reshape(-1, 2)
        return Segments(t=t_all, y=y_all, mode=m_all, F=FB[:, 0], beta=FB[:, 1], t_end=float(t),
                        y_end=np.array(s, dtype=float), mode_end=int(mode), n_crossings=n_cross,
                        n_slides=n_slide, t_sliding=t_slide)

    def _segment(self, mode: int, t0: float, s0, just_crossed, muted=frozenset()):
        """Field and terminal events of one smooth piece starting at (t0, s0): the
        switching events of ``mode`` first (their count is returned), then one event
        per kink. Each kink event records the sign it starts with (``start_sign``),
        so that the direction of a crossing is known; the kink ``just_crossed``
        (index, direction of that crossing) is watched in the opposite direction only,
        and the kinks in ``muted`` are not watched."""
        if mode == 0:
            def fun(t, s):
                return self.rhs(t, s, 0)

            def exit_plus(t, s):  # lambda -> 1: the + field leaves the surface
                rp, _ = self.one_sided_rates(t, s)
                return rp + self.k_slide * self.lateral(t, s)

            def exit_minus(t, s):  # lambda -> 0: the - field leaves the surface
                _, rm = self.one_sided_rates(t, s)
                return rm + self.k_slide * self.lateral(t, s)

            exit_plus.direction, exit_minus.direction = 1, -1
            switch = [exit_plus, exit_minus]
            # while sliding beta is the Filippov average, not a clip: only the force cap is a kink
            kinks = [2] if math.isfinite(self.fmax) else []
        else:
            def fun(t, s):
                return self.rhs(t, s, mode)

            def hit(t, s):
                return self.lateral(t, s)

            hit.direction = -mode
            switch = [hit]
            kinks = list(range(len(self._kink_functions(t0, s0))))
        events = switch + [self._kink_event(j, t0, s0, just_crossed) for j in kinks if j not in muted]
        for ev in events:
            ev.terminal = True
        return fun, events, len(switch)

    def _kink_event(self, j: int, t0: float, s0, just_crossed):
        def kink(t, s):
            return self._kink_functions(t, s)[j]

        kink.index = j
        g0 = kink(t0, s0)
        kink.start_sign = 1 if g0 > 0 else -1
        if just_crossed is not None and just_crossed[0] == j:  # on the far side now, whatever g0 rounds to
            kink.start_sign = just_crossed[1]
            kink.direction = -just_crossed[1]
        else:
            kink.direction = 0
        return kink

    def _after_event(self, t: float, s, mode: int, k: int) -> tuple[int, int, int]:
        """New mode after a switching event, and whether it was a crossing / the start of a slide."""
        if mode == 0:
            return (1 if k == 0 else -1), 0, 0
        tx, ty, _ = self._tau(t, s)
        lon = tx * math.cos(s[2]) + ty * math.sin(s[2])
        if lon >= 0:  # demand straight ahead: beta passes through 0 smoothly
            return -mode, 0, 0
        rp, rm = self.one_sided_rates(t, s)
        far = rm if mode == 1 else rp
        if mode * far < 0:  # the far side carries on away from the surface: cross
            return -mode, 1, 0
        return 0, 0, 1

    # -- stroboscopic map --

    def flow(self, s, t0: float, t1: float, mode: int | None = None, **kw) -> tuple[np.ndarray, int]:
        """State and mode at t1 starting from state ``s`` (and ``mode``) at t0."""
        seg = self.integrate(s, t0, t1, mode=mode, **kw)
        return seg.y_end, seg.mode_end


#: a kink event this close (relative, in s) to the start of its segment is a grazing touch
_GRAZE = 1e-10


def _polish_event(fun, event, t_old: float, y_old, t_e: float, method: str, rtol: float, atol: float):
    """Time and state of a located event, to the accuracy of a step rather than of the
    interpolant: the state is integrated from the last step point (t_old, y_old) to the
    root t_e found on the dense output, then one Newton step on the event function g
    along the field, dt = -g / (dg/dt), moves both onto g = 0 (dt is of the size of
    the interpolation error, so the first-order move costs O(dt^2))."""
    y_e = np.asarray(y_old, dtype=float)
    if t_e > t_old:
        y_e = solve_ivp(fun, (t_old, t_e), y_e, method=method, rtol=rtol, atol=atol).y[:, -1]
    f = np.asarray(fun(t_e, y_e), dtype=float)
    h = 1e-6 * max(1.0, abs(t_e) * 1e-3)
    rate = (event(t_e + h, y_e + h * f) - event(t_e - h, y_e - h * f)) / (2 * h)
    g = event(t_e, y_e)
    if rate != 0 and abs(g / rate) < 0.5 * (t_e - t_old):
        dt = -g / rate
        return t_e + dt, y_e + dt * f
    return t_e, y_e


# ------------------------------------------------------------------ sections and exponents


def state_difference(a, b) -> np.ndarray:
    """a - b for states [x, y, phi, xdot, ydot, phidot] with the phi entry wrapped to (-pi, pi]."""
    d = np.asarray(a, dtype=float) - np.asarray(b, dtype=float)
    d[..., 2] = wrap_angle(d[..., 2])
    return d


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


def distinct_points(points, tol: float) -> int:
    """Number of clusters of ``points`` (n, d) whose members lie within ``tol`` of
    the cluster's first point (max-norm); a period-k orbit of the map gives k."""
    pts = np.atleast_2d(np.asarray(points, dtype=float))
    if pts.shape[0] == 0:
        raise ValueError("points must not be empty")
    reps: list[np.ndarray] = []
    for p in pts:
        if not any(np.max(np.abs(p - r)) <= tol for r in reps):
            reps.append(p)
    return len(reps)


def section_period(points, tol: float, max_period: int = 8) -> tuple[int, bool]:
    """Smallest period k <= ``max_period`` of a stroboscopic sequence, and whether it is
    still converging: (k, False) if the last points repeat every k periods within
    ``tol`` (max-norm); (k, True) if d_j = |P_(j+k) - P_j| shrinks strictly at every
    step over the second half of the sequence (at least 8 steps; fewer could shrink
    by chance) *towards zero*: the Aitken extrapolation of its limit,
    d_n - (d_n - d_(n-1))^2 / (d_n - 2 d_(n-1) + d_(n-2)), is below ``tol`` or
    below half the last distance d_n. (A period-2k orbit approached from one side
    makes the lag-k distances shrink strictly too, but towards the orbit's non-zero
    spread, and the extrapolated limit is then close to d_n itself; a slow geometric
    approach to an orbit, whose ratio still creeps up towards the slowest
    multiplier, extrapolates to a small fraction of d_n.) (0, False) if neither
    holds for any k."""
    pts = np.atleast_2d(np.asarray(points, dtype=float))
    n = pts.shape[0]
    if n < 4:
        raise ValueError("need at least 4 section points")
    if not (np.isfinite(tol) and tol > 0):
        raise ValueError(f"tol must be a positive distance, got {tol!r}")
    for k in range(1, min(max_period, n // 2) + 1):
        tail = _lag_distances(pts, k)
        if np.all(tail[-k:] <= tol):
            return k, False
        if tail.size >= 8 and np.all(np.diff(tail) < 0) and _aitken_limit(tail) <= max(tol, 0.5 * tail[-1]):
            return k, True
    return 0, False


def section_margin(points, tol: float, max_period: int = 8) -> float:
    """How decisively :func:`section_period` decides a sequence, as a factor on ``tol``:
    for a period k found (not converging), ``tol`` over the distance at which the last
    points repeat every k periods; for none found, the smallest distance |P_(j+k) - P_j|
    over the second half at any lag k <= ``max_period``, over ``tol``; NaN for a
    sequence still converging (decided by :func:`section_period`'s extrapolation).
    A margin of 30 means the verdict would survive errors 30 times the tolerance."""
    pts = np.atleast_2d(np.asarray(points, dtype=float))
    k, converging = section_period(pts, tol, max_period)
    if converging:
        return math.nan
    if k:
        return float(tol / max(_lag_distances(pts, k)[-k:].max(), 1e-300))
    lags = range(1, min(max_period, pts.shape[0] // 2) + 1)
    return float(min(_lag_distances(pts, j).min() for j in lags) / tol)


def _lag_distances(pts: np.ndarray, k: int) -> np.ndarray:
    """|P_(j+k) - P_j| (max-norm) over the second half of a section sequence."""
    d = np.max(np.abs(pts[k:] - pts[:-k]), axis=1)
    return d[len(d) // 2:]


def _aitken_limit(d: np.ndarray) -> float:
    """Aitken's delta-squared estimate of the limit of a sequence from its last three terms."""
    d2, d1, d0 = d[-3], d[-2], d[-1]
    den = d0 - 2 * d1 + d2
    if den == 0:
        return float(d0)
    return float(d0 - (d0 - d1) ** 2 / den)


@dataclass(frozen=True)
class LyapunovEstimate:
    """Largest Lyapunov exponent (1/s) with its standard error over the renormalisation
    intervals, and the running estimate after each interval."""

    value: float
    stderr: float
    running: np.ndarray


def largest_lyapunov(flow: Callable, x0, dt: float, n_steps: int, *, d0: float = 1e-8,
                     n_transient: int = 0, difference: Callable | None = None,
                     direction=None) -> LyapunovEstimate:
    """Largest Lyapunov exponent by two nearby trajectories renormalised every ``dt`` (Benettin).

    ``flow(x, t0, t1)`` maps a state at t0 to t1 (it may carry extra state, e.g.
    a switching mode, as the second item of a tuple ``(x, extra)``: then
    ``x0`` is such a tuple too). After ``n_transient`` intervals the companion
    starts at distance ``d0`` along ``direction`` (default: all components
    equal); after each interval its separation d is measured with
    ``difference`` (default a - b), log(d / d0) recorded, and the companion
    pulled back to distance d0 along the separation.
    Returns the mean of log(d/d0)/dt and its standard error.
    """
    if dt <= 0 or n_steps < 2 or d0 <= 0:
        raise ValueError("need dt > 0, n_steps >= 2 and d0 > 0")
    diff = difference or (lambda a, b: np.asarray(a, float) - np.asarray(b, float))
    carry = isinstance(x0, tuple)
    state = x0
    t = 0.0
    for _ in range(n_transient):
        state = flow(state[0], t, t + dt, state[1]) if carry else flow(state, t, t + dt)
        t += dt
    x = np.asarray(state[0] if carry else state, dtype=float)
    u = np.ones_like(x) if direction is None else np.asarray(direction, dtype=float)
    u = u / np.linalg.norm(u)
    y = x + d0 * u
    extra_x = state[1] if carry else None
    extra_y = None
    logs = np.empty(n_steps)
    for i in range(n_steps):
        if carry:
            x, extra_x = flow(x, t, t + dt, extra_x)
            y, extra_y = flow(y, t, t + dt, None)
        else:
            x, y = flow(x, t, t + dt), flow(y, t, t + dt)
        t += dt
        d = diff(y, x)
        dn = float(np.linalg.norm(d))
        if not np.isfinite(dn) or dn == 0:
            raise RuntimeError(f"separation became {dn} at t = {t:.6g}")
        logs[i] = math.log(dn / d0)
        y = np.asarray(x, dtype=float) + d * (d0 / dn)
    rates = logs / dt
    return LyapunovEstimate(value=float(rates.mean()), stderr=float(rates.std(ddof=1) / math.sqrt(n_steps)),
                            running=np.cumsum(logs) / (dt * np.arange(1, n_steps + 1)))


# ------------------------------------------------------------------ regimes


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
    from concurrent.futures import ProcessPoolExecutor

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
    from .params import PAPER_DZ0, PAPER_Z0

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
    from .params import PAPER_DZ0, PAPER_Z0

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
