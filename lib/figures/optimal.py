"""Chapter 8's figures: the error against the cap, the paper's law beside the bound; the best
motions under the angle limits; the force that exact tracking needs over Fig. 5's grid."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

__all__ = ["plot_cap_bound", "plot_motions", "plot_force_maps", "plot_basin"]


def plot_cap_bound(bounds: dict, paper: dict, ax=None):
    """The largest distance |C - C_d| (m) against the cap (N), one panel a path: the certified
    lower bound and the achieved motion of :func:`lib.optimal.studies.study.cap_sweep` (a band between
    them), the paper's saturated law (:func:`lib.tracking.runs.force_cap_sweep`) as points, and
    the exact-tracking demand as a dotted line.

    Parameters
    ----------
    bounds : dict
        Path name -> cap_sweep frame (columns cap, max_error, max_error_achieved, demand).
    paper : dict
        Path name -> force_cap_sweep frame (columns cap, pos_err_max).
    ax : sequence of matplotlib.axes.Axes, optional
        One axis a path; a new figure when None.

    Returns
    -------
    matplotlib.figure.Figure
    """
    names = list(bounds)
    fig, axes = (plt.subplots(1, len(names), figsize=(5.2 * len(names), 3.8)) if ax is None
                 else (ax[0].figure, ax))
    for a, name in zip(np.atleast_1d(axes), names):
        b, p = bounds[name], paper[name]
        a.fill_between(b.cap, b.max_error, b.max_error_achieved, color="C0", alpha=0.35, lw=0)
        a.plot(b.cap, b.max_error, "C0-", label="least possible (lower bound)")
        a.plot(p.cap, p.pos_err_max, "C3o-", ms=4, label="paper's law, saturated")
        a.axvline(float(b.demand.iloc[0]), color="k", ls=":", lw=1, label="exact tracking's peak force")
        a.set_xlabel("force cap F_max (N)")
        a.set_ylabel("largest distance |C - C_d| (m)")
        a.set_title(name)
        a.set_ylim(bottom=0.0)
    np.atleast_1d(axes)[0].legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    return fig


def plot_motions(motions: dict, path, ax=None, n_bodies: int = 16):
    """The best motions found under the angle limits: C's path against the path (dashed), with
    the body's axis at ``n_bodies`` times a period, one panel a motion.

    Parameters
    ----------
    motions : dict
        Title -> PeriodicMotion (:func:`lib.optimal.motion.periodic_motion`).
    path : Reference
        The path (:func:`lib.trajectories.eight`), for C_d.
    ax : sequence of matplotlib.axes.Axes, optional
        One axis a motion.
    n_bodies : int
        Headings drawn a period.

    Returns
    -------
    matplotlib.figure.Figure
    """
    titles = list(motions)
    fig, axes = (plt.subplots(1, len(titles), figsize=(3.4 * len(titles), 3.6), sharey=True) if ax is None
                 else (ax[0].figure, ax))
    for a, title in zip(np.atleast_1d(axes), titles):
        m = motions[title]
        t = np.linspace(0.0, m.period, 801)
        zd = path.z(t)
        z, _ = m.state(t)
        a.plot(zd[:, 0], zd[:, 1], "k--", lw=1)
        a.plot(z[:, 0], z[:, 1], "C0-", lw=1.5)
        tb = np.linspace(0.0, m.period, n_bodies, endpoint=False)
        zb, _ = m.state(tb)
        L = 0.18
        a.quiver(zb[:, 0], zb[:, 1], L * np.cos(zb[:, 2]), L * np.sin(zb[:, 2]), angles="xy",
                 scale_units="xy", scale=1, width=0.006, color="C1")
        a.set_aspect("equal")
        a.set_title(title, fontsize=9)
        a.set_xlabel("x (m)")
    np.atleast_1d(axes)[0].set_ylabel("y (m)")
    fig.tight_layout()
    return fig


def plot_force_maps(maps, ax=None):
    """Three maps over Fig. 5's grid: the peak force (N) exact tracking of C needs, that of P
    under Chapter 7's law, and their ratio; points where the law for P holds no heading blank.

    Parameters
    ----------
    maps : pandas.DataFrame
        :func:`lib.optimal.studies.demand.exact_force_maps`: columns R (m), Theta (rad/s), F_C, F_P (N), ratio.
    ax : sequence of matplotlib.axes.Axes, optional
        Three axes.

    Returns
    -------
    matplotlib.figure.Figure
    """
    if ax is None:       # two panels a row, so each reads at a page's width (1280 px screens)
        fig, grid = plt.subplots(2, 2, figsize=(10.0, 7.6), sharex=True, sharey=True)
        grid[1, 1].remove()
        axes = (grid[0, 0], grid[0, 1], grid[1, 0])
    else:
        fig, axes = ax[0].figure, ax
    panels = (("F_C", "C exactly on the path: peak F (N)", "viridis", True),
              ("F_P", "P exactly on the path: peak F (N)", "viridis", True),
              ("ratio", "ratio F_P / F_C", "magma", True))
    for a, (col, label, cmap, log) in zip(axes, panels):
        v = maps[col].to_numpy(dtype=float)
        norm = plt.matplotlib.colors.LogNorm(vmin=np.nanmin(v[v > 0]), vmax=np.nanmax(v)) if log else None
        sc = a.scatter(maps.R, maps.Theta, c=v, s=14, marker="s", cmap=cmap, norm=norm)
        fig.colorbar(sc, ax=a, label=label)
        a.set_xlabel("R (m)")
        a.set_ylabel("Theta (rad/s)")
        a.xaxis.set_tick_params(labelbottom=True)
    fig.tight_layout()
    return fig


def plot_basin(frame, title: str = "", ax=None):
    """Which starts reach the controller's orbit (:func:`lib.optimal.verdict.basin`): the
    paper's start moved in heading (rad) and in x (m); filled, reached on both maps of the
    verdict (step h and h/2); open, not reached on either; grey diamonds, reached on one map only
    (undecided), where ``frame`` has the column ``settled``.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = (plt.subplots(figsize=(6.0, 3.6)) if ax is None else (ax.figure, ax))
    settled = frame["settled"] if "settled" in frame else np.ones(len(frame), bool)
    hit = frame[frame.reached]
    miss = frame[~frame.reached & settled]
    split = frame[~frame.reached & ~settled]
    ax.scatter(hit.heading_offset, hit.x_offset, s=40, c="C2", label="reaches the orbit")
    ax.scatter(miss.heading_offset, miss.x_offset, s=40, facecolors="none", edgecolors="C3",
               label="does not")
    if len(split):
        ax.scatter(split.heading_offset, split.x_offset, s=30, marker="D", c="0.6",
                   label="on one map only")
    ax.scatter([0.0], [0.0], marker="x", c="k", s=60, label="the paper's start")
    ax.set_xlabel("heading offset from the paper's start (rad)")
    ax.set_ylabel("x offset (m)")
    ax.set_title(title, fontsize=9)
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    fig.tight_layout()
    return fig


def plot_entry(entry, motion, path, title: str = "", ax=None):
    """An entry manoeuvre (:func:`lib.optimal.entry.entry_motion`): the path (dashed), C's
    path during the entry from the start (cross) to its end (circle, on the motion), and the
    motion's path over one period after it.

    Parameters
    ----------
    entry : lib.optimal.entry.Entry
        The entry (its ``path``: t (s), x, y (m)).
    motion : PeriodicMotion
        The motion it enters.
    path : Reference
        The path (:func:`lib.trajectories.eight`), for C_d.
    title : str
        The panel's title.
    ax : matplotlib.axes.Axes, optional
        The axis.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = (plt.subplots(figsize=(6.4, 3.8)) if ax is None else (ax.figure, ax))
    t = np.linspace(0.0, motion.period, 801)
    zd, z = path.z(t), motion.state(t)[0]
    ax.plot(zd[:, 0], zd[:, 1], "k--", lw=1, label="the path")
    ax.plot(entry.path[:, 1], entry.path[:, 2], "C3-", lw=1.3, label="C during the entry")
    ax.plot(z[:, 0], z[:, 1], "C0-", lw=1.5, label="C on the motion after it")
    ax.plot(*entry.path[0, 1:], "kx", ms=8, label="the paper's start")
    ax.plot(*entry.path[-1, 1:], "o", mfc="none", mec="C3", ms=7, label="the entry's end")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_aspect("equal")
    ax.set_title(title, fontsize=9)
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    fig.tight_layout()
    return fig
