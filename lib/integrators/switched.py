"""The switched integrator: the closed loop with an angle limit, integrated with event
location at its switching surface and Filippov sliding (paper Sec. 5, Chapter 4).

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

The vector field is evaluated by a scalar fast path of (2)-(4), (23) and its rate
(the integrator calls it millions of times); ``tests/test_limits.py`` checks it at
random states against the one vectorised definition in :mod:`lib.model`,
:mod:`lib.control` and :mod:`lib.trajectories`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from ..params import Body, Gains
from ..trajectories import Reference, position_kinematics

__all__ = ["SwitchedLoop", "Segments"]

TWO_PI = 2.0 * math.pi


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
        self._kin = position_kinematics(ref)
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
        (``_kink_functions``). A step across a kink would cost the
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


