"""Slow eights (paper Sec. 6, after (37)): what the heading does when the eight (28) is
traversed slowly, from the circle's equilibria (33)-(36) and the first-order
(overdamped) reduction of (37), without integrating (37) itself.

Starting on the reference the heading obeys (32), I_C phi'' + c_phi phi' = a (tau_y
cos phi - tau_x sin phi), with the feed-forward tau = m a_d + c v_d of the path. Along
the eight, seen in the frame of its tangent (speed v, curvature kappa, tangent angle
psi, the heading error p = phi - psi), the demand has a tangential part m v' + c v
and a normal part m v^2 kappa, and (32) reads

    I_C phi'' + c_phi phi' = a (m v^2 kappa cos p - (m v' + c v) sin p).

Three approximations of it, each exact in a limit:

* **Frozen** (adiabatic): at each point of the path the heading sits at the
  circle's stable equilibrium (:func:`lib.rotation.circle.circle_equilibria`) of
  the osculating circle, radius 1/|kappa|, rate v |kappa| (mirrored where the eight
  turns clockwise). The equilibrium exists where the local radius exceeds the
  circle's critical radius (36), i.e. k = c_phi |kappa| / (a sqrt(m^2 v^2
  kappa^2 + c^2)) <= 1, and is then stable ((35) has positive coefficients).
  With s = Theta t, v = Theta R sigma(s) and kappa = kappa_1(s)/R (sigma, kappa_1
  the unit eight's speed and curvature), k = c_phi |kappa_1| / (a R
  sqrt(m^2 Theta^2 sigma^2 kappa_1^2 + c^2)) is proportional to 1/R, so the
  heading can follow the whole path iff R >= r_follow(Theta) = max_s c_phi
  |kappa_1| / (a sqrt(m^2 Theta^2 sigma^2 kappa_1^2 + c^2)).
  Its error is the heading's lag: the heading relaxes towards the equilibrium
  at the rate a |tau| / c_phi, proportional to the speed, so per radian of the
  phase s the relaxation is a c R sigma / c_phi whatever Theta. The frozen
  picture is the limit of *large* eights (R >> r_follow), not of slow ones.
* **Overdamped** (first order): drop I_C phi'' from (32). In the phase s,
  (32) divided by I_C Theta^2 is phi_ss + A phi_s = T(phi, s) with
  T = (B Y' + C Y'') cos phi - (B X' + C X'') sin phi (:mod:`lib.rotation.field`;
  A = c_phi / (I_C Theta)), and the overdamped heading is phi_s = T / A. Its
  periodic solution keeps the whole lag (at every R, also below r_follow, where
  the heading cannot follow the sharpest bends and lags through them). The
  neglected inertia is of relative size 1/A = I_C Theta / c_phi: the limit of
  slow eights.
* **Overdamped with the first inertia correction**: the slow manifold of
  phi_ss + A phi_s = T to the next order in 1/A, phi_s = T/A - (T_s + T_phi T/A)/A^2,
  with T_s from the path's third derivatives (exact).

The path is the eight (28) itself: its speed, curvature (tangent angle rate over
speed) and third derivatives in closed form (:func:`lib.trajectories.eight_position`),
not the paper's 3-term series of the tangent angle, because the frozen equilibrium
and the boundary r_follow depend on the curvature, the derivative of that angle, and
the series' neglected harmonics decay slowly (Chapter 5: a_9 exceeds a_7), so its
derivative misses the peak curvature (:func:`series_peak_curvature`).

Units: R in m, Theta in rad/s, angles in rad, the phase s in rad.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..machinery import checks
from ..params import Body
from .field import coefficients, rotation_rates, rotation_rates_dphi
from ..trajectories import PAPER_HEADING_SERIES, eight_position

__all__ = ["SlowEight", "slow_eight_prediction", "unit_eight_geometry", "frozen_heading", "follow_radius",
           "series_peak_curvature"]


def unit_eight_geometry(s) -> tuple[np.ndarray, np.ndarray]:
    """Speed and signed curvature of the unit eight (28), X = sin(2s)/2, Y = sin s (R = 1 m).

    Parameters
    ----------
    s : float or array_like
        Phases s = Theta t (rad).

    Returns
    -------
    sigma : numpy.ndarray
        |(X', Y')| (m per radian of phase); the speed is v = Theta R sigma.
    kappa_1 : numpy.ndarray
        (X' Y'' - Y' X'') / sigma^3 (1/m), > 0 where the eight turns anticlockwise;
        the eight of size R has curvature kappa_1 / R.
    """
    _, _, X1, Y1, X2, Y2, _, _ = eight_position(1.0, 1.0, np.asarray(s, dtype=float))
    sig = np.hypot(X1, Y1)
    return sig, (X1 * Y2 - Y1 * X2) / sig**3


def _grid(n: int) -> np.ndarray:
    return 2 * np.pi * np.arange(n) / n


def follow_radius(body: Body, Theta, n_phase: int = 4096) -> np.ndarray:
    """r_follow(Theta) (m): the smallest R at which the frozen equilibrium exists all along
    the eight, max_s c_phi |kappa_1| / (a sqrt(m^2 Theta^2 sigma^2 kappa_1^2 + c^2)), the
    osculating circles' critical radius (36) scaled to the eight. At Theta -> 0 it is
    R_crit(0) max |kappa_1| with R_crit(0) = c_phi / (a c).

    Parameters
    ----------
    body : Body
        The body's parameters.
    Theta : float or array_like
        Rates (rad/s), >= 0.
    n_phase : int
        Phases sampled per period (>= 64); the maximum is refined by a parabola
        through the three samples round it (relative error 5e-9 at 4096).

    Returns
    -------
    numpy.ndarray
        r_follow (m), of the shape of ``Theta``.
    """
    checks.instance("body", body, Body)
    Th = checks.array("Theta", Theta, nonnegative=True)
    n_phase = checks.integer("n_phase", n_phase, minimum=64)
    s = _grid(n_phase)
    sig, kap = unit_eight_geometry(s)
    k1 = np.abs(kap)
    g = body.c_phi * k1 / (body.a * np.sqrt((body.m * Th[..., None] * sig * k1) ** 2 + body.c**2))
    return _peak(g)


def _peak(y: np.ndarray) -> np.ndarray:
    """The maximum over the last axis of samples y of a periodic function at even phases
    (the last sample followed by the first), refined by the parabola through the largest
    sample and its two neighbours (error third order in the spacing)."""
    n = y.shape[-1]
    i = np.argmax(y, axis=-1)
    ym, y0, yp = (np.take_along_axis(y, ((i + d) % n)[..., None], -1)[..., 0] for d in (-1, 0, 1))
    den = ym - 2 * y0 + yp
    return y0 - np.where(den < 0, 0.125 * (yp - ym) ** 2 / np.where(den < 0, den, -1.0), 0.0)


def frozen_heading(body: Body, R, Theta, s) -> tuple[np.ndarray, np.ndarray]:
    """The frozen equilibrium p*(s) (rad) of the heading error p = phi - psi on the
    eight, at phases s (rad), broadcast over R (m), Theta (rad/s) and s: the circle's
    stable equilibrium gamma - arcsin k of the osculating circle (radius 1/|kappa|,
    rate theta_loc = v |kappa| = Theta sigma |kappa_1|, gamma = arctan(m theta_loc / c),
    k its R_crit over radius), with the sign of the curvature.

    Parameters
    ----------
    body : Body
        The body's parameters.
    R, Theta, s : float or array_like
        Size (m, > 0), rate (rad/s, >= 0) and phases (rad), broadcast together.

    Returns
    -------
    p_star : numpy.ndarray
        The frozen equilibrium (rad), NaN where k > 1 (no equilibrium: the
        osculating circle is below its critical radius).
    k : numpy.ndarray
        R_crit of the osculating circle over its radius (dimensionless).
    """
    checks.instance("body", body, Body)
    R = checks.array("R", R, positive=True)
    Theta = checks.array("Theta", Theta, nonnegative=True)
    s = checks.array("s", s)
    R, Th, s = np.broadcast_arrays(R, Theta, s)
    sig, kap = unit_eight_geometry(s)
    th_loc = Th * sig * np.abs(kap)
    k = body.c_phi * np.abs(kap) / (body.a * R * np.hypot(body.m * th_loc, body.c))
    gam = np.arctan(body.m * th_loc / body.c)
    with np.errstate(invalid="ignore"):
        p = np.sign(kap) * (gam - np.arcsin(np.where(k <= 1, k, np.nan)))
    return p, k


def series_peak_curvature(n_phase: int = 4096) -> tuple[float, float]:
    """The unit eight's largest |kappa_1| (1/m) from its exact tangent angle and from the
    paper's 3-term series of it (:data:`lib.trajectories.PAPER_HEADING_SERIES`), whose
    derivative over the exact speed sigma stands in for the curvature.

    Parameters
    ----------
    n_phase : int
        Phases sampled per period (>= 64); the maxima are the sampled ones.

    Returns
    -------
    exact, series : float
        The two peak curvatures (1/m).
    """
    s = _grid(checks.integer("n_phase", n_phase, minimum=64))
    sig, kap = unit_eight_geometry(s)
    dpsi = -sum(a * k * np.sin(k * s) for k, a in PAPER_HEADING_SERIES.items())
    return float(np.abs(kap).max()), float(np.abs(dpsi / sig).max())


@dataclass(frozen=True)
class SlowEight:
    """The slow-eight prediction of :func:`slow_eight_prediction`, every field an array of
    the broadcast shape of (R, Theta).

    ``R`` (m), ``Theta`` (rad/s); ``r_follow`` (m): the frozen equilibrium exists all along
    the path iff R >= r_follow(Theta); ``k_max`` (1): the largest ratio of the osculating
    circle's critical radius (36) to its radius, r_follow / R; ``follows`` (bool): k_max
    <= 1. ``frozen_min``, ``frozen_max``, ``frozen_range`` (rad): the extremes and range
    of the frozen equilibrium p*(s) over a period (NaN where it does not follow).
    ``overdamped_range`` (rad): the range of p over the periodic solution of the
    overdamped (first-order) equation; ``overdamped_slips`` (bool): it has none that
    returns (its heading slips whole turns), range then NaN. ``corrected_range``,
    ``corrected_slips``: the same with the first inertia correction. ``steps``: RK4 steps
    per period of the overdamped runs (one number for all points)."""

    R: np.ndarray
    Theta: np.ndarray
    r_follow: np.ndarray
    k_max: np.ndarray
    follows: np.ndarray
    frozen_min: np.ndarray
    frozen_max: np.ndarray
    frozen_range: np.ndarray
    overdamped_range: np.ndarray
    overdamped_slips: np.ndarray
    corrected_range: np.ndarray
    corrected_slips: np.ndarray
    steps: int


def _forcing(n: int):
    """The unit eight's (X', Y', X'', Y'', X''', Y''') at the RK4 stage phases of n steps per
    period (2 n + 1 half-step points), and its tangent angle H at the n + 1 step points."""
    s = np.arange(2 * n + 1) * np.pi / n
    _, _, X1, Y1, X2, Y2, X3, Y3 = eight_position(1.0, 1.0, s)
    c1, c2 = np.cos(s[::2]), np.cos(2 * s[::2])
    H = np.pi + np.arctan2(-c1, -c2)
    return (X1, Y1, X2, Y2, X3, Y3), H


def _rate(phi, j, A, B, C, f, corrected: bool):
    """phi_s of the overdamped heading (T / A) or with the first inertia correction."""
    X1, Y1, X2, Y2, X3, Y3 = (a[j] for a in f)
    # the torque of (32) at rest (w = 0) from its one definition, its derivative along the
    # path (the same field with the derivatives one order up) and its derivative in phi
    T = rotation_rates(phi, 0.0, A, B, C, X1, Y1, X2, Y2)[1]
    if not corrected:
        return T / A
    Ts = rotation_rates(phi, 0.0, A, B, C, X2, Y2, X3, Y3)[1]
    Tphi = rotation_rates_dphi(phi, B, C, X1, Y1, X2, Y2)
    return T / A - (Ts + Tphi * T / A) / A**2


def _period(phi, A, B, C, f, n: int, corrected: bool, record: bool = False):
    """phi after one period (RK4, n steps); with ``record`` also phi at every step. Without
    ``record`` on the compiled engine (:func:`lib.integrators.compiled.overdamped_period`, the
    same steps point by point), with it vectorised here."""
    if not record:
        # imported here, not at the top: lib.integrators.compiled imports lib.rotation.field, whose
        # package's __init__ imports this module (the cycle through a package, tests/test_layout.py)
        from ..integrators.compiled import overdamped_period
        return overdamped_period(phi, A, B, C, f, n, corrected)
    h = 2 * np.pi / n
    out = [phi] if record else None
    for i in range(n):
        j = 2 * i
        k1 = _rate(phi, j, A, B, C, f, corrected)
        k2 = _rate(phi + 0.5 * h * k1, j + 1, A, B, C, f, corrected)
        k3 = _rate(phi + 0.5 * h * k2, j + 1, A, B, C, f, corrected)
        k4 = _rate(phi + h * k3, j + 2, A, B, C, f, corrected)
        phi = phi + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        if record:
            out.append(phi)
    return (phi, np.array(out)) if record else phi


def _periodic_range(A, B, C, f, H, n: int, corrected: bool, n_starts: int = 16, tol: float = 1e-11):
    """Range of p = phi - H over the attracting periodic solution of the first-order
    heading equation (winding 0 on the eight), for every point; NaN and slips = True
    where the period map phi(0) -> phi(2 pi) has no fixed point.

    The map's lift F is increasing with F(x + 2 pi) = F(x) + 2 pi, so g = F - id is
    2 pi-periodic; an attracting fixed point is where g falls through zero. g is
    sampled at ``n_starts`` starts round the reference's heading H(0), the falling
    crossing nearest p = 0 bracketed and refined by the Illinois method to |g| <= tol, each
    point on its own (a located point is not integrated again).
    The extremes of p over the orbit's steps are refined by parabolas. Against four times
    the steps, on the book's slow band (Fig. 5's 1800 points with Theta <= 0.3 rad/s, 1024
    steps), the overdamped range moves by 2.3e-6 rad at most and the corrected one by
    6.0e-5 rad (above 1e-5 at 95 of them)."""
    N = A.size
    x = H[0] + 2 * np.pi * (np.arange(n_starts) / n_starts - 0.5)
    g = _period(np.broadcast_to(x, (N, n_starts)), A[:, None], B[:, None], C[:, None], f, n, corrected) - x
    falls = (g > 0) & (np.roll(g, -1, axis=1) <= 0)
    slips = ~falls.any(axis=1)
    dist = np.where(falls, np.abs(np.arange(n_starts) + 0.5 - n_starts / 2), np.inf)
    i = np.argmin(dist, axis=1)
    rows = np.arange(N)
    lo, hi = x[i], x[i] + 2 * np.pi / n_starts
    glo, ghi = g[rows, i], np.roll(g, -1, axis=1)[rows, i]
    ok = ~slips
    glo, ghi = np.where(ok, glo, 1.0), np.where(ok, ghi, -1.0)
    side = np.zeros(N, dtype=int)
    xm, gm = np.zeros(N), np.where(ok, np.inf, 0.0)
    for _ in range(100):
        # a point stops once located: only the others are integrated again
        act = np.abs(gm) > tol
        xm = np.where(act, (lo * ghi - hi * glo) / (ghi - glo), xm)
        gm[act] = _period(xm[act], A[act], B[act], C[act], f, n, corrected) - xm[act]
        if np.all(np.abs(gm) <= tol):
            break
        left = gm > 0                            # the fixed point lies above xm
        up, down = act & left, act & ~left
        lo, glo = np.where(up, xm, lo), np.where(up, gm, glo)
        hi, ghi = np.where(down, xm, hi), np.where(down, gm, ghi)
        # Illinois: halve the stale end's value when the same end moves twice
        glo = np.where(down & (side == -1), 0.5 * glo, glo)
        ghi = np.where(up & (side == 1), 0.5 * ghi, ghi)
        side = np.where(up, 1, np.where(down, -1, side))
    else:
        raise RuntimeError("the periodic heading was not located to tolerance in 100 iterations")
    _, rec = _period(xm, A, B, C, f, n, corrected, record=True)
    p = (rec - H[:, None])[:-1].T                # one period, the end being the start
    rng = _peak(p) + _peak(-p)
    return np.where(slips, np.nan, rng), slips


def _steps(body: Body, R, Th) -> int:
    """RK4 steps per period for all points: a power of two (>= 256) with h L <= 0.25, L
    bounding |d phi_s / d phi| = |T_phi| / A <= (B max sigma + C max|acc|) / A."""
    A, B, C = coefficients(body, R, Th)
    L = float(np.max((B * np.sqrt(2.0) + C * np.sqrt(5.0)) / A))
    return int(max(256, 2 ** np.ceil(np.log2(2 * np.pi * L / 0.25))))


def slow_eight_prediction(body: Body, R, Theta, n_phase: int = 4096) -> SlowEight:
    """The slow-eight analysis of (37) at each broadcast pair (R (m), Theta (rad/s)): where
    the heading can follow the eight at the frozen equilibrium of the osculating circle
    ((33)-(36): exists, and is stable, iff R >= r_follow(Theta)), that equilibrium's range
    of the heading error p = phi - psi over a period, and the range over the periodic
    solution of the overdamped heading, without and with the first inertia correction
    (module docstring). The exact tangent angle of (28) is used, not the 3-term series.

    Parameters
    ----------
    body : Body
        The body's parameters.
    R, Theta : float or array_like
        Path size (m) and rate (rad/s), both positive; broadcast together.
    n_phase : int
        Phases per period at which the frozen equilibrium is evaluated (>= 64).

    Returns
    -------
    SlowEight
        Arrays of the broadcast shape (see :class:`SlowEight`).

    Raises
    ------
    TypeError
        If ``body`` is not a Body, or R, Theta are not real numbers.
    ValueError
        If an R or Theta is not finite or not positive (naming its index), or they do
        not broadcast.
    """
    checks.instance("body", body, Body)
    R = checks.array("R", R, positive=True)
    Th = checks.array("Theta", Theta, positive=True)
    n_phase = checks.integer("n_phase", n_phase, minimum=64)
    try:
        R, Th = np.broadcast_arrays(R, Th)
    except ValueError as e:
        raise ValueError(f"R and Theta must broadcast together, got shapes {R.shape} and {Th.shape}") from e
    shape = R.shape
    R, Th = R.ravel().copy(), Th.ravel().copy()
    A, B, C = coefficients(body, R, Th)                # the domain before any run (issue 37)
    checks.heading_damping(body, Th)
    checks.within_budget(checks.by_scale(body, R, Th, 2 * np.pi * (B * np.sqrt(2.0) + C * np.sqrt(5.0)) / A / 0.25),
                         checks.MAX_STEPS, what="a period would need", unit="RK4 steps",
                         values={"R": (R, "m"), "Theta": (Th, "rad/s")},
                         fix="outside the slow eights' domain (R far beyond the body's scale)")
    r_follow = follow_radius(body, Th, n_phase)
    k_max = r_follow / R
    follows = k_max <= 1.0
    p, _ = frozen_heading(body, R[:, None], Th[:, None], _grid(n_phase)[None, :])
    fmin, fmax = p.min(axis=1), p.max(axis=1)
    n = _steps(body, R, Th)
    f, H = _forcing(n)
    od, od_slips = _periodic_range(A, B, C, f, H, n, corrected=False)
    co, co_slips = _periodic_range(A, B, C, f, H, n, corrected=True)

    def out(a):
        return np.reshape(a, shape)

    return SlowEight(R=out(R), Theta=out(Th), r_follow=out(r_follow), k_max=out(k_max), follows=out(follows),
                     frozen_min=out(fmin), frozen_max=out(fmax), frozen_range=out(fmax - fmin),
                     overdamped_range=out(od), overdamped_slips=out(od_slips), corrected_range=out(co),
                     corrected_slips=out(co_slips), steps=n)
