"""How large an error bar is: the book's standard errors (:mod:`lib.dynamics.statistics`)
checked against the spread of the same estimate over independent starts on the same
chaotic attractor (the Methods page, section "How large an error bar is").

At each setting K runs start apart; each reports an estimate x_k and its standard error
s_k by the procedure the book uses. When the errors are honest, the standard deviation of
the K estimates matches the mean reported error: :func:`ensemble_ratio` gives their ratio
with its chi-square interval (K - 1 degrees of freedom). Two flows are studied, at the
settings of :data:`LIMIT_DEG` and :data:`FIG5_POINTS`:

- the switched closed loop under an angle limit on the eight (Chapter 4, and the paper's law
  of Chapter 8): the starts are the paper's initial state moved by :data:`START_SPREAD` in
  every coordinate, run :data:`BURN_IN` periods (the verdicts' transient) before anything is
  measured, far longer than chaos needs to separate them (:func:`limit_ensemble` reports how
  far apart they end up); the exponent over :data:`LIMIT_PERIODS` periods (blocks of 12, as
  :func:`lib.limits.verdicts.limit_verdicts`), the heading's drift over the same periods (block
  ends every 12) and C's RMS distance from the path over the last :data:`RMS_PERIODS` of them
  (per-period mean squares, shortest block 2, as :func:`lib.optimal.studies.compare.paper_rows`);
- the reduced rotation (32) at chaotic points of Fig. 5 (Chapter 5): distinct random starts
  p(0), dp/dt(0), each decided by :func:`lib.rotation.verdicts.rotation_verdicts` itself,
  whose exponent and drift the map reports; a start that lands on another attractor (another
  verdict) is counted and left out.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
from scipy import stats

from ..limits.runs import switched_runs
from ..machinery import checks
from ..params import PAPER_DZ0, PAPER_Z0, Body, Gains
from ..rotation.engine import _Engine, verdict_steps
from ..rotation.field import coefficients
from ..rotation.fig5 import _redo
from ..rotation.reduced import _initial
from ..rotation.verdicts import FIG5_GRID, VERDICT_DEFAULTS, _verdict_options, eight_rotation_sweep
from ..trajectories import eight
from ..dynamics.statistics import batch_grouping, batch_means, block_statistics, heading_drift, integrated_time

__all__ = ["ensemble_ratio", "limit_ensemble", "rotation_ensemble", "calibration_study", "ratio_table", "LIMIT_DEG",
           "heading_variogram", "VARIOGRAM_LAGS", "move_counts", "exponent_moves",
           "FIG5_POINTS",
           "LIMIT_STARTS", "ROTATION_STARTS", "VARIOGRAM_STARTS", "BURN_IN", "LIMIT_PERIODS", "RMS_PERIODS",
           "START_SPREAD", "RATIO_BAND", "LEVEL", "RMS_BLOCK", "SHORT_BLOCKS"]

#: the angle limits (deg) studied, without a cap, on Chapter 4's eight (R = 2 m, Theta = pi/4 rad/s)
LIMIT_DEG = (30, 45)
#: chaotic points of Fig. 5 studied, (i, j) on the n x n grid of ``FIG5_GRID``, R_i, Theta_j
FIG5_POINTS = ((2, 26), (58, 50), (74, 58), (10, 74), (50, 82), (82, 82), (18, 90), (66, 98), (2, 98))
#: independent starts per angle limit and per Fig. 5 point (a ratio's own spread is about 1 / sqrt(2 K),
#: 0.044 with 256 starts, against a band of 0.8 to 1.25), and for the heading's variogram
LIMIT_STARTS, ROTATION_STARTS, VARIOGRAM_STARTS = 32, 256, 64
#: periods run before measuring (the limit verdicts' transient), the periods measured, the RMS's last periods
BURN_IN, LIMIT_PERIODS, RMS_PERIODS = 60, 120, 100
#: the limit runs' starts are the paper's state moved by this much (m, rad, m/s, rad/s) in each coordinate
START_SPREAD = 1e-6
#: the band the ratio of spread to error must lie in, and the confidence level of its interval
RATIO_BAND, LEVEL = (0.8, 1.25), 0.95

#: the lags (periods) at which :func:`heading_variogram` measures the heading's displacement: a period,
#: the verdicts' block, the drift's batch over a run of 300 periods, the run a chaotic point leaves after,
#: and a longer one
VARIOGRAM_LAGS = (1, 12, 48, 72, 144)

#: blocks (periods) of the limit verdicts' exponent and drift
_LIMIT_BLOCK = 12
#: the shortest block (periods) Chapter 8 asks for the RMS distance's error (lib.optimal.studies.compare.RMS_BLOCK)
RMS_BLOCK = 2
#: the name of the RMS's error from fixed blocks of RMS_BLOCK periods in :func:`calibration_study`
SHORT_BLOCKS = f"RMS, blocks of {RMS_BLOCK}"
#: samples a period of the limit runs' RMS (the per-period mean square by the rectangle rule)
_RMS_SAMPLES = 20


def ensemble_ratio(estimates, stderrs, level: float = LEVEL) -> dict:
    """The spread of K estimates of one quantity from independent starts (their sample
    standard deviation s) over the mean of their reported standard errors, and its
    ``level`` confidence interval: (K - 1) s^2 / sigma^2 is chi-square on K - 1 degrees of
    freedom, so sigma lies in s sqrt((K - 1) / q_hi) .. s sqrt((K - 1) / q_lo) (the mean error,
    an average of K, taken as known). With K = 16 the interval is about [0.7, 1.5] times the
    ratio, with K = 64 about [0.85, 1.2]. An honest error does not give a ratio of 1 exactly: an
    error read from few batches is itself noisy, and its mean falls below the spread it
    estimates (by c4(B), 0.95 for B = 6 batches; its square is unbiased), so the ratio an honest
    error shows at these starts is ``honest`` = sqrt(mean s_k^2) / mean s_k (1 / c4(B) when the
    starts' errors share one law). Returns a dict: K, mean, spread, stderr (the mean error),
    ratio, lo, hi, honest.

    Parameters
    ----------
    estimates : array_like
        The K estimates (K,), finite, K >= 3.
    stderrs : array_like
        Their standard errors (K,), finite and positive.
    level : float
        The confidence level, in (0, 1).

    Returns
    -------
    dict
        K, mean, spread, stderr, ratio, lo, hi, honest.
    """
    x = np.asarray(estimates, dtype=float)
    s = np.asarray(stderrs, dtype=float)
    if x.ndim != 1 or x.size < 3 or not np.all(np.isfinite(x)):
        raise ValueError(f"estimates must be at least 3 finite values (K,), got shape {x.shape}")
    if s.shape != x.shape or not np.all(np.isfinite(s)) or not np.all(s > 0):
        raise ValueError(f"stderrs must be {x.size} finite positive values, as many as the estimates")
    if not 0 < level < 1:
        raise ValueError(f"level must lie in (0, 1), got {level}")
    K = x.size
    spread, mean_se = float(x.std(ddof=1)), float(s.mean())
    ratio = spread / mean_se
    q_lo, q_hi = stats.chi2.ppf([(1 - level) / 2, (1 + level) / 2], K - 1)
    return dict(K=K, mean=float(x.mean()), spread=spread, stderr=mean_se, ratio=ratio,
                lo=ratio * math.sqrt((K - 1) / q_hi), hi=ratio * math.sqrt((K - 1) / q_lo),
                honest=float(np.sqrt(np.mean(s ** 2)) / mean_se))


def limit_ensemble(body: Body, gains: Gains, angle_deg: float, starts: int = LIMIT_STARTS, *,
                   seed: int = 0) -> pd.DataFrame:
    """``starts`` runs of the switched closed loop on the eight (R = 2 m, Theta = pi/4 rad/s)
    under the angle limit ``angle_deg`` (deg, no cap), from the paper's state moved by
    :data:`START_SPREAD` times standard normal numbers (``seed``) in each coordinate, each
    measured after :data:`BURN_IN` periods as Chapters 4 and 8 measure one run: the largest
    Lyapunov exponent (1/s) over :data:`LIMIT_PERIODS` periods, blocks of 12
    (:func:`lib.dynamics.statistics.block_statistics`); the heading's drift (turns of
    p = phi - phi_d per period) from p at the ends of those blocks
    (:func:`lib.dynamics.statistics.heading_drift`); C's RMS distance from the path (m)
    over the last :data:`RMS_PERIODS` periods, from the per-period mean squares (shortest
    block 2), its error carried to the RMS by the derivative. Returns one row per start:
    lyapunov, lyapunov_stderr, drift, drift_stderr, rms, rms_stderr, and rms_stderr_short
    (the RMS's error from blocks of exactly :data:`RMS_BLOCK` periods, whatever their memory) and
    rms_tau (the integrated autocorrelation time of the per-period mean squares, periods);
    the frame's ``attrs``
    hold ``separation``, the smallest distance between two starts' states after the burn-in
    (m, rad, m/s, rad/s, max-norm, heading modulo 2 pi), against START_SPREAD at the start.

    Parameters
    ----------
    body, gains : Body, Gains
        The body and the gains of (23).
    angle_deg : float
        The angle limit (deg), in (0, 180].
    starts : int
        Starts (>= 3).
    seed : int
        The seed of the starts' offsets.

    Returns
    -------
    pandas.DataFrame
        One row per start.
    """
    angle = math.radians(checks.number("angle_deg", angle_deg, positive=True))
    if angle > math.pi:
        raise ValueError(f"angle_deg must be at most 180, got {angle_deg}")
    K = checks.integer("starts", starts, minimum=3)
    ref = eight(2.0, math.pi / 4)
    rng = np.random.default_rng(seed)
    S0 = np.concatenate([PAPER_Z0, PAPER_DZ0])[None] + START_SPREAD * rng.standard_normal((K, 6))
    runs = switched_runs(body, gains, ref, np.full(K, angle), None, s0=S0, n_periods=BURN_IN + LIMIT_PERIODS,
                         lyapunov_from=BURN_IN, record=(BURN_IN + LIMIT_PERIODS - RMS_PERIODS, _RMS_SAMPLES))
    T = ref.period
    lam, lam_se = block_statistics(runs.log_growth[:, :LIMIT_PERIODS], _LIMIT_BLOCK)
    t = runs.t[BURN_IN:]
    p = runs.states[:, BURN_IN:, 2] - ref.z(t)[:, 2][None]
    drift, drift_se = heading_drift(p[:, ::_LIMIT_BLOCK], _LIMIT_BLOCK)
    n = RMS_PERIODS * _RMS_SAMPLES
    rec, rt = runs.recorded[:, :n], runs.recorded_t[:n]
    d2 = np.sum((rec[..., :2] - ref.z(rt)[None, :, :2]) ** 2, axis=2).reshape(K, RMS_PERIODS, _RMS_SAMPLES).mean(axis=2)
    ms, ms_se = block_statistics(d2, RMS_BLOCK)
    rms = np.sqrt(ms)
    _, short_se = batch_means(d2.reshape(K, -1, RMS_BLOCK).mean(axis=2))      # blocks of 2 periods, as asked
    first = runs.states[:, BURN_IN].copy()
    first[:, 2] = np.mod(first[:, 2], 2 * np.pi)
    gaps = np.abs(first[:, None] - first[None])
    gaps[..., 2] = np.minimum(gaps[..., 2], 2 * np.pi - gaps[..., 2])
    gap = gaps.max(axis=2)[np.triu_indices(K, 1)].min()
    frame = pd.DataFrame(dict(lyapunov=lam / T, lyapunov_stderr=lam_se / T, drift=drift, drift_stderr=drift_se,
                              rms=rms, rms_stderr=ms_se / (2 * rms), rms_stderr_short=short_se / (2 * rms),
                              rms_tau=integrated_time(d2)))
    frame.attrs["separation"] = float(gap)
    return frame


def rotation_ensemble(body: Body, R: float, Theta: float, starts: int = ROTATION_STARTS, *,
                      seed: int = 0, **options) -> pd.DataFrame:
    """``starts`` runs of the reduced rotation (32) on the eight at (R (m), Theta (rad/s)), from
    distinct random starts p(0) uniform in [-pi, pi) rad and dp/dt(0) uniform in
    [-Theta/2, Theta/2) rad/s (``seed``), each decided by
    :func:`lib.rotation.verdicts.eight_rotation_sweep` with the map's defaults (or ``options``,
    the procedure's, e.g. a longer Lyapunov run): the frame of that function, one row per start
    (regime, lyapunov, lyapunov_stderr, slip, slip_stderr, ...).

    Parameters
    ----------
    body : Body
        The body.
    R : float
        The eight's size (m), > 0.
    Theta : float
        Its rate (rad/s), > 0.
    starts : int
        Starts (>= 3).
    seed : int
        The seed of the starts.
    **options
        The procedure's options (:data:`lib.rotation.verdicts.VERDICT_DEFAULTS`).

    Returns
    -------
    pandas.DataFrame
        One row per start.
    """
    R = checks.number("R", R, positive=True)
    Theta = checks.number("Theta", Theta, positive=True)
    K = checks.integer("starts", starts, minimum=3)
    p0, v0 = _rotation_starts(K, Theta, seed)
    return eight_rotation_sweep(body, np.full(K, R), np.full(K, Theta), p0=p0, v0=v0, **options)


def _rotation_starts(K: int, Theta: float, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """The K random starts of :func:`rotation_ensemble`: p(0) (rad) and dp/dt(0) (rad/s)."""
    rng = np.random.default_rng(seed)
    return rng.uniform(-np.pi, np.pi, K), rng.uniform(-0.5, 0.5, K) * Theta


def heading_variogram(body: Body, R: float, Theta: float, lags=VARIOGRAM_LAGS, starts: int = VARIOGRAM_STARTS, *,
                      seed: int = 0, transient: int = VERDICT_DEFAULTS["transient"]) -> pd.Series:
    """How far the heading of the reduced rotation (32) on the eight at (R (m), Theta (rad/s))
    moves in tau periods: the variance (turns^2) of p(t + tau) - p(t) at the sections
    (t = 0 mod T) over the random starts of :func:`rotation_ensemble` (same ``seed``) and
    over every t from the end of the ``transient`` (periods; the verdicts' by default) on, for
    each lag of ``lags`` (periods), each start run 2 max(lags) periods past it on the verdict map
    (:func:`lib.rotation.engine.verdict_steps` at the verdicts' h omega). It tells the drift's
    memory apart: a variance that grows as tau is a heading that slips at random, as the
    batch means of :func:`lib.dynamics.statistics.drift_statistics` assume; one that stays
    flat is a heading that oscillates without slipping, whose increments cancel; one that
    grows faster than tau has slips that persist beyond a block.

    Parameters
    ----------
    body : Body
        The body.
    R : float
        The eight's size (m), > 0.
    Theta : float
        Its rate (rad/s), > 0.
    lags : sequence of int
        Lags (periods), each >= 1.
    starts : int
        Starts (>= 3).
    seed : int
        The seed of the starts.
    transient : int
        Periods run before the first section (>= 0).

    Returns
    -------
    pandas.Series
        The variance (turns^2), indexed by the lag (periods).
    """
    checks.instance("body", body, Body)
    R = checks.number("R", R, positive=True)
    Theta = checks.number("Theta", Theta, positive=True)
    K = checks.integer("starts", starts, minimum=3)
    transient = checks.integer("transient", transient, minimum=0)
    lag = np.asarray(lags)
    if lag.ndim != 1 or lag.size == 0 or not np.issubdtype(lag.dtype, np.integer) or (lag < 1).any():
        raise ValueError(f"lags must be positive whole numbers of periods, got {lags!r}")
    p0, v0 = _rotation_starts(K, Theta, seed)
    RR, TT = np.full(K, R), np.full(K, Theta)
    eng = _Engine("eight", int(verdict_steps(body, "eight", RR[:1], TT[:1], VERDICT_DEFAULTS["h_verdict"])[0]),
                  "numba")
    A, B, C = coefficients(body, RR, TT)
    phi, w = _initial("eight", TT, p0, v0)
    if transient:
        o = eng.flow(phi, w, A, B, C, transient)
        phi, w = o["phi"] - eng.w2pi * transient, o["w"]
    n = 2 * int(lag.max())
    o = eng.flow(phi, w, A, B, C, n)
    sec = o["sec"][:, :, 0] - eng.w2pi * np.arange(1, n + 1)[:, None]          # (n, K), the eight: no winding
    var = [float(np.var((sec[k:] - sec[:-k]) / (2 * np.pi))) for k in lag]
    return pd.Series(var, index=pd.Index(lag, name="lag (periods)"), name="variance (turns^2)")


def move_counts(lam1, se1, blocks1, lam2, se2, blocks2, sigmas: float = 3.0) -> dict:
    """How many of M pairs of estimates of one quantity, each with its batch-means error from its
    own number of blocks, differ by more than ``sigmas`` combined errors sqrt(se1^2 + se2^2),
    against the count expected of honest errors: under a normal law, and under the t law of
    Welch's degrees of freedom (se1^2 + se2^2)^2 / (se1^4 / (b1 - 1) + se2^4 / (b2 - 1)), which an
    error read from few blocks follows (its tail is heavier: at 6 blocks each, 10 degrees of
    freedom put 1.3 % beyond 3, the normal law 0.27 %). Returns a dict: points (M), moved,
    normal, t (the expected counts) and spread (the standard deviation of the differences in
    combined errors, 1 for honest errors).

    Parameters
    ----------
    lam1, se1, blocks1, lam2, se2, blocks2 : array_like
        The two estimates (M,), their errors (M,, > 0) and their blocks (M,, >= 2).
    sigmas : float
        The threshold, in combined errors (> 0).

    Returns
    -------
    dict
        points, moved, normal, t, spread.
    """
    a = [np.asarray(x, dtype=float) for x in (lam1, se1, blocks1, lam2, se2, blocks2)]
    if any(x.ndim != 1 or x.shape != a[0].shape for x in a) or a[0].size < 2:
        raise ValueError("the six arrays must be 1-D of one length, at least 2")
    l1, s1, b1, l2, s2, b2 = a
    if not (np.all(np.isfinite(np.concatenate(a))) and np.all(s1 > 0) and np.all(s2 > 0)
            and np.all(b1 >= 2) and np.all(b2 >= 2)):
        raise ValueError("estimates must be finite, errors positive and blocks at least 2")
    sigmas = checks.number("sigmas", sigmas, positive=True)
    v = s1 ** 2 + s2 ** 2
    z = (l1 - l2) / np.sqrt(v)
    dof = v ** 2 / (s1 ** 4 / (b1 - 1) + s2 ** 4 / (b2 - 1))
    return dict(points=int(z.size), moved=int((np.abs(z) > sigmas).sum()),
                normal=float(z.size * 2 * stats.norm.sf(sigmas)), t=float(np.sum(2 * stats.t.sf(sigmas, dof))),
                spread=float(z.std(ddof=1)))


def exponent_moves(body: Body, frame: pd.DataFrame, *, steps_factor: int = 2, every: int = 1,
                   sigmas: float = 3.0) -> dict:
    """The exponents of a Fig. 5 map's chaotic points (every ``every``-th) decided again, from the
    same starts, on the verdict map of ``steps_factor`` times its steps, whose rounding and
    truncation send each run along another trajectory of the same attractor: :func:`move_counts`
    of the pairs decided chaotic on both (blocks: the batches of each error, the Lyapunov run's
    periods over the verdicts' block, merged as :func:`lib.dynamics.statistics.batch_means`
    merges them). With ``steps_factor`` = 1 the decision is repeated bit for bit, and nothing
    moves.

    Parameters
    ----------
    body : Body
        The body of the map.
    frame : pandas.DataFrame
        A frame of :func:`lib.rotation.fig5.fig5_map` (or of
        :func:`lib.rotation.verdicts.eight_rotation_sweep`) on the eight.
    steps_factor : int
        Steps of the second map over the first's (>= 1).
    every : int
        Take every ``every``-th chaotic point (>= 1).
    sigmas : float
        The threshold, in combined errors.

    Returns
    -------
    dict
        The dict of :func:`move_counts`, and ``chaotic`` (the chaotic points taken).
    """
    checks.instance("body", body, Body)
    need = {"R", "Theta", "regime", "lyapunov", "lyapunov_stderr", "periods", "verdict_steps", "steps",
            "period", "slip", "orbit_p"}
    missing = need - set(getattr(frame, "columns", ()))
    if missing:
        raise ValueError(f"frame: a frame of the Fig. 5 map, missing columns {sorted(missing)}")
    steps_factor = checks.integer("steps_factor", steps_factor, minimum=1)
    every = checks.integer("every", every, minimum=1)
    rows = np.flatnonzero((frame.regime == "chaotic").to_numpy())[::every]
    if rows.size < 2:
        raise ValueError(f"frame has {rows.size} chaotic points to take, need at least 2")
    opts = _verdict_options(dict(drift_periods=0))       # the exponent is compared: no drift run on
    out = _redo(body, "eight", frame, rows, opts, steps_factor=steps_factor)
    both = out["regime"] == "chaotic"
    first = frame.iloc[rows[both]]
    def blocks(periods):        # the batches behind each error: the blocks, merged as a long run's are
        return batch_grouping((np.asarray(periods) - opts["transient"]) // opts["block"], opts["block"])[1]
    res = move_counts(first.lyapunov, first.lyapunov_stderr, blocks(first.periods), out["lyapunov"][both],
                      out["lyapunov_stderr"][both], blocks(out["periods"][both]), sigmas)
    return dict(res, chaotic=int(rows.size))


def _rows(setting: str, frame: pd.DataFrame, columns, level: float) -> list:
    return [dict(setting=setting, estimator=name, **ensemble_ratio(frame[x], frame[se], level))
            for name, x, se in columns]


def calibration_study(body: Body, gains: Gains, *, limit_starts: int = LIMIT_STARTS,
                      rotation_starts: int = ROTATION_STARTS, level: float = LEVEL, seed: int = 0) -> pd.DataFrame:
    """The ensemble study of the Methods page: :func:`ensemble_ratio` of every estimator the
    book quotes with an error or decides a verdict by, at each angle limit of
    :data:`LIMIT_DEG` (:func:`limit_ensemble`, ``limit_starts`` starts: the exponent, the
    drift, the RMS distance) and at each Fig. 5 point of :data:`FIG5_POINTS`
    (:func:`rotation_ensemble`, ``rotation_starts`` starts: the exponent and the drift, over
    the starts the map decides ``chaotic``). One row per setting and estimator: setting,
    estimator, K, mean, spread, stderr, ratio, lo, hi, and: flow ("limit" or "rotation"),
    chaotic (starts decided chaotic, of ``starts``; all of them for the limit runs, which
    are not decided) and separation (the limit runs' smallest distance between two starts
    after the burn-in, NaN for the rotation), R and Theta (the Fig. 5 point, m and rad/s; NaN for
    the limit runs) and tau (the median integrated autocorrelation time
    of the RMS's per-period mean squares, periods; NaN for the other estimates). The rows of
    estimator :data:`SHORT_BLOCKS` are not an estimator the book uses: the RMS's error from fixed
    blocks of 2 periods, shorter than that memory, for comparison.

    Parameters
    ----------
    body, gains : Body, Gains
        The body and the gains of (23).
    limit_starts, rotation_starts : int
        Starts per setting (>= 3).
    level : float
        The confidence level of the intervals.
    seed : int
        The seed of the starts.

    Returns
    -------
    pandas.DataFrame
        One row per setting and estimator.
    """
    checks.instance("body", body, Body)
    checks.instance("gains", gains, Gains)
    limit_starts = checks.integer("limit_starts", limit_starts, minimum=3)
    rotation_starts = checks.integer("rotation_starts", rotation_starts, minimum=3)
    if not 0 < level < 1:
        raise ValueError(f"level must lie in (0, 1), got {level}")
    rows = []
    for deg in LIMIT_DEG:
        fr = limit_ensemble(body, gains, deg, limit_starts, seed=seed)
        for r in _rows(f"{deg} deg", fr, (("exponent", "lyapunov", "lyapunov_stderr"),
                                          ("drift", "drift", "drift_stderr"), ("RMS", "rms", "rms_stderr"),
                                          (SHORT_BLOCKS, "rms", "rms_stderr_short")), level):
            rows.append(dict(r, flow="limit", chaotic=limit_starts, separation=fr.attrs["separation"], R=np.nan,
                             Theta=np.nan,
                             tau=float(np.median(fr.rms_tau)) if r["estimator"].startswith("RMS") else np.nan))
    n = FIG5_GRID["n"]
    Rg, Tg = np.linspace(*FIG5_GRID["R"], n), np.linspace(*FIG5_GRID["Theta"], n)
    for i, j in FIG5_POINTS:
        fr = rotation_ensemble(body, Rg[i], Tg[j], rotation_starts, seed=seed)
        ch = fr[fr.regime == "chaotic"]
        label = f"R = {Rg[i]:.2f} m, Theta = {Tg[j]:.2f} rad/s"
        for r in _rows(label, ch, (("exponent", "lyapunov", "lyapunov_stderr"), ("drift", "slip", "slip_stderr")),
                       level):
            rows.append(dict(r, flow="rotation", chaotic=len(ch), separation=np.nan, tau=np.nan, R=Rg[i],
                             Theta=Tg[j]))
    return pd.DataFrame(rows)


def ratio_table(study: pd.DataFrame) -> pd.DataFrame:
    """:func:`calibration_study`'s ratios as the Methods page shows them: one row a setting, its
    starts K, and one column an estimator, each cell "ratio (interval)", the ratio of the spread
    over the starts to the mean standard error and its confidence interval; "-" where the setting
    has no such estimate (the reduced rotation has no RMS distance). The study's rows of the
    short, fixed blocks (:data:`SHORT_BLOCKS`) are left out.

    Parameters
    ----------
    study : pandas.DataFrame
        The frame of :func:`calibration_study` (columns setting, estimator, K, ratio, lo, hi).

    Returns
    -------
    pandas.DataFrame
        Columns setting, K starts, then one per estimator, in the study's order.
    """
    missing = {"setting", "estimator", "K", "ratio", "lo", "hi"} - set(getattr(study, "columns", ()))
    if missing:
        raise ValueError(f"study: a frame of calibration_study, missing columns {sorted(missing)}")
    cal = study[study.estimator != SHORT_BLOCKS]
    cells = cal.assign(cell=[f"{r:.2f} ({a:.2f}-{b:.2f})" for r, a, b in zip(cal.ratio, cal.lo, cal.hi)])
    settings = list(dict.fromkeys(cal.setting))
    wide = cells.pivot(index="setting", columns="estimator", values="cell").reindex(settings)
    wide = wide[list(dict.fromkeys(cal.estimator))].fillna("-")
    starts = cal.groupby("setting").K.first().reindex(settings)
    return pd.concat([starts.rename("K starts"), wide], axis=1).reset_index()
