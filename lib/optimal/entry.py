"""An entry manoeuvre onto a periodic motion (Chapter 8): from a start at t = 0, the inputs under
the motion's own limits that keep C closest to the path while they bring the state onto the
motion after a whole number of periods, by the Legendre collocation of
:mod:`lib.optimal.collocation` with the intervals left open (:func:`entry_transcription`). Its
inputs are then integrated by the book's integrator (:func:`lib.optimal.motion.run_held_inputs`),
so that the entry ends where the model goes, not where the collocation says. Open loop: a plan,
which the periodic LQR (:mod:`lib.optimal.tracker`) takes over at its end.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..machinery import checks
from ..machinery.summary import Summarised
from ..model import config_from_state, state_from_config
from ..params import PAPER_DZ0, PAPER_Z0, Body
from ..trajectories import make
from .collocation import ACCEPTED, IPOPT_OPTIONS, NX, Transcription, _bounds, _clip, _interval, tableau
from .motion import PeriodicMotion, check_motion_body, run_held_inputs

__all__ = ["Entry", "entry_motion", "entry_transcription", "ENTRY_PERIODS", "ENTRY_NODES"]

#: periods of the reference an entry manoeuvre lasts, and its collocation intervals a period
ENTRY_PERIODS, ENTRY_NODES = 2, 80


@lru_cache(maxsize=2)
def entry_transcription(body: Body, nodes: int, degree: int) -> Transcription:
    """The NLP of an entry manoeuvre: :func:`lib.optimal.collocation.transcription`'s, but open: from X_0 (fixed by the
    caller's bounds) to X_nodes = a target given as a parameter. Parameters: h (s), the target
    (6: m, m, rad, m/s, m/s, rad/s), then C_d at the collocation points.

    Parameters
    ----------
    body : Body
        The body.
    nodes : int
        Intervals of the whole entry.
    degree : int
        Legendre points per interval.

    Returns
    -------
    Transcription
        The solver (cached).
    """
    import casadi as ca
    tab = tableau(degree)
    d, N = degree, nodes
    block = NX * (d + 1) + 2
    w = ca.SX.sym("w", N * block)
    p = ca.SX.sym("p", 1 + NX + 2 * d * N)
    W = ca.reshape(w, block, N)
    Xs, U = W[:NX * (d + 1), :], W[NX * (d + 1):, :]
    Xnext = ca.horzcat(Xs[:NX, 1:], p[1:1 + NX])
    Cd = ca.reshape(p[1 + NX:], 2 * d, N)
    g, cost = _interval(body, tab).map(N)(ca.reshape(Xs, NX, (d + 1) * N), U, Xnext, ca.repmat(p[0], 1, N),
                                          ca.reshape(Cd, 2, d * N))
    nlp = {"x": w, "p": p, "f": ca.sum2(cost) / N, "g": ca.vec(g)}
    solver = ca.nlpsol("entry_motion", "ipopt", nlp, IPOPT_OPTIONS)
    return Transcription(nodes=N, degree=d, block=block, ng=int(nlp["g"].numel()), solver=solver)


@dataclass(frozen=True, repr=False)
class Entry(Summarised):
    """An entry manoeuvre (:func:`entry_motion`): inputs F (N), beta (rad) held on each interval
    of [0, periods T]; C's RMS and largest distance from the path over it (m, at the collocation
    points, ``path`` (M, 3): t (s), x, y (m) there); ``end``, the state its integrated inputs reach
    (heading brought back by whole turns to the motion's at t = 0), ``end_gap`` its mismatch."""

    F: np.ndarray
    beta: np.ndarray
    rms_error: float
    max_error: float
    end: np.ndarray
    end_gap: dict
    periods: int
    nodes: int
    path: np.ndarray


def entry_motion(body: Body, motion: PeriodicMotion, start=None, *, periods: int = ENTRY_PERIODS,
                 nodes: int = ENTRY_NODES, degree: int = 3) -> Entry:
    """An entry manoeuvre from ``start`` at t = 0 onto ``motion`` at t = periods T: the inputs,
    under the motion's own limits, that keep C closest to the path in RMS while they bring the
    state from the start to the motion's (its heading on the branch nearest the start's), by
    the Legendre collocation of :func:`entry_transcription` from the
    motion itself as first guess. Its inputs are then integrated from the start by the book's
    integrator, so that ``Entry.end`` is what the model reaches, not what the collocation
    says. Open loop: it is a plan, which the periodic LQR takes over at its end.

    Parameters
    ----------
    body : Body
        The body the motion was solved for.
    motion : lib.optimal.motion.PeriodicMotion
        The periodic motion to enter (:func:`lib.optimal.motion.periodic_motion`).
    start : array_like, shape (6,), optional
        The state at t = 0 (default: the paper's start).
    periods : int
        Reference periods the entry lasts (>= 1).
    nodes : int
        Collocation intervals a period (>= 8).
    degree : int
        Legendre points per interval (1 to 5).

    Returns
    -------
    Entry

    Raises
    ------
    RuntimeError
        If IPOPT ends in a status not accepted.
    """
    checks.instance("body", body, Body)
    if not all(hasattr(motion, k) for k in ("state", "inputs", "period", "turns", "F_max", "beta_max", "kind")):
        raise TypeError(f"motion must be a PeriodicMotion (lib.optimal.motion.periodic_motion), got {type(motion).__name__}")
    check_motion_body(body, motion)            # a motion of another body is refused, as track_motion refuses it
    x0 = checks.array("start", np.concatenate([PAPER_Z0, PAPER_DZ0]) if start is None else start, shape=(6,))
    periods = checks.integer("periods", periods, minimum=1)
    nodes = checks.integer("nodes", nodes, minimum=8)
    degree = checks.integer("degree", degree, minimum=1)
    if degree > 5:
        raise ValueError(f"degree must be at most 5, got {degree}")
    N, h, tab = nodes * periods, motion.period / nodes, tableau(degree)
    tk = np.arange(N) * h
    t_col, t_mid = tk[:, None] + h * tab.tau[None, :], tk + h / 2
    Cd = make(motion.kind, motion.R, motion.Theta).z(t_col[:, 1:])[..., :2]
    lap = 2 * np.pi * round((x0[2] - motion.state(0.0)[0][2]) / (2 * np.pi))   # the start's heading branch
    z, dz = motion.state(t_col)
    X, u = np.concatenate([z, dz], -1), _clip(np.stack(motion.inputs(t_mid), -1), motion.F_max, motion.beta_max)
    X[..., 2] += lap
    X[0, 0] = x0
    target = np.concatenate(motion.state(periods * motion.period)) + np.array([0, 0, lap, 0, 0, 0])
    tr = entry_transcription(body, N, degree)
    lo, hi = (b.reshape(N, tr.block) for b in _bounds(tr, motion.F_max, motion.beta_max))
    lo[0, :6] = hi[0, :6] = x0
    sol = tr.solver(x0=tr.pack(X, u), lbx=lo.ravel(), ubx=hi.ravel(), lbg=0, ubg=0,
                    p=np.concatenate([[h], target, Cd.ravel()]))
    status = tr.solver.stats()["return_status"]
    if status not in ACCEPTED:
        raise RuntimeError(f"entry onto the motion ({periods} periods, {nodes} intervals a period): IPOPT {status}")
    Xs, us = tr.unpack(np.asarray(sol["x"]).ravel())
    e2 = ((Xs[:, 1:, :2] - Cd) ** 2).sum(-1)
    q = run_held_inputs(body, state_from_config(x0[:3], x0[3:]), us[:, 0], us[:, 1], h)[0]   # what the model does
    z1, dz1 = config_from_state(q)
    end = np.concatenate([z1, dz1]) - np.array([0, 0, lap + 2 * np.pi * motion.turns * periods, 0, 0, 0])
    gap = np.abs(end - np.concatenate(motion.state(0.0)))
    return Entry(F=us[:, 0], beta=us[:, 1], rms_error=float(np.sqrt(max((e2 @ tab.B).mean(), 0.0))),
                 max_error=float(np.sqrt(e2.max())), end=end, periods=periods, nodes=nodes,
                 path=np.c_[t_col.ravel(), Xs[..., :2].reshape(-1, 2)],
                 end_gap={"position": float(np.hypot(gap[0], gap[1])), "heading": float(gap[2]),
                          "velocity": float(np.hypot(gap[3], gap[4])), "rate": float(gap[5])})
