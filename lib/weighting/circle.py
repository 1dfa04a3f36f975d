"""The circle (27) under the weighted allocation, exactly: its steady motion and where it
stops being stable (Chapter 6).

With equal position weights w_x = w_y and equal position gains on x and y, the full
closed loop (2)-(4), (23) with the weighted least-squares allocation
(:func:`lib.allocation.allocate_least_squares`) is equivariant under rotations of the
plane, and the circle (27) is a rotation at the constant rate Theta. In the frame that
rotates with the reference the loop is therefore *autonomous*. Its state there is

    y = (xi, eta, p, xi', eta', p'),

with (xi, eta) the body's position in the rotating frame (m; the reference point sits
at (R, 0)), p = phi - phi_d = phi - Theta t - pi/2 the heading error (rad, unwrapped)
and their rates in that frame (m/s, rad/s). The field is derived from the one
closed-loop right-hand side, :meth:`lib.closed_loop.ClosedLoop.rates`: a rotating
state is carried to the inertial state at time t, the inertial rates are evaluated
there and carried back (:func:`rotating_field`); the result does not depend on t.

The steady motion of the circle (a constant position error in the rotating frame and
a constant heading error) is an equilibrium of this field, and its six eigenvalues
decide local stability exactly (:func:`circle_steady_state`). With w_phi = 0 the
allocation is (25)-(26): the position error obeys (24) and vanishes, and the heading
sits at the stable equilibrium p_s of (33) (:func:`lib.rotation.circle.circle_equilibria`).
:func:`circle_weight_limit` continues the equilibrium in w_phi and finds the first
weight at which it loses stability or ceases to exist.

Units: R in m, Theta in rad/s, errors in m and rad, eigenvalues in 1/s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.optimize import brentq, root

from ..allocation import Allocation
from ..rotation.circle import circle_equilibria
from ..closed_loop import ClosedLoop, reference_of
from ..params import Body, Gains
from .rotating_frame import _field, inertial_to_rotating, rotating_to_inertial  # the maps re-exported
from ..trajectories import Circle

__all__ = ["CircleSteadyState", "WeightLimit", "rotating_field", "rotating_to_inertial", "inertial_to_rotating",
           "circle_steady_state", "circle_weight_limit", "circle_weight_sweep", "circle_error_weight",
           "LIMIT_KINDS"]

#: how the steady motion of the circle can stop being stable along w_phi
LIMIT_KINDS = ("real eigenvalue crossing", "complex pair", "fold")

#: central-difference step of the Jacobian (in units of the state: m, rad, m/s, rad/s)
_FD_STEP = 1e-6
#: largest ratio between two successive weights of a continuation (and the first nonzero weight)
_CONT_RATIO, _CONT_START = 1.25, 1e-4
#: largest change of (xi, eta, p) (m, rad) between two steps of :func:`circle_weight_limit`
_MAX_JUMP = 0.5


@dataclass(frozen=True)
class CircleSteadyState:
    """The steady motion of the circle (27) under the weighted allocation, as an equilibrium
    in the rotating frame.

    ``radial`` and ``tangential``: the position error in the rotating frame (m; radial
    positive outwards, tangential positive along the motion for Theta > 0); ``heading``:
    p = phi - phi_d (rad, unwrapped); ``eigenvalues``: the six eigenvalues of the
    linearisation (1/s), sorted by decreasing real part (a complex pair with its positive
    imaginary part first); ``state``: the equilibrium
    y = (xi, eta, p, 0, 0, 0) (m, m, rad); ``weights``: (w_x, w_y, w_phi)."""

    radial: float
    tangential: float
    heading: float
    eigenvalues: np.ndarray
    state: np.ndarray
    weights: tuple

    @property
    def position_error(self) -> float:
        """Distance from the reference point (m), constant in the steady motion."""
        return math.hypot(self.radial, self.tangential)

    @property
    def max_real(self) -> float:
        """The largest real part of the eigenvalues (1/s), negative iff locally asymptotically stable."""
        return float(self.eigenvalues[0].real)

    @property
    def stable(self) -> bool:
        return self.max_real < 0


@dataclass(frozen=True)
class WeightLimit:
    """The first heading weight w_phi (w_x = w_y = 1) at which the circle's steady motion
    loses stability (``kind`` "real eigenvalue crossing" or "complex pair": an eigenvalue, or a
    pair, crosses the imaginary axis) or ceases to exist (``kind`` "fold": the branch of
    equilibria turns back). ``eigenvalue``: the critical eigenvalue at the limit (1/s; its
    imaginary part is the angular frequency of the motion born there, rad/s); ``steady``: the
    steady state at the limit; ``rtol``: relative accuracy of ``w_phi``."""

    w_phi: float
    kind: str
    eigenvalue: complex
    steady: CircleSteadyState
    rtol: float


def _check(body, gains, R, Theta) -> tuple[float, float]:
    if not isinstance(body, Body):
        raise TypeError(f"body must be a lib.params.Body, got {type(body).__name__}")
    if not isinstance(gains, Gains):
        raise TypeError(f"gains must be a lib.params.Gains, got {type(gains).__name__}")
    if gains.kp[0] != gains.kp[1] or gains.kv[0] != gains.kv[1]:
        raise ValueError("the circle's steady motion needs equal gains on x and y (kp[0] == kp[1], "
                         f"kv[0] == kv[1]), got kp = {gains.kp}, kv = {gains.kv}: otherwise the loop is "
                         "not autonomous in the rotating frame")
    for name, v in (("R", R), ("Theta", Theta)):
        if isinstance(v, bool) or not np.isscalar(v) or not np.isfinite(v) or not v > 0:
            raise ValueError(f"{name} must be a positive finite number (R in m, Theta in rad/s), got {v!r}")
    return float(R), float(Theta)


def _check_weights(weights) -> tuple[float, float, float]:
    w = np.asarray(weights, dtype=float) if not isinstance(weights, (str, bytes)) else np.array([])
    if w.shape != (3,) or not np.all(np.isfinite(w)) or np.any(w < 0):
        raise ValueError(f"weights must be three finite non-negative numbers (w_x, w_y, w_phi), got {weights!r}")
    if w[0] != w[1] or w[0] <= 0:
        raise ValueError(f"the circle's steady motion needs equal positive position weights w_x = w_y > 0, "
                         f"got {weights!r}: otherwise the loop is not autonomous in the rotating frame")
    return float(w[0]), float(w[1]), float(w[2])


def _loop(body, gains, R, Theta, weights) -> ClosedLoop:
    return ClosedLoop.of(body, gains, reference_of(Circle(R, Theta)), Allocation("least_squares", weights))


def rotating_field(body: Body, gains: Gains, R: float, Theta: float, weights, y, t: float = 0.0) -> np.ndarray:
    """The closed loop on the circle (27) with the weighted allocation, written in the frame
    rotating with the reference: y' for states y = (xi, eta, p, xi', eta', p') of shape (..., 6)
    (m, m, rad, m/s, m/s, rad/s), from :meth:`lib.closed_loop.ClosedLoop.rates` evaluated at
    time ``t`` (s). Autonomous: the result does not depend on ``t`` (up to rounding).

    Parameters
    ----------
    body : Body
        The body.
    gains : Gains
        The gains of (23).
    R : float
        Radius (m), > 0.
    Theta : float
        Rate (rad/s), > 0.
    weights : array_like
        (w_x, w_y, w_phi).
    y : array_like
        Rotating-frame states (..., 6).
    t : float
        Time (s).

    Returns
    -------
    numpy.ndarray
        y' (..., 6) (m/s, m/s, rad/s, m/s^2, m/s^2, rad/s^2).
    """
    R, Theta = _check(body, gains, R, Theta)
    weights = _check_weights(weights)
    if isinstance(t, bool) or not np.isscalar(t) or not np.isfinite(t):
        raise ValueError(f"t must be a finite time in s, got {t!r}")
    y = np.asarray(y, dtype=float)
    if y.ndim == 0 or y.shape[-1] != 6:
        raise ValueError(f"y must have a last axis of length 6, got shape {y.shape}")
    return _field(_loop(body, gains, R, Theta, weights), Theta, y, float(t))


def _jacobian(loop: ClosedLoop, Theta: float, y, h: float = _FD_STEP, t: float = 0.0) -> np.ndarray:
    """Central-difference Jacobian of the rotating field at y (all 12 points in one call)."""
    E = h * np.eye(6)
    f = _field(loop, Theta, np.concatenate([y + E, y - E]), t)
    return ((f[:6] - f[6:]) / (2 * h)).T


def _solve(loop: ClosedLoop, Theta: float, guess, t: float = 0.0) -> np.ndarray | None:
    """The equilibrium (xi, eta, p) near ``guess``; None when the solver does not converge."""
    def g(x):
        return _field(loop, Theta, np.r_[x, 0.0, 0.0, 0.0], t)[3:]

    sol = root(g, np.asarray(guess, dtype=float), method="hybr", tol=1e-14)
    if not sol.success and not np.all(np.abs(g(sol.x)) < 1e-11):
        return None
    x = sol.x
    for _ in range(3):      # polish with Newton on the central-difference Jacobian
        r = g(x)
        if np.max(np.abs(r)) < 1e-13:
            break
        J = _jacobian(loop, Theta, np.r_[x, 0.0, 0.0, 0.0], t=t)[3:, :3]
        x = x - np.linalg.solve(J, r)
    if not np.all(np.isfinite(x)) or np.max(np.abs(g(x))) > 1e-9:
        return None
    return x


def _state(loop, Theta, R, x, weights, t: float = 0.0) -> CircleSteadyState:
    y = np.r_[x, 0.0, 0.0, 0.0]
    lam = np.linalg.eigvals(_jacobian(loop, Theta, y, t=t))
    lam = lam[np.lexsort((-lam.imag, -lam.real))]
    return CircleSteadyState(float(x[0] - R), float(x[1]), float(x[2]), lam, y, tuple(weights))


def _start(body, R, Theta) -> np.ndarray:
    """The w_phi = 0 equilibrium: on the reference point, heading at p_s of (33)."""
    return np.array([R, 0.0, circle_equilibria(body, R, Theta)[0]])


def _continue(body, gains, R, Theta, w, targets, t: float = 0.0):
    """Continue the equilibrium from w_phi = 0 through the increasing weights ``targets``
    (w_x = w_y = w), with steps of at most a factor _CONT_RATIO; yields (w_phi, x) at each
    target, or (w_phi, None) from the first target beyond a failure."""
    x, w_now = _start(body, R, Theta), 0.0
    first = _CONT_START * w
    for target in targets:
        while x is not None and w_now < target:
            w_next = target if w_now == 0 and target <= first else min(target, max(w_now * _CONT_RATIO, first))
            x, w_now = _solve(_loop(body, gains, R, Theta, (w, w, w_next)), Theta, x, t), w_next
        yield target, x


def circle_steady_state(body: Body, gains: Gains, R: float, Theta: float, weights=(1.0, 1.0, 0.0),
                        t: float = 0.0) -> CircleSteadyState:
    """The steady motion of the circle (27) of radius ``R`` (m) run at ``Theta`` (rad/s) > 0
    under the weighted allocation with ``weights`` = (w_x, w_y, w_phi), w_x = w_y > 0: the
    equilibrium of the closed loop in the rotating frame (:func:`rotating_field`) on the branch
    that starts at w_phi = 0 from the circle's equilibrium of Chapter 5 (zero position error,
    heading error p_s of :func:`lib.rotation.circle.circle_equilibria`) and is continued in
    w_phi (steps of at most a factor 1.25) by a Newton-type solver (scipy ``root``, hybr,
    polished by Newton to a residual below 1e-13 m/s^2 and rad/s^2).

    Returns a :class:`CircleSteadyState`: the radial and tangential position errors (m), the
    heading error (rad) and the six eigenvalues (1/s) of the central-difference Jacobian
    (step 1e-6) at the equilibrium. ``t`` (s): the time at which the rotating frame is carried
    to the inertial one (the result does not depend on it; a check). Raises ValueError when R
    is below the critical radius (36) (no equilibrium at w_phi = 0) and RuntimeError when the
    continuation fails before w_phi (the branch has folded back: no steady state on it at this
    weight).

    Parameters
    ----------
    body : Body
        The body.
    gains : Gains
        The gains of (23).
    R : float
        Radius (m), > 0.
    Theta : float
        Rate (rad/s), > 0.
    weights : array_like
        (w_x, w_y, w_phi), w_x = w_y > 0.
    t : float
        Time (s) of the check.

    Returns
    -------
    CircleSteadyState
        radial, tangential (m) and heading (rad) errors, the six eigenvalues (1/s), the
        rotating-frame state and the weights.
    """
    R, Theta = _check(body, gains, R, Theta)
    w = _check_weights(weights)
    if isinstance(t, bool) or not np.isscalar(t) or not np.isfinite(t):
        raise ValueError(f"t must be a finite time in s, got {t!r}")
    (_, x), = _continue(body, gains, R, Theta, w[0], [w[2]], float(t))
    if x is None:
        raise RuntimeError(f"no steady state on the branch from w_phi = 0 at weights {w}: the "
                           "continuation in w_phi failed before it (a fold)")
    return _state(_loop(body, gains, R, Theta, w), Theta, R, x, w, float(t))


def circle_weight_sweep(body: Body, gains: Gains, R: float, Theta: float, w_phi) -> pd.DataFrame:
    """The steady motion along the weights ``w_phi`` (w_x = w_y = 1), by one continuation.

    Returns a DataFrame, one row per weight (in the order given): w_phi, radial, tangential,
    position_error (m), heading (rad), max_real (1/s, largest real part of the eigenvalues),
    max_imag (rad/s, |imaginary part| of that eigenvalue) and stable; NaN (and stable False)
    where the branch no longer exists.

    Parameters
    ----------
    body : Body
        The body.
    gains : Gains
        The gains of (23).
    R : float
        Radius (m), > 0.
    Theta : float
        Rate (rad/s), > 0.
    w_phi : array_like
        The weights.

    Returns
    -------
    pandas.DataFrame
        One row per weight (columns above).
    """
    R, Theta = _check(body, gains, R, Theta)
    wp = np.atleast_1d(np.asarray(w_phi, dtype=float))
    if wp.ndim != 1 or wp.size == 0 or not np.all(np.isfinite(wp)) or np.any(wp < 0):
        raise ValueError(f"w_phi must be a non-empty 1-D array of finite non-negative weights, got {w_phi!r}")
    order = np.argsort(wp, kind="stable")
    rows = {}
    for i, (target, x) in zip(order, _continue(body, gains, R, Theta, 1.0, wp[order])):
        if x is None:
            rows[i] = dict(w_phi=target, radial=np.nan, tangential=np.nan, position_error=np.nan,
                           heading=np.nan, max_real=np.nan, max_imag=np.nan, stable=False)
            continue
        st = _state(_loop(body, gains, R, Theta, (1.0, 1.0, target)), Theta, R, x, (1.0, 1.0, target))
        rows[i] = dict(w_phi=target, radial=st.radial, tangential=st.tangential,
                       position_error=st.position_error, heading=st.heading, max_real=st.max_real,
                       max_imag=abs(st.eigenvalues[0].imag), stable=st.stable)
    return pd.DataFrame([rows[i] for i in range(wp.size)])


def circle_weight_limit(body: Body, gains: Gains, R: float, Theta: float, w_max: float = 1e3,
                        rtol: float = 1e-6) -> WeightLimit:
    """The smallest heading weight w_phi (w_x = w_y = 1) at which the steady motion of the
    circle (27), continued from w_phi = 0 (:func:`circle_steady_state`), loses stability or
    ceases to exist, searched up to ``w_max``.

    Continuation in log w_phi (steps of a factor 1.25 from 1e-4) watches the largest real part
    of the eigenvalues; at its first sign change brentq on it in log w_phi locates the limit to
    relative ``rtol`` (1e-6). The kind is "complex pair" when the critical eigenvalue has an
    imaginary part (|Im| > 1e-6 |lambda| + 1e-9 1/s: a Hopf point of the loop in the
    rotating frame), else "real eigenvalue crossing". Where the continuation fails
    first (no equilibrium found within 0.5 m and rad of the last one even with the step halved
    down to ``rtol``), the branch has
    folded back: kind "fold" at the last weight with an equilibrium. Raises ValueError when the
    steady motion is unstable already at w_phi = 0 and RuntimeError when no limit lies below
    ``w_max``.

    Parameters
    ----------
    body : Body
        The body.
    gains : Gains
        The gains of (23).
    R : float
        Radius (m), > 0.
    Theta : float
        Rate (rad/s), > 0.
    w_max : float
        Largest weight searched.
    rtol : float
        Relative tolerance in w_phi.

    Returns
    -------
    WeightLimit
        w_phi, kind, the eigenvalue (1/s) there, the steady state and rtol.
    """
    R, Theta = _check(body, gains, R, Theta)
    for name, v, lo in (("w_max", w_max, _CONT_START), ("rtol", rtol, 0.0)):
        if isinstance(v, bool) or not np.isscalar(v) or not np.isfinite(v) or not v > lo:
            raise ValueError(f"{name} must be a finite number above {lo:g}, got {v!r}")
    if rtol >= 0.1:
        raise ValueError(f"rtol must be below 0.1, got {rtol!r}")

    def steady(wp, x):
        # an equilibrium more than _MAX_JUMP (m or rad) from the last one is taken as a jump to
        # another branch, and refused like a failure (the step is then halved)
        loop = _loop(body, gains, R, Theta, (1.0, 1.0, wp))
        xs = _solve(loop, Theta, x)
        if xs is None or np.max(np.abs(xs - x)) > _MAX_JUMP:
            return None
        return xs, _state(loop, Theta, R, xs, (1.0, 1.0, wp))

    x0 = _start(body, R, Theta)
    st0 = _state(_loop(body, gains, R, Theta, (1.0, 1.0, 0.0)), Theta, R, x0, (1.0, 1.0, 0.0))
    if not st0.stable:
        raise ValueError(f"the circle's steady motion is not stable at w_phi = 0 (max Re = {st0.max_real:g} 1/s)")
    w_prev, x_prev, st_prev = 0.0, x0, st0
    w_next = _CONT_START
    while w_prev < w_max:
        got = steady(w_next, x_prev)
        if got is None:                              # halve the step in log w_phi
            if w_prev > 0 and w_next / w_prev - 1 < rtol:
                return WeightLimit(w_prev, "fold", complex(st_prev.eigenvalues[0]), st_prev, rtol)
            w_next = math.sqrt(w_prev * w_next) if w_prev > 0 else w_next / 2
            continue
        x_next, st_next = got
        if st_next.max_real >= 0:
            lo, hi = (math.log(w_prev), math.log(w_next)) if w_prev > 0 else (math.log(w_next) - 50,
                                                                            math.log(w_next))

            def f(logw):
                g = steady(math.exp(logw), x_prev)
                if g is None:
                    raise RuntimeError(f"continuation failed at w_phi = {math.exp(logw):.6g} inside the bracket")
                return g[1].max_real

            logw = brentq(f, lo, hi, xtol=rtol / 4, rtol=4 * np.finfo(float).eps)
            w_c = math.exp(logw)
            _, st_c = steady(w_c, x_prev)
            lam = complex(st_c.eigenvalues[0])
            kind = "complex pair" if abs(lam.imag) > 1e-6 * abs(lam) + 1e-9 else "real eigenvalue crossing"
            return WeightLimit(w_c, kind, lam, st_c, rtol)
        w_prev, x_prev, st_prev = w_next, x_next, st_next
        w_next = min(w_prev * _CONT_RATIO, w_max) if w_prev < w_max else w_prev * _CONT_RATIO
    raise RuntimeError(f"the circle's steady motion stays stable up to w_max = {w_max:g}")


def circle_error_weight(body: Body, gains: Gains, R: float, Theta: float, level: float, w_max: float = 1e3,
                        rtol: float = 1e-6) -> float:
    """The smallest heading weight w_phi (w_x = w_y = 1) at which the steady position error of
    the circle (:attr:`CircleSteadyState.position_error`, m) reaches ``level`` (m) on the branch
    continued from w_phi = 0 (steps of a factor 1.25 in w_phi from 1e-4, then brentq in
    log w_phi to relative ``rtol``). It is the exact counterpart of a tolerance on the position
    error met by the steady motion (e.g. 0.1 R, the tolerance of "held"), whether or not that
    motion is still stable there. Raises RuntimeError when the branch ends (a fold) or
    ``w_max`` is passed first.

    Parameters
    ----------
    body : Body
        The body.
    gains : Gains
        The gains of (23).
    R : float
        Radius (m), > 0.
    Theta : float
        Rate (rad/s), > 0.
    level : float
        The position error (m).
    w_max : float
        Largest weight searched.
    rtol : float
        Relative tolerance in w_phi.

    Returns
    -------
    float
        w_phi.
    """
    R, Theta = _check(body, gains, R, Theta)
    for name, v in (("level", level), ("w_max", w_max), ("rtol", rtol)):
        if isinstance(v, bool) or not np.isscalar(v) or not np.isfinite(v) or not v > 0:
            raise ValueError(f"{name} must be a positive finite number, got {v!r}")

    def err(wp, x):
        xs = _solve(_loop(body, gains, R, Theta, (1.0, 1.0, wp)), Theta, x)
        return xs, (np.inf if xs is None else math.hypot(xs[0] - R, xs[1]) - level)

    x_prev, w_prev, w_next = _start(body, R, Theta), 0.0, _CONT_START
    while w_prev < w_max:
        x_next, e = err(w_next, x_prev)
        if x_next is None:
            raise RuntimeError(f"the steady motion's branch ends near w_phi = {w_next:.6g} before its "
                               f"position error reaches {level:g} m")
        if e >= 0:
            lo = math.log(w_prev) if w_prev > 0 else math.log(w_next) - 50
            return math.exp(brentq(lambda lw: err(math.exp(lw), x_prev)[1], lo, math.log(w_next),
                                   xtol=rtol / 4, rtol=4 * np.finfo(float).eps))
        x_prev, w_prev, w_next = x_next, w_next, min(w_next * _CONT_RATIO, w_max) if w_next < w_max else 2 * w_max
    raise RuntimeError(f"the steady position error stays below {level:g} m up to w_max = {w_max:g}")
