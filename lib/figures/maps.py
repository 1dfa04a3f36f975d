"""The book's figures (Matplotlib). Each takes an optional ``ax`` and returns the figure,
so notebooks can compose them. The maps of Chapters 4-6 are here; the body and the tracking
figures are in :mod:`lib.figures.tracking`, re-exported here."""

from __future__ import annotations

import numpy as np
import matplotlib.pyplot as plt
from matplotlib.colors import ListedColormap, LogNorm
from matplotlib.patches import Patch

import pandas as pd

from ..angles import wrap_angle
from ..rotation.circle import circle_critical_radius
from ..params import Body
from .tracking import (body_outline, draw_body, new_axes, plot_bifurcation, plot_errors, plot_force,
                       plot_path, plot_section)

__all__ = ["body_outline", "draw_body", "new_axes", "plot_path", "plot_errors", "plot_force", "plot_bifurcation",
           "plot_section", "plot_fig5", "plot_fig5_exponents", "plot_circle_map", "plot_heading_orbits",
           "REGIME_COLORS", "LIMIT_COLORS", "plot_limit_sweep", "plot_limit_map"]




#: how each non-periodic regime of :func:`lib.rotation.verdicts.rotation_verdicts` is drawn on the maps
REGIME_COLORS = {"slipping": "C3", "chaotic": "0.15", "transient": "C1", "quasiperiodic": "C0", "undecided": "0.7"}


def _grid(frame: pd.DataFrame, column: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(R, Theta, values) of a sweep on a rectangular grid, values (n_Theta, n_R)."""
    table = frame.pivot_table(index="Theta", columns="R", values=column, aggfunc="first", dropna=False)
    return table.columns.to_numpy(float), table.index.to_numpy(float), table.to_numpy(float)


def _cells(R: np.ndarray, Th: np.ndarray):
    """Cell edges for pcolormesh around grid centres."""
    def edges(v):
        mid = (v[1:] + v[:-1]) / 2
        return np.concatenate([[v[0] - (mid[0] - v[0])], mid, [v[-1] + (v[-1] - mid[-1])]])
    return edges(R), edges(Th)


def plot_fig5(frame: pd.DataFrame, ax=None):
    """Fig. 5: range (rad) of the rotation error over the attracting orbit at the periodic
    points of a rectangular (R, Theta) grid (:func:`lib.rotation.verdicts.rotation_verdicts`), the
    other regimes in flat colours (:data:`REGIME_COLORS`), and the points whose heading is
    lost (column ``lost``) ringed. The paper's empty circles compare with the points not held
    (every colour but the periodic map's; Chapter 5), not with the rings. Returns the figure.

    Parameters
    ----------
    frame : pandas.DataFrame
        Verdicts on a rectangular grid.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (default new ones).

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    fig, ax = new_axes(ax, figsize=(7, 5))
    R, Th, rng = _grid(frame, "range")
    _, _, per = _grid(frame.assign(is_per=(frame.regime == "periodic").astype(float)), "is_per")
    Re, Te = _cells(R, Th)
    mesh = ax.pcolormesh(Re, Te, np.ma.masked_where(per != 1.0, rng), cmap="viridis", norm=LogNorm(), shading="flat")
    fig.colorbar(mesh, ax=ax, label="range of $p$ on the orbit (rad, log scale)")
    handles = []
    for regime, color in REGIME_COLORS.items():
        _, _, sel = _grid(frame.assign(sel=(frame.regime == regime).astype(float)), "sel")
        if np.any(sel == 1.0):
            ax.pcolormesh(Re, Te, np.ma.masked_where(sel != 1.0, sel), cmap=ListedColormap([color]),
                          shading="flat")
            handles.append(Patch(color=color, label=f"{regime} ({int(np.sum(sel == 1.0))})"))
    lost = frame[frame.lost]
    handles.append(ax.scatter(lost.R, lost.Theta, s=10, facecolors="none", edgecolors="w", linewidths=0.6,
                              label=f"lost ({len(lost)})"))
    ax.set(xlabel="R (m)", ylabel=r"$\Theta$ (rad/s)")
    ax.set_facecolor("0.5")
    ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=3, fontsize=8, facecolor="0.75")
    return fig


def plot_fig5_exponents(frame: pd.DataFrame):
    """Beside Fig. 5: the largest Floquet multiplier modulus of the attracting orbit
    (periodic and slipping points) and the largest Lyapunov exponent (1/s) of the
    other points, on the same (R, Theta) grid. Returns the figure.

    Parameters
    ----------
    frame : pandas.DataFrame
        Verdicts on a rectangular grid.

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.4), sharey=True, layout="constrained")
    R, Th, flo = _grid(frame, "floquet")
    _, _, lya = _grid(frame.assign(ly=np.where(frame.regime.isin(["periodic", "slipping"]), np.nan, frame.lyapunov)),
                      "ly")
    Re, Te = _cells(R, Th)
    m1 = a1.pcolormesh(Re, Te, np.ma.masked_invalid(flo), cmap="magma", vmin=0, vmax=1, shading="flat")
    fig.colorbar(m1, ax=a1, label=r"largest Floquet modulus $|\mu_1|$")
    lim = np.nanmax(np.abs(lya)) if np.isfinite(lya).any() else 1.0
    m2 = a2.pcolormesh(Re, Te, np.ma.masked_invalid(lya), cmap="coolwarm", vmin=-lim, vmax=lim, shading="flat")
    fig.colorbar(m2, ax=a2, label=r"largest Lyapunov exponent $\lambda_1$ (1/s)")
    for ax, title in ((a1, "attracting orbits"), (a2, "no attracting orbit reached")):
        ax.set(xlabel="R (m)", title=title)
        ax.set_facecolor("0.85")
    a1.set_ylabel(r"$\Theta$ (rad/s)")
    return fig


def plot_circle_map(frame: pd.DataFrame, body: Body, coexists=None, ax=None):
    """Where the circle's rotation error settles or slips (``frame`` from
    :func:`lib.rotation.circle_global.circle_final_state`), with the analytic boundary R_crit(theta) of (36)
    and, if given, the points where slipping coexists with the stable equilibrium.

    Parameters
    ----------
    frame : pandas.DataFrame
        End states of :func:`lib.rotation.circle_global.circle_final_state`.
    body : Body
        The body.
    coexists : array_like, optional
        Per point, whether slipping coexists.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (default new ones).

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    if ax is None:
        fig, ax = plt.subplots(figsize=(7, 5))
    for regime, style in (("settled", dict(color="C0", marker=".")), ("slipping", dict(color="C3", marker="x"))):
        sel = frame[frame.regime == regime]
        ax.scatter(sel.R, sel.theta, s=12, label=f"{regime} (from the reference)", **style)
    if coexists is not None:
        sel = frame[np.asarray(coexists, bool)]
        ax.scatter(sel.R, sel.theta, s=60, facecolors="none", edgecolors="k",
                   label="slipping coexists with $p_s$")
    th = np.linspace(frame.theta.min(), frame.theta.max(), 300)
    ax.plot([circle_critical_radius(body, x) for x in th], th, "k", lw=2, label=r"$R_{crit}(\theta)$, (36)")
    ax.set(xlabel="R (m)", ylabel=r"$\theta$ (rad/s)")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=2, fontsize=8)
    return ax.figure


def plot_heading_orbits(orbits: dict, t, p, distances: dict, multiplier: float):
    """The eight's heading error against its attracting orbits: (a) each orbit's p over
    one period (``orbits``: label -> :class:`lib.rotation.attractor.RotationAttractor`) with the
    run's last period (t (s), p (rad)) on top; (b) the run's distance to each orbit per
    period (``distances``: label -> array, from ``distance_per_period``) on a log scale,
    with the rate |mu_1|^j of the slowest Floquet multiplier ``multiplier``. Returns the figure.

    Parameters
    ----------
    orbits : dict
        Label -> RotationAttractor.
    t, p : array_like
        The run's last period: times (s) and p (rad).
    distances : dict
        Label -> distance per period (rad).
    multiplier : float
        The slowest multiplier, for the expected rate.

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.2), layout="constrained")
    for i, (label, orb) in enumerate(orbits.items()):
        a.plot(orb.t, orb.p, color=f"C{i}", lw=2, label=f"orbit {label}")
    T = float(next(iter(orbits.values())).t[-1])
    last = t >= t[-1] - T - 1e-9
    tl, pl = np.mod(t[last], T), p[last]
    near = min(orbits.values(), key=lambda o: np.abs(wrap_angle(pl - np.interp(tl, o.t, o.p))).max())
    pl = pl - 2 * np.pi * np.round(np.mean(pl - np.interp(tl, near.t, near.p)) / (2 * np.pi))
    a.plot(tl, pl, "k.", ms=2, label="run from the Table's start, last period")
    a.set(xlabel="time within the period (s)", ylabel="$p$ (rad)", title="(a)")
    a.legend(fontsize=8)
    for i, (label, d) in enumerate(distances.items()):
        j = np.arange(d.size)
        b.semilogy(j, d, "o-", ms=3, color=f"C{i}", label=f"distance to orbit {label}")
    d_last = min(distances.values(), key=lambda d: d[-1])
    j = np.arange(d_last.size)
    b.semilogy(j, d_last[-1] * multiplier ** (j - j[-1]), "k:", label=r"$|\mu_1|^j$")
    b.set(xlabel="period $j$", ylabel="largest $|p - p_{orbit}|$ over the period (rad)", title="(b)")
    b.legend(fontsize=8)
    return fig


#: colours of the regimes of :func:`lib.limits.verdicts.limit_verdicts` on Chapter 4's figures
LIMIT_COLORS = {"periodic": "C2", **REGIME_COLORS}


def plot_limit_sweep(frame: pd.DataFrame, sections, *, axes, column: int = 4,
                     label: str = r"$p$ at $t=kT$ (rad)", title: str | None = None):
    """A bifurcation diagram over the angle limit with the largest Lyapunov exponent beneath
    it, on two axes sharing the angle axis: ``axes`` = (top, bottom). Top: the chosen column
    of each run's section (error states at t = kT, ``sections`` (N, L, 6)), coloured by the
    regime in ``frame`` (:func:`lib.limits.verdicts.limit_verdicts`); bottom: lambda_1 (1/s) with
    +-3 standard errors, and zero. Returns the figure.

    Parameters
    ----------
    frame : pandas.DataFrame
        Verdicts of :func:`lib.limits.verdicts.limit_verdicts`.
    sections : array_like
        Sections (N, L, 6).
    axes : tuple of matplotlib.axes.Axes
        (top, bottom).
    column : int
        The error state's column.
    label : str
        The y label.
    title : str, optional
        Title.

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    top, bot = axes
    deg = frame.angle_deg.to_numpy()
    for regime, color in LIMIT_COLORS.items():
        sel = (frame.regime == regime).to_numpy()
        if sel.any():
            L = sections.shape[1]
            top.plot(np.repeat(deg[sel], L), sections[sel, :, column].ravel(), ".", ms=1.5, color=color,
                     label=f"{regime} ({int(sel.sum())})")
            bot.errorbar(deg[sel], frame.lyapunov[sel], yerr=3 * frame.lyapunov_stderr[sel], fmt="o", ms=2.5,
                         color=color, elinewidth=0.8)
    bot.axhline(0.0, color="k", lw=0.6)
    top.set(ylabel=label, title=title)
    top.legend(fontsize=7, markerscale=5, loc="upper right")
    bot.set(xlabel=r"angle limit $\beta_{max}$ (deg)", ylabel=r"$\lambda_1$ (1/s), $\pm 3$ SE")
    return top.figure


def plot_limit_map(frame: pd.DataFrame, *, ax=None):
    """Regime map over (angle limit, force cap) from :func:`lib.limits.verdicts.limit_verdicts`: one
    cell per run, coloured by regime, periodic cells labelled with their period; the
    uncapped runs (force_limit inf) form the top row. Returns the figure.

    Parameters
    ----------
    frame : pandas.DataFrame
        Verdicts of :func:`lib.limits.verdicts.limit_verdicts`.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (default new ones).

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    fig, ax = new_axes(ax, figsize=(8, 4))
    caps = np.sort(frame.force_limit.unique())
    angles = np.sort(frame.angle_deg.unique())
    names = list(LIMIT_COLORS)
    code = np.full((caps.size, angles.size), np.nan)
    for r in frame.itertuples():
        i, j = np.searchsorted(caps, r.force_limit), np.searchsorted(angles, r.angle_deg)
        code[i, j] = names.index(r.regime)
        if r.regime in ("periodic", "slipping"):
            ax.text(j, i, str(r.period), ha="center", va="center", fontsize=7, color="w")
    ax.imshow(code, origin="lower", aspect="auto", cmap=ListedColormap([LIMIT_COLORS[n] for n in names]),
              vmin=-0.5, vmax=len(names) - 0.5, interpolation="nearest")
    ax.set_xticks(range(angles.size), [f"{a:g}" for a in angles], fontsize=7)
    ax.set_yticks(range(caps.size), ["none" if not np.isfinite(c) else f"{c:g}" for c in caps], fontsize=8)
    ax.set(xlabel=r"angle limit $\beta_{max}$ (deg)", ylabel=r"force cap $F_{max}$ (N)")
    counts = frame.regime.value_counts()
    ax.legend(handles=[Patch(color=LIMIT_COLORS[n], label=f"{n} ({counts[n]})") for n in names if n in counts],
              loc="upper center", bbox_to_anchor=(0.5, -0.18), ncol=5, fontsize=8)
    return fig


def plot_bistable_window(theta, r_crit, r_edge, grid: pd.DataFrame, grid_r_crit, coexists,
                         theta_close: float, mark=None, ax=None):
    """The circle's bistable window over the rate: R_edge/R_crit - 1 (log scale) against
    theta (rad/s), from ``theta``, ``r_crit``, ``r_edge`` (arrays, m) of
    :func:`lib.rotation.circle_global.bistable_window`; over it the grid points of
    :func:`lib.rotation.circle_global.circle_final_state` (``grid``, with R_crit per point ``grid_r_crit``) where a
    slipping motion coexists (``coexists``, by simulation) or not; a dashed line at
    ``theta_close`` and, if given, ``mark`` = (theta, R_edge/R_crit - 1) as a star.

    Parameters
    ----------
    theta, r_crit, r_edge : array_like
        Rates (rad/s) and the window's edges (m).
    grid : pandas.DataFrame
        Simulated points.
    grid_r_crit : array_like
        R_crit (m) per grid point.
    coexists : array_like
        Per grid point, whether slipping coexists.
    theta_close : float
        The closing rate (rad/s).
    mark : float, optional
        A rate (rad/s) to mark.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (default new ones).

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    if ax is None:
        fig, ax = plt.subplots(figsize=(7, 4.5))
    theta, excess = np.asarray(theta), np.asarray(r_edge) / np.asarray(r_crit) - 1.0
    ax.semilogy(theta[excess > 0], excess[excess > 0], "k", lw=2,
                label=r"$R_{edge}/R_{crit} - 1$ (homoclinic, shooting)")
    g_excess = np.asarray(grid.R) / np.asarray(grid_r_crit) - 1.0
    coexists = np.asarray(coexists, bool)
    inside = (g_excess > 0) & (g_excess < 1.5)
    ax.scatter(grid.theta[inside & coexists], g_excess[inside & coexists], s=40,
               facecolors="none", edgecolors="C3", label="grid: slipping coexists")
    ax.scatter(grid.theta[inside & ~coexists], g_excess[inside & ~coexists], s=10,
               color="C0", marker=".", label="grid: settles only")
    ax.axvline(theta_close, color="0.4", ls="--", lw=1,
               label=r"$\theta$ where the window closes")
    if mark is not None:
        ax.plot(*mark, "*", color="C1", ms=12, label=r"the paper's $\theta = \pi/4$")
    ax.set(xlabel=r"$\theta$ (rad/s)", ylabel=r"$R/R_{crit} - 1$", ylim=(1e-5, 2.0))
    ax.legend(loc="lower right", fontsize=8)
    return ax.figure
