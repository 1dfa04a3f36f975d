"""Chapter 6: what weighting the heading in the allocation does, over many parameter points.

The position-only law (25)-(26) leaves the heading to itself; the weighted
allocation :func:`lib.allocation.allocate_least_squares` trades position tracking
for heading tracking through the weight w_phi. This module maps that trade-off over
the (R, Theta) plane of Fig. 5: the verdicts of both laws compared on one map, the
weight where the eight stops being held, the limits' effect. The batch runs are in
:mod:`lib.weighting.batch`, the verdicts in :mod:`lib.weighting.verdicts`, the circle's exact
answer in :mod:`lib.weighting.circle`; all re-exported here.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..machinery import checks
from ..dynamics import verdicts as dv
from ..dynamics.verdicts import REGIMES
from .batch import BatchResult, closed_loop_batch, steady_metrics  # re-exported
from .verdicts import LOOP_VERDICT_DEFAULTS, _points, closed_loop_verdicts
from ..params import Body, Gains
from ..trajectories import KINEMATICS
from .circle import circle_error_weight, circle_steady_state, circle_weight_limit, circle_weight_sweep

__all__ = ["BatchResult", "closed_loop_batch", "steady_metrics", "LOOP_VERDICT_DEFAULTS", "closed_loop_verdicts",
           "verdict_runs", "held", "stability_boundary", "refine_boundary", "extend_undecided", "MapComparison", "compare_on_map",
           "limits_comparison", "circle_steady_state", "circle_weight_limit", "circle_weight_sweep",
           "circle_error_weight"]


def held(frame: pd.DataFrame) -> np.ndarray:
    """(N,) bool, the book's one definition of "held" (:func:`lib.dynamics.verdicts.held`):
    the closed loop reaches an attracting periodic orbit (verdict ``periodic``), the heading is
    not lost, and the position is tracked (column ``tracked`` of :func:`closed_loop_verdicts`).

    Parameters
    ----------
    frame : pandas.DataFrame
        A frame of :func:`closed_loop_verdicts`.

    Returns
    -------
    numpy.ndarray
        One bool per row.
    """
    return dv.held(frame.regime.to_numpy(), frame.lost.to_numpy(), frame.tracked.to_numpy())


def verdict_runs(body: Body, gains: Gains, runs: dict, **options) -> dict:
    """Several sets of points through ONE call of :func:`closed_loop_verdicts` (the batch
    integrator's cost is mostly per step, not per point, so one call is much cheaper than
    several). ``runs`` maps a name to a dict with ``kind``, ``R``, ``Theta`` and optionally
    ``weights`` ((3,) or (N, 3)), ``z0``, ``dz0`` ((3,) or (N, 3)); ``options`` go to
    :func:`closed_loop_verdicts` (``executor`` and ``chunk_size`` too: the points of all runs are
    chunked together).

    Parameters
    ----------
    body : Body
        The plant.
    gains : Gains
        The gains of (23).
    runs : dict
        Name -> dict(kind, R (m), Theta (rad/s), [weights, z0 (m, m, rad), dz0]).
    **options
        Keywords of :func:`closed_loop_verdicts` (``executor``, ``chunk_size``, ``progress`` too).

    Returns
    -------
    dict of pandas.DataFrame
        The frames by name, each indexed from 0.
    """
    if not runs:
        raise ValueError("no runs given")
    parts, sizes = [], []
    for name, r in runs.items():
        unknown = set(r) - {"kind", "R", "Theta", "weights", "z0", "dz0"}
        if unknown or not {"kind", "R", "Theta"} <= set(r):
            raise ValueError(f"run {name!r} needs kind, R, Theta (and optionally weights, z0, dz0); "
                             f"unknown keys {sorted(unknown)}")
        R, Theta, w = _points(r["R"], r["Theta"], r.get("weights", (1.0, 1.0, 0.0)))
        ref = [np.concatenate(KINEMATICS[r["kind"]](R, Theta, 0.0)[:2], axis=1)] if r["kind"] in KINEMATICS else None
        if ref is None:
            raise ValueError(f"runs[{name!r}]['kind'] must be one of {sorted(KINEMATICS)} (the trajectory), "
                             f"got {r['kind']!r}")
        s0 = ref[0]
        for key, sl in (("z0", slice(0, 3)), ("dz0", slice(3, 6))):
            if r.get(key) is not None:
                s0[:, sl] = np.broadcast_to(np.asarray(r[key], dtype=float), (R.size, 3))
        parts.append((np.full(R.size, r["kind"], dtype=object), R, Theta, w, s0))
        sizes.append(R.size)
    kinds, R, Theta, w, s0 = (np.concatenate([p[i] for p in parts]) for i in range(5))
    frame = closed_loop_verdicts(body, gains, kinds, R, Theta, w, z0=s0[:, :3], dz0=s0[:, 3:], **options)
    edges = np.cumsum([0] + sizes)
    return {name: frame.iloc[a:b].reset_index(drop=True) for name, a, b in zip(runs, edges[:-1], edges[1:])}


def stability_boundary(w_phi, frame: pd.DataFrame) -> dict:
    """Where, along increasing weights ``w_phi`` (N,), the verdict of ``frame`` (one row per
    weight, :func:`closed_loop_verdicts`) first stops being :func:`held`: ``last_held`` (the
    largest weight before the first change), ``first_lost`` (the weight at it; NaN if every
    weight holds), ``ratio`` (their quotient, the resolution of the grid there), ``changes``
    (how often the verdict flips along the grid: more than 1 means it is not monotone), and
    ``verdict`` (regime, and "position not tracked" or "heading lost" where so) at ``first_lost``.

    Parameters
    ----------
    w_phi : array_like
        Increasing weights (N,).
    frame : pandas.DataFrame
        Their verdicts (:func:`closed_loop_verdicts`).

    Returns
    -------
    dict
        last_held, first_lost, ratio, changes, verdict.
    """
    w = np.asarray(w_phi, dtype=float)
    if w.ndim != 1 or w.size != len(frame) or w.size < 2 or np.any(np.diff(w) <= 0):
        raise ValueError("w_phi must be an increasing 1-D array with one weight per row of frame")
    h = held(frame)
    if not h[0]:
        raise ValueError(f"the smallest weight {w[0]:g} is not held: no boundary to locate above it")
    bad = np.flatnonzero(~h)
    if bad.size == 0:
        return dict(last_held=float(w[-1]), first_lost=np.nan, ratio=np.nan, changes=0, verdict="held")
    i = int(bad[0])
    r = frame.iloc[i]
    verdict = r.regime + (", position not tracked" if not r.tracked else "") + (", heading lost" if r.lost else "")
    return dict(last_held=float(w[i - 1]), first_lost=float(w[i]), ratio=float(w[i] / w[i - 1]) if w[i - 1] > 0
                else np.inf, changes=int(np.count_nonzero(np.diff(h.astype(int)))), verdict=verdict)


@dataclass(frozen=True)
class MapComparison:
    """The paper's law and the weighted law on the same (R, Theta) points of the eight, from the
    same start, over the same horizon, classified by the same :func:`closed_loop_verdicts`:
    ``paper`` and ``weighted`` are its frames (one row per point, in the same order)."""

    paper: pd.DataFrame
    weighted: pd.DataFrame

    @property
    def lost(self) -> np.ndarray:
        """Whether the heading is lost (it slips) under the paper's law, per point (N,)."""
        return self.paper.lost.to_numpy()

    @property
    def paper_held(self) -> np.ndarray:
        """Whether the paper's law holds the loop (:func:`held`), per point (N,)."""
        return held(self.paper)

    @property
    def held(self) -> np.ndarray:
        """Whether the weighted law holds the loop (:func:`held`), per point (N,)."""
        return held(self.weighted)

    @property
    def counts(self) -> pd.DataFrame:
        """Points per regime, then heading lost (it slips), turns round (the other reading),
        position not tracked, and held (:func:`held`), for each law (columns)."""
        rows = {}
        for law, f in (("paper's law", self.paper), ("weighted law", self.weighted)):
            c = {r: int((f.regime == r).sum()) for r in REGIMES}
            c.update({"heading lost": int(f.lost.sum()), "turns round": int(f.turns_round.sum()),
                      "position not tracked": int((~f.tracked).sum()), "held": int(held(f).sum())})
            rows[law] = c
        return pd.DataFrame(rows)

    @staticmethod
    def _why(f: pd.DataFrame) -> np.ndarray:
        """Why a law does not hold a point, one reason each, in this order: the position is not
        tracked; the heading is lost; the loop is not periodic; else held."""
        return np.where(~f.tracked, "position not tracked", np.where(
            f.lost, "heading lost", np.where(f.regime != "periodic", "not periodic", "held")))

    @property
    def cross(self) -> pd.DataFrame:
        """The points by the paper's law (rows, held or not held) against the weighted law
        (columns, held or the first reason it is not, one of position not tracked, heading
        lost, not periodic), with totals; the "held" row and column total the counts' "held"."""
        pl = pd.Series(np.where(self.paper_held, "held", "not held"), name="paper's law")
        wl = pd.Series(self._why(self.weighted), name="weighted law")
        x = pd.crosstab(pl, wl, margins=True, margins_name="total")
        return x.reindex(index=["held", "not held", "total"],
                         columns=["held", "position not tracked", "heading lost", "not periodic", "total"],
                         fill_value=0)


def compare_on_map(body: Body, gains: Gains, R, Theta, w_phi: float, **options) -> MapComparison:
    """Classify the paper's law (w_phi = 0, exactly (25)-(26)) and the weighted law (weights
    (1, 1, ``w_phi``)) on the eight at the points (R_i (m), Theta_i (rad/s)), both started on
    the reference, by one call of :func:`closed_loop_verdicts` (``options`` go there).

    Parameters
    ----------
    body : Body
        The body.
    gains : Gains
        The gains of (23).
    R, Theta : array_like
        Radii (m) and rates (rad/s).
    w_phi : float
        The weight of the weighted law, > 0.
    **options
        The options of :func:`closed_loop_verdicts`.

    Returns
    -------
    MapComparison
        Both frames and their counts.
    """
    w_phi = checks.number("w_phi", w_phi, positive=True)
    R, Theta, _ = _points(R, Theta, (1.0, 1.0, 0.0))
    f = verdict_runs(body, gains, {"paper": dict(kind="eight", R=R, Theta=Theta, weights=(1.0, 1.0, 0.0)),
                                   "weighted": dict(kind="eight", R=R, Theta=Theta, weights=(1.0, 1.0, w_phi))},
                     **options)
    return MapComparison(f["paper"], f["weighted"])


def limits_comparison(body: Body, gains: Gains, kind: str, R: float, Theta: float, weights, limits: dict, *,
                      periods: int = 5, dt: float = 0.01, z0=None, dz0=None) -> pd.DataFrame:
    """The weighted law under force and angle limits, met by projection
    (``allocation="least_squares"``) and exactly (``"limited"``), by :func:`closed_loop_batch`:
    for each named :class:`lib.allocation.Limits` in ``limits``, both runs over ``periods``
    reference periods with RK4 step ``dt`` (s), and :func:`steady_metrics` over the last period
    (sampled every second step).
    Returns one row per (limits, law): the limits' name, ``law``, and the metrics' columns.

    Parameters
    ----------
    body : Body
        The body.
    gains : Gains
        The gains of (23).
    kind : str
        ``"circle"`` or ``"eight"``.
    R : float
        Radius (m).
    Theta : float
        Rate (rad/s).
    weights : array_like
        (w_x, w_y, w_phi).
    limits : dict
        Name -> :class:`lib.allocation.Limits`.
    periods : int
        Reference periods.
    dt : float
        RK4 step (s).
    z0, dz0 : array_like, optional
        Start.

    Returns
    -------
    pandas.DataFrame
        One row per (limits, law).
    """
    if not limits:
        raise ValueError("no limits given")
    if isinstance(periods, bool) or not isinstance(periods, (int, np.integer)) or periods < 2:
        raise ValueError(f"periods must be an integer >= 2, got {periods!r}")
    T = 2 * np.pi / abs(float(Theta))
    rows = []
    for name, lim in limits.items():
        for law in ("least_squares", "limited"):
            res = closed_loop_batch(body, gains, kind, R, Theta, weights, t_end=periods * T, dt=dt, record_dt=2 * dt,
                                    z0=z0, dz0=dz0, allocation=law, limits=lim)
            m = steady_metrics(res, n_periods=1.0).iloc[0].to_dict()
            rows.append({"limits": name, "law": "projection" if law == "least_squares" else "exact", **m})
    return pd.DataFrame(rows)


def extend_undecided(body: Body, gains: Gains, run: dict, frame: pd.DataFrame, factor: int = 2,
                     **options) -> pd.DataFrame:
    """Decide the undecided rows of ``frame`` (one row per point of ``run``, the dict given to
    :func:`verdict_runs`: kind, R, Theta, weights, z0, dz0) again over ``factor`` times as many
    observed periods (and blocks as long): a slowly attracting orbit (|mu| near 1) that the run
    had not yet come within the reach tolerance of is then reached. Returns a copy of ``frame``
    with those rows replaced and a column ``horizon`` (observed periods).

    Parameters
    ----------
    body : Body
        The body.
    gains : Gains
        The gains of (23).
    run : dict
        The run of the frame (:func:`verdict_runs`).
    frame : pandas.DataFrame
        Its verdicts.
    factor : int
        Horizon factor.
    **options
        The options of :func:`closed_loop_verdicts`.

    Returns
    -------
    pandas.DataFrame
        The frame, its undecided rows decided again, with a column ``horizon``.
    """
    if isinstance(factor, bool) or not isinstance(factor, (int, np.integer)) or factor < 2:
        raise ValueError(f"factor must be an integer >= 2, got {factor!r}")
    o = {**LOOP_VERDICT_DEFAULTS, **options}
    n = len(frame)

    def redo(rows, k):
        sub = {}
        for key, v in run.items():
            a = np.asarray(v, dtype=object if key == "kind" else float)
            per_point = a.ndim >= 1 and a.shape[0] == n and key != "kind" and not (
                key in ("z0", "dz0") and a.shape == (3,))
            sub[key] = a[rows] if per_point else v
        longer = {**options, "periods": o["periods"] * k, "block": o["block"] * k}
        return verdict_runs(body, gains, {"redo": sub}, **longer)["redo"]

    return dv.redecide_undecided(frame, o["periods"], factor, redo)


def refine_boundary(body: Body, gains: Gains, run: dict, w_phi, frame: pd.DataFrame, n: int = 7,
                    **options) -> tuple[dict, np.ndarray, pd.DataFrame]:
    """One bisection round, in log w_phi, of the boundary :func:`stability_boundary` finds on the
    grid ``w_phi`` with verdicts ``frame``: ``n`` weights evenly spaced in log between the last
    held and the first lost weight, classified by one :func:`closed_loop_verdicts` call with the
    rest of ``run`` (kind, R, Theta, w_x = w_y = 1, z0, dz0), which narrows the bracket by a
    factor n + 1 in log. Returns the new boundary, and all weights with their verdicts, sorted.

    Parameters
    ----------
    body : Body
        The body.
    gains : Gains
        The gains of (23).
    run : dict
        kind, R (m), Theta (rad/s), z0, dz0.
    w_phi : array_like
        The grid of weights.
    frame : pandas.DataFrame
        Its verdicts.
    n : int
        New weights.
    **options
        The options of :func:`closed_loop_verdicts`.

    Returns
    -------
    boundary : dict
        :func:`stability_boundary` on all weights.
    w_phi : numpy.ndarray
        All weights, sorted.
    frame : pandas.DataFrame
        Their verdicts.
    """
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise ValueError(f"n must be a positive integer, got {n!r}")
    b = stability_boundary(w_phi, frame)
    if not np.isfinite(b["first_lost"]) or b["last_held"] <= 0:
        raise ValueError("no boundary between two positive weights to refine")
    w_new = np.geomspace(b["last_held"], b["first_lost"], n + 2)[1:-1]
    r = {k: v for k, v in run.items() if k != "weights"}
    new = verdict_runs(body, gains, {"fine": dict(r, weights=np.c_[np.ones(n), np.ones(n), w_new])}, **options)
    w_all = np.r_[np.asarray(w_phi, dtype=float), w_new]
    order = np.argsort(w_all, kind="stable")
    both = pd.concat([frame, new["fine"]], ignore_index=True).iloc[order].reset_index(drop=True)
    return stability_boundary(w_all[order], both), w_all[order], both
