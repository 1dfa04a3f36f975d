"""The chapters' computations that later pages read again, one function each: a chapter calls
it, and the report, the errata and the front page call it too, so that each call's arguments
are written once and the build's cache (:func:`lib.machinery.cache.cached`) serves every call
after the first. Each takes the body and the gains the chapter uses (the paper's Table:
``Body()``, ``Gains()``); the path is the paper's circle or Chapter 3's eight, R0 = 2 m and
Theta0 = pi / 4 rad/s.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
import pandas as pd

from ..allocation import Limits
from ..limits.attractors import heading_offset_starts, lyapunov_horizons, mirrored_start, start_attractors
from ..limits.torus import NS_ANGLE_DEG, NS_START_CAP, torus_birth
from ..limits.confirm import confirmed_limit_verdicts
from ..machinery.cache import cached
from ..optimal.studies.compare import limits_study
from ..optimal.studies.entries import entry_rows
from ..optimal.studies.study import mesh_study
from ..params import PAPER_DZ0, PAPER_Z0, Body, Gains
from ..percussion.full_loop import full_loop_verdicts, grid_sample
from ..simulate import OPEN_LOOP_HORIZON, Integration, open_loop_comparison, simulate
from ..tracking.mismatch import mismatch_study
from ..tracking.runs import run
from ..trajectories import circle, eight

__all__ = ["R0", "THETA0", "FIG4_CAP", "SWEEP_DEG", "CHAOS_DEG", "LYAPUNOV_DEG", "HORIZONS", "MIRROR_OFFSETS_DEG",
           "fig4_run", "angle_sweep", "chaos_row", "torus", "lyapunov_convergence", "mirror_starts",
           "mirror_attractors", "wrong_model", "circle_run", "full_loop_sample", "limits_comparison", "entries",
           "motion_meshes", "open_loop_deviations", "open_loop_gap"]

#: the paper's circle (its Table), and Chapter 3's eight, in m and rad/s
R0, THETA0 = 2.0, math.pi / 4
#: the paper's force cap of Fig. 4 (N)
FIG4_CAP = 4.0
#: Chapter 4's bifurcation sweep, every whole degree of the angle limit
SWEEP_DEG = np.arange(10, 91)
#: the angle limit (deg) of that sweep without a cap whose exponent the report and the front page quote
CHAOS_DEG = 30
#: Chapter 4's exponent convergence, its angle limits (deg) and horizons (periods after the transient)
LYAPUNOV_DEG, HORIZONS = (30, 45), (48, 120, 240, 480)
#: Chapter 4's heading offsets of the starts whose attractors it maps (deg)
MIRROR_OFFSETS_DEG = np.arange(-180, 180, 30)


def fig4_run(body: Body, gains: Gains):
    """Chapter 4's run of the paper's Fig. 4: ten periods of the eight with F capped at
    :data:`FIG4_CAP`.

    Parameters
    ----------
    body, gains : Body, Gains
        The body and the gains of (23).

    Returns
    -------
    TrackingRun
        :func:`lib.tracking.runs.run`'s result.
    """
    return cached(run, body, gains, "eight", R0, THETA0, 10, limits=Limits(force=FIG4_CAP),
                  integration=Integration(rtol=1e-9, atol=1e-9))


def angle_sweep(body: Body, gains: Gains, cap):
    """Chapter 4's decided sweep over the angle limit (:data:`SWEEP_DEG`) on the eight.

    Parameters
    ----------
    body, gains : Body, Gains
        The body and the gains of (23).
    cap : float or None
        The force cap (N), None for none.

    Returns
    -------
    LimitVerdicts
        :func:`lib.limits.confirm.confirmed_limit_verdicts`' frame (the verdicts confirmed from
        moved starts) and runs.
    """
    return cached(confirmed_limit_verdicts, body, gains, eight(R0, THETA0), np.radians(SWEEP_DEG), cap)


def chaos_row(free):
    """The row at :data:`CHAOS_DEG` of :func:`angle_sweep`'s frame without a cap, whose exponent
    and standard error the report's chaos row and the front page quote.

    Parameters
    ----------
    free : pandas.DataFrame
        The frame of :func:`angle_sweep` with ``cap`` None.

    Returns
    -------
    pandas.Series
        The row.
    """
    return free[free.angle_deg.round() == CHAOS_DEG].iloc[0]


def torus(body: Body, gains: Gains):
    """Chapter 4's Neimark-Sacker cap (:func:`lib.limits.torus.torus_birth`).

    Parameters
    ----------
    body, gains : Body, Gains
        The body and the gains of (23).

    Returns
    -------
    TorusBirth
        The located crossing.
    """
    return cached(torus_birth, body, gains, eight(R0, THETA0), math.radians(NS_ANGLE_DEG), NS_START_CAP)


def lyapunov_convergence(body: Body, gains: Gains) -> pd.DataFrame:
    """Chapter 4's largest exponent against its horizon (:data:`LYAPUNOV_DEG`, :data:`HORIZONS`).

    Parameters
    ----------
    body, gains : Body, Gains
        The body and the gains of (23).

    Returns
    -------
    pandas.DataFrame
        :func:`lib.limits.attractors.lyapunov_horizons`' frame.
    """
    return cached(lyapunov_horizons, body, gains, eight(R0, THETA0), np.radians(LYAPUNOV_DEG), None,
                  list(HORIZONS))


def mirror_starts(body: Body, gains: Gains, deg: float, cap) -> np.ndarray:
    """Chapter 4's starts at an angle limit: the paper's start turned by each heading offset of
    :data:`MIRROR_OFFSETS_DEG`, then the paper's start mirrored.

    Parameters
    ----------
    body, gains : Body, Gains
        The body and the gains of (23).
    deg : float
        The angle limit (deg).
    cap : float or None
        The force cap (N).

    Returns
    -------
    numpy.ndarray
        The starts (13, 6).
    """
    s0 = np.concatenate([PAPER_Z0, PAPER_DZ0])
    ms = mirrored_start(body, gains, eight(R0, THETA0), math.radians(deg), cap, s0)
    return np.vstack([heading_offset_starts(np.radians(MIRROR_OFFSETS_DEG)), ms])


def mirror_attractors(body: Body, gains: Gains, deg: float, cap) -> pd.DataFrame:
    """Chapter 4's attractors from :func:`mirror_starts` (:func:`lib.limits.attractors.start_attractors`).

    Parameters
    ----------
    body, gains : Body, Gains
        The body and the gains of (23).
    deg : float
        The angle limit (deg).
    cap : float or None
        The force cap (N).

    Returns
    -------
    pandas.DataFrame
        One row a start, the paper's start (offset 0) at row 6, the mirrored start last.
    """
    return cached(start_attractors, body, gains, eight(R0, THETA0), math.radians(deg), cap,
                  mirror_starts(body, gains, deg, cap))


def wrong_model(body: Body, gains: Gains) -> dict:
    """Chapter 3's wrong-model study (:func:`lib.tracking.mismatch.mismatch_study`).

    Parameters
    ----------
    body, gains : Body, Gains
        The body and the gains of (23).

    Returns
    -------
    dict
        The study's frames.
    """
    return cached(mismatch_study, body, gains, R0, THETA0, transient=96)


def circle_run(body: Body, gains: Gains):
    """Chapter 5's run on the paper's circle, 60 s from the paper's start.

    Parameters
    ----------
    body, gains : Body, Gains
        The body and the gains of (23).

    Returns
    -------
    SimulationResult
        :func:`lib.simulate.simulate`'s result.
    """
    return cached(simulate, body, gains, circle(R0, THETA0), 60.0)


def full_loop_sample(body: Body, gains: Gains) -> tuple[pd.DataFrame, np.ndarray]:
    """Chapter 7's full loop of the law for P on a 10 x 10 sample of Fig. 5's grid.

    Parameters
    ----------
    body, gains : Body, Gains
        The body and the gains of (23).

    Returns
    -------
    frame : pandas.DataFrame
        :func:`lib.percussion.full_loop.full_loop_verdicts`' frame.
    rows : numpy.ndarray
        The sample's rows in Fig. 5's grid.
    """
    R_s, Th_s, rows = grid_sample(10)
    return cached(full_loop_verdicts, body, gains, R_s, Th_s), rows


def limits_comparison(body: Body, gains: Gains) -> dict:
    """Chapter 8's comparison under the limits (:func:`lib.optimal.studies.compare.limits_study`).

    Parameters
    ----------
    body, gains : Body, Gains
        The body and the gains of (23).

    Returns
    -------
    dict
        The study.
    """
    return cached(limits_study, body, gains, R0, THETA0)


def _motion_meshes(body: Body, gains: Gains) -> dict:
    return mesh_study(body, limits_comparison(body, gains)["motions"])


def motion_meshes(body: Body, gains: Gains) -> dict:
    """Chapter 8's best motions found under the angle limits, refined through the meshes and
    re-integrated (:func:`lib.optimal.studies.study.mesh_study` of :func:`limits_comparison`'s motions),
    computed once per build.

    Parameters
    ----------
    body, gains : Body, Gains
        The body and the gains of (23).

    Returns
    -------
    dict
        ``chains`` and ``frame``, as :func:`lib.optimal.studies.study.mesh_study` returns them.
    """
    return cached(_motion_meshes, body, gains)


def _entry_rows(body: Body, gains: Gains) -> pd.DataFrame:
    return entry_rows(body, limits_comparison(body, gains)["motions"])


def entries(body: Body, gains: Gains) -> pd.DataFrame:
    """Chapter 8's entries from the paper's start onto the best motions found of
    :func:`limits_comparison` (:func:`lib.optimal.studies.entries.entry_rows`), computed once per build.

    Parameters
    ----------
    body, gains : Body, Gains
        The body and the gains of (23).

    Returns
    -------
    pandas.DataFrame
        One row a setting.
    """
    return cached(_entry_rows, body, gains)


@lru_cache(maxsize=1)
def open_loop_deviations() -> dict[str, float]:
    """Chapter 1's open-loop run: the largest deviation, over the run and the state, of the
    body-frame form (``"state"``) and of the printed drift (``"printed"``) from (2)-(4).

    Returns
    -------
    dict
        "state", "printed" -> max |q - q_(2)-(4)| (mixed units: a consistency check, not a finding).
    """
    _, runs = open_loop_comparison(Body(), OPEN_LOOP_HORIZON)
    return {k: float(np.abs(runs[k] - runs["config"]).max()) for k in ("state", "printed")}


def open_loop_gap() -> tuple[float, float, float]:
    """Distance (m) of the printed drift's centre of mass from the true one, and their headings'
    difference (rad), at the end of Chapter 1's open-loop run (the front page and the report
    quote both), with the heading's scale, for the run's accuracy.

    Returns
    -------
    tuple of float
        (distance in m, heading difference in rad modulo 2 pi, largest |phi| of the true run in rad).
    """
    _, runs = open_loop_comparison(Body(), OPEN_LOOP_HORIZON)
    d = runs["printed"][-1] - runs["config"][-1]
    return (float(np.hypot(d[0], d[1])), float(abs(np.angle(np.exp(1j * d[2])))),
            float(np.abs(runs["config"][:, 2]).max()))
