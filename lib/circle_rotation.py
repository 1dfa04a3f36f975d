"""The rotation on the circle (27), paper Sec. 6, eqs. (33)-(36): in the rotation error
p = phi - theta t - pi/2 the heading obeys the autonomous, pendulum-like (33)
(corrected; see :mod:`lib.rotation_equations`). Its equilibria, their linearisation
(34)-(35) and the critical radius (36) are in closed form here; the global
behaviour (settling or slipping, and where both coexist) is integrated.

Units: R in m, theta in rad/s, angles in rad, times in s.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
from scipy.integrate import solve_ivp

from .angles import wrap_angle
from .params import Body

__all__ = ["circle_critical_radius", "circle_equilibria", "circle_jacobian", "circle_eigenvalues",
           "circle_rotation_rhs", "circle_final_state", "circle_slipping_coexists"]


def _check_circle_args(body: Body, R=None, theta=None) -> None:
    if not isinstance(body, Body):
        raise TypeError(f"body must be a lib.params.Body, got {type(body).__name__}")
    for name, v in (("R", R), ("theta", theta)):
        if v is None:
            continue
        if isinstance(v, bool) or not np.isscalar(v) or not np.isfinite(v):
            raise ValueError(f"{name} must be a finite real number, got {v!r}")
    if R is not None and R <= 0:
        raise ValueError(f"circle radius R must be positive, got {R!r} m")
    if theta is not None and theta <= 0:
        raise ValueError(f"angular rate theta must be positive (rad/s), got {theta!r}")


def circle_critical_radius(body: Body, theta: float) -> float:
    """Critical radius of (36), R_crit = c_phi / (a sqrt(m^2 theta^2 + c^2)) (m).

    Equilibria of (33) exist iff R >= R_crit; for R > R_crit there are two per
    turn, one stable and one saddle. ``theta`` > 0 in rad/s.
    """
    _check_circle_args(body, None, theta)
    return body.c_phi / (body.a * math.hypot(body.m * theta, body.c))


def circle_equilibria(body: Body, R: float, theta: float) -> tuple[float, float]:
    """The two equilibria (stable, saddle) of the corrected (33), p = phi - theta t - pi/2 (rad).

    With gamma = arctan(m theta / c) and k = R_crit / R <= 1, (33) at rest reads
    sin(p - gamma) = -k, so p_stable = gamma - arcsin k and
    p_saddle = gamma + pi + arcsin k, both wrapped to (-pi, pi].
    Raises ValueError when R < R_crit (no equilibrium: the rotation slips for ever).
    """
    _check_circle_args(body, R, theta)
    r_crit = circle_critical_radius(body, theta)
    if R < r_crit:
        raise ValueError(f"no equilibrium: R = {R!r} m is below the critical radius "
                         f"R_crit = {r_crit:.6g} m of (36) at theta = {theta!r} rad/s")
    k = min(r_crit / R, 1.0)
    gamma = math.atan(body.m * theta / body.c)
    return float(wrap_angle(gamma - math.asin(k))), float(wrap_angle(gamma + math.pi + math.asin(k)))


def circle_jacobian(body: Body, R: float, theta: float, p0: float) -> np.ndarray:
    """Jacobian of (33) (corrected) at (p0, 0): the matrix of the linearisation (34)."""
    k21 = -body.a * R * theta / body.I * (body.c * math.cos(p0) + body.m * theta * math.sin(p0))
    return np.array([[0.0, 1.0], [k21, -body.c_phi / body.I]])


def circle_eigenvalues(body: Body, R: float, theta: float) -> np.ndarray:
    """Eigenvalues (1/s) of the linearisation (34) at the stable equilibrium:
    the roots of (35), lambda^2 + c_phi/I lambda + theta/I sqrt(a^2 R^2 (m^2 theta^2 + c^2) - c_phi^2).
    Complex array of two values, sorted by real part."""
    p_s, _ = circle_equilibria(body, R, theta)
    k0 = theta / body.I * math.sqrt(max(body.a**2 * R**2 * (body.m**2 * theta**2 + body.c**2)
                                        - body.c_phi**2, 0.0))
    lam = np.roots([1.0, body.c_phi / body.I, k0]).astype(complex)
    return lam[np.argsort(lam.real)]


def circle_rotation_rhs(body: Body, R, theta, p, v_p) -> np.ndarray:
    """Right side of the corrected (33): returns v_p' (rad/s^2); vectorised over arrays."""
    p, v_p = np.asarray(p, dtype=float), np.asarray(v_p, dtype=float)
    return (-body.c_phi / body.I * v_p - body.a * body.c * theta * R / body.I * np.sin(p)
            + body.a * body.m * theta**2 * R / body.I * np.cos(p) - body.c_phi * theta / body.I)


def _circle_arrays(body, R, theta, *arrays):
    if not isinstance(body, Body):
        raise TypeError(f"body must be a lib.params.Body, got {type(body).__name__}")
    out = np.broadcast_arrays(*(np.atleast_1d(np.asarray(a, dtype=float)) for a in (R, theta) + arrays))
    out = [np.ravel(a).copy() for a in out]
    if out[0].size == 0:
        raise ValueError("empty input arrays")
    if not all(np.all(np.isfinite(a)) for a in out):
        raise ValueError("inputs must be finite")
    if np.any(out[0] <= 0) or np.any(out[1] <= 0):
        raise ValueError("R (m) and theta (rad/s) must be positive")
    return out


def circle_final_state(body: Body, R, theta, p0=0.0, v0=0.0, t_end: float = 300.0,
                       t_max: float = 5000.0, rtol: float = 1e-9, atol: float = 1e-9) -> pd.DataFrame:
    """Integrate the corrected (33) from p(0) = ``p0`` (rad), p'(0) = ``v0`` (rad/s)
    for all broadcast (R, theta, p0, v0) together (one stacked ``solve_ivp`` per
    stage) and classify the end state.

    ``settled``: within 1e-4 of the stable equilibrium (mod 2 pi) and at rest;
    ``slipping``: p changed by more than a whole turn over the second half of
    the run; otherwise the run is extended, doubling its length, up to ``t_max``
    s, after which the point is ``undecided``. Returns a DataFrame with R, theta,
    p0, v0, p_end, v_end, t_end (s) and regime."""
    R, theta, p0, v0 = _circle_arrays(body, R, theta, p0, v0)
    N = R.size
    ps = np.full(N, np.nan)
    for i in range(N):
        try:
            ps[i] = circle_equilibria(body, float(R[i]), float(theta[i]))[0]
        except ValueError:
            pass
    p, v = p0.copy(), v0.copy()
    t_used = np.zeros(N)
    regime = np.full(N, "undecided", dtype=object)
    todo = np.arange(N)
    span = float(t_end)
    while todo.size and t_used[todo[0]] + span <= t_max + 1e-9:
        Rr, th = R[todo], theta[todo]
        n = todo.size

        def rhs(t, y):
            return np.concatenate([y[n:], circle_rotation_rhs(body, Rr, th, y[:n], y[n:])])

        sol = solve_ivp(rhs, (0.0, span), np.concatenate([p[todo], v[todo]]), method="DOP853",
                        rtol=rtol, atol=atol, t_eval=[span / 2, span])
        mid, p[todo], v[todo] = sol.y[:n, 0], sol.y[:n, -1], sol.y[n:, -1]
        t_used[todo] += span
        gap = np.abs(wrap_angle(p[todo] - ps[todo]))
        settled = (gap < 1e-4) & (np.abs(v[todo]) < 1e-4)
        slipping = ~settled & (np.abs(p[todo] - mid) > 2 * np.pi)
        regime[todo[settled]] = "settled"
        regime[todo[slipping]] = "slipping"
        todo = todo[~(settled | slipping)]
        span *= 2
    return pd.DataFrame({"R": R, "theta": theta, "p0": p0, "v0": v0, "p_end": p, "v_end": v,
                         "t_end": t_used, "regime": regime.astype(str)})


def circle_slipping_coexists(body: Body, R, theta, t_end: float = 400.0) -> np.ndarray:
    """Whether a slipping (running) motion of the corrected (33) coexists with the
    stable equilibrium, for each broadcast (R (m), theta (rad/s)) with R > R_crit.

    Test: follow the branch of the saddle's unstable manifold that leaves towards
    decreasing p (the direction of the constant drag torque -c_phi theta). If it
    passes the next saddle, p_saddle - 2 pi, the motion runs on for ever and a
    running periodic orbit exists; if it falls into the stable equilibrium, every
    motion not on the saddle's stable manifold settles. (This is the homoclinic
    bifurcation of the damped driven pendulum, Strogatz 2015, Sec. 8.5.)
    """
    R, theta = _circle_arrays(body, R, theta)
    N = R.size
    ps = np.empty(N)
    y0 = np.empty(2 * N)
    for i in range(N):
        _, sad = circle_equilibria(body, float(R[i]), float(theta[i]))
        J = circle_jacobian(body, float(R[i]), float(theta[i]), sad)
        lam, vec = np.linalg.eig(J)
        u = np.real(vec[:, np.argmax(lam.real)])
        u = -u if u[0] > 0 else u
        ps[i] = sad
        y0[i], y0[N + i] = sad + 1e-6 * u[0] / np.hypot(*u), 1e-6 * u[1] / np.hypot(*u)

    def rhs(t, y):
        p, v = y[:N], y[N:]
        return np.concatenate([v, circle_rotation_rhs(body, R, theta, p, v)])

    sol = solve_ivp(rhs, (0.0, t_end), y0, method="DOP853", rtol=1e-10, atol=1e-12, dense_output=True)
    pmin = np.full(N, np.inf)
    for chunk in np.array_split(np.linspace(0, t_end, 40001), 10):
        pmin = np.minimum(pmin, sol.sol(chunk)[:N].min(axis=1))
    return pmin < ps - 2 * np.pi
