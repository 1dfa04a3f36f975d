"""The entries of Chapter 8: from the paper's start, an entry manoeuvre onto each setting's best
motion, then the periodic LQR decided from where it ends (:func:`entry_rows`, its table and its
basin over moved starts), and the entry's inputs run open loop on a plant, pushed or not
(:func:`entry_end`), which the margins and the wrong plants of :mod:`.margins` use.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from ...allocation import Limits
from ...integrators.batch import RK4, integrate
from ...machinery import checks
from ...machinery.kinds import round_directed
from ...model import config_accel
from ...params import Body
from ..entry import Entry, entry_motion
from ..motion import PeriodicMotion
from ..tracker import DEFAULT_STARTS, periodic_lqr
from ..verdict import motion_verdict, offset_starts
from .study import setting_label


__all__ = ["ENTRY_STEPS", "entry_end", "entry_rows", "entry_table", "entry_basin"]

#: RK4 steps on each input piece of an entry run open loop (:func:`entry_end`): its end moves by
#: about 1e-6 against DOP853 at rtol 1e-10 (14 times less a halving), a thousandth of the reach tolerance
ENTRY_STEPS = 4


def entry_end(plant: Body, motion, entry: Entry, start=None, *, push=None) -> np.ndarray:
    """Where the inputs of ``entry`` (planned on the model, :func:`lib.optimal.entry.entry_motion`),
    applied open loop, bring ``plant`` from ``start`` ((6,) or (S, 6), default the paper's start)
    under an optional constant world-frame ``push`` (Fx, Fy) (N). RK4, :data:`ENTRY_STEPS` steps
    an input piece.

    Returns
    -------
    numpy.ndarray
        The states at t = ``entry.periods`` T, the motion's phase 0, shaped as ``start``, the
        heading brought back by the plan's turns as in ``end`` of :class:`lib.optimal.entry.Entry`.
    """
    checks.instance("plant", plant, Body)
    checks.instance("entry", entry, Entry, "lib.optimal.entry.Entry")
    x0 = checks.array("start", DEFAULT_STARTS[0] if start is None else start)
    X = checks.array("start", np.atleast_2d(x0), shape=(None, 6))
    px, py = (0.0, 0.0) if push is None else checks.array("push", push, shape=(2,))
    h, pushed = motion.period / entry.nodes, np.array([px / plant.m, py / plant.m, 0.0])
    turns = 2 * np.pi * (np.round((X[:, 2] - motion.state(0.0)[0][2]) / (2 * np.pi)) + motion.turns * entry.periods)

    def rates(F, beta):
        return lambda t, Y: np.concatenate([Y[:, 3:], config_accel(plant, Y[:, :3], Y[:, 3:], F, beta) + pushed], -1)
    for k, (F, beta) in enumerate(zip(entry.F, entry.beta)):
        X = integrate(rates(F, beta), X, k * h, (k + 1) * h, h / ENTRY_STEPS, RK4)[1][-1]
    X[:, 2] -= turns
    return X.reshape(x0.shape)


def entry_rows(body: Body, motions: dict, *, periods: int = 2, steps: int = 2,
               verdict_periods: int = 8) -> pd.DataFrame:
    """From the paper's start, an entry (:func:`lib.optimal.entry.entry_motion`) onto each setting's motion, then
    the periodic LQR: its loop decided by :func:`lib.optimal.verdict.motion_verdict` from the
    state the entry's integrated inputs reach (at t = periods T, the motion's phase 0).

    Parameters
    ----------
    body : Body
        The body.
    motions : dict
        (angle limit in deg or None, cap in N or None) -> PeriodicMotion.
    periods : int
        Periods of each entry.
    steps, verdict_periods : int
        :func:`motion_verdict`'s ``steps`` and ``periods``.

    Returns
    -------
    pandas.DataFrame
        One row a setting: setting, angle_deg, cap, regime, reached and settled (the entry's end
        reaches the orbit on both maps; the two maps agree), entry_rms and entry_max (m),
        entry_time (s), end_position (m) and end_heading (rad), the entry's end against the motion.
    """
    checks.instance("body", body, Body)
    if not isinstance(motions, dict) or not all(isinstance(m, PeriodicMotion) for m in motions.values()):
        raise TypeError("motions must be a dict (angle limit, cap) -> PeriodicMotion (limit_motions' result)")
    rows = []
    for (angle, cap), m in motions.items():
        e = entry_motion(body, m, periods=periods)
        limits = Limits(cap, None if angle is None else math.radians(angle))
        v = motion_verdict(body, m, limits=limits, lqr=periodic_lqr(body, m), starts=e.end[None],
                           steps=steps, periods=verdict_periods)
        rows.append(dict(setting=setting_label(angle, cap), angle_deg=angle, cap=cap, regime=v.regime,
                         reached=bool(v.reached[0]), settled=bool(v.settled[0]), entry_rms=e.rms_error,
                         entry_max=e.max_error, entry_time=periods * m.period, end_position=e.end_gap["position"],
                         end_heading=e.end_gap["heading"]))
    return pd.DataFrame(rows)


def entry_table(rows: pd.DataFrame) -> pd.DataFrame:
    """:func:`entry_rows` as the page shows it: setting, whether the paper's start reaches the
    orbit after the entry ("yes", "no", or "undecided" where the verdict's two maps disagree), the
    entry's RMS and largest distance of C from the path (m, rounded up: values of a motion that
    exists) and the gap of its integrated end to the motion's state (m, one significant digit, up).

    Parameters
    ----------
    rows : pandas.DataFrame
        The frame of :func:`entry_rows`.

    Returns
    -------
    pandas.DataFrame
        The cells, formatted.
    """
    up = lambda v, f: round_directed(float(v), f, "up")      # noqa: E731
    return pd.DataFrame({
        "setting": rows.setting,
        "paper's start reaches": ["yes" if r else ("no" if s else "undecided")
                                  for r, s in zip(rows.reached, rows.settled)],
        "entry RMS (m)": [up(v, ".3f") for v in rows.entry_rms],
        "entry largest (m)": [up(v, ".3f") for v in rows.entry_max],
        "end gap (m)": [up(v, ".0e") for v in rows.end_position]})


def entry_basin(body: Body, motion: PeriodicMotion, limits: Limits, *,
                heading_offsets=np.linspace(-np.pi, np.pi, 5)[:-1], position_offsets=(-1.0, 0.0, 1.0),
                periods: int = 2, steps: int = 2, verdict_periods: int = 8) -> pd.DataFrame:
    """The basin of :func:`lib.optimal.verdict.basin` with the entry: from the paper's start at
    rest moved by each heading offset (rad) and each offset of x (m), an entry
    (:func:`lib.optimal.entry.entry_motion`) onto ``motion``, then its periodic LQR decided
    from the entry's end by :func:`motion_verdict` on both maps. A start whose entry IPOPT does
    not solve is recorded as not reached, ``entry`` False.

    Parameters
    ----------
    body, motion, limits
        The body, the motion and its limits.
    heading_offsets, position_offsets : array_like
        The grid of offsets (rad, m).
    periods, steps, verdict_periods : int
        The entry's periods, and :func:`motion_verdict`'s ``steps`` and ``periods``.

    Returns
    -------
    pandas.DataFrame
        Columns heading_offset (rad), x_offset (m), entry, reached, settled.
    """
    checks.instance("body", body, Body)
    checks.instance("motion", motion, PeriodicMotion)
    checks.instance("limits", limits, Limits)
    H, X, S0 = offset_starts(heading_offsets, position_offsets)     # the LQR basin's grid
    ends, found = [], []
    for s in S0:
        try:
            ends.append(entry_motion(body, motion, s, periods=periods).end), found.append(True)
        except RuntimeError:
            ends.append(np.concatenate(motion.state(0.0)) + 1.0), found.append(False)   # far: not reached
    v = motion_verdict(body, motion, limits=limits, lqr=periodic_lqr(body, motion), starts=np.array(ends),
                       steps=steps, periods=verdict_periods)
    found = np.array(found)
    return pd.DataFrame(dict(heading_offset=H.ravel(), x_offset=X.ravel(), entry=found, reached=v.reached & found,
                             settled=v.settled | ~found))
