"""The rotation on the circle (27), paper Sec. 6, eqs. (33)-(36): in the rotation error
p = phi - theta t - pi/2 the heading obeys the autonomous, pendulum-like (33)
(corrected; see :mod:`lib.rotation.equations`). Its equilibria, their linearisation
(34)-(35) and the critical radius (36) are in closed form; the global
behaviour (settling or slipping, and where both coexist) is integrated here, and the
bistable window located as a homoclinic bifurcation. The closed forms live in
:mod:`lib.rotation.circle` and are re-exported here.

Units: R in m, theta in rad/s, angles in rad, times in s.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
from scipy.integrate import solve_ivp

from ..machinery import checks
from ..angles import wrap_angle
from .circle import (_check_circle_args, circle_critical_radius, circle_eigenvalues, circle_equilibria,
                     circle_jacobian, circle_rotation_rhs)
from ..params import Body

__all__ = ["circle_critical_radius", "circle_equilibria", "circle_jacobian", "circle_eigenvalues",
           "circle_rotation_rhs", "circle_final_state", "circle_slipping_coexists",
           "homoclinic_miss", "bistable_window", "WINDOW_RESOLUTION", "window_closing_rate",
           "torque_pendulum_threshold"]


def _circle_arrays(body, R, theta, *arrays):
    checks.instance("body", body, Body)
    names = ("R", "theta", "p0", "v0")[:2 + len(arrays)]
    checked = [checks.array(n, a, positive=i < 2) for i, (n, a) in enumerate(zip(names, (R, theta) + arrays))]
    out = np.broadcast_arrays(*(np.atleast_1d(a) for a in checked))
    out = [np.ravel(a).copy() for a in out]
    if out[0].size == 0:
        raise ValueError("empty input arrays")
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
    p0, v0, p_end, v_end, t_end (s) and regime.

    Parameters
    ----------
    body : Body
        The body.
    R, theta : array_like
        Radii (m) and rates (rad/s), > 0, broadcast.
    p0, v0 : array_like
        Start (rad, rad/s), broadcast.
    t_end : float
        First horizon (s).
    t_max : float
        Longest horizon (s).
    rtol, atol : float
        Tolerances of ``solve_ivp``.

    Returns
    -------
    pandas.DataFrame
        One row per broadcast point: R, theta, p0, v0, p_end, v_end, t_end (s), regime.
    """
    R, theta, p0, v0 = _circle_arrays(body, R, theta, p0, v0)
    t_end, t_max = (checks.number(n, v, positive=True, unit="s") for n, v in (("t_end", t_end), ("t_max", t_max)))
    checks.path_budget(body, R, theta, t_max, names=("R", "theta"), limit=checks.MAX_ODE_STEPS,
                       damping=False)
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

    Parameters
    ----------
    body : Body
        The body.
    R, theta : array_like
        Radii (m) and rates (rad/s), broadcast, R > R_crit.
    t_end : float
        Horizon (s) of the branch's integration.

    Returns
    -------
    numpy.ndarray
        One bool per broadcast point.
    """
    R, theta = _circle_arrays(body, R, theta)
    t_end = checks.number("t_end", t_end, positive=True, unit="s")
    checks.path_budget(body, R, theta, t_end, names=("R", "theta"), limit=checks.MAX_ODE_STEPS,
                       damping=False)
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


# --- the bistable window: the homoclinic bifurcation of (33) -----------------------------

WINDOW_RESOLUTION = 1e-6
"""The bistable window is looked for from k = R_crit/R = 1 - WINDOW_RESOLUTION outwards:
a window narrower than that (in k, and so relatively in R) counts as closed."""


def homoclinic_miss(body: Body, R: float, theta: float, rtol: float = 1e-10) -> float:
    """Signed miss of the saddle's unstable branch of the corrected (33) at the next saddle
    in the direction of slipping, at R (m) > R_crit, theta (rad/s); dimensionless.

    (33) reads p'' = -(c_phi/I) p' - U'(p) with U(p) = -A cos(p - gamma) + (c_phi theta/I) p,
    A = a theta R sqrt(m^2 theta^2 + c^2)/I (1/s^2), gamma = arctan(m theta/c): a damped
    pendulum on a tilted washboard, the constant term -c_phi theta/I driving p negative,
    with the energy E = p'^2/2 + U(p) falling along every motion. The branch leaves the
    saddle p_u towards decreasing p (start: an offset of 1e-2 of the distance to the
    node above, at most 1e-4 rad, along the eigenvector of :func:`circle_jacobian` with
    positive eigenvalue; the offset across the manifold dies out at the stable rate)
    and is integrated by ``solve_ivp`` (LSODA, ``rtol``: near R_crit at strong
    damping the passage by the saddle-node is stiff) until an event: it reaches
    p_u - 2 pi (it runs on), turns (p' = 0: it is then trapped in the well of p_s, E being
    below the barrier) or falls half way down the barrier (E below
    (U(p_u - 2 pi) + U(p_s))/2: trapped too, and never turning if it creeps into a node).
    Returns (U(p_u - 2 pi) - E_end)/A: -p'^2/(2A) < 0 at the next saddle when the branch
    runs on, > 0 when it falls back, zero on the homoclinic connection.

    Parameters
    ----------
    body : Body
        The body.
    R : float
        Radius (m), > R_crit.
    theta : float
        Angular rate (rad/s), > 0.
    rtol : float
        Relative tolerance of ``solve_ivp``.

    Returns
    -------
    float
        The signed miss (dimensionless): positive where the branch runs on past the next saddle.
    """
    p_s, p_u = circle_equilibria(body, R, theta)
    rtol = checks.number("rtol", rtol, positive=True)
    # the branch passes one saddle: about a period of the pendulum's own oscillation, well
    # within 100 reference periods
    checks.path_budget(body, R, theta, 200 * math.pi / theta, names=("R", "theta"), limit=checks.MAX_ODE_STEPS)
    if p_u < p_s:                              # the saddle just above p_s
        p_u += 2 * math.pi
    target = p_u - 2 * math.pi                 # the saddle just below p_s
    A = body.a * theta * R * math.hypot(body.m * theta, body.c) / body.I
    gamma = math.atan(body.m * theta / body.c)
    tilt = body.c_phi * theta / body.I

    def dU(p):                                 # (U(p) - U(target))/A, without cancellation
        return (2 * math.sin(0.5 * (p + target) - gamma) * math.sin(0.5 * (p - target))
                + tilt / A * (p - target))

    lam, vec = np.linalg.eig(circle_jacobian(body, R, theta, p_u))
    i = int(np.argmax(lam.real))
    u = np.real(vec[:, i]) / np.hypot(*np.real(vec[:, i]))
    u = -u if u[0] > 0 else u                  # towards decreasing p
    gap = p_s + 2 * math.pi - p_u              # to the node above: small near R_crit
    delta = min(1e-4, 1e-2 * gap)
    floor = 0.5 * dU(p_s)                      # half way down the barrier to U(p_s)

    def rhs(t, y):
        return [y[1], float(circle_rotation_rhs(body, R, theta, y[0], y[1]))]

    def stop(t, y):                            # the first of the three events to come
        return min(y[0] - target, -y[1], 0.5 * y[1] ** 2 / A + dU(y[0]) - floor)

    stop.terminal, stop.direction = True, -1
    # leaving the saddle takes about ln(gap/delta)/lambda_u; one swing about 2 pi/sqrt(A)
    chunk = 10.0 * (math.log(gap / delta + 2.0) / float(lam.real[i])
                    + 2 * math.pi / math.sqrt(A))
    y = np.array([p_u + delta * u[0], delta * u[1]])
    for _ in range(40):
        sol = solve_ivp(rhs, (0.0, chunk), y, method="LSODA", rtol=rtol,
                        atol=rtol * 1e-2, events=stop)
        if sol.status == 1:
            p_end, v_end = sol.y[:, -1]
            return -(0.5 * v_end**2 / A + dU(p_end))
        if sol.status != 0:
            raise RuntimeError(f"solve_ivp failed on (33): {sol.message}")
        y = sol.y[:, -1]
    raise RuntimeError(f"the saddle's branch of (33) stayed undecided at R = {R!r} m, "
                       f"theta = {theta!r} rad/s (on the saddle's stable manifold?)")


def _linear_miss(body: Body, R: float, theta: float) -> float:
    """:func:`homoclinic_miss` made linear across the connection for ``brentq``: near it
    the miss goes as |R - R_edge|^nu, nu = 2|l_s|/(l_u + |l_s|) (the passage by the
    saddle, eigenvalues l_u > 0 > l_s of :func:`circle_jacobian`); returns sign * |miss|^(1/nu)."""
    m = homoclinic_miss(body, R, theta)
    lam = np.sort(np.linalg.eigvals(circle_jacobian(
        body, R, theta, circle_equilibria(body, R, theta)[1])).real)
    return math.copysign(abs(m) ** ((lam[1] - lam[0]) / (-2.0 * lam[0])), m)


def bistable_window(body: Body, Theta: float) -> tuple[float, float]:
    """The circle's bistable window at rate ``Theta`` (rad/s): (R_crit, R_edge), both in m.

    For R_crit < R < R_edge a running (slipping) rotation of the corrected (33) coexists
    with the stable equilibrium p_s; above R_edge every motion off the saddles' stable
    manifolds settles at p_s. R_crit is the critical radius (36). R_edge is the homoclinic
    bifurcation of (33): the R at which the saddle's unstable branch, leaving towards
    decreasing p (the direction of the constant torque -c_phi Theta/I), reaches the next
    saddle p_u - 2 pi exactly (:func:`homoclinic_miss` is zero). In normalised time (33)
    is p'' + alpha p' + sin(p - gamma) = -k with k = R_crit/R and
    alpha = sqrt(c_phi k/(I Theta)), so R_edge/R_crit depends on Theta only through
    alpha at R_crit, sqrt(c_phi/(I Theta)). Where no window exists (that damping above
    the damped pendulum's threshold, about 1.19), R_edge = R_crit.

    Method: a window exists iff the branch runs on at k = 1 - ``WINDOW_RESOLUTION``
    (a narrower window is not resolved); k is then lowered in steps until the branch
    falls back, and ``scipy.optimize.brentq`` finds the sign change of the miss between
    the last two steps to 1e-10 in k, so to about 1e-10 relative in R (the shooting's
    own error, at ``rtol`` 1e-10, is smaller). The edge is the first sign change
    going outwards from R_crit.

    Parameters
    ----------
    body : Body
        The body.
    Theta : float
        Angular rate (rad/s), > 0.

    Returns
    -------
    R_crit, R_edge : float
        The window's edges (m).
    """
    from scipy.optimize import brentq

    _check_circle_args(body)
    Theta = checks.number("Theta", Theta, positive=True, unit="rad/s")
    r_crit = circle_critical_radius(body, Theta)

    def miss(s):                                # s = 1 - k = 1 - R_crit/R
        return _linear_miss(body, r_crit / (1.0 - s), Theta)

    lo = WINDOW_RESOLUTION
    if miss(lo) >= 0.0:
        return r_crit, r_crit
    for hi in (1e-4, 3e-3, 0.03, 0.1, 0.25, 0.5, 0.75, 0.9, 0.99, 0.999):
        if hi <= lo:
            continue
        if miss(hi) > 0.0:
            s = brentq(miss, lo, hi, xtol=1e-10)
            return r_crit, r_crit / (1.0 - s)
        lo = hi
    raise RuntimeError(f"the running rotation persists to R = {r_crit / (1 - lo):.6g} m "
                       f"at Theta = {Theta!r} rad/s: no outer edge found")


def window_closing_rate(body: Body) -> float:
    """The rate Theta_close (rad/s) below which the bistable window of
    :func:`bistable_window` is closed (narrower than ``WINDOW_RESOLUTION`` in k).

    ``scipy.optimize.brentq`` over Theta on the sign of :func:`homoclinic_miss` at
    k = R_crit/R = 1 - ``WINDOW_RESOLUTION``: there the branch runs on for Theta above
    Theta_close and falls back below. The normalised damping at R_crit,
    sqrt(c_phi/(I Theta_close)), is then the damped pendulum's threshold
    (:func:`torque_pendulum_threshold`) at that k.

    Parameters
    ----------
    body : Body
        The body.

    Returns
    -------
    float
        Theta_close (rad/s).
    """
    from scipy.optimize import brentq

    _check_circle_args(body)
    k = 1.0 - WINDOW_RESOLUTION

    def miss(log_theta):
        th = math.exp(log_theta)
        return _linear_miss(body, circle_critical_radius(body, th) / k, th)

    # up to the rotation's domain (lib.machinery.domain.heading_damping): 2 pi 8 c_phi / I_C, 71 times
    # the closing rate c_phi / (I_C 1.19^2) of any body
    lo, hi = math.log(1e-3), math.log(0.999 * 2 * math.pi * checks.MAX_DAMPING_PERIODS * body.c_phi / body.I)
    if not miss(lo) > 0.0 > miss(hi):
        raise RuntimeError(f"the window does not close between Theta = 1e-3 and {math.exp(hi):.4g} rad/s")
    return math.exp(brentq(miss, lo, hi, xtol=1e-12))


def torque_pendulum_threshold(k: float = 1.0 - WINDOW_RESOLUTION) -> float:
    """The damping alpha at which the normalised pendulum q'' + alpha q' + sin q = -k
    (0 < k < 1) has its homoclinic connection: the saddle q_u = pi + arcsin k's branch
    towards decreasing q reaching q_u - 2 pi. A running orbit coexists with the stable
    equilibrium iff alpha is below it; as k -> 1 it tends to the classical value, about
    1.19 (Strogatz 2015, Sec. 8.5). Computed apart from (33) and :func:`homoclinic_miss`
    (its own shooting, LSODA, rtol 1e-11), as their independent check.

    Parameters
    ----------
    k : float
        The normalised torque, in (0, 1).

    Returns
    -------
    float
        The threshold damping alpha (dimensionless).
    """
    from scipy.optimize import brentq

    k = checks.number("k", k, positive=True)
    if not k < 1.0:
        raise ValueError(f"k must be a number in (0, 1), got {k!r}")
    q_u = math.pi + math.asin(k)
    q_s = -math.asin(k)
    target = q_u - 2 * math.pi

    def dU(q):                                 # U(q) - U(target), U = -cos q + k q
        return 2 * math.sin(0.5 * (q + target)) * math.sin(0.5 * (q - target)) + k * (q - target)

    def miss(alpha):
        root = math.sqrt(alpha**2 + 4.0 * math.sqrt(1.0 - k * k))
        lam_u, lam_s = 0.5 * (root - alpha), -0.5 * (root + alpha)
        gap = q_s + 2 * math.pi - q_u
        d = min(1e-4, 1e-2 * gap)
        floor = 0.5 * dU(q_s)

        def stop(t, y):
            return min(y[0] - target, -y[1], 0.5 * y[1] ** 2 + dU(y[0]) - floor)

        stop.terminal, stop.direction = True, -1
        y = [q_u - d / math.hypot(1.0, lam_u), -d * lam_u / math.hypot(1.0, lam_u)]
        span = 10.0 * (math.log(gap / d + 2.0) / lam_u + 2 * math.pi)
        for _ in range(40):
            sol = solve_ivp(lambda t, y: [y[1], -alpha * y[1] - math.sin(y[0]) - k],
                            (0.0, span), y, method="LSODA", rtol=1e-11, atol=1e-13,
                            events=stop)
            if sol.status == 1:
                m = -(0.5 * sol.y[1, -1] ** 2 + dU(sol.y[0, -1]))
                return math.copysign(abs(m) ** ((lam_u - lam_s) / (-2.0 * lam_s)), m)
            y = sol.y[:, -1]
        raise RuntimeError(f"undecided branch at alpha = {alpha!r}")

    return brentq(miss, 0.1 * k, 4.0, xtol=1e-12)      # alpha ~ pi k/4 for small k
