"""The book's Fig. 5 map (Chapter 5): :func:`lib.rotation.verdicts.eight_rotation_sweep` on the
grid :data:`lib.rotation.verdicts.FIG5_GRID`, with every verdict that a chaotic transient may
have decided taken again (:func:`confirm_attractors`: ``transient`` where the attractor reached
differs) and every heading lost without an orbit tested again over a longer horizon
(:func:`confirm_lost`).

Units: R in m, Theta in rad/s, angles in rad.
"""

from __future__ import annotations

from types import MappingProxyType

import numpy as np
import pandas as pd

from ..angles import wrap_angle
from ..dynamics import verdicts as dv
from ..machinery import checks
from ..machinery.robustness import ROBUST_REL, perturbed
from ..params import Body
from .engine import RotationMap, _Engine
from .field import coefficients
from .verdicts import FIG5_GRID, _check_body_kind, _verdict_core, _verdict_options, eight_rotation_sweep

__all__ = ["fig5_map", "CONFIRMATIONS", "ORBIT_TOL", "LOST_FACTOR", "confirm_attractors", "confirm_lost"]

#: the extra decisions :func:`confirm_attractors` can take: the start (p, dp/dt) moved by a
#: relative 1e-12 (:func:`lib.machinery.robustness.perturbed`), or the verdict map's steps per
#: period doubled (the fine map, on which orbits are compared, unchanged)
CONFIRMATIONS = MappingProxyType({"perturbed": "start + 1e-12", "steps_x2": "steps x2"})

#: two decisions reach the same orbit when one's point at s = 0 lies within this of one of
#: the other's k points (rad, in p): both are located by Newton on the same fine map (to
#: about 1e-7 rad, the verdict map alone to about 1e-5 rad), and distinct coexisting orbits
#: of the map lie 1e-2 rad or more apart
ORBIT_TOL = 1e-4

#: the longer horizon of :func:`confirm_lost`, in multiples of the Lyapunov run the first drift test observed
LOST_FACTOR = 4


def fig5_map(body: Body, n: int = FIG5_GRID["n"], *, confirm=("perturbed",), lost_factor: int | None = LOST_FACTOR,
             executor=None, chunk_size: int | None = None, progress: bool | None = None) -> pd.DataFrame:
    """The book's Fig. 5 (Chapter 5, and the report's row on it): :func:`lib.rotation.verdicts.eight_rotation_sweep`
    on the n x n grid :data:`lib.rotation.verdicts.FIG5_GRID`, Theta varying slowest; then the headings lost
    without an orbit tested over ``lost_factor`` times their horizon (:func:`confirm_lost`;
    None skips), and the points that saw a chaotic transient decided again by ``confirm``
    (:func:`confirm_attractors`; ``()`` skips).

    Parameters
    ----------
    body : Body
        The body.
    n : int
        Points per side (>= 2, at most :data:`lib.machinery.domain.MAX_GRID_POINTS` points in all).
    confirm : str or tuple of str
        A key of :data:`CONFIRMATIONS`, or a tuple of them.
    lost_factor : int, optional
        Horizon factor of :func:`confirm_lost`.
    executor, chunk_size, progress
        As in :func:`lib.rotation.verdicts.rotation_verdicts`.

    Returns
    -------
    pandas.DataFrame
        The frame of :func:`lib.rotation.verdicts.rotation_verdicts`, n^2 rows, with the
        columns of :func:`confirm_attractors` and :func:`confirm_lost`.
    """
    n = checks.integer("n", n, minimum=2)
    checks.grid_budget(n)              # before the grid is built
    checks.instance("body", body, Body)
    confirm = _confirmations(confirm)  # the options first, not after the sweep (issue 37)
    if lost_factor is not None:
        checks.integer("lost_factor", lost_factor, minimum=2)
    R, Th = np.meshgrid(np.linspace(*FIG5_GRID["R"], n), np.linspace(*FIG5_GRID["Theta"], n))
    frame = eight_rotation_sweep(body, R.ravel(), Th.ravel(), executor=executor, chunk_size=chunk_size,
                                 progress=progress)
    if lost_factor is not None:
        frame = confirm_lost(body, "eight", frame, lost_factor)
    return confirm_attractors(body, "eight", frame, confirm)


def _confirmations(confirm) -> tuple:
    """``confirm`` as a tuple of keys of :data:`CONFIRMATIONS`: one key (a str) or a sequence of them."""
    if isinstance(confirm, str):
        confirm = (confirm,)
    try:
        confirm = tuple(confirm)
    except TypeError:
        raise TypeError(f"confirm must be a key of {list(CONFIRMATIONS)} or a tuple of them, got "
                        f"{type(confirm).__name__} {confirm!r}") from None
    for key in confirm:
        checks.one_of("confirm", key, tuple(CONFIRMATIONS))
    return confirm


def _redo(body, kind, frame, rows, opts, *, start=0.0, steps_factor=1, x0=(0.0, 0.0)):
    """The decision of ``rows`` of ``frame`` taken again (the dict of
    :func:`lib.rotation.verdicts._verdict_core`), from the reference start moved by ``start``
    (relative), the verdict map's steps times ``steps_factor``; and whether each orbit found is
    the first decision's: its k points at s = 0 hold the first's ``orbit_p`` within
    :data:`ORBIT_TOL`, and it slips the same turns."""
    R, Th = frame.R.to_numpy()[rows], frame.Theta.to_numpy()[rows]
    n_pts, n_fine = frame.verdict_steps.to_numpy()[rows], frame.steps.to_numpy()[rows]
    x0 = np.broadcast_to(np.asarray(x0, dtype=float), (rows.size, 2))
    # each start moved alike (the signs of one (2,) start), so that a point's decision does not depend on the batch
    p0, v0 = (np.array([perturbed(x, start) for x in x0]) if start else x0).T.copy()
    out = _verdict_core(body, kind, R, Th, p0, v0, n_pts * steps_factor, opts, "numba", n_fine)
    k1 = frame.period.to_numpy()[rows]
    n1 = np.rint(np.nan_to_num(frame.slip.to_numpy()[rows]) * k1).astype(int)   # turns of an orbit (k1 > 0)
    cand = np.flatnonzero(np.isin(out["regime"], dv.ORBIT_REGIMES) & (out["period"] == k1) & (out["slip_n"] == n1))
    same = np.zeros(rows.size, bool)
    for n in np.unique(n_fine[cand]):
        eng = _Engine(kind, int(n), "numba")
        g = cand[n_fine[cand] == n]
        A, B, C = coefficients(body, R[g], Th[g])
        pts = dv.orbit_points(RotationMap(eng, A, B, C), np.arange(g.size), out["x"][g], out["period"][g])
        p = wrap_angle(pts[..., 0] - eng.H0)                                     # (K, M), NaN past each k
        gap = np.abs(wrap_angle(p - frame.orbit_p.to_numpy()[rows][g]))
        same[g] = np.nanmin(gap, axis=0) <= ORBIT_TOL
    out["same_orbit"] = same
    return out


def _rows(x0, frame, rows) -> np.ndarray:
    """The starts (M, 2) of ``rows`` from ``x0`` (2,) or (N, 2)."""
    x0 = np.asarray(x0, dtype=float)
    return x0 if x0.ndim == 1 else np.broadcast_to(x0, (len(frame), 2))[rows]


def _other_orbit(regime, period, r, j) -> bool:
    """Whether decision ``r`` reaches, at row j, an orbit of the first's regime and period, but another one."""
    return regime in dv.ORBIT_REGIMES and r["regime"][j] == regime and r["period"][j] == period \
        and not r["same_orbit"][j]


def _describe(regime, period) -> str:
    return f"{regime}, period {period}" if regime in dv.ORBIT_REGIMES else regime


def confirm_attractors(body: Body, kind: str, frame: pd.DataFrame, confirm=("perturbed",), *, x0=(0.0, 0.0),
                       **options) -> pd.DataFrame:
    """A copy of a frame of :func:`lib.rotation.verdicts.rotation_verdicts` (started on the
    reference, or from ``x0`` = (p0 (rad), dp/dt(0) (rad/s)), (2,) or (N, 2); its default step
    bounds) whose points that saw a chaotic transient
    (:func:`lib.dynamics.verdicts.needs_confirmation`: decided ``chaotic``, or an orbit reached
    after the transient) are decided again, once per key of ``confirm``
    (:data:`CONFIRMATIONS`); where the attractors reached differ
    (:func:`lib.dynamics.verdicts.attractor_determined`) the verdict becomes ``transient``
    (transient chaos: attractor not determined), its period 0 and its reason listing the
    decisions; the other columns keep the first decision's numbers. Column ``confirmed``:
    the extra decisions taken (0 where not triggered).

    Parameters
    ----------
    body : Body
        The body.
    kind : str
        ``"eight"`` or ``"circle"``.
    frame : pandas.DataFrame
        Verdicts from the reference start.
    confirm : str or tuple of str
        A key of :data:`CONFIRMATIONS`, or a tuple of them.
    **options
        The procedure's options, as given to the first decision.

    Returns
    -------
    pandas.DataFrame
        The frame, with ``transient`` verdicts and the column ``confirmed``.
    """
    _check_body_kind(body, kind)
    confirm = _confirmations(confirm)
    opts = _verdict_options(options)
    out = frame.copy()
    rows = np.flatnonzero(dv.needs_confirmation(frame.regime, frame.periods, opts["transient"]))
    out["confirmed"] = 0
    if rows.size == 0 or not confirm:
        return out
    opts["drift_periods"] = 0                 # the regime and the orbit are compared: no drift run on
    redo = [_redo(body, kind, frame, rows, opts, start=ROBUST_REL if key == "perturbed" else 0.0,
                  steps_factor=2 if key == "steps_x2" else 1, x0=_rows(x0, frame, rows)) for key in confirm]
    first_r, first_k = frame.regime.to_numpy()[rows], frame.period.to_numpy()[rows]
    ok = dv.attractor_determined([first_r] + [r["regime"] for r in redo], [first_k] + [r["period"] for r in redo],
                                 [r["same_orbit"] for r in redo])
    out.iloc[rows, out.columns.get_loc("confirmed")] = len(confirm)
    bad = np.flatnonzero(~ok)
    for j in bad:
        seen = [f"reference start: {_describe(first_r[j], first_k[j])}"] + [
            f"{CONFIRMATIONS[key]}: {_describe(r['regime'][j], r['period'][j])}"
            + (", another orbit" if _other_orbit(first_r[j], first_k[j], r, j) else "")
            for key, r in zip(confirm, redo)]
        i = frame.index[rows[j]]
        out.loc[i, ["regime", "period", "reason"]] = [dv.TRANSIENT, 0, "transient chaos: attractor not determined ("
                                                      + "; ".join(seen) + ")"]
    return out


def confirm_lost(body: Body, kind: str, frame: pd.DataFrame, factor: int = LOST_FACTOR, *, x0=(0.0, 0.0),
                 **options) -> pd.DataFrame:
    """A copy of a frame of :func:`lib.rotation.verdicts.rotation_verdicts` whose headings lost
    without a slipping orbit (from the reference, or from ``x0`` as in :func:`confirm_attractors`;
    a drift test over h periods of Lyapunov run, the frame's ``drift_periods``) are decided again from the same
    start over a Lyapunov run of ``factor`` h periods, every block of it
    (no early stop): ``lost`` stays True only where the heading is lost again
    (:func:`lib.dynamics.verdicts.heading_lost`: a slipping orbit, or the drift more than 3
    standard errors plus the slip band from zero over the longer run); ``slip`` and
    ``slip_stderr`` become the longer run's. A point whose longer run reaches an orbit its
    first run did not is ``transient`` (its attractor is not determined by one horizon).
    Column ``lost_horizon``: the periods of the Lyapunov run the lost verdict rests on
    (0 on an orbit).

    Parameters
    ----------
    body : Body
        The body.
    kind : str
        ``"eight"`` or ``"circle"``.
    frame : pandas.DataFrame
        Verdicts from the reference start.
    factor : int
        Horizon factor (>= 2).
    **options
        The procedure's options, as given to the first decision.

    Returns
    -------
    pandas.DataFrame
        The frame, with ``lost`` decided again and the column ``lost_horizon``.
    """
    _check_body_kind(body, kind)
    factor = checks.integer("factor", factor, minimum=2)
    opts = _verdict_options(options)
    out = frame.copy()
    orbit = frame.regime.isin(dv.ORBIT_REGIMES).to_numpy()
    h = np.where(orbit, 0, frame.drift_periods.to_numpy())
    out["lost_horizon"] = h
    drift = frame.slip_stderr.to_numpy() > 0                  # lost by the drift test (0 on an orbit)
    todo = np.flatnonzero(frame.lost.to_numpy() & drift & ~orbit & (h > 0))
    for hh in np.unique(h[todo]):
        rows = todo[h[todo] == hh]
        o = dict(opts, lyapunov_periods=int(factor * hh), min_lyapunov_periods=int(factor * hh))
        r = _redo(body, kind, frame, rows, o, x0=_rows(x0, frame, rows))
        idx = frame.index[rows]
        out.loc[idx, "lost"] = r["lost"]
        out.loc[idx, "slip"], out.loc[idx, "slip_stderr"] = r["slip"], r["slip_stderr"]
        out.loc[idx, "lost_horizon"] = out.loc[idx, "drift_periods"] = r["drift_periods"]
        moved = np.isin(r["regime"], dv.ORBIT_REGIMES)
        for j in np.flatnonzero(moved):
            longer = f"{factor} x the horizon: {_describe(r['regime'][j], r['period'][j])} after {r['periods'][j]} periods"
            first = frame.regime.iloc[rows[j]]
            reason = (frame.reason.iloc[rows[j]][:-1] + f"; {longer})" if first == dv.TRANSIENT else
                      f"transient chaos: attractor not determined (reference start: {first}; {longer})")
            out.loc[idx[j], ["regime", "period", "reason"]] = [dv.TRANSIENT, 0, reason]
    return out
