"""The best periodic motions of the body on the circle (27) and the eight (28) under the
paper's limits (Sec. 5): how close to the path any controller can keep C.

Over one period T = 2 pi / Theta of the path, the full model (2)-(4) with inputs F >= 0
(<= F_max if given) and |beta| <= beta_max (if given) runs a periodic motion X(T) = X(0) +
(0, 0, 2 pi n, 0, 0, 0) (n = 0 on the eight, whose tangent oscillates about pi; n = 1 on the
circle, whose tangent turns once a period); :func:`periodic_motion` finds the one that
minimises the RMS distance sqrt((1/T) int_0^T |C - C_d(t)|^2 dt) of C from the path point
C_d(t), by direct collocation solved by IPOPT (:mod:`lib.optimal.collocation`) from several
starts (the problem is not convex), and :func:`verify_motion` integrates its piecewise-constant
inputs with the book's integrator to check that it is a motion of the model.

Defaults and cost: 80 intervals of degree-3 Legendre collocation (2080 unknowns) and four
starts ("paper", "force", "shifted+-"); one call takes about 0.4 to 1.3 s of CPU on the
eight under an angle limit, the first call of a process about 1 s more (the paper's orbit for
the "paper" start, and the solver's construction, both cached). Under an angle limit and
without a force cap the optimum asks for force pulses that grow as the mesh refines (the
infimum is approached by impulses): its RMS error moves by a few per cent between 40 and
160 intervals, and the collocation's order shows in :func:`verify_motion` only with a cap.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from functools import lru_cache

import numpy as np
from scipy.optimize import minimize_scalar

from ..angles import wrap_angle
from ..machinery import checks
from ..model import config_from_state, state_from_config
from ..params import Body
from ..percussion import paper_steady
from ..simulate import simulate_open_loop
from ..trajectories import KINEMATICS, POSITIONS, heading_turns, make
from .collocation import ACCEPTED, tableau, transcription

__all__ = ["PeriodicMotion", "periodic_motion", "verify_motion", "STARTS", "MAX_NODES", "FREE_ANGLE"]

#: the starts :func:`periodic_motion` knows ("shifted" is two solves, +- beta_max / 2)
STARTS = ("paper", "force", "shifted")
#: the largest mesh accepted (intervals per period)
MAX_NODES = 2000
#: the bound on |beta| (rad) when no angle limit is given; beta is then free, but bounded a
#: little beyond +-pi to keep the NLP bounded (every force direction stays reachable)
FREE_ANGLE = math.pi + 1.0
#: the shift of the "shifted" starts' heading when no angle limit is given (rad)
FREE_SHIFT = math.pi / 4
#: harmonics of the paper's steady heading kept for the "paper" start (it is smooth)
HARMONICS = 64
#: how close (in intervals) to a node a time counts as the node
NODE_SNAP = 1e-9
#: dense samples per interval for the largest distance, before its refinement
DENSE = 16


@dataclass(frozen=True)
class PeriodicMotion:
    """An optimal periodic motion on a path (one period), as :func:`periodic_motion` returns it.

    Attributes
    ----------
    t : numpy.ndarray
        (nodes,) node times t_k = k T / nodes in [0, T) (s).
    z : numpy.ndarray
        (nodes, 3) the configuration (x (m), y (m), phi (rad)) at the nodes.
    dz : numpy.ndarray
        (nodes, 3) its rate (m/s, m/s, rad/s).
    F : numpy.ndarray
        (nodes,) the force (N) on the interval starting at t_k.
    beta : numpy.ndarray
        (nodes,) its angle (rad) on the same interval.
    max_error : float
        max_t |C - C_d(t)| (m) over the period, on the collocation polynomials (16 samples
        per interval, the largest refined by a bounded scalar search).
    rms_error : float
        sqrt((1/T) int_0^T |C - C_d|^2 dt) (m) by the collocation quadrature.
    period : float
        T = 2 pi / Theta (s).
    kind : str
        The path, ``"eight"`` or ``"circle"``.
    R : float
        Its size (m).
    Theta : float
        Its rate (rad/s).
    F_max : float or None
        The force cap (N), None if absent.
    beta_max : float or None
        The angle limit (rad), None if absent.
    nodes : int
        Collocation intervals a period.
    degree : int
        Collocation degree.
    turns : int
        n, the heading gains 2 pi n per period.
    starts : tuple
        One (start name, rms objective (m) or nan, IPOPT status) per start tried.
    collocation : numpy.ndarray
        (nodes, degree + 1, 6) the states (x, y, phi, x', y', phi') at each interval's start
        and its Legendre points: the polynomials behind :meth:`state`.
    """

    t: np.ndarray
    z: np.ndarray
    dz: np.ndarray
    F: np.ndarray
    beta: np.ndarray
    max_error: float
    rms_error: float
    period: float
    kind: str
    R: float
    Theta: float
    F_max: float | None
    beta_max: float | None
    nodes: int
    degree: int
    turns: int
    starts: tuple
    collocation: np.ndarray = field(repr=False)

    def _locate(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(interval index, local time s in [0, 1), whole periods) of times t (s)."""
        t = np.asarray(t, dtype=float)
        laps = np.floor(t / self.period)
        x = (t - laps * self.period) * (self.nodes / self.period)
        # a node time computed in floating point belongs to the interval it starts
        k = np.minimum(np.maximum(np.floor(x + NODE_SNAP).astype(int), 0), self.nodes - 1)
        return k, np.minimum(np.maximum(x - k, 0.0), 1.0), laps

    def inputs(self, t) -> tuple[np.ndarray, np.ndarray]:
        """The piecewise-constant inputs at times t (s), any shape, periodic in t.

        Returns
        -------
        F, beta : numpy.ndarray
            Force (N) and angle (rad), shape t.shape (floats for a scalar t).
        """
        k, _, _ = self._locate(t)
        return self.F[k], self.beta[k]

    def state(self, t) -> tuple[np.ndarray, np.ndarray]:
        """The collocation polynomials at times t (s), any shape; periodic extension (phi
        gains 2 pi ``turns`` per period).

        Returns
        -------
        z, dz : numpy.ndarray
            Configuration (m, m, rad) and its rate (m/s, m/s, rad/s), shape t.shape + (3,).
        """
        k, s, laps = self._locate(t)
        L = tableau(self.degree).weights(s)
        X = np.einsum("...r,...ri->...i", L, self.collocation[k])
        X[..., 2] += 2 * np.pi * self.turns * laps
        return X[..., :3], X[..., 3:]


def _check_limits(F_max, beta_max):
    if F_max is not None:
        F_max = checks.number("F_max", F_max, positive=True, unit="N")
    if beta_max is not None:
        beta_max = checks.number("beta_max", beta_max, positive=True, maximum=math.pi, unit="rad")
    return F_max, beta_max


def _check_guess(guess, kind, R, Theta) -> tuple:
    if guess is None:
        return ()
    guesses = tuple(guess) if isinstance(guess, (list, tuple)) else (guess,)
    for i, g in enumerate(guesses):
        name = "guess" if len(guesses) == 1 and not isinstance(guess, (list, tuple)) else f"guess[{i}]"
        checks.instance(name, g, PeriodicMotion)
        if g.kind != kind or not (math.isclose(g.R, R, rel_tol=1e-12) and math.isclose(g.Theta, Theta, rel_tol=1e-12)):
            raise ValueError(f"{name} must be a motion on the same path (kind {kind!r}, R = {R} m, Theta = {Theta} "
                             f"rad/s), got kind {g.kind!r}, R = {g.R} m, Theta = {g.Theta} rad/s")
    return guesses


def _check_starts(starts, guesses) -> tuple:
    if isinstance(starts, str) or not isinstance(starts, (list, tuple)):
        raise TypeError(f"starts must be a tuple of names from {list(STARTS)}, got {type(starts).__name__} {starts!r}")
    for s in starts:
        checks.one_of("starts entry", s, STARTS)
    if not starts and not guesses:
        raise ValueError("starts must name at least one start when no guess is given")
    return tuple(dict.fromkeys(starts))


def _force(body: Body, kind: str, R: float, Theta: float, t) -> tuple[np.ndarray, np.ndarray]:
    """The force that keeps C on the path, w = m C_d'' + c C_d' (N), and its rate (N/s), (..., 2)."""
    _, _, vx, vy, ax, ay, jx, jy = POSITIONS[kind](R, Theta, np.asarray(t, dtype=float))
    w = body.m * np.stack([ax, ay], -1) + body.c * np.stack([vx, vy], -1)
    dw = body.m * np.stack([jx, jy], -1) + body.c * np.stack([ax, ay], -1)
    return w, dw


@lru_cache(maxsize=16)
def _paper_heading(body: Body, kind: str, R: float, Theta: float) -> np.ndarray:
    """The paper's steady heading error p = phi - phi_d (rad) as complex Fourier coefficients
    c_k (k = 0 .. HARMONICS) of p(t) = c_0 + 2 Re sum_k c_k exp(i k Theta t) (cached: the book
    asks for it under several limits)."""
    p = paper_steady(body, kind, R, Theta).p[:-1]
    return np.fft.rfft(p)[:HARMONICS + 1] / len(p)


def _fourier(coeffs: np.ndarray, Theta: float, t) -> tuple[np.ndarray, np.ndarray]:
    """The series of :func:`_paper_heading` and its rate (rad/s) at times t (s)."""
    k = np.arange(len(coeffs))
    e = np.exp(1j * np.multiply.outer(np.asarray(t, dtype=float), k * Theta))
    mult = np.where(k == 0, 1.0, 2.0)
    return (mult * coeffs * e).sum(-1).real, (mult * 1j * k * Theta * coeffs * e).sum(-1).real


def _path_start(body, kind, R, Theta, t_col, t_mid, heading):
    """A start with C on the path: states at the collocation times ``t_col`` (nodes, d + 1),
    inputs at the interval mid-times ``t_mid`` (the force w of the path, its angle to the
    heading), the heading (phi, phi') given by ``heading(t)``."""
    ref = make(kind, R, Theta)
    z, dz, _ = ref.kinematics(t_col)
    phi, dphi = heading(t_col)
    X = np.concatenate([z[..., :2], phi[..., None], dz[..., :2], dphi[..., None]], axis=-1)
    w, _ = _force(body, kind, R, Theta, t_mid)
    u = np.stack([np.hypot(w[:, 0], w[:, 1]), wrap_angle(np.arctan2(w[:, 1], w[:, 0]) - heading(t_mid)[0])], -1)
    return X, u


def _start(name, body, kind, R, Theta, turns, t_col, t_mid, shift):
    """The (states, inputs) of a named start (see :func:`periodic_motion`): ``"paper"`` the
    paper's steady heading; ``"force"`` the heading along w = m C_d'' + c C_d' turned by
    ``shift`` (rad), continuous, with a linear drift added if w's winding over a period is not
    the path's turn n (never on the book's paths)."""
    T = 2 * np.pi / Theta
    ref = make(kind, R, Theta)
    if name == "paper":
        coeffs = _paper_heading(body, kind, R, Theta)

        def heading(t):
            p, dp = _fourier(coeffs, Theta, t)
            zd, dzd, _ = ref.kinematics(t)
            return zd[..., 2] + p, dzd[..., 2] + dp
        return _path_start(body, kind, R, Theta, t_col, t_mid, heading)
    tt = np.linspace(0.0, T, 257)
    w, _ = _force(body, kind, R, Theta, tt)
    ang = np.unwrap(np.arctan2(w[:, 1], w[:, 0]))
    slip = 2 * np.pi * (turns - round((ang[-1] - ang[0]) / (2 * np.pi))) / T

    def heading(t):
        w, dw = _force(body, kind, R, Theta, t)
        raw = np.arctan2(w[..., 1], w[..., 0])
        near = np.interp(t, tt, ang)            # the unwrapped branch; t lies in [0, T)
        phi = raw + 2 * np.pi * np.round((near - raw) / (2 * np.pi)) + slip * t + shift
        rate = (w[..., 0] * dw[..., 1] - w[..., 1] * dw[..., 0]) / (w ** 2).sum(-1) + slip
        return phi, rate
    return _path_start(body, kind, R, Theta, t_col, t_mid, heading)


def _guess_start(g: PeriodicMotion, t_col, t_mid):
    z, dz = g.state(t_col)
    F, beta = g.inputs(t_mid)
    return np.concatenate([z, dz], -1), np.stack([F, beta], -1)


def _bounds(tr, F_max, beta_max):
    lo = np.full((tr.nodes, tr.block), -np.inf)
    hi = np.full((tr.nodes, tr.block), np.inf)
    b = FREE_ANGLE if beta_max is None else beta_max
    lo[:, -2], hi[:, -2] = 0.0, np.inf if F_max is None else F_max
    lo[:, -1], hi[:, -1] = -b, b
    return lo.ravel(), hi.ravel()


def _clip(u, F_max, beta_max):
    b = FREE_ANGLE if beta_max is None else beta_max
    return np.stack([np.clip(u[:, 0], 0.0, np.inf if F_max is None else F_max), np.clip(u[:, 1], -b, b)], -1)


def _max_error(motion: PeriodicMotion, ref) -> float:
    """Largest |C - C_d| (m): DENSE samples per interval, the largest refined by a bounded search."""
    n = motion.nodes * DENSE
    t = np.arange(n) * (motion.period / n)

    def dist(tt):
        return np.linalg.norm(motion.state(tt)[0][..., :2] - ref.z(tt)[..., :2], axis=-1)

    d = dist(t)
    i = int(np.argmax(d))
    dt = motion.period / n
    res = minimize_scalar(lambda s: -float(dist(s)), bounds=(t[i] - dt, t[i] + dt), method="bounded",
                          options={"xatol": 1e-9 * motion.period})
    return max(float(d[i]), -float(res.fun))


def periodic_motion(body: Body, R: float, Theta: float, *, kind: str = "eight", F_max: float | None = None,
                    beta_max: float | None = None, nodes: int = 80, degree: int = 3, guess=None,
                    starts=STARTS) -> PeriodicMotion:
    """The periodic motion of the model (2)-(4) that keeps C closest to the path, in RMS.

    Minimises the mean of |C - C_d(t)|^2 over a period by Legendre collocation
    (:mod:`lib.optimal.collocation`) under F >= 0, F <= F_max and |beta| <= beta_max, with X(T) =
    X(0) + (0, 0, 2 pi n, 0, 0, 0). Solved by IPOPT from every start; the best accepted
    optimum is kept. Starts: ``"paper"``, the paper's law's steady orbit (C on the path,
    :func:`lib.percussion.paper_steady`, its inputs clipped into the limits); ``"force"``, C
    on the path with the heading along the force w = m C_d'' + c C_d' that keeps it there
    (beta = 0); ``"shifted"``, the same with the heading turned by +beta_max / 2 and by
    -beta_max / 2 (two solves; +-pi/4 without an angle limit); and each motion in ``guess``,
    interpolated onto the mesh (continuation in beta_max).

    Parameters
    ----------
    body : Body
        The body.
    R : float
        Size of the path (m), > 0.
    Theta : float
        Rate of the path (rad/s), > 0; the period is T = 2 pi / Theta (s).
    kind : str
        ``"eight"`` (28) (n = 0) or ``"circle"`` (27) (n = 1).
    F_max : float, optional
        Force cap (N), > 0; None for none.
    beta_max : float, optional
        Angle limit (rad), in (0, pi]; None leaves beta free in [-pi - 1, pi + 1] (rad).
    nodes : int
        Intervals per period, 8 to :data:`MAX_NODES`.
    degree : int
        Legendre points per interval, 1 to 5 (order 2 degree at the nodes).
    guess : PeriodicMotion or sequence of PeriodicMotion, optional
        Earlier solutions on the same path (kind, R, Theta), used as extra starts.
    starts : tuple of str
        Which of :data:`STARTS` to run (may be empty when ``guess`` is given).

    Returns
    -------
    PeriodicMotion
        The best accepted optimum, with every start's objective and status.

    Raises
    ------
    TypeError, ValueError
        For a wrong argument, naming it, before any solve.
    RuntimeError
        If no start ends in an accepted IPOPT status (listing each start's status).
    """
    R, Theta, F_max, beta_max, nodes, degree, guesses, starts = _check_args(
        body, R, Theta, kind, F_max, beta_max, nodes, degree, guess, starts)
    turns = heading_turns(make(kind, R, Theta))
    T = 2 * np.pi / Theta
    h = T / nodes
    tab = tableau(degree)
    tk = np.arange(nodes) * h
    t_col = tk[:, None] + h * tab.tau[None, :]
    t_mid = tk + h / 2
    ref = make(kind, R, Theta)
    Cd = ref.z(t_col[:, 1:])[..., :2]
    tr = transcription(body, nodes, degree)
    sh = FREE_SHIFT if beta_max is None else beta_max / 2
    named = [(s, s, 0.0) for s in starts if s != "shifted"]
    if "shifted" in starts:
        named += [("shifted+", "force", sh), ("shifted-", "force", -sh)]
    jobs = [(name, lambda s=src, d=dsh: _start(s, body, kind, R, Theta, turns, t_col, t_mid, d))
            for name, src, dsh in named]
    jobs += [(f"guess[{i}]", lambda g=g: _guess_start(g, t_col, t_mid)) for i, g in enumerate(guesses)]
    par = np.concatenate([[h, 2 * np.pi * turns], Cd.ravel()])
    Xs, u, table = _best(tr, jobs, par, F_max, beta_max)
    e2 = ((Xs[:, 1:, :2] - Cd) ** 2).sum(-1)
    rms = math.sqrt(max(float((e2 @ tab.B).mean()), 0.0))
    motion = PeriodicMotion(t=tk, z=Xs[:, 0, :3].copy(), dz=Xs[:, 0, 3:].copy(), F=u[:, 0].copy(),
                            beta=u[:, 1].copy(), max_error=math.nan, rms_error=rms, period=T, kind=kind, R=R,
                            Theta=Theta, F_max=F_max, beta_max=beta_max, nodes=nodes, degree=degree, turns=turns,
                            starts=table, collocation=Xs)
    for arr in (tk, motion.z, motion.dz, motion.F, motion.beta, Xs):
        arr.setflags(write=False)
    return replace(motion, max_error=_max_error(motion, ref))


def _check_args(body, R, Theta, kind, F_max, beta_max, nodes, degree, guess, starts) -> tuple:
    """:func:`periodic_motion`'s arguments checked, in its order; R, Theta, the limits, nodes,
    degree, the guesses (a tuple) and the starts returned."""
    checks.instance("body", body, Body)
    R = checks.number("R", R, positive=True, unit="m")
    Theta = checks.number("Theta", Theta, positive=True, unit="rad/s")
    checks.one_of("kind", kind, ("eight", "circle"))
    checks.loop_domain(body, None, KINEMATICS[kind], [R], [Theta], heading_gains=False)  # before any solve
    F_max, beta_max = _check_limits(F_max, beta_max)
    nodes = checks.integer("nodes", nodes, minimum=8)
    if nodes > MAX_NODES:
        raise ValueError(f"nodes must be at most {MAX_NODES}, got {nodes}")
    degree = checks.integer("degree", degree, minimum=1)
    if degree > 5:
        raise ValueError(f"degree must be at most 5, got {degree}")
    guesses = _check_guess(guess, kind, R, Theta)
    return R, Theta, F_max, beta_max, nodes, degree, guesses, _check_starts(starts, guesses)


def _best(tr, jobs, par, F_max, beta_max) -> tuple[np.ndarray, np.ndarray, tuple]:
    """Solve from every start of ``jobs`` ((name, () -> (states, inputs))); the best accepted
    optimum's states (nodes, d + 1, 6) and inputs (nodes, 2), and the table of starts. A start
    that cannot be built (the paper's law holds no period-1 orbit) is recorded, not solved."""
    lbx, ubx = _bounds(tr, F_max, beta_max)
    table, best = [], None
    for name, make_start in jobs:
        try:
            X, u = make_start()
        except ValueError as exc:
            table.append((name, math.nan, f"no start: {exc}"))
            continue
        sol = tr.solver(x0=tr.pack(X, _clip(u, F_max, beta_max)), lbx=lbx, ubx=ubx, lbg=0.0, ubg=0.0, p=par)
        status = tr.solver.stats()["return_status"]
        ok = status in ACCEPTED
        obj = float(sol["f"])
        table.append((name, math.sqrt(max(obj, 0.0)) if ok else math.nan, status))
        if ok and (best is None or obj < best[0]):
            best = (obj, np.array(sol["x"]).ravel())
    if best is None:
        raise RuntimeError("periodic_motion: IPOPT accepted no start: " + "; ".join(f"{n}: {s}" for n, _, s in table))
    X, u = tr.unpack(best[1])
    return X, u, tuple(table)


def verify_motion(body: Body, motion: PeriodicMotion, *, rtol: float = 1e-10, atol: float = 1e-10) -> float:
    """The return error of a motion's inputs integrated by the book's integrator.

    Integrates the model (2)-(4) (:func:`lib.simulate.simulate_open_loop`, ``form="config"``)
    under ``motion.inputs`` from ``motion.state(0)`` over one period, interval by interval
    (each interval's inputs are constant, so the integrator never steps across a jump), and
    returns max |X(T) - X(0) - (0, 0, 2 pi n, 0, 0, 0)| over the six state components.

    Parameters
    ----------
    body : Body
        The body (the one the motion was solved for).
    motion : PeriodicMotion
        The motion.
    rtol, atol : float
        Tolerances of the integrator, > 0.

    Returns
    -------
    float
        The return error, a max-norm over components in the state's own units (m, m, rad,
        m/s, m/s, rad/s), not a physical length.
    """
    checks.instance("body", body, Body)
    checks.instance("motion", motion, PeriodicMotion)
    rtol = checks.number("rtol", rtol, positive=True)
    atol = checks.number("atol", atol, positive=True)
    z0, dz0 = motion.state(0.0)
    q = state_from_config(z0, dz0)
    h = motion.period / motion.nodes
    for k in range(motion.nodes):
        F, beta = float(motion.F[k]), float(motion.beta[k])
        _, qs = simulate_open_loop(body, lambda t, F=F: F, lambda t, b=beta: b, q, h, form="config",
                                   t_eval=np.array([h]), rtol=rtol, atol=atol)
        q = qs[-1]
    z1, dz1 = config_from_state(q)
    X0 = np.concatenate([z0, dz0])
    X1 = np.concatenate([z1, dz1])
    X1[2] -= 2 * np.pi * motion.turns
    return float(np.max(np.abs(X1 - X0)))
