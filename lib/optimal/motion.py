"""The best periodic motions of the body on the circle (27) and the eight (28) under the
paper's limits (Sec. 5): how close to the path any controller can keep C.

:func:`periodic_motion` finds a periodic motion X(T) = X(0) + (0, 0, 2 pi n, 0, 0, 0) of (2)-(4)
(T = 2 pi / Theta; n = 0 on the eight, 1 on the circle) under F >= 0, F <= F_max, |beta| <= beta_max
that minimises the RMS distance of C from C_d(t), by collocation solved by IPOPT
(:mod:`lib.optimal.collocation`) from several starts (not convex: a best found); :func:`reintegrated`
integrates its inputs, a motion of the model; :func:`lib.optimal.held.held_force_motion` makes the
convex bound's achieved motions motions of the full model.

Defaults and cost: 80 intervals of degree-3 Legendre collocation (2080 unknowns), starts "paper",
"force", "shifted+-" and, under a cap alone, "convex"; a solve takes about 0.3 to 1.3 s of CPU.
The inputs are held in the body's frame on each interval, so the force turns with the heading
within it: with a cap the best found RMS error falls as h^2 with the mesh (Chapter 8 refines each
motion and extrapolates, :func:`lib.optimal.studies.study.richardson`); without one the optimum asks for
force pulses whose peak grows as the mesh refines. The starts meet one optimum at the meshes the
book tries; that says no better one was met, not that none exists.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from ..machinery import checks
from ..machinery.summary import Summarised
from ..model import config_from_state, state_from_config
from ..params import Body
from ..simulate import simulate_open_loop
from ..trajectories import KINEMATICS, heading_turns, make
from .held import _convex_held
from .collocation import ACCEPTED, FREE_ANGLE, _bounds, _clip, _guess_start, _max_error, _start, tableau, transcription

__all__ = ["PeriodicMotion", "periodic_motion", "verify_motion", "return_errors", "reintegrated", "STARTS",
           "START_TIE", "MAX_NODES", "FREE_ANGLE", "MOTION_RETURN_TOL", "check_motion_body", "run_held_inputs"]

#: the starts :func:`periodic_motion` knows ("shifted" is two solves, +- beta_max / 2; "convex"
#: needs a cap)
STARTS = ("paper", "force", "shifted", "convex")
#: starts whose RMS errors (m) differ by less than this are counted as ending at one optimum found
#: (IPOPT's tol 1e-10 on the mean square moves the RMS by about 1e-9 m)
START_TIE = 1e-8
#: the largest mesh accepted (intervals per period)
MAX_NODES = 2000
#: the shift of the "shifted" starts' heading when no angle limit is given (rad)
FREE_SHIFT = math.pi / 4
#: how close (in intervals) to a node a time counts as the node
NODE_SNAP = 1e-9
#: Gauss-Legendre points an interval of :func:`reintegrated`'s RMS
QUADRATURE = 6
#: the most a motion's inputs may miss returning it to its start on the given body (max-norm, state
#: units) for it to count as that body's motion (:func:`check_motion_body`): the reach tolerance
MOTION_RETURN_TOL = 1e-3


@dataclass(frozen=True, repr=False)
class PeriodicMotion(Summarised):
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

    @property
    def best_start(self) -> str:
        """The first start (in ``starts``' order) whose RMS lies within :data:`START_TIE` of the least."""
        return min(self.starts, key=lambda s: (not s[1] <= self.rms_error + START_TIE, self.starts.index(s)))[0]

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
    return (None if F_max is None else checks.number("F_max", F_max, positive=True, unit="N"),
            None if beta_max is None else checks.number("beta_max", beta_max, positive=True, maximum=math.pi, unit="rad"))


def _check_guess(guess, kind, R, Theta) -> tuple:
    """((start name, motion), ...) of ``guess``: a motion, a sequence (named guess[i]) or a dict by name."""
    if guess is None:
        return ()
    if isinstance(guess, dict):
        named = tuple((str(k), g) for k, g in guess.items())
    else:
        guesses = tuple(guess) if isinstance(guess, (list, tuple)) else (guess,)
        named = tuple((f"guess[{i}]", g) for i, g in enumerate(guesses))
    for i, (key, g) in enumerate(named):
        name = "guess" if not isinstance(guess, (list, tuple, dict)) else f"guess[{key if isinstance(guess, dict) else i}]"
        checks.instance(name, g, PeriodicMotion)
        if g.kind != kind or not (math.isclose(g.R, R, rel_tol=1e-12) and math.isclose(g.Theta, Theta, rel_tol=1e-12)):
            raise ValueError(f"{name} must be a motion on the same path (kind {kind!r}, R = {R} m, Theta = {Theta} "
                             f"rad/s), got kind {g.kind!r}, R = {g.R} m, Theta = {g.Theta} rad/s")
    return named


def _check_starts(starts, guesses, F_max, beta_max) -> tuple:
    if starts is None:
        return ("paper", "force", "shifted") + (("convex",) if F_max is not None and beta_max is None else ())
    if isinstance(starts, str) or not isinstance(starts, (list, tuple)):
        raise TypeError(f"starts must be a tuple of names from {list(STARTS)}, got {type(starts).__name__} {starts!r}")
    for s in starts:
        checks.one_of("starts entry", s, STARTS)
    if not starts and not guesses:
        raise ValueError("starts must name at least one start when no guess is given")
    if "convex" in starts and F_max is None:
        raise ValueError("starts entry 'convex' needs a force cap F_max (the convex problem is the cap's)")
    return tuple(dict.fromkeys(starts))


def periodic_motion(body: Body, R: float, Theta: float, *, kind: str = "eight", F_max: float | None = None,
                    beta_max: float | None = None, nodes: int = 80, degree: int = 3, guess=None,
                    starts=None, shifts=()) -> PeriodicMotion:
    """The best periodic motion found of (2)-(4) for C's RMS distance from the path: a local optimum.

    Minimises the mean of |C - C_d(t)|^2 over a period by Legendre collocation
    (:mod:`lib.optimal.collocation`) under F >= 0, F <= F_max and |beta| <= beta_max, with X(T) =
    X(0) + (0, 0, 2 pi n, 0, 0, 0). Solved by IPOPT from every start; the best accepted
    optimum is kept. Starts: ``"paper"``, the paper's law's steady orbit (C on the path,
    :func:`lib.percussion.paper_steady`, its inputs clipped into the limits); ``"force"``, C
    on the path with the heading along the force w = m C_d'' + c C_d' that keeps it there
    (beta = 0); ``"shifted"``, the same with the heading turned by +beta_max / 2 and by
    -beta_max / 2 (two solves; +-pi/4 without an angle limit); ``"convex"``, the optimum of
    the cap's convex problem (:func:`lib.optimal.bound.cap_bound` at ``nodes`` nodes, its
    RMS-optimal held world force, with the heading on its periodic orbit under that force,
    :func:`lib.optimal.held.held_force_motion`; needs ``F_max``, its beta clipped into an angle limit); and each
    motion in ``guess``, interpolated onto the mesh (continuation in beta_max).

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
    guess : PeriodicMotion, sequence or dict of PeriodicMotion, optional
        Earlier solutions on the same path (kind, R, Theta), used as extra starts, named
        ``guess[i]`` in ``starts`` of the result, or by their keys when given as a dict.
    starts : tuple of str, optional
        Which of :data:`STARTS` to run (may be empty when ``guess`` is given); default
        ``"paper"``, ``"force"``, ``"shifted"``, and ``"convex"`` under a cap without an angle limit.
    shifts : sequence of float
        More starts: the ``"force"`` start with its heading turned by each angle (rad), named
        ``"heading +12.0 deg"`` (a multi-start).

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
    shifts = [float(d) for d in checks.array("shifts", shifts, ndim=1)]
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
    named = [(s, s, 0.0) for s in starts if s not in ("shifted", "convex")]
    if "shifted" in starts:
        named += [("shifted+", "force", sh), ("shifted-", "force", -sh)]
    jobs = [(name, lambda s=src, d=dsh: _start(s, body, kind, R, Theta, turns, t_col, t_mid, d))
            for name, src, dsh in named]
    jobs += [(f"heading {math.degrees(d):+.1f} deg", lambda d=d: _start("force", body, kind, R, Theta, turns, t_col,
                                                                         t_mid, d)) for d in shifts]
    if "convex" in starts:
        jobs.append(("convex", lambda: _guess_start(_convex_held(body, kind, R, Theta, F_max, nodes), t_col, t_mid)))
    jobs += [(name, lambda g=g: _guess_start(g, t_col, t_mid)) for name, g in guesses]
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
    return R, Theta, F_max, beta_max, nodes, degree, guesses, _check_starts(starts, guesses, F_max, beta_max)


def _best(tr, jobs, par, F_max, beta_max) -> tuple[np.ndarray, np.ndarray, tuple]:
    """Solve from every start of ``jobs`` ((name, () -> (states, inputs))); the best accepted
    optimum's states (nodes, d + 1, 6) and inputs (nodes, 2), and the table of starts. A start
    that cannot be built (the paper's law holds no period-1 orbit) is recorded, not solved."""
    lbx, ubx = _bounds(tr, F_max, beta_max)
    table, best = [], None
    for name, make_start in jobs:
        try:
            X, u = make_start()
        except (ValueError, RuntimeError) as exc:
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


def run_held_inputs(body: Body, q: np.ndarray, F, beta, h: float, *, te=None, rtol: float = 1e-10,
                    atol: float = 1e-10) -> tuple[np.ndarray, np.ndarray | None]:
    """The model (2)-(4) under inputs held on intervals of ``h`` (s), F[k] (N) and beta[k] (rad) on
    the k-th, from the state ``q`` (state form of :func:`lib.model.state_from_config`), by the book's
    integrator (:func:`lib.simulate.simulate_open_loop`) interval by interval, so that it never steps
    across a jump of the inputs: the one integration of a motion's or an entry's inputs.

    Parameters
    ----------
    body : Body
        The body.
    q : numpy.ndarray
        (6,) the start, state form.
    F, beta : array_like
        (K,) the held inputs.
    h : float
        The interval (s), > 0.
    te : array_like, optional
        Times within an interval (s, in (0, h)) at which to record the state on every interval.
    rtol, atol : float
        The integrator's tolerances.

    Returns
    -------
    end : numpy.ndarray
        (6,) the state after the K intervals, state form.
    samples : numpy.ndarray or None
        (K, len(te), 6) the states at ``te`` on each interval, state form (None without ``te``).
    """
    te = None if te is None else np.asarray(te, dtype=float)
    t_eval = np.array([h]) if te is None else np.r_[te, h]
    samples = []
    for Fk, bk in zip(np.asarray(F, dtype=float), np.asarray(beta, dtype=float)):
        qs = simulate_open_loop(body, lambda t, F=Fk: F, lambda t, b=bk: b, q, h, form="config", t_eval=t_eval,
                                rtol=rtol, atol=atol)[1]
        samples.append(qs[:-1])
        q = qs[-1]
    return q, (None if te is None else np.stack(samples))


def check_motion_body(body: Body, motion) -> None:
    """Refuse a motion of :func:`periodic_motion` that is not a motion of ``body``: its inputs, run on
    ``body``'s model (:func:`verify_motion`), miss returning it to its start by more than
    :data:`MOTION_RETURN_TOL`. (A motion does not record the body it was solved for; a duck-typed
    motion is taken as given.)

    Parameters
    ----------
    body : Body
        The body the caller will run the motion on.
    motion : PeriodicMotion or a duck-typed motion
        The motion.

    Raises
    ------
    ValueError
        Naming the body and the miss.
    """
    if not isinstance(motion, PeriodicMotion):
        return
    miss = verify_motion(body, motion)
    if not miss <= MOTION_RETURN_TOL:
        raise ValueError(f"motion is not a periodic motion of body = {body}: its inputs on that body miss returning "
                         f"it to its start by {miss:.3g} (max-norm of m, rad, m/s, rad/s; at most "
                         f"{MOTION_RETURN_TOL:g}); solve it for this body (lib.optimal.periodic_motion(body, ...))")


def _return_mismatch(body: Body, motion: PeriodicMotion, rtol, atol) -> tuple[np.ndarray, float]:
    """X(T) - X(0) - (0, 0, 2 pi n, 0, 0, 0) (6,) of a motion's inputs integrated over one period, and
    the RMS distance (m) of the integrated C from the path, by Gauss-Legendre quadrature of
    :data:`QUADRATURE` points on each interval (the integrated motion is smooth within one)."""
    checks.instance("body", body, Body)
    checks.instance("motion", motion, PeriodicMotion)
    rtol, atol = checks.number("rtol", rtol, positive=True), checks.number("atol", atol, positive=True)
    z0, dz0 = motion.state(0.0)
    h, ref = motion.period / motion.nodes, make(motion.kind, motion.R, motion.Theta)
    s, w = np.polynomial.legendre.leggauss(QUADRATURE)
    te = h * (s + 1) / 2
    q, qs = run_held_inputs(body, state_from_config(z0, dz0), motion.F, motion.beta, h, te=te, rtol=rtol, atol=atol)
    sq = sum(w @ ((qs[k, :, :2] - ref.z(motion.t[k] + te)[:, :2]) ** 2).sum(1) / 2 for k in range(motion.nodes))
    X1 = np.concatenate(config_from_state(q)) - np.concatenate([z0, dz0]) - [0, 0, 2 * np.pi * motion.turns, 0, 0, 0]
    return X1, math.sqrt(sq / motion.nodes)


def verify_motion(body: Body, motion: PeriodicMotion, *, rtol: float = 1e-10, atol: float = 1e-10) -> float:
    """The return error of a motion's inputs integrated by the book's integrator: the model (2)-(4)
    (:func:`lib.simulate.simulate_open_loop`, ``form="config"``) under ``motion.inputs`` from
    ``motion.state(0)`` over one period, interval by interval (the inputs are constant on each,
    so the integrator never steps across a jump); max |X(T) - X(0) - (0, 0, 2 pi n, 0, 0, 0)|.

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
        A max-norm over the six components in their own units (m, m, rad, m/s, m/s, rad/s), not
        a length (:func:`reintegrated` gives it per quantity).
    """
    return float(np.max(np.abs(_return_mismatch(body, motion, rtol, atol)[0])))


def return_errors(body: Body, motion: PeriodicMotion, *, rtol: float = 1e-10, atol: float = 1e-10) -> dict:
    """:func:`reintegrated` without its ``rms``: the mismatch after one period, per quantity.

    Returns
    -------
    dict
        ``position`` (m), ``heading`` (rad), ``velocity`` (m/s), ``rate`` (rad/s).
    """
    return {k: v for k, v in reintegrated(body, motion, rtol=rtol, atol=atol).items() if k != "rms"}


def reintegrated(body: Body, motion: PeriodicMotion, *, rtol: float = 1e-10, atol: float = 1e-10) -> dict:
    """A motion's inputs integrated as by :func:`verify_motion`: the mismatch after a period per quantity,
    and the RMS distance of the integrated C from the path (a motion of the model's: a best found's value).

    Returns
    -------
    dict
        ``position`` |dC| (m), ``heading`` |d phi| (rad), ``velocity`` |dC'| (m/s), ``rate``
        |d phi'| (rad/s); ``rms`` (m).
    """
    d, rms = _return_mismatch(body, motion, rtol, atol)
    return dict(position=float(np.hypot(d[0], d[1])), heading=float(abs(d[2])),
                velocity=float(np.hypot(d[3], d[4])), rate=float(abs(d[5])), rms=rms)
