"""One verdict for both laws: the full six-state closed loop (2)-(4), (23) under any
allocation (weights (w_x, w_y, w_phi); w_phi = 0 is exactly the paper's law (25)-(26)),
classified by the book's one decision procedure (:mod:`lib.dynamics.verdicts`), as
Chapter 5 classifies the reduced rotation (32). Chapter 6 uses it for both laws.

This module supplies the period map (``_PeriodFlow``: all points in lockstep by
the batch RK4 in the normalised time tau = t / T) and what the closed loop reports
beyond the verdict: the position's drift and whether it is held.

The procedure of :func:`closed_loop_verdicts`. All points run together by the batch RK4
(:mod:`lib.integrators.batch`) in tau = t / T (``steps`` per reference period T = 2 pi / |Theta|,
128), so that the stroboscopic section of each point, its error state e = s - s_d (x, y, p, and
rates; p = phi - phi_d unwrapped) at t = j T, falls on a step (:data:`LOOP_VERDICT_DEFAULTS`):

1. ``transient`` periods (32), then ``periods`` (72) more with a companion trajectory
   (Benettin: started ``d0`` away, renormalised every period): the largest Lyapunov
   exponent lambda T per period, with its standard error from the means of blocks of
   ``block`` (12) periods; the drift of p (turns per period) and of the mean position
   error (m per period), each with its batch-means standard error; ranges and RMS values.
2. Periodic orbit: where the last two section states repeat within ``candidate_tol`` at a
   lag k <= ``max_period`` (8), up to n whole turns of p, Newton on P^k(e) = e + 2 pi n e_p
   with a forward-difference Jacobian (residual <= ``newton_tol``); the orbit attracts when
   every Floquet multiplier (eigenvalue of DP^k) lies inside the unit circle, and is reached
   when the last section state is within ``reach_tol`` of one of its k points and has closed
   in over the last periods no slower than the slowest multiplier allows. Verdict
   ``periodic`` (n = 0) or ``slipping`` (n != 0). Whole turns are allowed only where
   w_phi = 0: there the loop does not see p beyond phi modulo 2 pi; with w_phi > 0, (23)
   demands a torque from the unwrapped p, so a state a whole turn on is a different state.
3. Otherwise, as in Chapter 5: ``chaotic`` when lambda T > max(3 SE, ``lyapunov_band``);
   ``quasiperiodic`` when |lambda T| <= band, SE <= band / 3 and the (p, dp/dt) section
   closes on itself (:func:`lib.dynamics.verdicts.section_returns` <= ``return_tol``);
   else ``undecided`` with a reason.

``lost`` (the heading, :func:`lib.dynamics.verdicts.heading_lost`): slipping, or no orbit
and |drift of p| > 3 SE + ``slip_band`` (1e-3 turns per period); ``turns_round`` the other
reading (range of p above 2 pi: over the last block on an orbit, over the observed periods
otherwise). ``position_lost``: no orbit and either the mean position error grows by more
than 3 SE + ``position_band`` (1e-3 m per period) or, over the last block, the body is
farther from its reference point than the radius R of the path itself; or the state became
non-finite. ``tracked``: the position is not lost and its largest error over the last block
is at most ``position_tol`` R (0.1 R: the body stays on the path it is asked to follow).

Units: R in m, Theta in rad/s, angles in rad, times in s; drifts per reference period.
"""

from __future__ import annotations

from types import MappingProxyType

import numpy as np
import pandas as pd

from ..machinery import checks
from ..allocation import Allocation, Limits
from ..angles import wrap_angle
from ..closed_loop import ClosedLoop, _lean_rows
from ..dynamics import verdicts as dv
from ..integrators import batch
from ..machinery.parallel import concat_frames, map_chunks
from ..params import Body, Gains
from ..trajectories import KINEMATICS

__all__ = ["LOOP_VERDICT_DEFAULTS", "closed_loop_verdicts"]


def _points(R, Theta, weights):
    R = np.atleast_1d(checks.array("R", R, positive=True))
    Theta = np.atleast_1d(checks.array("Theta", Theta))
    w = checks.array("weights", weights, nonnegative=True)
    if w.ndim == 0 or not np.all(np.any(w > 0, axis=-1)):
        raise ValueError(f"weights (w_x, w_y, w_phi) must be non-negative and not all zero, got {weights!r}")
    if w.shape[-1] != 3:
        raise ValueError(f"weights must be (w_x, w_y, w_phi): 3 numbers or an (N, 3) array, got shape {w.shape}")
    if w.ndim == 1:
        w = np.broadcast_to(w, (max(R.size, Theta.size), 3))
    if R.ndim != 1 or Theta.ndim != 1 or w.ndim != 2 or w.shape[1] != 3:
        raise ValueError("R and Theta must be 1-D arrays and weights (3,) or (N, 3)")
    if R.size == 0 or Theta.size == 0 or w.shape[0] == 0:
        raise ValueError("no parameter points given (empty arrays)")
    n = max(R.size, Theta.size, w.shape[0])
    try:
        R, Theta, w = np.broadcast_to(R, n), np.broadcast_to(Theta, n), np.broadcast_to(w, (n, 3))
    except ValueError:
        raise ValueError(f"R ({R.size}), Theta ({Theta.size}) and weights ({w.shape[0]}) must have equal "
                         "lengths (or length 1)") from None
    if not np.all(Theta != 0):
        raise ValueError(f"Theta[{int(np.flatnonzero(Theta == 0)[0])}] must be non-zero (rad/s)")
    return R, Theta, w


def _check_loop(body, gains, kind, allocation, limits) -> Limits:
    if kind not in KINEMATICS:
        raise ValueError(f"kind must be one of {sorted(KINEMATICS)} (the trajectory), got {kind!r}")
    checks.instance("body", body, Body)
    checks.instance("gains", gains, Gains)
    if allocation not in ("least_squares", "limited"):
        raise ValueError(f"allocation must be 'least_squares' (limits by projection) or 'limited' (the exact "
                         f"optimum under the limits), got {allocation!r}")
    return Limits() if limits is None else checks.instance("limits", limits, Limits)


#: the default options of :func:`closed_loop_verdicts` (read-only), for the book to quote
LOOP_VERDICT_DEFAULTS = MappingProxyType(dict(
    steps=128, transient=32, periods=72, block=12, max_period=8, candidate_tol=0.05, newton_tol=1e-8,
    newton_iter=6, fd_step=1e-6, reach_tol=0.05, reach_floor=1e-9, lyapunov_band=0.01, slip_band=1e-3,
    position_band=1e-3, position_tol=0.1, return_tol=0.05, d0=1e-7))


def _lean(allocation, limits, w) -> bool:
    """Whether ``_PeriodFlow`` runs its lean field: the least-squares law without limits
    and w_x w_y > 0 at every point of the call."""
    return allocation == "least_squares" and limits.force is None and limits.angle is None \
        and bool(np.all(w[:, 0] * w[:, 1] > 0))


class _PeriodFlow:
    """The closed loop of N points in the normalised time tau = t / T_i (T_i = 2 pi / |Theta_i|
    the reference period), all points in lockstep: ``n`` classical RK4 steps per period, so
    the stroboscopic section of every point falls on whole tau.

    The RK4 stages fall on the 2n phases tau = m / (2n) (mod 1), so the reference (z_d, dz_d,
    ddz_d) is tabulated there once per point (the heading advanced by its winding per period).
    Without limits, the field of the weighted allocation is evaluated in a lean form
    (:meth:`field`): (23), the normal equations of :func:`lib.allocation.allocate_least_squares`
    solved in closed form, and (2)-(4) with Q = B(phi) u, without passing through (F, beta);
    the tests check it against :meth:`lib.closed_loop.ClosedLoop.rates` at random states. With
    limits, or with w_x w_y = 0, the loop runs through :class:`ClosedLoop` itself."""

    #: the heading's column in the error state (x, y, p, and rates): a :class:`lib.dynamics.verdicts.PeriodMap`
    turn_axis = 2

    def __init__(self, body, gains, kinds, R, Theta, w, allocation, limits, n, lean=None):
        self.body, self.gains, self.kinds, self.n = body, gains, kinds, n
        self.R, self.Theta, self.w, self.allocation, self.limits = R, Theta, w, allocation, limits
        self.T = 2 * np.pi / np.abs(Theta)
        frac = np.arange(2 * n + 1) / (2 * n)
        table = np.empty((R.size, 2 * n + 1, 9))
        for kind in np.unique(kinds):
            r = kinds == kind
            z, dz, ddz = KINEMATICS[kind](R[r, None], Theta[r, None], frac[None, :] * self.T[r, None])
            table[r] = np.concatenate([z, dz, ddz], axis=-1)
        self.table = np.ascontiguousarray(table[:, :-1].transpose(1, 2, 0))     # (2n, 9, N): phase, component, point
        self.wind = table[:, -1, 2] - table[:, 0, 2]                            # heading advance per period (rad)
        # ``lean`` given: decided once for all points of a call, so that a chunk of them
        # (:func:`lib.machinery.parallel.map_chunks`) runs the same field as the whole call
        self.lean = _lean(allocation, limits, w) if lean is None else bool(lean)

    def kin(self, idx):
        """The kinematics t -> (z_d, dz_d, ddz_d) of the rows ``idx`` (t (M,) in s)."""
        R, Th, kinds = self.R[idx], self.Theta[idx], self.kinds[idx]
        groups = [(kinds == k, KINEMATICS[k]) for k in np.unique(kinds)]

        def kinematics(t):
            t = np.broadcast_to(t, R.shape)
            out = [np.empty(R.shape + (3,)) for _ in range(3)]
            for r, kin in groups:
                for o, v in zip(out, kin(R[r], Th[r], t[r])):
                    o[r] = v
            return tuple(out)
        return kinematics

    def reference(self, idx, tau):
        """s_d = (z_d, dz_d) (M, 6) of the rows ``idx`` at a section, whole tau (one, or (M,))."""
        tau = np.broadcast_to(np.asarray(tau, dtype=float), (len(idx),))
        turns = np.round(tau)
        if np.any(np.abs(tau - turns) > 1e-9):
            raise ValueError("sections fall on whole tau")
        ref = self.table[0, :6, idx]
        ref[:, 2] += turns * self.wind[idx]
        return ref

    def _phase(self, tau: float) -> tuple[int, int]:
        """(whole periods, stage phase index m) of tau = whole + m / (2n)."""
        m = tau * 2 * self.n
        mi = int(round(m))
        if abs(m - mi) > 1e-6:
            raise ValueError(f"tau = {tau!r} is not a stage phase of the {self.n}-step grid")
        return divmod(mi, 2 * self.n)

    def _lookup(self, idx, tau: float):
        turns, mi = self._phase(tau)
        ref = self.table[mi, :, idx]
        ref[:, 2] += turns * self.wind[idx]
        return ref

    def field(self, idx, tau: float, y):
        """dy/dtau of the rows ``idx`` (lean form, no limits): T (dz, ddz) at t = tau T."""
        return self._field(idx)(tau, y)

    def _field(self, idx):
        """The lean field of the rows ``idx`` as a function (tau, y), with everything that does not
        change along the run gathered once; compiled (``lib.closed_loop._lean_rows``)."""
        b, g = self.body, self.gains
        T = np.ascontiguousarray(self.T[idx])
        table, wind = np.ascontiguousarray(self.table[:, :, idx]), np.ascontiguousarray(self.wind[idx])  # (2n, 9, M)
        wx, wy, wp = (np.ascontiguousarray(c) for c in self.w[idx].T)
        w = np.stack([wx, wy, wp * b.a, wp * b.a * b.a])
        k = np.r_[g.kp, g.kv].astype(float)
        bv = np.array([b.m, b.I, b.c, b.c_phi, b.a])
        Tm, TI = T / b.m, T / b.I

        def f(tau, y):
            turns, mi = self._phase(tau)
            out = np.empty((T.size, 6))
            _lean_rows(table[mi], turns, wind, np.ascontiguousarray(y, dtype=float), T, Tm, TI, w, k, bv, out)
            return out
        return f

    def rates(self, idx):
        if self.lean:
            return self._field(idx)
        T = self.T[idx]
        loop = ClosedLoop.of(self.body, self.gains, self.kin(idx), Allocation(self.allocation, self.w[idx]),
                             self.limits)
        return lambda tau, y: T[:, None] * loop.rates(tau * T, y)[0]

    def periods(self, idx, y, tau0: float, k: int):
        """Integrate the rows ``idx`` from state y (M, 6) at tau0 over k periods; returns the
        states at the k section times (k, M, 6)."""
        f, h = self.rates(idx), 1.0 / self.n
        out = np.empty((k,) + y.shape)
        with np.errstate(all="ignore"):
            for q in range(k):
                for _, y in batch.steps(f, y, tau0 + q, h, self.n, batch.RK4):
                    pass
                out[q] = y
        return out

    def error_map(self, idx, e, k):
        """P^k in error coordinates: from e = s - s_d at a section, the error state k periods
        later; k an integer or one per row (each row leaves the batch at its own k)."""
        k = np.broadcast_to(np.asarray(k, dtype=int), (len(idx),))
        idx = np.asarray(idx)
        y = e + self.reference(idx, 0.0)
        out = np.empty_like(y)
        act = np.arange(len(idx))
        for q in range(int(k.max())):
            y[act] = self.periods(idx[act], y[act], 0.0, 1)[-1] if q == 0 else \
                self.periods(idx[act], y[act], float(q), 1)[-1]
            done = k[act] == q + 1
            out[act[done]] = y[act[done]]
            act = act[~done]
        return out - self.reference(idx, k.astype(float))

    advance = error_map


def _loop_options(options: dict) -> dict:
    o = checks.options(options, LOOP_VERDICT_DEFAULTS, dict(steps=16, transient=1, periods=24, block=2, max_period=1,
                                                            newton_iter=1))
    if o["periods"] // o["block"] < 3:
        raise ValueError(f"periods ({o['periods']}) must hold at least 3 blocks of {o['block']} periods")
    return o


def closed_loop_verdicts(body: Body, gains: Gains, kind: str, R, Theta, weights=(1.0, 1.0, 0.0), *,
                         z0=None, dz0=None, allocation: str = "least_squares", limits: Limits | None = None,
                         executor=None, chunk_size: int | None = None, progress: bool | None = None,
                         **options) -> pd.DataFrame:
    """The verdict of Chapter 5 (:data:`lib.dynamics.verdicts.REGIMES`, and ``lost``) for the full
    six-state closed loop (2)-(4), (23) with the weighted allocation (weights (w_x, w_y, w_phi) per
    point; w_phi = 0 is exactly the paper's law (25)-(26)), on ``kind`` ("eight" (28) or "circle"
    (27)) at the points (R_i (m), Theta_i (rad/s)), from z0, dz0 ((3,) or (N, 3); default: on the
    reference), for any weights: one criterion for both laws, by the procedure of the module's
    docstring (:mod:`lib.weighting.verdicts`: the run, the orbit, the exponent, ``lost``,
    ``position_lost`` and ``tracked``).

    Before any run, the points are checked against the sweep's domain
    (:func:`lib.machinery.domain.loop_domain`) and against the option ``steps``: a point whose
    error dynamics (23)-(24) turn faster than ``steps`` RK4 steps a period can follow is refused,
    naming the gains (or Theta, where a slow rate sets the cost), as :func:`lib.simulate.simulate`
    refuses them, rather than reported as a run that diverged.

    Scale-out: with an ``executor`` (any :class:`concurrent.futures.Executor`) the points go to
    it in consecutive chunks of ``chunk_size`` (default: two chunks per worker; without an
    executor, ``chunk_size`` runs the chunks here one after another), by
    :func:`lib.machinery.parallel.map_chunks`. The field (lean or through :class:`ClosedLoop`) is
    chosen once for all points of the call and every point is decided on its own, so the frame is
    the one of the single call. ``progress``: a bar over the points on stderr
    (:func:`lib.machinery.parallel.show_progress`; default None: only when run interactively).

    Parameters
    ----------
    body : Body
        The plant (and the controller's model).
    gains : Gains
        The gains of (23).
    kind : str or array_like
        ``"eight"`` (28) or ``"circle"`` (27), or one per point.
    R : float or array_like
        Radii (m), > 0.
    Theta : float or array_like
        Rates (rad/s), non-zero.
    weights : array_like
        (w_x, w_y, w_phi) >= 0, not all zero, (3,) or (N, 3); zero weights are allowed
        (w_x w_y = 0 runs through :class:`lib.closed_loop.ClosedLoop`).
    z0, dz0 : array_like, optional
        Start configuration (m, m, rad) and rates (m/s, m/s, rad/s), (3,) or (N, 3);
        default on the reference.
    allocation : str
        ``"least_squares"`` (limits by projection) or ``"limited"`` (exact under limits).
    limits : Limits, optional
        Force and angle limits (default none).
    executor : concurrent.futures.Executor, optional
        Where the chunks of points run (a process pool, a dask ``Client.get_executor()``).
    chunk_size : int, optional
        Points per chunk (default: two chunks per worker with an executor, else all).
    progress : bool, optional
        A progress bar on stderr (default None: only when run interactively).
    **options
        The procedure's options, :data:`LOOP_VERDICT_DEFAULTS`.

    Returns
    -------
    pandas.DataFrame
        One row per point: R, Theta, w_phi, regime, period, floquet (largest
        multiplier modulus), lyapunov, lyapunov_stderr (1/s; for an orbit ln|mu_1| / (k T)),
        slip, slip_stderr (turns per period), lost, pos_drift, pos_drift_stderr (m per period),
        position_lost, tracked, residual, distance, turns_round, p_range (rad, over the last block),
        p_rms (rad, RMS of p wrapped to (-pi, pi], last block), pos_rms, pos_max (m, last block;
        NaN where the run diverged), periods, reason.
    """
    kinds, R, Theta, w, limits, o = _checked_points(body, gains, kind, R, Theta, weights, allocation, limits, options)
    starts = [_start_array(name, v, R.size) for name, v in (("z0", z0), ("dz0", dz0))]
    parts = map_chunks(_verdict_chunk, R.size, (kinds, R, Theta, w, *starts),
                       dict(body=body, gains=gains, allocation=allocation, limits=limits, o=o,
                            lean=_lean(allocation, limits, w)), executor, chunk_size, progress)
    return concat_frames(parts)


def _checked_points(body, gains, kind, R, Theta, weights, allocation, limits, options):
    """The arguments of :func:`closed_loop_verdicts` checked, and the points inside the domain, before
    any run: (kinds, R, Theta, weights (N, 3), limits, options)."""
    kinds = np.atleast_1d(np.asarray(kind, dtype=object))
    if kinds.ndim != 1 or kinds.size == 0:
        raise ValueError(f"kind must be 'circle', 'eight' or a 1-D array of them, got {kind!r}")
    for k in set(kinds.tolist()):
        limits = _check_loop(body, gains, k, allocation, limits)
    R, Theta, w = _points(R, Theta, weights)
    try:
        kinds = np.broadcast_to(kinds, R.shape)
    except ValueError:
        raise ValueError(f"kind has {kinds.size} entries for {R.size} points") from None
    o = _loop_options(options)
    for k in set(kinds.tolist()):                 # the domain before any run (issue 37)
        checks.loop_domain(body, gains, KINEMATICS[k], R[kinds == k], Theta[kinds == k],
                           heading_gains=bool(np.any(w[:, 2] > 0)))
    _check_steps(body, gains, R, Theta, o["steps"])
    return kinds, R, Theta, np.ascontiguousarray(w), limits, o


def _check_steps(body, gains, R, Theta, steps: int) -> None:
    """Refuse a point whose error dynamics on the position, M e'' + (Kv + N) e' + Kp e = 0 of
    (23)-(24) (:func:`lib.machinery.domain.loop_modes`), turn faster than ``steps`` RK4 steps a
    reference period follow, h |lambda| <= :data:`lib.machinery.domain.RK4_REACH`: there the run
    diverges. Names the gains, or Theta where a slow rate sets the cost
    (:func:`lib.machinery.domain.rate_culprit`), and the steps that every point needs (inside the
    domain, at most :data:`lib.machinery.domain.MAX_STEPS`)."""
    mode = checks.loop_modes(body, gains, heading_gains=False)["body and gains"]
    need = 2 * np.pi / np.abs(Theta) * abs(mode) / checks.RK4_REACH
    on_theta = checks.rate_culprit(body, Theta, mode)
    checks.within_budget({"gains": np.where(on_theta, 0, need), "Theta": np.where(on_theta, need, 0)}, steps,
                         what="a period would need", unit=f"RK4 steps (the error dynamics' fastest rate, about "
                         f"{abs(mode):.3g} 1/s, at h |lambda| <= {checks.RK4_REACH:g})",
                         values={"Theta": (Theta, "rad/s")},
                         fix=f"raise the option steps to {int(np.ceil(need.max()))} (steps={steps} given)")


def _start_array(name: str, v, N: int):
    """A start ``z0`` or ``dz0`` checked, (N, 3), or None."""
    if v is None:
        return None
    v = checks.array(name, v)
    try:
        return np.broadcast_to(v, (N, 3))
    except ValueError:
        raise ValueError(f"{name} must have shape (3,) or ({N}, 3), got {np.shape(v)}") from None


def _verdict_chunk(kinds, R, Theta, w, z0, dz0, *, body, gains, allocation, limits, o, lean) -> pd.DataFrame:
    """The frame of :func:`closed_loop_verdicts` for validated points (one chunk of them),
    on the field ``lean`` chosen for the whole call."""
    flow = _PeriodFlow(body, gains, kinds, R, Theta, w, allocation, limits, o["steps"], lean=lean)
    obs = _observe(flow, _start(flow, z0, dz0), o)
    out = _decide(flow, obs, w[:, 2] == 0, o)
    acc = obs["acc"]
    cnt = acc["cnt"][-1]
    # a run that diverged has no steady measures: NaN, not what the NaN-skipping sums left
    steady = {"p_range": acc["lmax"] - acc["lmin"], "p_rms": np.sqrt(acc["p2"] / cnt),
              "pos_rms": np.sqrt(acc["pos2"] / cnt), "pos_max": acc["posmax"]}
    steady = {k: np.where(obs["finite"], v, np.nan) for k, v in steady.items()}
    return pd.DataFrame({"kind": kinds, "R": R, "Theta": Theta, "w_phi": w[:, 2], **out, **steady,
                         "periods": int(obs["t_end"]), "steps": o["steps"]})


def _start(flow: _PeriodFlow, z0, dz0) -> np.ndarray:
    """The initial states (N, 6): on the reference, or z0, dz0 ((N, 3), checked by :func:`_start_array`)."""
    s0 = flow.reference(np.arange(flow.R.size), 0.0)
    for v, sl in ((z0, slice(0, 3)), (dz0, slice(3, 6))):
        if v is not None:
            s0[:, sl] = v
    return s0


def _observe(flow: _PeriodFlow, s0, o) -> dict:
    """``transient`` periods, then ``periods`` more with a Benettin companion (started ``d0``
    away, renormalised every period). Returns the section's error states ``hist`` (L + 1, N,
    6), the companion's log growth per period ``logs`` (N, L), the accumulated ranges and
    position errors ``acc``, which runs stayed ``finite``, and ``t_end`` (periods)."""
    N, n, Bk = flow.R.size, o["steps"], o["block"]
    nb = o["periods"] // Bk
    L = nb * Bk
    idx = np.arange(N)
    y = flow.periods(idx, s0, 0.0, o["transient"])[-1]
    tau0 = float(o["transient"])
    Y = np.concatenate([y, y + o["d0"] * np.ones(6) / np.sqrt(6.0)])
    both = np.concatenate([idx, idx])
    hist = np.empty((L + 1, N, 6))
    hist[0] = y - flow.reference(idx, tau0)
    logs = np.full((N, L), np.nan)
    acc = dict(pmin=np.full(N, np.inf), pmax=np.full(N, -np.inf), lmin=np.full(N, np.inf), lmax=np.full(N, -np.inf),
               pos=np.zeros((N, nb)), pos2=np.zeros(N), posmax=np.zeros(N), p2=np.zeros(N), cnt=np.zeros(nb))
    f, h = flow.rates(both), 1.0 / n
    for q in range(L):
        b = q // Bk
        with np.errstate(all="ignore"):
            for tq, Yq in batch.steps(f, Y, tau0 + q, h, n, batch.RK4):
                _accumulate(acc, flow._lookup(idx, tq), Yq[:N], b, last=b == nb - 1)
            Y = Yq
            d = Y[N:] - Y[:N]
            dn = np.sqrt((d * d).sum(axis=1))
            logs[:, q] = np.log(dn / o["d0"])
            Y = np.concatenate([Y[:N], Y[:N] + d * (o["d0"] / np.where(dn > 0, dn, 1.0))[:, None]])
        hist[q + 1] = Y[:N] - flow.reference(idx, tau0 + q + 1)
    finite = np.all(np.isfinite(hist[-1]), axis=1) & np.all(np.isfinite(logs), axis=1)
    return dict(hist=hist, logs=logs, acc=acc, finite=finite, t_end=tau0 + L)


def _accumulate(acc: dict, zd, Y, b: int, last: bool) -> None:
    """At one step end: the range of p, the position error's block sum, and over the last
    block its RMS values and maximum."""
    p = Y[:, 2] - zd[:, 2]
    e = np.hypot(Y[:, 0] - zd[:, 0], Y[:, 1] - zd[:, 1])
    acc["pmin"], acc["pmax"] = np.fmin(acc["pmin"], p), np.fmax(acc["pmax"], p)
    acc["pos"][:, b] += e
    acc["cnt"][b] += 1
    if last:
        acc["lmin"], acc["lmax"] = np.fmin(acc["lmin"], p), np.fmax(acc["lmax"], p)
        acc["pos2"] += e * e
        acc["p2"] += wrap_angle(p) ** 2
        acc["posmax"] = np.fmax(acc["posmax"], e)


def _decide(flow: _PeriodFlow, obs: dict, turns, o) -> dict:
    """The verdict columns from an observed run, by :mod:`lib.dynamics.verdicts`: the orbit
    reached (Newton with a difference Jacobian), else the rule on the exponent; the heading's
    and the position's drift, and whether each is lost."""
    hist, logs, acc, finite = obs["hist"], obs["logs"], obs["acc"], obs["finite"]
    N, Bk, T = hist.shape[1], o["block"], flow.T
    out = dict(regime=np.full(N, "undecided", dtype=object), period=np.zeros(N, int), floquet=np.full(N, np.nan),
               lyapunov=np.full(N, np.nan), lyapunov_stderr=np.full(N, np.nan), slip=np.full(N, np.nan),
               slip_stderr=np.full(N, np.nan), lost=np.zeros(N, bool), pos_drift=np.full(N, np.nan),
               pos_drift_stderr=np.full(N, np.nan), position_lost=np.zeros(N, bool), residual=np.full(N, np.nan),
               distance=np.full(N, np.nan), reason=np.full(N, "", dtype=object))
    good = np.flatnonzero(finite)
    orb = dv.find_orbits(lambda i, x, k: dv.difference_jacobian(flow, i, x, k, o["fd_step"]), flow, good,
                         hist[:, good], max_period=o["max_period"], candidate_tol=o["candidate_tol"],
                         newton_tol=o["newton_tol"], reach_tol=o["reach_tol"], reach_floor=o["reach_floor"],
                         newton_options=dict(max_iter=o["newton_iter"], stall_after=2), turns=turns[good])
    f = orb["found"]
    g, k, nn = good[f], orb["k"][f], orb["n"][f]
    rho = orb["rho"][f]
    out["regime"][g], out["period"][g] = dv.orbit_regime(nn), k
    out["slip"][g], out["slip_stderr"][g], out["lost"][g] = nn / k, 0.0, nn != 0
    out["floquet"][g], out["lyapunov"][g] = rho, np.log(rho) / (k * T[g])
    out["residual"][g], out["distance"][g] = orb["residual"][f], orb["distance"][f]

    lam, se = dv.block_statistics(logs, Bk)
    drift, dse = dv.heading_drift(hist[::Bk, :, 2].T, Bk)
    pdrift, pse = dv.drift_statistics(acc["pos"] / acc["cnt"], Bk)
    out["pos_drift"], out["pos_drift_stderr"] = pdrift, pse
    orbit = np.zeros(N, bool)
    orbit[g] = True
    rest = finite & ~orbit
    returns = dv.section_returns(np.where(finite[None, :, None], hist[:, :, [2, 5]], 0.0))
    regime, reason = dv.classify(lam, se, returns, band=o["lyapunov_band"], return_tol=o["return_tol"],
                                 max_period=o["max_period"])
    out["regime"][rest], out["reason"][rest] = regime[rest], reason[rest]
    out["lyapunov"][rest], out["lyapunov_stderr"][rest] = lam[rest] / T[rest], se[rest] / T[rest]
    out["slip"][rest], out["slip_stderr"][rest] = drift[rest], dse[rest]
    out["lost"][rest] = dv.heading_lost(False, 0, drift, dse, slip_band=o["slip_band"])[rest]
    # the other reading: over the orbit (the last block) where there is one, over the run otherwise
    out["turns_round"] = dv.turns_round(np.where(orbit, acc["lmax"] - acc["lmin"], acc["pmax"] - acc["pmin"]))
    out["position_lost"][rest] = ((pdrift > dv.SIGMAS * pse + o["position_band"]) | (acc["posmax"] > flow.R))[rest]
    bad = ~finite
    out["reason"][bad] = "the state became non-finite (the run diverged)"
    out["lost"][bad] = out["position_lost"][bad] = True
    out["tracked"] = ~out["position_lost"] & (acc["posmax"] <= o["position_tol"] * flow.R)
    return out
