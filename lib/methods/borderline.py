"""The calibration where the verdicts are decided (the Methods page, "How large an error bar
is"): the Fig. 5 points whose lost or chaotic verdict lies near its line of
:data:`lib.dynamics.verdicts.SIGMAS` standard errors, the spread of the same estimates over
independent starts there (:func:`borderline_study`), a sign test of the lean of the spread-to-error
ratios (:func:`sign_test`), and the t law that an error read from a few batches follows
(:func:`t_threshold`, :func:`verdict_changes`).

Two statistics decide the words, each a number of standard errors (:mod:`lib.dynamics.verdicts`):
a run that reaches no orbit is ``lost`` when z = (|drift| - slip band) / SE exceeds 3, and
``chaotic`` when z = lambda T / SE exceeds 3 (and lambda T the band). An error read from B batch
means has B - 1 degrees of freedom: under honest errors z follows Student's t law on B - 1
degrees of freedom, not the normal law. That has two consequences measured here. The mean
reported error is below the spread of the estimates by the factor c4(B) (0.95 at 6 batches),
so the ratio spread / mean error of an honest error leans above 1, by about 1 / c4: the ratio
an honest error shows at the starts measured is sqrt(mean SE^2) / mean SE (``honest`` of
:func:`lib.methods.calibration.ensemble_ratio`). And a line at 3 errors is crossed by chance
more often than the normal tail says; the t quantile of the same tail, :func:`t_threshold`, is
the correction.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy import special, stats

from ..machinery import checks
from ..params import Body
from ..rotation.verdicts import VERDICT_DEFAULTS
from .calibration import ensemble_ratio, rotation_ensemble
from ..dynamics.statistics import batch_grouping
from ..dynamics.verdicts import ORBIT_REGIMES, SIGMAS, TRANSIENT

__all__ = ["TESTS", "BORDERLINE_STARTS", "PER_SIDE", "WIDTH", "t_threshold", "honest_lean", "verdict_statistics",
           "borderline_points", "borderline_study", "borderline_table", "sign_test", "verdict_changes"]

#: the two verdicts decided at SIGMAS standard errors, and the words they decide
TESTS = ("lost", "chaotic")
#: independent starts per borderline point (a ratio's interval about 0.85 to 1.2 times it)
BORDERLINE_STARTS = 64
#: points taken on each side of each line, the nearest to it
PER_SIDE = 2
#: a verdict is borderline when its statistic lies within this many standard errors of the line
WIDTH = 1.0


def t_threshold(batches, sigmas: float = SIGMAS):
    """The line, in standard errors, that an error read from ``batches`` batch means (B - 1
    degrees of freedom) crosses by chance as often as a normal error crosses ``sigmas``: Student's
    t quantile t_{B-1}(1 - Phi(-sigmas)), one tail. 5.51 at 6 batches, 3.34 at 25, 3 in the limit.

    Parameters
    ----------
    batches : int or array_like
        Batch means behind each error (>= 2).
    sigmas : float
        The normal line (> 0).

    Returns
    -------
    float or numpy.ndarray
        The line, in standard errors, of the shape of ``batches``.
    """
    b = np.asarray(batches)
    if not np.issubdtype(b.dtype, np.number) or b.size == 0 or not np.all(b >= 2):
        raise ValueError(f"batches must be whole numbers of batch means >= 2, got {batches!r}")
    sigmas = checks.number("sigmas", sigmas, positive=True)
    q = stats.t.isf(stats.norm.sf(sigmas), b - 1)
    return float(q) if np.ndim(q) == 0 else q


def honest_lean(batches):
    """The ratio spread / mean error that honest errors, each read from ``batches`` independent
    normal batch means, show over many starts: 1 / c4(B), c4(B) = sqrt(2 / (B - 1))
    Gamma(B / 2) / Gamma((B - 1) / 2) the mean of a sample standard deviation over the one it
    estimates. 1.051 at 6 batches, 1.010 at 25, 1 in the limit.

    Parameters
    ----------
    batches : int or array_like
        Batch means behind each error (>= 2).

    Returns
    -------
    float or numpy.ndarray
        1 / c4(B), of the shape of ``batches``.
    """
    b = np.asarray(batches)
    if not np.issubdtype(b.dtype, np.number) or b.size == 0 or not np.all(b >= 2):
        raise ValueError(f"batches must be whole numbers of batch means >= 2, got {batches!r}")
    b = b.astype(float)
    lean = 1 / np.exp(0.5 * np.log(2 / (b - 1)) + special.gammaln(b / 2) - special.gammaln((b - 1) / 2))
    return float(lean) if np.ndim(lean) == 0 else lean


def verdict_statistics(frame: pd.DataFrame) -> pd.DataFrame:
    """Each Fig. 5 point's two statistics, in standard errors, and the batches behind each error
    (the map's options, :data:`lib.rotation.verdicts.VERDICT_DEFAULTS`): ``lost_z`` = (|slip| -
    slip band) / slip_stderr for a run that reached no orbit (NaN on an orbit, whose slip is
    exact), over ``lost_batches`` batches of its drift's run (``drift_periods``); ``chaotic_z`` =
    lambda / SE for a run that reached no orbit and whose exponent clears the band (NaN where the
    band decides), over ``chaotic_batches`` batches of its Lyapunov run (``periods`` less the
    transient). Both as :func:`lib.dynamics.statistics.batch_grouping` merges the blocks. The rule
    says lost / chaotic where the statistic exceeds :data:`lib.dynamics.verdicts.SIGMAS`.

    Parameters
    ----------
    frame : pandas.DataFrame
        A frame of :func:`lib.rotation.fig5.fig5_map`.

    Returns
    -------
    pandas.DataFrame
        lost_z, lost_batches, chaotic_z, chaotic_batches, on the frame's index.
    """
    need = {"regime", "Theta", "lyapunov", "lyapunov_stderr", "slip", "slip_stderr", "periods", "drift_periods"}
    missing = need - set(getattr(frame, "columns", ()))
    if missing:
        raise ValueError(f"frame: a frame of the Fig. 5 map, missing columns {sorted(missing)}")
    o = VERDICT_DEFAULTS
    free = ~frame.regime.isin(ORBIT_REGIMES).to_numpy()
    se = frame.slip_stderr.to_numpy(dtype=float)
    drift = free & np.isfinite(se) & (se > 0)
    with np.errstate(invalid="ignore", divide="ignore"):
        lost_z = np.where(drift, (np.abs(frame.slip.to_numpy(dtype=float)) - o["slip_band"]) / se, np.nan)
        lam = frame.lyapunov.to_numpy(dtype=float) * 2 * np.pi / frame.Theta.to_numpy(dtype=float)   # per period
        lse = frame.lyapunov_stderr.to_numpy(dtype=float) * 2 * np.pi / frame.Theta.to_numpy(dtype=float)
        expo = free & np.isfinite(lse) & (lse > 0) & (lam > o["lyapunov_band"])
        chaotic_z = np.where(expo, lam / lse, np.nan)
    block = o["block"]
    nb_drift = np.maximum(frame.drift_periods.to_numpy() // block, 1)
    nb_expo = np.maximum((frame.periods.to_numpy() - o["transient"]) // block, 1)
    return pd.DataFrame(dict(lost_z=lost_z, lost_batches=np.where(drift, batch_grouping(nb_drift, block)[1], 0),
                             chaotic_z=chaotic_z,
                             chaotic_batches=np.where(expo, batch_grouping(nb_expo, block)[1], 0)),
                        index=frame.index)


def borderline_points(frame: pd.DataFrame, test: str, per_side: int = PER_SIDE, width: float = WIDTH,
                      sigmas: float = SIGMAS) -> np.ndarray:
    """The Fig. 5 points whose ``test`` verdict (``"lost"`` or ``"chaotic"``) lies within ``width``
    standard errors of its line at ``sigmas`` (:func:`verdict_statistics`): the ``per_side``
    nearest to the line above it (the verdict said) and the ``per_side`` nearest at or below it
    (not said), ties in the frame's order, so the choice is the same on every run. Points whose
    attractor is not determined (``transient``) are left out: starts there reach different
    attractors by construction. Returns their positions in the frame (iloc), in the frame's order.

    Parameters
    ----------
    frame : pandas.DataFrame
        A frame of :func:`lib.rotation.fig5.fig5_map`.
    test : str
        ``"lost"`` or ``"chaotic"``.
    per_side : int
        Points on each side (>= 1).
    width : float
        Standard errors either side of the line (> 0).
    sigmas : float
        The line (> 0).

    Returns
    -------
    numpy.ndarray
        Positions (int), at most 2 ``per_side``.
    """
    checks.one_of("test", test, TESTS)
    per_side = checks.integer("per_side", per_side, minimum=1)
    width = checks.number("width", width, positive=True)
    sigmas = checks.number("sigmas", sigmas, positive=True)
    z = verdict_statistics(frame)[f"{test}_z"].to_numpy()
    ok = np.isfinite(z) & (np.abs(z - sigmas) <= width) & (frame.regime != TRANSIENT).to_numpy()
    picked = []
    for side in (ok & (z > sigmas), ok & (z <= sigmas)):
        rows = np.flatnonzero(side)
        picked += rows[np.argsort(np.abs(z[rows] - sigmas), kind="stable")[:per_side]].tolist()
    return np.array(sorted(picked), dtype=int)


def borderline_study(body: Body, frame: pd.DataFrame, starts: int = BORDERLINE_STARTS, *,
                     per_side: int = PER_SIDE, seed: int = 0) -> pd.DataFrame:
    """The ensemble study of :mod:`lib.methods.calibration` at the points of
    :func:`borderline_points` for each test of :data:`TESTS`: ``starts`` random starts at each
    (:func:`lib.methods.calibration.rotation_ensemble`), decided by the map's procedure over the
    horizon the point's verdict rests on (a drift decided again over a longer run,
    :func:`lib.rotation.fig5.confirm_lost`, is run that long, without an early exit), and
    :func:`lib.methods.calibration.ensemble_ratio` of the exponent and of the drift over the
    starts that reach no orbit. One row per point and estimator: test, side ("above" or
    "below" the line), setting, R (m), Theta (rad/s), z (the map's statistic, standard errors),
    horizon (periods of Lyapunov run the verdict rests on), free (starts reaching no orbit, of
    ``starts``), early (of those, the starts that left the Lyapunov run early, clearly chaotic),
    estimator, and the keys of ``ensemble_ratio`` (K, mean, spread, stderr, ratio, lo, hi,
    honest).

    Parameters
    ----------
    body : Body
        The body of the map.
    frame : pandas.DataFrame
        A frame of :func:`lib.rotation.fig5.fig5_map`.
    starts : int
        Starts per point (>= 3).
    per_side : int
        Points on each side of each line.
    seed : int
        The seed of the starts.

    Returns
    -------
    pandas.DataFrame
        One row per point and estimator.
    """
    checks.instance("body", body, Body)
    starts = checks.integer("starts", starts, minimum=3)
    stat = verdict_statistics(frame)
    o = VERDICT_DEFAULTS
    rows = []
    for test in TESTS:
        for i in borderline_points(frame, test, per_side):
            r = frame.iloc[i]
            horizon = int(r.drift_periods) if test == "lost" else int(r.periods) - o["transient"]
            longer = test == "lost" and horizon > o["drift_periods"]
            opts = dict(lyapunov_periods=horizon, min_lyapunov_periods=horizon) if longer else {}
            ens = rotation_ensemble(body, r.R, r.Theta, starts, seed=seed, **opts)
            free = ens[~ens.regime.isin(ORBIT_REGIMES)]
            early = int((free.periods < o["transient"] + (horizon if longer else o["lyapunov_periods"])).sum())
            z = stat[f"{test}_z"].iloc[i]
            base = dict(test=test, side="above" if z > SIGMAS else "below",
                        setting=f"R = {r.R:.2f} m, Theta = {r.Theta:.2f} rad/s", R=r.R, Theta=r.Theta, z=z,
                        horizon=horizon, free=len(free), early=early)
            for name, x, se in (("exponent", "lyapunov", "lyapunov_stderr"), ("drift", "slip", "slip_stderr")):
                good = free[np.isfinite(free[x]) & (free[se] > 0)]
                if len(good) >= 3:
                    rows.append(dict(base, estimator=name, **ensemble_ratio(good[x], good[se])))
    return pd.DataFrame(rows)


def sign_test(ratios, reference=1.0, alternative: str = "greater") -> dict:
    """The sign test of a lean: of n ratios (ties with ``reference`` left out), how many lie above
    their ``reference`` (one value, or one per ratio), against a fair coin
    (:func:`scipy.stats.binomtest`, p = 1/2). ``alternative`` "greater" asks whether they lie
    above more often than by chance: for spread / error, errors too small. Returns a dict: above,
    n, pvalue.

    Parameters
    ----------
    ratios : array_like
        The ratios (n,), finite.
    reference : float or array_like
        What each would be without a lean: 1, or an honest error's ratio.
    alternative : str
        "greater", "less" or "two-sided".

    Returns
    -------
    dict
        above, n, pvalue.
    """
    r = np.asarray(ratios, dtype=float)
    if r.ndim != 1 or r.size == 0 or not np.all(np.isfinite(r)):
        raise ValueError(f"ratios must be finite values (n,), got {ratios!r}")
    ref = np.broadcast_to(np.asarray(reference, dtype=float), r.shape) if np.ndim(reference) == 0 else \
        np.asarray(reference, dtype=float)
    if ref.shape != r.shape or not np.all(np.isfinite(ref)):
        raise ValueError(f"reference must be one finite value or one per ratio ({r.size}), got {reference!r}")
    checks.one_of("alternative", alternative, ("greater", "less", "two-sided"))
    untied = r != ref
    n, above = int(untied.sum()), int((r > ref).sum())
    if n == 0:
        raise ValueError("ratios: every ratio ties with its reference; nothing to test")
    return dict(above=above, n=n, pvalue=float(stats.binomtest(above, n, 0.5, alternative=alternative).pvalue))


def verdict_changes(frame: pd.DataFrame, sigmas: float = SIGMAS) -> dict:
    """How many of a Fig. 5 map's lost and chaotic verdicts the t law would change: each point's
    statistic (:func:`verdict_statistics`) against :func:`t_threshold` of its batches in place of
    ``sigmas``. The t line lies above the normal one, so a verdict can only be withdrawn; a
    withdrawn chaotic verdict that left the Lyapunov run early would first run on, so these are
    the verdicts whose statistic lies between the two lines. Returns a dict: lost (all lost
    headings), lost_drift (of them, decided by the drift test, without an orbit; the others slip
    on an orbit, exactly), lost_changed, chaotic, chaotic_changed, chaotic_early (of the changed,
    those that left the Lyapunov run early) and lines (the t lines met, in standard errors, by
    their batches).

    Parameters
    ----------
    frame : pandas.DataFrame
        A frame of :func:`lib.rotation.fig5.fig5_map`.
    sigmas : float
        The normal line.

    Returns
    -------
    dict
        lost, lost_drift, lost_changed, chaotic, chaotic_changed, chaotic_early, lines.
    """
    sigmas = checks.number("sigmas", sigmas, positive=True)
    stat = verdict_statistics(frame)
    lost = frame.lost.to_numpy(dtype=bool)
    by_drift = lost & np.isfinite(stat.lost_z.to_numpy())
    chaotic = (frame.regime == "chaotic").to_numpy()
    lines = {}

    def under(z, b, rows):
        bb = b[rows]
        q = t_threshold(bb, sigmas) if rows.any() else np.array([])
        lines.update({int(k): float(v) for k, v in zip(bb, np.atleast_1d(q))})
        out = np.zeros(z.size, bool)
        out[rows] = z[rows] <= q
        return out

    lost_changed = under(stat.lost_z.to_numpy(), stat.lost_batches.to_numpy(), by_drift)
    chaotic_changed = under(stat.chaotic_z.to_numpy(), stat.chaotic_batches.to_numpy(), chaotic)
    early = frame.periods.to_numpy() < VERDICT_DEFAULTS["transient"] + VERDICT_DEFAULTS["lyapunov_periods"]
    return dict(lost=int(lost.sum()), lost_drift=int(by_drift.sum()), lost_changed=int(lost_changed.sum()),
                chaotic=int(chaotic.sum()), chaotic_changed=int(chaotic_changed.sum()),
                chaotic_early=int((chaotic_changed & early).sum()), lines=dict(sorted(lines.items())))


def borderline_table(study: pd.DataFrame) -> pd.DataFrame:
    """:func:`borderline_study` as the Methods page shows it: one row a point, the line it lies
    near (test) and its side, the point, the map's statistic (standard errors), the horizon
    (periods), the starts that reach no orbit and how many of them left the Lyapunov run early,
    and for the exponent and the drift "ratio (interval)", the ratio of the spread over the starts
    to the mean error.

    Parameters
    ----------
    study : pandas.DataFrame
        The frame of :func:`borderline_study`.

    Returns
    -------
    pandas.DataFrame
        One row per point.
    """
    need = {"test", "side", "setting", "z", "horizon", "free", "early", "estimator", "ratio", "lo", "hi"}
    missing = need - set(getattr(study, "columns", ()))
    if missing:
        raise ValueError(f"study: a frame of borderline_study, missing columns {sorted(missing)}")
    cell = [f"{r:.3g} ({a:.3g}-{b:.3g})" for r, a, b in zip(study.ratio, study.lo, study.hi)]
    keys = ["test", "side", "setting"]
    wide = study.assign(cell=cell).pivot(index=keys, columns="estimator", values="cell")
    first = study.drop_duplicates(keys).set_index(keys)
    out = pd.DataFrame({"line, side": [f"{t}, {s}" for t, s, _ in first.index],
                        "point": [p for _, _, p in first.index], "z (errors)": [f"{z:.2f}" for z in first.z],
                        "horizon (periods)": first.horizon.to_numpy(),
                        "starts: no orbit, early": [f"{f}, {e}" for f, e in zip(first.free, first.early)]})
    cells = wide.reindex(first.index)[[c for c in ("exponent", "drift") if c in wide]].fillna("-")
    return pd.concat([out, cells.reset_index(drop=True)], axis=1)
