"""The other starts under the force and angle limits (Chapter 4): the mirror symmetry of
the closed loop on the eight, the attractors that starts reach and their mirrors, and how
the largest Lyapunov exponent converges with the horizon and with the initial separation.

**The symmetry.** Let sigma (x, y, phi) = (x, -y, -phi), acting on a state
[x, y, phi, xdot, ydot, phidot] as ``MIRROR``. Equations (2)-(4) are unchanged by sigma with
beta -> -beta (F cos(phi + beta) is even, F sin(phi + beta) and F a sin(beta) are odd).
The eight (28), x_d = R/2 sin(2 Theta t), y_d = R sin(Theta t), satisfies
z_d(t + T/2) = sigma z_d(t) (the heading modulo 2 pi). The law (23) with diagonal gains maps
(tau_x, tau_y) to (tau_x, -tau_y) (its heading row is not used by (25)-(26)), so (25)-(26)
give the same F and -beta; the angle limit |beta| <= beta_max and the force cap are even in
beta, and the switching surface S (lat = 0, lon < 0) maps to itself with its sides exchanged,
so Filippov solutions map to Filippov solutions. Hence if z(t) is a solution, so is
sigma z(t + T/2). On the period map P (the state at t = k T) this is the half-period mirror
G(s) = sigma Phi(T/2, 0) s: G commutes with P and G(G(s)) = P(s). An attractor A of P is
either its own mirror (G(A) = A) or one of a pair A, G(A) with the same multipliers and
exponents. The start sigma s0 at t = T/2 (the mirror of a start s0 at t = 0) is at
G(s0) at t = T: it reaches G(A) if s0 reaches A.

Verdicts are the book's (:func:`lib.limits.verdicts.limit_verdicts`, decided by
:mod:`lib.dynamics.verdicts`); this module only names the attractors they reach.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..machinery import checks
from ..dynamics import verdicts as dv
from .confirm import SAME_ORBIT_TOL, confirmed_limit_verdicts
from .verdicts import LIMIT_DEFAULTS
from .runs import STEPS_PER_PERIOD, switched_runs
from ..integrators.switched import SwitchedLoop
from ..params import PAPER_DZ0, PAPER_Z0, Body, Gains
from ..trajectories import Eight

__all__ = ["MIRROR", "mirror_state", "half_period_mirror", "mirror_defect", "mirrored_start",
           "heading_offset_starts", "start_attractors", "lyapunov_horizons", "lyapunov_separations",
           "SAME_ORBIT_TOL"]

#: The mirror sigma on a state [x, y, phi, xdot, ydot, phidot], as signs, (x, -y, -phi) and their rates.
MIRROR = np.array([1.0, -1.0, -1.0, 1.0, -1.0, -1.0])



def _check_loop(body, gains, ref, angle_limit, force_limit) -> tuple[float, float]:
    checks.instance("body", body, Body)
    checks.instance("gains", gains, Gains)
    checks.instance("ref", ref, Eight, "lib.trajectories.Eight (the mirror symmetry is the eight's)")
    b = checks.number("angle_limit", angle_limit, positive=True, maximum=np.pi, unit="rad")
    f = np.inf if force_limit is None else checks.number("force_limit", force_limit, positive=True,
                                                         finite=False, unit="N")
    return b, f


def _states(name: str, s) -> np.ndarray:
    return np.atleast_2d(checks.array(name, s, shape=(..., 6))).reshape(-1, 6)


def mirror_state(s) -> np.ndarray:
    """The mirror sigma of states ``s`` (..., 6) = [x (m), y (m), phi (rad), xdot (m/s),
    ydot (m/s), phidot (rad/s)]: (x, -y, -phi, xdot, -ydot, -phidot).

    Parameters
    ----------
    s : array_like, shape (..., 6)
        States.

    Returns
    -------
    numpy.ndarray
        sigma s, the same shape.
    """
    return checks.array("s", s, shape=(..., 6)) * MIRROR


def half_period_mirror(body: Body, gains: Gains, ref: Eight, angle_limit: float, force_limit: float | None,
                       s, *, steps_per_period: int = STEPS_PER_PERIOD) -> np.ndarray:
    """The half-period mirror G(s) = sigma Phi(T/2, 0) s of the closed loop (2)-(4), (23),
    (25)-(26) under the limits: the state at t = T/2 of the run from ``s`` at t = 0,
    mirrored (compiled integrator, :func:`lib.limits.runs.switched_runs`). G(G(s)) = P(s).

    Parameters
    ----------
    body, gains : Body, Gains
        The body and the gains of (23).
    ref : Eight
        The eight (28); the symmetry holds for it only.
    angle_limit : float
        beta_max (rad), in (0, pi].
    force_limit : float or None
        The force cap (N); None or inf for none.
    s : array_like, shape (6,) or (N, 6)
        States at t = 0.
    steps_per_period : int
        Steps of the compiled integrator per period T (even, so T/2 is on the grid).

    Returns
    -------
    numpy.ndarray, shape (N, 6)
        G(s), states at phase 0.
    """
    b, f = _check_loop(body, gains, ref, angle_limit, force_limit)
    x = _states("s", s)
    r = switched_runs(body, gains, ref, np.full(len(x), b), np.full(len(x), f), s0=x, n_periods=1,
                      samples_per_period=2, steps_per_period=steps_per_period)
    return r.states[:, 1] * MIRROR


def mirror_defect(body: Body, gains: Gains, ref: Eight, angle_limit: float, force_limit: float | None, s0,
                  n_periods: int, *, steps_per_period: int = STEPS_PER_PERIOD) -> np.ndarray:
    """How far the mirrored run departs from the mirror of the run: with z the run from
    ``s0`` at t = 0 and w the run from G(s0) (:func:`half_period_mirror`) at t = 0, the
    max-norm of w(j T/2) - sigma z(j T/2 + T/2) for j = 0, ..., 2 ``n_periods`` (zero for
    an exact symmetry; rounding errors grow at the Lyapunov rate on a chaotic run).

    Parameters
    ----------
    body, gains, ref, angle_limit, force_limit, steps_per_period
        As for :func:`half_period_mirror`.
    s0 : array_like, shape (6,)
        The start at t = 0.
    n_periods : int
        Periods T of the mirrored run compared.

    Returns
    -------
    numpy.ndarray, shape (2 n_periods + 1,)
        The defect at t = j T/2 (m, rad, m/s, rad/s mixed in the max-norm).
    """
    b, f = _check_loop(body, gains, ref, angle_limit, force_limit)
    x = checks.array("s0", s0, shape=(6,))
    n = checks.integer("n_periods", n_periods, minimum=1)
    z = switched_runs(body, gains, ref, b, f, s0=x, n_periods=n + 1, samples_per_period=2,
                      steps_per_period=steps_per_period).states[0]
    w = switched_runs(body, gains, ref, b, f, s0=z[1] * MIRROR, n_periods=n, samples_per_period=2,
                      steps_per_period=steps_per_period).states[0]
    return np.abs(w - z[1:2 * n + 2] * MIRROR).max(axis=1)


def mirrored_start(body: Body, gains: Gains, ref: Eight, angle_limit: float, force_limit: float | None, s0,
                   *, rtol: float = 1e-11, atol: float = 1e-11) -> np.ndarray:
    """The mirror of a start: the run from sigma ``s0`` at t = T/2, followed to t = T by the
    adaptive event-located integrator (:class:`lib.integrators.switched.SwitchedLoop`), where the period
    map takes over. By the symmetry this state is G(s0) (:func:`half_period_mirror`), which
    the compiled integrator computes by another route.

    Parameters
    ----------
    body, gains, ref, angle_limit, force_limit
        As for :func:`half_period_mirror`.
    s0 : array_like, shape (6,)
        The start at t = 0 being mirrored.
    rtol, atol : float
        Tolerances of the adaptive integrator.

    Returns
    -------
    numpy.ndarray, shape (6,)
        The mirrored start's state at t = T (phase 0).
    """
    b, f = _check_loop(body, gains, ref, angle_limit, force_limit)
    x = checks.array("s0", s0, shape=(6,))
    loop = SwitchedLoop(body, gains, ref, b, None if np.isinf(f) else f)
    T = ref.period
    return loop.integrate(x * MIRROR, T / 2, T, rtol=rtol, atol=atol).y_end


def heading_offset_starts(offsets, base=None) -> np.ndarray:
    """Starts at t = 0 that differ from ``base`` (default the paper's, at rest at
    (1 m, 0, pi/2)) only in the heading phi, by ``offsets`` (rad).

    Parameters
    ----------
    offsets : array_like, shape (N,)
        Heading offsets (rad).
    base : array_like, shape (6,), optional
        The state offset.

    Returns
    -------
    numpy.ndarray, shape (N, 6)
        The starts.
    """
    d = checks.array("offsets", offsets, ndim=1, nonempty=True)
    s = np.concatenate([PAPER_Z0, PAPER_DZ0]) if base is None else checks.array("base", base, shape=(6,))
    out = np.tile(s, (d.size, 1))
    out[:, 2] += d
    return out


def _orbit_points(body, gains, ref, b, f, x, k, steps) -> np.ndarray:
    """The k phase-0 points P^j(x), j = 1..k, of an orbit through x: (k, 6)."""
    return switched_runs(body, gains, ref, b, f, s0=x, n_periods=int(k), steps_per_period=steps).states[0, 1:]


def _distance(x, pts) -> float:
    """Max-norm distance (heading modulo 2 pi) from a state x (6,) to the nearest of pts (k, 6)."""
    return float(dv.distance_to_orbit(np.asarray(x)[None], np.asarray(pts)[:, None], turn_axis=2)[0][0])


def start_attractors(body: Body, gains: Gains, ref: Eight, angle_limit: float, force_limit: float | None,
                     starts, *, steps_per_period: int = STEPS_PER_PERIOD, **options) -> pd.DataFrame:
    """Which attractor each start reaches, and its mirror.

    Each start (at t = 0) is decided by :func:`lib.limits.verdicts.limit_verdicts` (``options`` as
    there), and confirmed from the start moved by 1e-12
    (:func:`lib.limits.confirm.confirmed_limit_verdicts`: ``transient`` where the decisions differ).
    The orbits reached are then named in the order of the starts: the first is A,
    the next distinct one B, ...; an orbit that is the mirror G(X) of an orbit X named
    before (G from :func:`half_period_mirror`) is named X' (A' is the mirror of A). Two
    orbits are the same when each point of one lies within :data:`lib.limits.confirm.SAME_ORBIT_TOL` of the
    other's points. An orbit equal to its own mirror is symmetric.

    Parameters
    ----------
    body, gains, ref, angle_limit, force_limit, steps_per_period
        As for :func:`half_period_mirror`.
    starts : array_like, shape (N, 6)
        States at t = 0.
    **options
        Options of :func:`lib.limits.verdicts.limit_verdicts` (:data:`lib.limits.verdicts.LIMIT_DEFAULTS`).

    Returns
    -------
    pandas.DataFrame
        One row per start: regime, period, floquet (largest |multiplier|), lyapunov and
        lyapunov_stderr (1/s), lost (the heading slips), attractor (the name; the regime for
        a run with no orbit), symmetric (the orbit is its own mirror; None without an
        orbit), mirror_gap (the Hausdorff distance between the orbit's points and
        their mirrors G(points), max-norm, the heading modulo 2 pi: 0 for a symmetric
        orbit), orbit (its point at t = 0, or None).
    """
    b, f = _check_loop(body, gains, ref, angle_limit, force_limit)
    x = _states("starts", starts)
    fr = confirmed_limit_verdicts(body, gains, ref, np.full(len(x), b), np.full(len(x), f), s0=x,
                                  steps_per_period=steps_per_period, **options)[0]
    named: list[tuple[str, np.ndarray]] = []         # (name, the orbit's points)
    names, sym, gap = [], [], []
    for q, row in enumerate(fr.itertuples()):
        if row.orbit is None:
            names.append(row.regime), sym.append(None), gap.append(np.nan)
            continue
        pts = _orbit_points(body, gains, ref, b, f, row.orbit, row.period, steps_per_period)
        gs = half_period_mirror(body, gains, ref, b, f, pts, steps_per_period=steps_per_period)
        gap.append(max(max(_distance(g, pts) for g in gs), max(_distance(p, gs) for p in pts)))
        sym.append(gap[-1] <= SAME_ORBIT_TOL)
        same = [n for n, p in named if len(p) == len(pts) and _distance(row.orbit, p) <= SAME_ORBIT_TOL]
        if same:
            names.append(same[0])
            continue
        letter = chr(ord("A") + sum(1 for n, _ in named if not n.endswith("'")))
        named.append((letter, pts))
        if not sym[-1]:
            named.append((letter + "'", gs))         # G maps the orbit's points onto its mirror's
        names.append(letter)
    out = fr[["regime", "period", "floquet", "lyapunov", "lyapunov_stderr", "lost", "orbit"]].copy()
    out.insert(0, "angle_deg", np.degrees(b))
    out.insert(1, "force_limit", f)
    out["attractor"], out["symmetric"], out["mirror_gap"] = names, sym, gap
    return out


def _lyapunov_points(body, gains, ref, angle_limits, force_limits):
    checks.instance("body", body, Body)
    checks.instance("gains", gains, Gains)
    checks.instance("ref", ref, Eight, "lib.trajectories.Eight")
    b = checks.array("angle_limits", angle_limits, ndim=1, nonempty=True, positive=True)
    f = checks.array("force_limits", np.full(b.size, np.inf) if force_limits is None else force_limits,
                     shape=(b.size,), finite=False, positive=True)
    if np.any(b > np.pi):
        raise ValueError(f"angle_limits[{int(np.argmax(b > np.pi))}] must be at most pi rad")
    return b, f


def lyapunov_horizons(body: Body, gains: Gains, ref: Eight, angle_limits, force_limits, horizons, *,
                      d0: float = 1e-7, s0=None, transient: int = LIMIT_DEFAULTS["transient"],
                      block: int = LIMIT_DEFAULTS["block"],
                      steps_per_period: int = STEPS_PER_PERIOD) -> pd.DataFrame:
    """The largest Lyapunov exponent over growing horizons, from one run per point: the
    Benettin estimate of :func:`lib.limits.verdicts.limit_verdicts` (a companion ``d0`` away,
    renormalised every period from the end of the ``transient``), its mean and batch-means
    standard error over the first n periods (blocks of ``block`` periods,
    :func:`lib.dynamics.verdicts.block_statistics`) for each n of ``horizons``. At
    n = ``LIMIT_DEFAULTS['periods']`` it is the exponent limit_verdicts reports.

    Parameters
    ----------
    body, gains, ref
        As for :func:`half_period_mirror`.
    angle_limits : array_like, shape (M,)
        beta_max (rad) of each point.
    force_limits : array_like, shape (M,), or None
        Force caps (N; inf for none).
    horizons : array_like of int
        Periods n after the transient, each a multiple of ``block`` of at least two blocks.
    d0 : float
        The companion's initial separation (plain Euclidean norm of the state).
    s0 : array_like, shape (6,), optional
        The start (default the paper's).
    transient, block, steps_per_period : int
        As in :func:`lib.limits.verdicts.limit_verdicts`.

    Returns
    -------
    pandas.DataFrame
        Columns angle_deg, force_limit (N), horizon (periods), lyapunov, stderr (1/s).
    """
    b, f = _lyapunov_points(body, gains, ref, angle_limits, force_limits)
    blk = checks.integer("block", block, minimum=1)
    n = np.array([checks.integer(f"horizons[{i}]", h, minimum=2 * blk) for i, h in enumerate(horizons)])
    if n.size == 0 or np.any(n % blk):
        raise ValueError(f"horizons must be non-empty multiples of block ({blk}), got {n.tolist()}")
    ntr = checks.integer("transient", transient, minimum=0)
    r = switched_runs(body, gains, ref, b, f, s0=s0, n_periods=ntr + int(n.max()), lyapunov_from=ntr, d0=d0,
                      steps_per_period=steps_per_period)
    rows = []
    for h in n:
        lam, se = dv.block_statistics(r.log_growth[:, :h], blk)
        rows += [dict(angle_deg=np.degrees(b[i]), force_limit=f[i], horizon=int(h), lyapunov=lam[i] / r.period,
                      stderr=se[i] / r.period) for i in range(b.size)]
    return pd.DataFrame(rows)


def lyapunov_separations(body: Body, gains: Gains, ref: Eight, angle_limits, force_limits, d0s, *,
                         periods: int, s0=None, transient: int = LIMIT_DEFAULTS["transient"],
                         block: int = LIMIT_DEFAULTS["block"],
                         steps_per_period: int = STEPS_PER_PERIOD) -> pd.DataFrame:
    """The largest Lyapunov exponent with its standard error for each initial separation
    d0 of ``d0s``, over ``periods`` periods (:func:`lyapunov_horizons` at one horizon).
    The reference run is the same for every d0: only the companion changes.

    Parameters
    ----------
    body, gains, ref, angle_limits, force_limits, s0, transient, block, steps_per_period
        As for :func:`lyapunov_horizons`.
    d0s : array_like, shape (K,)
        Initial separations, each in (0, 1e-3).
    periods : int
        The horizon (periods after the transient), a multiple of ``block``.

    Returns
    -------
    pandas.DataFrame
        Columns angle_deg, force_limit (N), d0, horizon, lyapunov, stderr (1/s).
    """
    d = checks.array("d0s", d0s, ndim=1, nonempty=True, positive=True)
    if np.any(d >= 1e-3):
        raise ValueError(f"d0s[{int(np.argmax(d >= 1e-3))}] must be below 1e-3, got {d[d >= 1e-3][0]!r}")
    parts = [lyapunov_horizons(body, gains, ref, angle_limits, force_limits, [periods], d0=float(x), s0=s0,
                               transient=transient, block=block, steps_per_period=steps_per_period)
             .assign(d0=float(x)) for x in d]
    out = pd.concat(parts, ignore_index=True)
    return out[["angle_deg", "force_limit", "d0", "horizon", "lyapunov", "stderr"]]
