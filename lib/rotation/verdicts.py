"""Decisive verdicts on the heading of the reduced rotation equation (32) over many
(R, Theta) points at once (paper Sec. 6, Fig. 5): each point is periodic, slipping,
chaotic, quasi-periodic or undecided, decided by the book's one decision procedure
(:mod:`lib.dynamics.verdicts`), not waited for.

This module holds the schedule that makes the Fig. 5 map take seconds: points run
together on the compiled period map (:mod:`lib.rotation.engine`) and leave as soon as
they are decided, Newton tried on the way during a short transient and again during
the Lyapunov run. The one-point view (the attracting orbit a start reaches) and the
map's summary are in :mod:`lib.rotation.attractor`; the book's Fig. 5 map, its verdicts
decided again where the last bits may decide them (transient chaos), is in
:mod:`lib.rotation.fig5`.

Units: R in m, Theta in rad/s, angles in rad, the phase s in rad; w = d phi / ds.

The schedule of :func:`rotation_verdicts`, with its options' defaults (:data:`VERDICT_DEFAULTS`):

1. Transient: ``transient`` periods (48) in chunks of ``chunk`` (8). From
   ``min_transient`` (8) periods on, after every chunk, a point whose last section
   states (at s = 0 mod 2 pi) repeat within ``candidate_tol`` (rad) at some lag
   k <= ``max_period`` (8), up to n whole turns of p, is handed to Newton on
   P^k(x) - x - (2 pi (n + winding k), 0) (P the period map, its Jacobian exact).
   It is decided when Newton converges (residual <= ``newton_tol`` rad), all
   Floquet multipliers (eigenvalues of DP^k) lie inside the unit circle, and the
   run *reaches this orbit*: its state is within ``reach_tol`` (rad, phi modulo
   2 pi) of one of the orbit's k points and the distance has shrunk over the
   last periods, no slower than the slowest multiplier allows (or is below
   ``reach_floor``). Verdict ``periodic`` (n = 0) or ``slipping`` (n != 0).
2. Otherwise the largest Lyapunov exponent: a tangent vector carried by the exact
   Jacobian, renormalised every period, over up to ``lyapunov_periods`` (300)
   periods; lambda (1/s) is the mean log growth per period divided by the period
   2 pi / Theta, its standard error from the means of blocks of ``block`` (12)
   periods (batch means, so that correlated periods do not shrink it; a long run merges
   them into batches of up to 48 periods, at least 6 of them, as the drift's,
   :func:`lib.dynamics.statistics.long_run_means`). After every block from
   ``min_lyapunov_periods`` (72) on, a point that is not clearly
   expanding is handed to Newton again, and a clearly chaotic one (lambda T above
   the band and 5 standard errors) stops. If its heading has moved a whole turn, it
   then runs on without its tangent vector, for its drift alone, to ``drift_periods``
   (300) periods of Lyapunov run (0: no further), so that the drift's error has
   batches long against the heading's slips, 48 periods
   (:func:`lib.dynamics.statistics.drift_statistics`); its regime, exponent and range
   are those decided when it stopped.
   At the end: ``chaotic`` when lambda T > max(3 SE, ``lyapunov_band``) (T the
   period, so the band is per period, 0.01); ``quasiperiodic`` when |lambda T| <=
   band, its SE <= band / 3, and the section closes on itself: the run comes back
   near its earlier section states (:func:`section_returns` <= ``return_tol``,
   0.05), as it does on a closed invariant curve; else ``undecided`` (with a reason).
"""

from __future__ import annotations

from types import MappingProxyType

import numpy as np
import pandas as pd

from ..machinery import checks
from ..angles import wrap_angle
from ..dynamics import verdicts as dv
from ..dynamics.statistics import long_run_means
from ..machinery.parallel import concat_frames, map_chunks
from ..params import Body
from .reduced import ENGINES, check_grid, _initial
from .engine import _NEWTON, RotationMap, _Engine, _on_fine_map, check_domain, verdict_steps
from .field import coefficients

__all__ = ["REGIMES", "VERDICT_DEFAULTS", "SLOW_FLOQUET", "verdict_steps", "section_returns", "rotation_verdicts",
           "eight_rotation_sweep", "FIG5_GRID"]

#: the verdicts of :func:`rotation_verdicts` (defined in :mod:`lib.dynamics.verdicts`)
REGIMES = dv.REGIMES
section_returns = dv.section_returns


def eight_rotation_sweep(body: Body, R, Theta, **options) -> pd.DataFrame:
    """Fig. 5: the verdict on the rotation error on the eight (28) and its steady-state
    range, started on the reference, for each pair (R_i (m), Theta_i (rad/s)), decided by
    :func:`rotation_verdicts` (see there for the options, the columns and ``executor``).

    Parameters
    ----------
    body : Body
        The body.
    R : array_like
        Radii R_i (m), > 0, 1-D.
    Theta : array_like
        Rates Theta_i (rad/s), > 0, as long as ``R``.
    **options
        Keywords of :func:`rotation_verdicts`.

    Returns
    -------
    pandas.DataFrame
        One row per point, the columns of :func:`rotation_verdicts`.
    """
    return rotation_verdicts(body, "eight", R, Theta, **options)


#: The book's Fig. 5 grid (:func:`lib.rotation.fig5.fig5_map`) of n x n points, R evenly in ``R`` (m) and Theta evenly in ``Theta`` (rad/s).
FIG5_GRID = MappingProxyType(dict(R=(0.25, 4.0), Theta=(0.05, 1.5), n=100))


def _check_body_kind(body, kind):
    checks.one_of("kind", kind, ("eight", "circle"))
    checks.instance("body", body, Body)


_DEFAULTS = dict(transient=48, min_transient=8, chunk=8, max_period=8, lyapunov_periods=300, block=12,
                 min_lyapunov_periods=72, drift_periods=300,
                 newton_tol=1e-10, candidate_tol=0.05, reach_tol=0.05, reach_floor=1e-9,
                 lyapunov_band=0.01, slip_band=1e-3, h_verdict=0.25, return_tol=0.05)


#: the default options of :func:`rotation_verdicts` (read-only), for the book to quote
VERDICT_DEFAULTS = MappingProxyType(_DEFAULTS)

#: a Floquet modulus above this counts as a slowly attracting orbit in :class:`lib.rotation.attractor.MapSummary`
SLOW_FLOQUET = 0.9


def _verdict_options(options: dict) -> dict:
    o = checks.options(options, _DEFAULTS, dict(transient=1, min_transient=1, chunk=1, lyapunov_periods=0,
                                                min_lyapunov_periods=0, max_period=1, block=2, drift_periods=0),
                       extra=("max_periods",))
    mp = options.get("max_periods")
    if mp is not None:  # a total budget of periods per point: the transient first
        mp = checks.integer("max_periods", mp, minimum=2)
        o["transient"] = min(o["transient"], mp)
        o["min_transient"] = min(o["min_transient"], o["transient"])
        o["lyapunov_periods"] = min(o["lyapunov_periods"], mp - o["transient"])
    o["min_transient"] = min(o["min_transient"], o["transient"])
    o["drift_periods"] = min(o["drift_periods"], o["lyapunov_periods"])
    return o


def rotation_verdicts(body: Body, kind: str, R, Theta, *, p0=0.0, v0=0.0, h_lambda: float = 0.125,
                      steps: int | None = None, engine: str = "numba", executor=None,
                      chunk_size: int | None = None, progress: bool | None = None, **options) -> pd.DataFrame:
    """Decisive verdict on the rotation error p = phi - phi_d of the reduced rotation
    equation (32) on the reference ``kind`` (``"eight"`` (28) or ``"circle"`` (27)) at each
    point (R_i (m), Theta_i (rad/s)), started on the reference with p(0) = ``p0`` (rad),
    dp/dt(0) = ``v0`` (rad/s) (scalars or arrays).

    All points run together in the phase s = Theta t by the compiled fixed-step
    8th-order Dormand-Prince flow with its exact Jacobian
    (:func:`lib.integrators.compiled.rotation_flow`; ``engine="numpy"`` runs the same
    scheme vectorised in numpy); points leave the arrays as soon as they are decided.
    Two step sizes (``steps`` fixes both): the verdict is decided on the *verdict map*,
    :func:`verdict_steps` with h omega <= ``h_verdict`` (0.25), and every orbit found is
    then located again by Newton on the *fine map*, h omega <= ``h_lambda`` (0.125),
    which gives its point, multipliers and range (the range to about 1e-7 rad; the
    verdict map alone is good to about 1e-5 rad, which the verdict does not need).

    The schedule, step by step, is the module's (:mod:`lib.rotation.verdicts`, "The schedule").

    ``max_periods`` (option) caps the periods integrated per point (transient first).

    Scale-out: with an ``executor`` (any :class:`concurrent.futures.Executor`, e.g.
    :func:`lib.machinery.parallel.process_pool` or a dask ``Client.get_executor()``) the points go to it
    in consecutive chunks of ``chunk_size`` (default: two chunks per worker) and the frames
    come back in order (:func:`lib.machinery.parallel.map_chunks`); every point is decided on its own,
    so the frame is the one of the single-process run. Without one, ``chunk_size`` runs the
    chunks one after another here (bounding the memory of a large map).
    ``progress``: a bar over the points on stderr (:func:`lib.machinery.parallel.show_progress`; default None: only when run
    interactively, never under pytest or in the book build).

    Parameters
    ----------
    body : Body
        The body (m, I_C, a, c, c_phi enter A, B, C of (32)).
    kind : str
        ``"eight"`` (28) or ``"circle"`` (27).
    R : array_like
        Radii R_i (m), > 0, 1-D.
    Theta : array_like
        Rates Theta_i (rad/s), > 0, 1-D, as long as ``R``.
    p0, v0 : float or array_like
        Start p(0) (rad) and dp/dt(0) (rad/s), one value or one per point.
    h_lambda : float
        Step bound of the fine map, h Lambda <= h_lambda (see above).
    steps : int, optional
        Steps per period of both maps (>= 8), instead of the bounds.
    engine : str
        ``"numba"`` (compiled, default) or ``"numpy"``.
    executor : concurrent.futures.Executor, optional
        Where the chunks of points run (a process pool, a dask ``Client.get_executor()``).
    chunk_size : int, optional
        Points per chunk (default: two chunks per worker with an executor, else all).
    progress : bool, optional
        A progress bar on stderr (default None: only when run interactively).
    **options
        The procedure's options, :data:`VERDICT_DEFAULTS` (and ``max_periods``).

    Returns
    -------
    pandas.DataFrame
        One row per point, in order: R (m), Theta (rad/s), regime;
        period (reference periods of the orbit, periodic/slipping; 0 otherwise); range (rad:
        max - min of p over the attracting orbit at every step (a slipping one over the k
        periods from its point at s = 0, where p runs on by 2 pi n), extremes refined by cubic
        Hermite interpolation (:func:`lib.dynamics.sampled.sampled_range`); over the Lyapunov run otherwise);
        floquet (largest multiplier modulus); lyapunov, lyapunov_stderr (1/s; for an orbit
        ln|mu_1| / (k T) with no error); slip, slip_stderr (turns of p per period: n / k on
        an orbit, the measured drift over the Lyapunov run, run on where the heading slipped,
        with its batch-means error otherwise); lost (bool, :func:`lib.dynamics.verdicts.heading_lost`):
        the heading slips whole turns against the reference: the verdict is ``slipping``, or no attracting orbit is
        reached and the drift differs from zero by more than 3 standard errors plus
        ``slip_band`` (1e-3 turns per period); turns_round (bool,
        :func:`lib.dynamics.verdicts.turns_round`): the other reading, range > 2 pi, whether or
        not the heading comes back; orbit_p (rad, p at s = 0 mod 2 pi at the orbit point the
        run is nearest to: which orbit is reached), distance (rad, from the run's last state to
        that point), residual (rad, Newton's), mirror (rad, on the eight: the distance from
        the orbit to its mirror image, 0 for a symmetric orbit; a positive one coexists with
        its mirror image, a second attractor), periods (integrated until the verdict),
        drift_periods (of Lyapunov run the drift is measured over; 0 on an orbit), steps (per
        period of the fine map), verdict_steps (of the verdict map), reason (why undecided).
    """
    _check_body_kind(body, kind)
    checks.one_of("engine", engine, sorted(ENGINES))
    R, Theta = check_grid(R, Theta)
    h_lambda = checks.number("h_lambda", h_lambda, positive=True)
    check_domain(body, kind, R, Theta, h_lambda)
    opts = _verdict_options(options)
    N = R.size
    p0, v0 = checks.array("p0", p0), checks.array("v0", v0)
    try:
        p0 = np.broadcast_to(p0, (N,)).copy()
        v0 = np.broadcast_to(v0, (N,)).copy()
    except ValueError as e:
        raise ValueError(f"p0 and v0 must be scalars or arrays of length {N}") from e
    n_pts, n_fine = _step_counts(body, kind, R, Theta, h_lambda, steps, opts)
    parts = map_chunks(_verdict_frame, N, (R, Theta, p0, v0, n_pts, n_fine),
                       dict(body=body, kind=kind, opts=opts, engine=engine), executor, chunk_size, progress)
    return concat_frames(parts)


def _verdict_frame(R, Theta, p0, v0, n_pts, n_fine, *, body, kind, opts, engine) -> pd.DataFrame:
    """The frame of :func:`rotation_verdicts` for validated points (one chunk of them)."""
    res = _verdict_core(body, kind, R, Theta, p0, v0, n_pts, opts, engine, n_fine)
    cols = {k: v for k, v in res.items() if k not in ("x", "mult", "slip_n")}
    cols["turns_round"] = dv.turns_round(res["range"])
    return pd.DataFrame({"R": R, "Theta": Theta, **cols, "steps": n_fine, "verdict_steps": n_pts})


def _step_counts(body, kind, R, Theta, h_lambda, steps, opts):
    """Steps per period of the verdict map (h omega <= ``h_verdict``) and of the fine map
    (h omega <= ``h_lambda``) on which orbits are located and measured; ``steps`` fixes both."""
    if steps is not None:
        n = np.full(R.size, checks.integer("steps", steps, minimum=8))
        return n, n
    n_fine = verdict_steps(body, kind, R, Theta, h_lambda)
    return np.minimum(verdict_steps(body, kind, R, Theta, opts["h_verdict"]), n_fine), n_fine


#: a clearly chaotic point leaves the Lyapunov run early, at this many standard errors
EARLY_SIGMAS = 5.0


def _new_out(N: int) -> dict:
    return dict(regime=np.full(N, "undecided", dtype=object), period=np.zeros(N, int), range=np.full(N, np.nan),
                floquet=np.full(N, np.nan), lyapunov=np.full(N, np.nan), lyapunov_stderr=np.full(N, np.nan),
                slip=np.full(N, np.nan), slip_stderr=np.full(N, np.nan), lost=np.zeros(N, bool),
                orbit_p=np.full(N, np.nan), distance=np.full(N, np.nan), residual=np.full(N, np.nan),
                mirror=np.full(N, np.nan), periods=np.zeros(N, int), drift_periods=np.zeros(N, int),
                reason=np.full(N, "", dtype=object),
                x=np.full((N, 2), np.nan), mult=np.full((N, 2), np.nan + 0j), slip_n=np.zeros(N, int))


def _period_mean(logs: np.ndarray) -> np.ndarray:
    """The mean over the periods (axis 0) of ``logs`` (P, M), summed period by period, so that
    each point's mean does not depend on the other points in the batch (numpy's ``mean(axis=0)``
    sums a single column pairwise, several columns in order: the last bit would depend on M,
    and a sweep in chunks would differ from the sweep in one piece)."""
    s = logs[0].copy()
    for row in logs[1:]:
        s += row
    return s / logs.shape[0]


class _Batch:
    """The points of one step count on their way through the schedule of :func:`_verdict_core`:
    their states, recent sections and (once it starts) their Lyapunov run; decided points
    leave, their verdict written to ``out`` (the arrays of all points, indexed by ``idx``)."""

    def __init__(self, eng, body, kind, R, Theta, p0, v0, idx, opts, out):
        self.eng, self.opts, self.out, self.Theta = eng, opts, out, Theta
        A, B, C = coefficients(body, R[idx], Theta[idx])
        phi, w = _initial(kind, Theta[idx], p0[idx], v0[idx])
        self.s = dict(idx=idx, A=A, B=B, C=C, phi=phi, w=w)
        self.hist = np.stack([phi, w], axis=-1)[None]
        self.tried = np.full((opts["max_period"], idx.size), np.inf)
        self.lyap: dict = {}
        self.pending: list = []              # chaotic points whose drift runs on (run_on)
        self.t = 0

    @property
    def n(self) -> int:
        return self.s["idx"].size

    def map(self, rows=slice(None)) -> RotationMap:
        return RotationMap(self.eng, self.s["A"][rows], self.s["B"][rows], self.s["C"][rows])

    def keep(self, mask) -> None:
        for d in (self.s, self.lyap):
            for key in d:
                d[key] = d[key][:, mask] if key == "sec" else d[key][mask]
        self.hist, self.tried = self.hist[:, mask], self.tried[:, mask]

    def advance(self, c: int, renorm: bool = False) -> dict:
        s, eng = self.s, self.eng
        o = eng.flow_with(s, c, self.lyap["J"]) if renorm else eng.flow(s["phi"], s["w"], s["A"], s["B"], s["C"], c)
        sec = o["sec"]
        sec[:, :, 0] -= eng.w2pi * np.arange(1, c + 1)[:, None]
        s["phi"], s["w"] = o["phi"] - eng.w2pi * c, o["w"]
        self.hist = np.concatenate([self.hist, sec])[-(2 * self.opts["max_period"] + 1):]
        self.t += c
        return o

    def try_orbits(self, sub=None) -> None:
        """:func:`lib.dynamics.verdicts.find_orbits` for the rows ``sub`` (default all); the rows
        that reach an attracting orbit are decided (periodic or slipping) and leave."""
        o, out = self.opts, self.out
        sub = np.arange(self.n) if sub is None else sub
        rmap = self.map(sub)
        tried = self.tried[:, sub]
        r = dv.find_orbits(rmap.step, rmap, np.arange(sub.size), self.hist[:, sub], max_period=o["max_period"],
                           candidate_tol=o["candidate_tol"], newton_tol=o["newton_tol"], reach_tol=o["reach_tol"],
                           reach_floor=o["reach_floor"], newton_options=_NEWTON, tried=tried)
        self.tried[:, sub] = tried
        f = np.flatnonzero(r["found"])
        if f.size == 0:
            return
        g = self.s["idx"][sub[f]]
        k, nn = r["k"][f], r["n"][f]
        out["regime"][g], out["period"][g], out["slip_n"][g] = dv.orbit_regime(nn), k, nn
        out["slip"][g], out["slip_stderr"][g], out["lost"][g] = nn / k, 0.0, nn != 0
        out["x"][g], out["mult"][g] = r["x"][f], r["mult"][f]
        mod = r["rho"][f]
        out["floquet"][g] = mod
        out["lyapunov"][g] = np.log(mod) * self.Theta[g] / (2 * np.pi * k)
        out["orbit_p"][g] = wrap_angle(r["near"][f, 0] - self.eng.H0)
        out["distance"][g], out["residual"][g], out["periods"][g] = r["distance"][f], r["residual"][f], self.t
        m = np.ones(self.n, bool)
        m[sub[f]] = False
        self.keep(m)

    def start_lyapunov(self, nb_max: int) -> None:
        M = self.n
        self.lyap = dict(J=np.tile(np.array([[1.0, 0.0], [1.0, 0.0]]) / np.sqrt(2.0), (M, 1, 1)),
                         lo=np.full(M, np.inf), hi=np.full(M, -np.inf), pb=np.empty((M, nb_max + 1)),
                         logs=np.empty((M, nb_max)), sec=np.empty((0, M, 2)))
        self.lyap["pb"][:, 0] = self.s["phi"]

    def lyapunov_block(self, b: int) -> None:
        """One block of the Lyapunov run: the tangent vector's log growth, the range of p, the
        heading at the block's end, the section states."""
        ly = self.lyap
        o = self.advance(self.opts["block"], renorm=True)
        ly["sec"] = np.concatenate([ly["sec"], o["sec"]])
        ly["J"] = o["J"]
        ly["lo"], ly["hi"] = np.minimum(ly["lo"], o["pmin"]), np.maximum(ly["hi"], o["pmax"])
        ly["pb"][:, b + 1] = self.s["phi"]
        ly["logs"][:, b] = _period_mean(o["logs"])

    def conclude(self, done, nb: int) -> None:
        """The rule (:func:`lib.dynamics.verdicts.classify`) for the rows ``done`` after ``nb``
        blocks, with the heading's drift and whether it is lost; they leave."""
        o, out, ly = self.opts, self.out, self.lyap
        g = self.s["idx"][done]
        T = 2 * np.pi / self.Theta[g]
        lam, se = long_run_means(ly["logs"][done, :nb], o["block"])
        out["lyapunov"][g], out["lyapunov_stderr"][g] = lam / T, se / T
        returns = dv.section_returns(ly["sec"][:, done])
        regime, reason = dv.classify(lam, se, returns, band=o["lyapunov_band"], return_tol=o["return_tol"],
                                     max_period=o["max_period"])
        ring = np.flatnonzero(regime == "quasiperiodic")
        if ring.size:
            rows = np.flatnonzero(done)[ring]
            rmap = self.map(rows)
            att, mu = dv.enclosed_orbit(rmap.step, np.arange(rows.size), ly["sec"][:, rows], turn_axis=0,
                                        newton_tol=o["newton_tol"], newton_options=_NEWTON)
            out["floquet"][g[ring]] = mu
            regime[ring[att]] = "undecided"
            reason[ring[att]] = [f"slow spiral onto an attracting orbit inside the curve (|mu| = {m:.4f})"
                                 for m in mu[att]]
        out["regime"][g], out["reason"][g] = regime, reason
        drift, dse = dv.heading_drift(ly["pb"][done, :nb + 1], o["block"])
        out["slip"][g], out["slip_stderr"][g] = drift, dse
        out["range"][g] = ly["hi"][done] - ly["lo"][done]
        out["lost"][g] = dv.heading_lost(False, 0, drift, dse, slip_band=o["slip_band"])
        out["periods"][g], out["drift_periods"][g] = self.t, nb * o["block"]
        more = o["drift_periods"] // o["block"] - nb
        on = np.flatnonzero(done)[np.ptp(ly["pb"][done, :nb + 1], axis=1) >= 2 * np.pi]
        if more > 0 and on.size:               # a heading that slipped: its drift runs on
            s = self.s
            self.pending.append((s["idx"][on], s["phi"][on], s["w"][on], s["A"][on], s["B"][on], s["C"][on],
                                 ly["pb"][on, :nb + 1], more))
        self.keep(~done)

    def run_on(self) -> None:
        """The drifts of the chaotic points that left the Lyapunov run early with a heading that
        slipped, run on without the tangent vector to ``drift_periods`` periods of Lyapunov run:
        their heading at every further block end, their drift and whether it is lost again."""
        o, out, eng, B = self.opts, self.out, self.eng, self.opts["block"]
        for g, phi, w, A, Bc, C, pb, more in self.pending:
            ends = np.arange(1, more + 1) * B
            sec = eng.flow(phi, w, A, Bc, C, more * B)["sec"]
            heading = np.concatenate([pb, (sec[ends - 1, :, 0] - eng.w2pi * ends[:, None]).T], axis=1)
            drift, dse = dv.heading_drift(heading, B)
            out["slip"][g], out["slip_stderr"][g] = drift, dse
            out["lost"][g] = dv.heading_lost(False, 0, drift, dse, slip_band=o["slip_band"])
            out["drift_periods"][g] = (heading.shape[1] - 1) * B
        self.pending = []


def _decide_group(batch: _Batch) -> None:
    """The schedule for one group of points: a transient in chunks, with Newton on the points
    that nearly repeat; then the Lyapunov run in blocks, with Newton again on the points that
    are not clearly expanding, a clearly chaotic point leaving early, and the rule at the end."""
    o, out = batch.opts, batch.out
    while batch.t < o["transient"] and batch.n:
        batch.advance(min(o["chunk"], o["transient"] - batch.t))
        if batch.t >= o["min_transient"]:
            batch.try_orbits()
    nb_max = o["lyapunov_periods"] // o["block"]
    if batch.n and nb_max < 2:
        out["reason"][batch.s["idx"]] = "no attracting orbit reached within the period budget"
        out["periods"][batch.s["idx"]] = batch.t
    if batch.n == 0 or nb_max < 2:
        return
    batch.start_lyapunov(nb_max)
    _lyapunov_run(batch, nb_max)
    batch.run_on()


def _lyapunov_run(batch: _Batch, nb_max: int) -> None:
    """The Lyapunov run of :func:`_decide_group`, in blocks, until every point is decided."""
    o = batch.opts
    for b in range(nb_max):
        batch.lyapunov_block(b)
        nb = b + 1
        if batch.t - o["transient"] < o["min_lyapunov_periods"] and nb < nb_max:
            continue
        lam, se = long_run_means(batch.lyap["logs"][:, :nb], o["block"])
        trymask = lam < dv.SIGMAS * se
        if trymask.any():
            batch.try_orbits(np.flatnonzero(trymask))
            if batch.n == 0:
                break
            lam, se = long_run_means(batch.lyap["logs"][:, :nb], o["block"])
        final = nb == nb_max
        chaotic = (lam > o["lyapunov_band"]) & (lam > (dv.SIGMAS if final else EARLY_SIGMAS) * se)
        done = chaotic | final
        if done.any():
            batch.conclude(done, nb)
        if batch.n == 0:
            break


def _verdict_core(body, kind, R, Theta, p0, v0, n_pts, opts, engine, n_fine=None):
    """The verdicts of :func:`rotation_verdicts` as a dict of arrays, plus the orbit's point x
    (N, 2) and multipliers (N, 2) for periodic/slipping points: decided on the map of
    ``n_pts`` steps per period, each orbit then located again on the map of ``n_fine``
    steps (default: the same) for its point, multipliers and range."""
    out = _new_out(R.size)
    n_fine = n_pts if n_fine is None else n_fine
    for n in np.unique(n_pts):
        idx = np.flatnonzero(n_pts == n)
        _decide_group(_Batch(_Engine(kind, int(n), engine), body, kind, R, Theta, p0, v0, idx, opts, out))
    _on_fine_map(body, kind, R, Theta, n_pts, n_fine, opts, engine, out)
    return out
