"""The least tracking error any control can leave under a force cap: a certified bound.

Whatever the heading, the centre of mass C = (x, y) obeys the translational part of eqs. (2)-(3),

    m C'' + c C' = F_w,    |F_w| = F <= F_max,

with F_w = F (cos(phi + beta), sin(phi + beta)) the world-frame force. With beta free the direction
of F_w is free, so under the cap alone the periodic motions of C form a convex set, and the least
error against the circle (27) or the eight (28) is a convex problem. With p = m C' + c C (so
p' = F_w), kappa = c/m and h = T/N (T = 2 pi/Theta the path's period), every admissible F_w gives,
node to node,

    p_{k+1} = p_k + G_k,                                       G_k = int_0^h F_w(t_k + r) dr,
    C_{k+1} = e^{-kappa h} C_k + (1 - e^{-kappa h})/c p_k + (wbar/m) G_k + E_k,

with |G_k| <= F_max h, w(r) = (1 - e^{-kappa (h - r)})/kappa, wbar its mean over [0, h] and
E_k = (1/m) int_0^h (w - wbar) F_w dr, |E_k| <= delta = (F_max/m) int_0^h |w - wbar| dr
(:func:`interval_map`). Both C and p are periodic.

* The RELAXED problem (E_k free in its ball, and, by default, tied to G_k by two more cones that
  every admissible F_w satisfies: |G_k + al m E_k| <= F_max h for al = 1/wbar and
  al = -1/(w(0) - wbar), see :func:`cap_bound`) holds the node values of every admissible motion:
  its optimum is a lower bound on the node-sampled error of every motion under the cap, and, for
  the largest distance, on the largest distance over continuous time.
* The ACHIEVED problem (E_k = 0) is the zero-order hold F_w = G_k/h: an exact admissible motion,
  evaluated densely between the nodes (closed form), an upper bound on the true optimum.

:func:`exact_peak_force` is the force |m C_d'' + c C_d'| that exact tracking of C needs.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp
from scipy.optimize import minimize_scalar

from ..machinery import checks
from ..machinery.summary import Summarised
from ..params import Body
from ..trajectories import KINEMATICS, POSITIONS

if TYPE_CHECKING:  # imported where used: cvxpy loads in about 0.5 s, most pages never call it
    import cvxpy as cp

__all__ = ["IntervalMap", "interval_map", "exact_peak_force", "CapBound", "cap_bound", "MAX_NODES"]

#: the most nodes :func:`cap_bound` accepts (its problems grow linearly with them)
MAX_NODES = 20000
#: sub-samples per node interval where the achieved motions are evaluated
SUBSAMPLES = 16
#: Clarabel's stopping tolerances, tried in turn; 1e-9, then its defaults (1e-8) where the first
#: ends short of them ("AlmostSolved", which a mesh of the eight meets now and then); a solve that
#: meets neither raises
SOLVER_OPTIONS = ({"tol_gap_abs": 1e-9, "tol_gap_rel": 1e-9, "tol_feas": 1e-9}, {})
_KINDS = ("eight", "circle")


def _phi2(x):
    """x - 1 + e^{-x}, to full relative precision for x >= 0 (a series below 0.5)."""
    x = np.asarray(x, dtype=float)
    small = x < 0.5
    xs = np.where(small, x, 0.0)
    term, total = xs * xs / 2, np.zeros_like(xs)
    for n in range(3, 24):                      # (0.5)^23/23! < 1e-30
        total = total + term
        term = -term * xs / n
    return np.where(small, total, x + np.expm1(-np.where(small, 1.0, x)))


@dataclass(frozen=True)
class IntervalMap:
    """The node-to-node map of m C'' + c C' = F_w over an interval of length h (s):
    C_{k+1} = a C_k + b p_k + q G_k + E_k, |E_k| <= spread F_max.

    h (s); a = e^{-kappa h} (1); b = (1 - e^{-kappa h})/c (m/(N s)); q = wbar/m (m/(N s));
    spread = (1/m) int_0^h |w - wbar| dr (m/N); wbar and wmax = w(0) = (1 - e^{-kappa h})/kappa,
    the mean and the largest value of the weight w (s); m the body's mass (kg)."""

    h: float
    a: float
    b: float
    q: float
    spread: float
    wbar: float
    wmax: float
    m: float


def interval_map(body: Body, h: float) -> IntervalMap:
    """The exact node-to-node map over one interval and the radius of its remainder E_k.

    With x = kappa h and u = h - r, w = (1 - e^{-kappa u})/kappa rises from 0; wbar =
    h phi2(x)/x^2 (phi2(x) = x - 1 + e^{-x}); w = wbar at u* = -log(1 - kappa wbar)/kappa; as
    w - wbar has zero mean, int |w - wbar| = 2 int_{u*}^h (w - wbar) = 2 (1 - e^{-x})
    phi2(kappa (h - u*)) / (kappa^3 h), evaluated without cancellation (phi2 by its series).

    Parameters
    ----------
    body : Body
        The body (m, c).
    h : float
        Interval length (s), > 0.

    Returns
    -------
    IntervalMap
        a, b, q, spread (the remainder's radius per newton of cap, m/N), wbar, wmax, m.
    """
    checks.instance("body", body, Body)
    h = checks.number("h", h, positive=True, unit="s")
    k = body.c / body.m
    x = k * h
    one_minus_a = -math.expm1(-x)
    p2 = float(_phi2(x))
    wbar = h * p2 / x**2
    u_star = -math.log1p(-p2 / x) / k
    spread = 2 * one_minus_a * float(_phi2(k * (h - u_star))) / (k**3 * h) / body.m
    return IntervalMap(h=h, a=math.exp(-x), b=one_minus_a / body.c, q=wbar / body.m, spread=spread,
                       wbar=wbar, wmax=one_minus_a / k, m=body.m)


def _check_rates(name: str, value, unit: str):
    if np.ndim(value) == 0 and not isinstance(value, (list, tuple)):
        return checks.number(name, value, positive=True, unit=unit), True
    return checks.array(name, value, positive=True, nonempty=True), False


def _peak_square_eight(m: float, c: float, Theta: np.ndarray, samples: int = 128) -> np.ndarray:
    """max over s of g(s) = A1 cos^2(2s + al1) + A2 cos^2(s + al2) (period pi; A1 = c^2 + 4 m^2
    Theta^2, A2 = c^2 + m^2 Theta^2), so that the eight's |m C_d'' + c C_d'|^2 = R^2 Theta^2 g: a
    dense search, then safeguarded Newton steps on g' = 0 from the two best discrete local maxima
    (g is a trigonometric polynomial of degree 2 in 2s: at most two maxima), each kept in the
    bracket of its sample; the larger of the polished and the sampled value."""
    th = Theta[..., None]
    A1, A2 = c**2 + 4 * (m * th) ** 2, c**2 + (m * th) ** 2
    al1, al2 = np.arctan2(2 * m * th, c), np.arctan2(m * th, c)
    ds = math.pi / samples
    s = np.arange(samples) * ds
    g = A1 * np.cos(2 * s + al1) ** 2 + A2 * np.cos(s + al2) ** 2
    local = (g >= np.roll(g, 1, -1)) & (g >= np.roll(g, -1, -1))
    cand = np.argsort(np.where(local, g, -np.inf), axis=-1)[..., -2:]
    s0 = cand * ds
    best = np.take_along_axis(g, cand, -1)
    x = s0.copy()
    for _ in range(12):
        d1 = -2 * A1 * np.sin(4 * x + 2 * al1) - A2 * np.sin(2 * x + 2 * al2)
        d2 = -8 * A1 * np.cos(4 * x + 2 * al1) - 2 * A2 * np.cos(2 * x + 2 * al2)
        step = np.where(d2 < 0, -d1 / np.where(d2 < 0, d2, -1.0), np.sign(d1) * ds / 4)
        x = np.clip(x + step, s0 - ds, s0 + ds)
    polished = A1 * np.cos(2 * x + al1) ** 2 + A2 * np.cos(x + al2) ** 2
    return np.maximum(polished, best).max(-1)


def exact_peak_force(body: Body, R, Theta, *, kind: str = "eight"):
    """The largest force |m C_d'' + c C_d'| (N) over a period: what exact tracking of C needs,
    whatever the heading (eqs. (2)-(3) with C = C_d on the path (27) or (28)).

    Circle: the constant R Theta sqrt(m^2 Theta^2 + c^2). Eight: |.|^2 = R^2 Theta^2 g(Theta t),
    g(s) = (c^2 + 4 m^2 Theta^2) cos^2(2 s + al1) + (c^2 + m^2 Theta^2) cos^2(s + al2),
    al1 = atan2(2 m Theta, c), al2 = atan2(m Theta, c); its maximum is found by a dense search
    (128 samples over its period pi) and Newton steps on g' = 0 to machine precision, not read
    off the samples.

    Parameters
    ----------
    body : Body
        The body (m, c).
    R : float or array_like
        Size of the path (m), > 0.
    Theta : float or array_like
        Rate of the reference (rad/s), > 0; broadcast against R.
    kind : str
        ``"eight"`` (28) or ``"circle"`` (27).

    Returns
    -------
    float or numpy.ndarray
        The peak force (N): a float when R and Theta are both scalars, else their broadcast shape.
    """
    checks.instance("body", body, Body)
    R, r_scalar = _check_rates("R", R, "m")
    Theta, t_scalar = _check_rates("Theta", Theta, "rad/s")
    checks.one_of("kind", kind, _KINDS)
    R, Theta = np.asarray(R, float), np.asarray(Theta, float)
    try:
        np.broadcast_shapes(R.shape, Theta.shape)
    except ValueError as err:
        raise ValueError(f"R (shape {R.shape}) and Theta (shape {Theta.shape}) do not broadcast") from err
    m, c = body.m, body.c
    if kind == "circle":
        per_R = Theta * np.sqrt((m * Theta) ** 2 + c**2)
    else:            # the peak depends on Theta alone once divided by R: search over Theta only
        per_R = Theta * np.sqrt(_peak_square_eight(m, c, Theta))
    out = R * per_R
    return float(out) if (r_scalar and t_scalar) else out


@dataclass(frozen=True, repr=False)
class CapBound(Summarised):
    """The least error of C's tracking under the cap |F_w| <= F_max, bracketed.

    max_error (m): certified lower bound on the largest distance |C - C_d| over a period (the
    relaxed problem's dual objective); rms_error (m): lower bound on the RMS distance over the
    nodes (likewise); max_error_achieved, rms_error_achieved (m): the largest distance and the
    continuous-time RMS distance of the zero-order-hold motions of the two achieved problems
    (upper bounds on the true optima); t (s, (N,)) the nodes; C (m, (N, 2)), V (m/s, (N, 2)) and
    F (N, (N, 2), the world-frame force held on [t_k, t_k + h)) the achieved motion of the
    max-distance problem; C_rms, V_rms, F_rms the same for the RMS problem; gap (m): the largest
    ABSOLUTE duality gap (primal - dual objective) of the four solves; kind, R (m), Theta (rad/s),
    F_max (N), nodes as passed."""

    max_error: float
    rms_error: float
    max_error_achieved: float
    rms_error_achieved: float
    t: np.ndarray
    C: np.ndarray
    V: np.ndarray
    F: np.ndarray
    C_rms: np.ndarray
    V_rms: np.ndarray
    F_rms: np.ndarray
    gap: float
    kind: str
    R: float
    Theta: float
    F_max: float
    nodes: int


def _solve(problem: cp.Problem, what: str) -> tuple[float, float]:
    """Solve with Clarabel through cvxpy's own chain, keeping Clarabel's solution object (cvxpy's
    ``solver_stats.extra_stats`` is empty for Clarabel). Returns (dual objective, absolute gap)."""
    import cvxpy as cp
    for opts in SOLVER_OPTIONS:
        data, chain, inverse = problem.get_problem_data(solver="CLARABEL", solver_opts=dict(opts))
        raw = chain.solve_via_data(problem, data, solver_opts=dict(opts))
        with warnings.catch_warnings():     # cvxpy warns of an inaccurate solution: the status says it
            warnings.simplefilter("ignore", UserWarning)
            problem.unpack_results(raw, chain, inverse)
        if problem.status == cp.OPTIMAL:
            break
    if problem.status != cp.OPTIMAL:
        raise RuntimeError(f"Clarabel did not solve the {what} problem: status {problem.status!r} "
                           f"(Clarabel: {raw.status})")
    offset = problem.value - raw.obj_val
    return min(raw.obj_val, raw.obj_val_dual) + offset, abs(raw.obj_val - raw.obj_val_dual)


def _program(imap: IntervalMap, D: np.ndarray, F_max: float, objective: str, relaxed: bool,
             coupled: bool):
    """The discrete problem on N nodes: variables C, p (N, 2), g = G/(F_max h) and, relaxed,
    e = E/delta (N, 2), all within unit balls; C and p periodic. ``coupled`` adds, per node,
    |G + al m E| <= F_max h at al = 1/wbar and al = -1/(w(0) - wbar) (see :func:`cap_bound`)."""
    import cvxpy as cp
    N = D.shape[0]
    shift = sp.csr_matrix((np.ones(N), (np.arange(N), (np.arange(N) + 1) % N)), shape=(N, N))
    C, P, g = cp.Variable((N, 2)), cp.Variable((N, 2)), cp.Variable((N, 2))
    Gs = F_max * imap.h
    step = imap.a * C + imap.b * P + imap.q * Gs * g
    cons = [shift @ P == P + Gs * g]
    if relaxed:
        e = cp.Variable((N, 2))
        cons += [cp.norm(e, 2, axis=1) <= 1, shift @ C == step + imap.spread * F_max * e]
    else:
        cons.append(shift @ C == step)
    if relaxed and coupled:
        # G + al m E in units of F_max h: g + al m (spread/h) e; these imply |g| <= 1 (g is a
        # convex combination of the two), which is left out: redundant cones stall Clarabel
        for al in (1 / imap.wbar, -1 / (imap.wmax - imap.wbar)):
            cons.append(cp.norm(g + (al * imap.m * imap.spread / imap.h) * e, 2, axis=1) <= 1)
    else:
        cons.append(cp.norm(g, 2, axis=1) <= 1)
    if objective == "max":
        s = cp.Variable()
        cons.append(cp.norm(C - D, 2, axis=1) <= s)
        cost = s
    else:
        cost = cp.norm(C - D, "fro") / math.sqrt(N)
    return cp.Problem(cp.Minimize(cost), cons), P, g


def _zoh_motion(body: Body, imap: IntervalMap, G: np.ndarray, p0: np.ndarray, F_max: float):
    """The exact periodic motion under the held force F_k = G_k/h: the force's mean (zero at the
    solver's tolerance) removed and, if the solver left it a hair above the cap, scaled onto it;
    then p_k = p_0 + h sum F, and C_0 the periodic solution of the node map (C is fixed up to a
    translation, which p_0 fixes). Returns C, p, F (N, 2)."""
    h, N = imap.h, G.shape[0]
    F = G / h
    drift = float(np.hypot(*F.mean(0)))
    if drift > 1e-6 * F_max:
        raise RuntimeError(f"the solver's held force does not sum to zero over the period (mean "
                           f"{drift:.3g} N against F_max = {F_max:g} N): p would not be periodic")
    F = F - F.mean(0)
    peak = np.hypot(F[:, 0], F[:, 1]).max()
    if peak > F_max:
        F = F * (F_max / peak)
    p = p0 + h * np.vstack([np.zeros(2), np.cumsum(F, 0)[:-1]])
    u = imap.b * p + imap.q * h * F
    C = np.empty_like(u)
    C[0] = (imap.a ** np.arange(N - 1, -1, -1)) @ u / (-math.expm1(-body.c / body.m * h * N))
    for k in range(N - 1):
        C[k + 1] = imap.a * C[k] + u[k]
    return C, p, F


def _zoh_distance(body: Body, imap: IntervalMap, C, p, F, position, t):
    """|C(t) - C_d(t)| (m) of the held-force motion at times t in [0, N h): per interval,
    C(t_k + r) = e^{-kappa r} C_k + (1 - e^{-kappa r})/c p_k + F_k phi2(kappa r)/(m kappa^2)."""
    k_ = body.c / body.m
    idx = np.minimum((t // imap.h).astype(int), C.shape[0] - 1)
    r = (t - idx * imap.h)[:, None]
    pos = (np.exp(-k_ * r) * C[idx] - np.expm1(-k_ * r) / body.c * p[idx]
           + F[idx] * _phi2(k_ * r) / (body.m * k_**2))
    xd, yd = position(t)[:2]
    return np.hypot(pos[:, 0] - xd, pos[:, 1] - yd)


def _achieved(body, imap, C, p, F, position, N):
    """(largest distance, continuous-time RMS distance) of a held-force motion: SUBSAMPLES per
    interval; the largest sample polished by a bounded search (xatol 1e-12) over its two
    neighbouring sub-intervals; the mean square by Simpson's rule on each interval."""
    S, T = SUBSAMPLES, N * imap.h
    t = np.arange(N * S) * (imap.h / S)
    d = _zoh_distance(body, imap, C, p, F, position, t)
    i = int(np.argmax(d))

    def neg(tt):
        return -float(_zoh_distance(body, imap, C, p, F, position, np.array([tt % T]))[0])
    res = minimize_scalar(neg, bounds=(t[i] - imap.h / S, t[i] + imap.h / S), method="bounded",
                          options={"xatol": 1e-12})
    peak = max(float(d[i]), -float(res.fun))
    w = np.where(np.arange(N * S) % 2 == 1, 4.0, 2.0)     # Simpson's 1 4 2 ... 4 1, wrapped
    rms = math.sqrt(float(np.sum(w * d**2)) * (imap.h / S) / 3 / T)
    return peak, rms


def cap_bound(body: Body, R: float, Theta: float, F_max: float, *, kind: str = "eight",
              nodes: int = 256, coupled: bool = True) -> CapBound:
    """Bracket the least tracking error of C under the force cap |F_w| <= F_max, any heading.

    Four second-order-cone programs (Clarabel through cvxpy), on ``nodes`` equally spaced nodes
    over one period T = 2 pi/Theta: for each objective, the largest node distance
    max_k |C_k - C_d(t_k)| and the RMS node distance sqrt(mean_k |C_k - C_d(t_k)|^2), the
    relaxed problem (lower bounds) and the zero-order-hold problem (achieved motions, upper
    bounds); see the module docstring.

    The relaxation. Besides |G_k| <= F_max h and |E_k| <= delta, the pair (G_k, E_k) obeys, when
    ``coupled`` (default), |G_k + al m E_k| <= F_max h for al = 1/wbar and al = -1/(w(0) - wbar):
    G_k + al m E_k = int_0^h (1 + al (w - wbar)) F_w dr, the weight 1 + al (w - wbar) is >= 0
    for these al (0 <= w <= w(0)) and its integral is h, so every admissible F_w satisfies it (and
    every al between them, by convexity in al). Without it (``coupled=False``, the plain ball
    |E_k| <= delta) the relaxed optimum lies O(h) below the true one (a saturated force cannot
    also carry the largest remainder, but the plain relaxation lets it); with it the bracket
    closes as O(h^2) (observed: on the paper's eight at 4 N and 256 nodes the bracket on the
    largest distance is 0.24 mm wide with the cones, 14 mm without).

    The certificate. cvxpy's ``solver_stats.extra_stats`` is empty for Clarabel, so the problems
    are compiled with ``get_problem_data``, solved with ``SolvingChain.solve_via_data`` and read
    back with ``unpack_results`` (what ``Problem.solve`` does), which keeps Clarabel's solution
    object and its dual objective ``obj_val_dual``. The lower bounds are min(primal, dual) plus
    cvxpy's constant offset, floored at 0: bounds up to the dual residual of Clarabel's stopping
    test (tolerances :data:`SOLVER_OPTIONS`). ``gap`` is the largest |primal - dual| (m).

    Parameters
    ----------
    body : Body
        The body (m, c; the heading's parameters do not enter).
    R : float
        Size of the path (m), > 0.
    Theta : float
        Rate of the reference (rad/s), > 0.
    F_max : float
        The force cap (N), > 0.
    kind : str
        ``"eight"`` (28) or ``"circle"`` (27).
    nodes : int
        Nodes per period, 16 to :data:`MAX_NODES`.
    coupled : bool
        Add the coupling cones between G_k and E_k to the relaxed problems (default True).

    Returns
    -------
    CapBound
        The bounds (m), the achieved motions, the gap (m, absolute).

    Raises
    ------
    RuntimeError
        If a solve does not end with status optimal (names the problem and the status).
    """
    checks.instance("body", body, Body)
    R = checks.number("R", R, positive=True, unit="m")
    Theta = checks.number("Theta", Theta, positive=True, unit="rad/s")
    F_max = checks.number("F_max", F_max, positive=True, unit="N")
    checks.one_of("kind", kind, _KINDS)
    checks.loop_domain(body, None, KINEMATICS[kind], [R], [Theta], heading_gains=False)  # before any solve
    N = checks.integer("nodes", nodes, minimum=16)
    if N > MAX_NODES:
        raise ValueError(f"nodes must be at most MAX_NODES = {MAX_NODES}, got {N}")
    coupled = checks.flag("coupled", coupled)
    T = 2 * math.pi / Theta
    imap = interval_map(body, T / N)
    t = np.arange(N) * imap.h

    def position(tt):
        return POSITIONS[kind](R, Theta, tt)

    D = np.stack(position(t)[:2], -1)
    bounds, gaps, motions = {}, [], {}
    for objective in ("max", "rms"):
        prob, _, _ = _program(imap, D, F_max, objective, relaxed=True, coupled=coupled)
        bounds[objective], gap = _solve(prob, f"relaxed {objective}-distance")
        gaps.append(gap)
        prob, P, g = _program(imap, D, F_max, objective, relaxed=False, coupled=coupled)
        gaps.append(_solve(prob, f"achieved {objective}-distance")[1])
        C, p, F = _zoh_motion(body, imap, F_max * imap.h * g.value, P.value[0], F_max)
        motions[objective] = (C, p, F, _achieved(body, imap, C, p, F, position, N))
    (C, p, F, (mx, _)), (Cr, pr, Fr, (_, rms)) = motions["max"], motions["rms"]
    return CapBound(max_error=max(0.0, bounds["max"]), rms_error=max(0.0, bounds["rms"]),
                    max_error_achieved=mx, rms_error_achieved=rms, t=t,
                    C=C, V=(p - body.c * C) / body.m, F=F,
                    C_rms=Cr, V_rms=(pr - body.c * Cr) / body.m, F_rms=Fr,
                    gap=max(gaps), kind=kind, R=R, Theta=Theta, F_max=F_max, nodes=N)
