"""One point's view of the rotation verdicts (:mod:`lib.rotation.verdicts`): the attracting
orbit of the heading that a start reaches, with its Floquet multipliers and its p(t);
and what a map of verdicts shows, summarised for the book to quote (Fig. 5).

Units: R in m, Theta in rad/s, angles in rad, times in s.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.interpolate import CubicSpline

from ..machinery import checks
from ..angles import wrap_angle
from ..dynamics.verdicts import REGIMES, orbit_points
from ..params import Body
from .reduced import check_grid, _shape
from .engine import RotationMap, _Engine, check_domain
from .field import coefficients
from .verdicts import SLOW_FLOQUET, _check_body_kind, _step_counts, _verdict_core, _verdict_options

__all__ = ["RotationAttractor", "rotation_attractor", "MapSummary", "map_summary"]


@dataclass(frozen=True)
class RotationAttractor:
    """The attracting orbit of the heading that the run from one start reaches
    (:func:`rotation_attractor`).

    ``regime`` ("periodic" or "slipping"), ``period`` k (reference periods), ``slip`` n
    (whole turns of p per k periods); ``states`` (k, 2): (p (rad), dp/dt (rad/s)) at
    t = 0, T, ..., (k - 1) T (mod k T) on the orbit, starting with the point the run is
    nearest to at its end; ``multipliers`` (2,) complex, the Floquet multipliers
    (eigenvalues of DP^k), by decreasing modulus; ``t`` (s) and ``p`` (rad): the orbit
    over its k periods at every integration step (t from 0 to k T, p continuous);
    ``range`` (rad), ``residual`` (rad, Newton's), ``periods`` (integrated before
    the verdict)."""

    regime: str
    period: int
    slip: int
    states: np.ndarray
    multipliers: np.ndarray
    t: np.ndarray
    p: np.ndarray
    range: float
    residual: float
    periods: int

    def distance_per_period(self, t, p) -> np.ndarray:
        """How far a heading error p(t) (rad, at times t (s) from the start of the same
        reference, e.g. a full closed-loop run) is from this orbit: for each complete
        period j (t in [j T, (j + 1) T)), the largest |p - p_orbit| (modulo 2 pi) over
        its samples; p_orbit is the orbit's p at the same time modulo k T (cubic spline).
        A run that reaches the orbit has these shrink like |mu_1|^(j / k)."""
        t, p = np.asarray(t, dtype=float), np.asarray(p, dtype=float)
        if t.ndim != 1 or t.shape != p.shape or t.size < 2:
            raise ValueError(f"t and p must be 1-D arrays of equal length >= 2, got {t.shape}, {p.shape}")
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(p))) or np.any(t < 0):
            raise ValueError("t must be finite and non-negative, p finite")
        kT = float(self.t[-1])
        T = kT / self.period
        # the orbit's p continues by the slip n: p(t + k T) = p(t) + 2 pi n
        turns = np.floor(t / kT)
        orbit = CubicSpline(self.t, self.p)(t - turns * kT) + 2 * np.pi * self.slip * turns
        d = np.abs(wrap_angle(p - orbit))
        j = np.floor(t / T + 1e-9).astype(int)
        n = int(np.floor(t[-1] / T + 1e-9))
        if n < 1:
            raise ValueError("p(t) must cover at least one full reference period")
        return np.array([d[j == i].max() for i in range(n)])


def rotation_attractor(body: Body, kind: str, R: float, Theta: float, *, p0: float = 0.0, v0: float = 0.0,
                       h_lambda: float = 0.125, steps: int | None = None, **options) -> RotationAttractor:
    """The attracting periodic orbit of the heading error p = phi - phi_d of (32) on the
    reference ``kind`` at one point (R (m), Theta (rad/s)) that the run from p(0) = ``p0``
    (rad), dp/dt(0) = ``v0`` (rad/s) reaches, as decided by :func:`lib.rotation.verdicts.rotation_verdicts`
    (same options). On the eight (28) the rotation equation (37) is symmetric and has two
    mirror-image period-1 orbits; which one a start reaches is reported by
    ``states[0, 0]``. Raises ValueError if the run reaches no attracting orbit (the
    verdict is then chaotic, quasiperiodic or undecided).

    Parameters
    ----------
    body : Body
        The body.
    kind : str
        ``"eight"`` or ``"circle"``.
    R : float
        Radius (m).
    Theta : float
        Rate (rad/s).
    p0, v0 : float
        Start (rad, rad/s).
    h_lambda : float
        Step bound.
    steps : int, optional
        Steps per period.
    **options
        The options of :func:`lib.rotation.verdicts.rotation_verdicts`.

    Returns
    -------
    RotationAttractor
        The verdict, the orbit's period, slip and states, its multipliers, p (rad) sampled
    over it at times t (s), its range (rad) and Newton's residual.
    """
    for name, v in (("R", R), ("Theta", Theta), ("p0", p0), ("v0", v0)):
        if isinstance(v, bool) or not np.isscalar(v) or not isinstance(v, (int, float, np.integer, np.floating)):
            raise TypeError(f"{name} must be a real scalar, got {type(v).__name__}")
    R_, Th = check_grid([R], [Theta])
    if not (np.isfinite(p0) and np.isfinite(v0)):
        raise ValueError("initial p0 and v0 must be finite")
    _check_body_kind(body, kind)
    h_lambda = checks.number("h_lambda", h_lambda, positive=True)
    check_domain(body, kind, R_, Th, h_lambda)             # the verdicts' domain, before any run
    opts = _verdict_options(options)
    n_pts, n_fine = _step_counts(body, kind, R_, Th, h_lambda, steps, opts)
    n = int(n_fine[0])
    res = _verdict_core(body, kind, R_, Th, np.array([float(p0)]), np.array([float(v0)]), n_pts, opts, "numba",
                        n_fine)
    regime = res["regime"][0]
    if regime not in ("periodic", "slipping"):
        raise ValueError(f"no attracting orbit is reached at R = {R} m, Theta = {Theta} rad/s from p0 = {p0}: "
                         f"the verdict is {regime} {res['reason'][0]}".rstrip())
    k = int(res["period"][0])
    eng = _Engine(kind, n, "numba")
    A, B, C = coefficients(body, R_, Th)
    x = res["x"][:1].copy()
    pts = orbit_points(RotationMap(eng, A, B, C), np.array([0]), x, k)[:k, 0]          # P(x), ..., P^k(x) ~ x + shift
    pts = np.concatenate([x, pts[:-1]])
    # start at the orbit point nearest to the run's end (the one reported by orbit_p)
    j = int(np.argmin(np.abs(wrap_angle(pts[:, 0] - eng.H0 - res["orbit_p"][0]))))
    x0 = pts[j:j + 1].copy()
    x0[0, 0] = eng.H0 + wrap_angle(x0[0, 0] - eng.H0)
    p, dp = eng.record(x0[:, 0], x0[:, 1], A, B, C, k)
    p = np.concatenate([[x0[0, 0] - eng.H0], p[0]])
    t = np.arange(p.size) * eng.h / Th[0]
    states = np.roll(pts, -j, axis=0)
    H1_0 = _shape(kind)[0](0.0)[5]
    states = np.column_stack([wrap_angle(states[:, 0] - eng.H0), (states[:, 1] - H1_0) * Th[0]])
    return RotationAttractor(regime=regime, period=k, slip=int(round(res["slip"][0] * k)), states=states,
                             multipliers=res["mult"][0], t=t, p=p, range=float(res["range"][0]),
                             residual=float(res["residual"][0]), periods=int(res["periods"][0]))


@dataclass(frozen=True)
class MapSummary:
    """What a map of verdicts (:func:`lib.rotation.verdicts.rotation_verdicts`) shows, for the book to quote.

    Counts: ``n_grid`` points; ``n_periodic``, ``n_slipping``, ``n_chaotic``,
    ``n_transient`` (transient chaos: attractor not determined), ``n_quasiperiodic``, ``n_undecided`` per regime; ``n_lost`` where the heading is lost
    (column ``lost``: it slips), of them ``n_lost_slipping`` on a slipping orbit and
    ``n_lost_no_orbit`` without an orbit (drifting) and ``n_lost_transient`` lost on the run from
    the reference whose attractor is not determined (``transient``); ``n_turns_round`` the count under the
    other reading (column ``turns_round``: the range of p exceeds a full turn), of them
    ``n_turns_round_periodic`` on periodic orbits and ``n_turns_round_chaotic`` chaotic;
    ``n_chaotic_within_turn`` chaotic points whose heading stays within one turn, ``chaotic_range_median`` (rad) the median range of the chaotic points;
    ``n_period_gt1`` orbits longer than one
    reference period, ``max_period`` the longest. Ranges (rad) over the periodic orbits:
    ``range_min``, ``range_max``. ``theta_min_lost``, ``theta_min_chaotic`` (rad/s): the
    slowest rate at which stability is lost / chaos occurs (NaN if never). Over the
    chaotic points: ``lyapunov_min``, ``lyapunov_max`` (1/s) and ``lyapunov_sigmas_min``,
    the smallest exponent in standard errors. Over the orbits: ``floquet_max``, the
    slowest contraction, and ``n_slow`` orbits with a multiplier above 0.9 in modulus.
    ``n_asymmetric``: orbits that are not their own mirror image (mirror distance above
    1e-6 rad), so that their mirror image coexists as a second attractor.
    ``periods_median``, ``periods_max``: reference periods integrated per point."""

    n_grid: int
    n_periodic: int
    n_slipping: int
    n_chaotic: int
    n_transient: int
    n_quasiperiodic: int
    n_undecided: int
    n_lost: int
    n_lost_slipping: int
    n_lost_no_orbit: int
    n_lost_transient: int
    n_turns_round: int
    n_turns_round_periodic: int
    n_turns_round_chaotic: int
    n_chaotic_within_turn: int
    chaotic_range_median: float
    n_period_gt1: int
    max_period: int
    range_min: float
    range_max: float
    theta_min_lost: float
    theta_min_chaotic: float
    lyapunov_min: float
    lyapunov_max: float
    lyapunov_sigmas_min: float
    floquet_max: float
    n_slow: int
    n_asymmetric: int
    periods_median: float
    periods_max: int


def map_summary(frame: pd.DataFrame) -> MapSummary:
    """The :class:`MapSummary` of a frame returned by :func:`lib.rotation.verdicts.rotation_verdicts` (or
    :func:`lib.rotation.verdicts.eight_rotation_sweep`).

    Parameters
    ----------
    frame : pandas.DataFrame
        A frame of verdicts.

    Returns
    -------
    MapSummary
        The counts and ranges the book quotes.
    """
    need = {"regime", "period", "range", "floquet", "lyapunov", "lyapunov_stderr", "lost", "turns_round", "Theta",
            "periods"}
    if not isinstance(frame, pd.DataFrame) or not need <= set(frame.columns):
        raise ValueError(f"frame must be a DataFrame of rotation_verdicts with columns {sorted(need)}")
    if len(frame) == 0:
        raise ValueError("frame must not be empty")
    reg = frame.regime
    per, cha = frame[reg == "periodic"], frame[reg == "chaotic"]
    orb = frame[reg.isin(["periodic", "slipping"])]
    nan = float("nan")

    def lo(s):
        return float(s.min()) if len(s) else nan

    def hi(s):
        return float(s.max()) if len(s) else nan

    return MapSummary(
        n_grid=len(frame), **{f"n_{r}": int((reg == r).sum()) for r in REGIMES},
        n_lost=int(frame.lost.sum()), n_lost_slipping=int((frame.lost & (reg == "slipping")).sum()),
        n_lost_no_orbit=int((frame.lost & ~reg.isin(["slipping", "transient"])).sum()),
        n_lost_transient=int((frame.lost & (reg == "transient")).sum()),
        n_turns_round=int(frame.turns_round.sum()),
        n_turns_round_periodic=int((frame.turns_round & (reg == "periodic")).sum()),
        n_turns_round_chaotic=int((frame.turns_round & (reg == "chaotic")).sum()),
        n_chaotic_within_turn=int((~cha.turns_round).sum()),
        chaotic_range_median=float(cha["range"].median()) if len(cha) else nan, n_period_gt1=int((orb.period > 1).sum()),
        max_period=int(orb.period.max()) if len(orb) else 0,
        range_min=lo(per["range"]), range_max=hi(per["range"]),
        theta_min_lost=lo(frame.Theta[frame.lost]), theta_min_chaotic=lo(cha.Theta),
        lyapunov_min=lo(cha.lyapunov), lyapunov_max=hi(cha.lyapunov),
        lyapunov_sigmas_min=lo(cha.lyapunov / cha.lyapunov_stderr),
        floquet_max=hi(orb.floquet), n_slow=int((orb.floquet > SLOW_FLOQUET).sum()),
        n_asymmetric=int((orb.mirror > 1e-6).sum()) if "mirror" in orb else 0,
        periods_median=float(frame.periods.median()), periods_max=int(frame.periods.max()))
