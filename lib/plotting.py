"""The book's figures (Matplotlib). Each takes an optional ``ax`` and returns the figure,
so notebooks can compose them."""

from __future__ import annotations

import numpy as np
import matplotlib.pyplot as plt
from matplotlib.colors import ListedColormap, LogNorm
from matplotlib.patches import FancyArrowPatch, Patch, Polygon

import pandas as pd

from .angles import wrap_angle
from .circle_rotation import circle_critical_radius
from .params import Body

__all__ = ["body_outline", "draw_body", "new_axes", "plot_path", "plot_errors", "plot_force", "plot_bifurcation",
           "plot_section", "plot_fig5", "plot_fig5_exponents", "plot_circle_map", "plot_heading_orbits",
           "REGIME_COLORS", "LIMIT_COLORS", "plot_limit_sweep", "plot_limit_map"]


def new_axes(ax=None, **subplot_kw):
    """Return (fig, ax), creating them when ``ax`` is None.

    Parameters
    ----------
    ax : matplotlib.axes.Axes, optional
        Existing axes.
    **subplot_kw
        Keywords of ``plt.subplots``.

    Returns
    -------
    fig : matplotlib.figure.Figure
        The figure.
    ax : matplotlib.axes.Axes
        The axes.
    """
    if ax is None:
        fig, ax = plt.subplots(**subplot_kw)
        return fig, ax
    return ax.figure, ax


def body_outline(body: Body, x: float, y: float, phi: float, scale: float = 1.0) -> np.ndarray:
    """Corners (m) of a boat-shaped outline of the body: symmetric about its axis,
    length 2.5 a, bow forward, so that the force point (a ahead of C) lies inside it.

    Parameters
    ----------
    body : Body
        The body (its a).
    x, y : float
        Position of C (m).
    phi : float
        Heading (rad).
    scale : float
        Drawing scale.

    Returns
    -------
    numpy.ndarray
        Corners (m), (n, 2).
    """
    L, W = 1.25 * body.a * scale, 0.45 * body.a * scale
    local = np.array([[L, 0.0], [0.4 * L, W], [-L, W], [-L, -W], [0.4 * L, -W]])
    c, s = np.cos(phi), np.sin(phi)
    return local @ np.array([[c, s], [-s, c]]) + np.array([x, y])


def draw_body(x: float, y: float, phi: float, body: Body, F: float | None = None, beta: float | None = None,
              *, ax=None, force_scale: float = 0.1, scale: float = 1.0, color: str = "C0",
              axes_arrows: bool = False):
    """Draw the body at (x, y) with heading phi (rad); optionally the force F (N)
    at angle beta (rad) to the axis, applied at distance a ahead of C on the
    symmetry line (Fig. 1). That is where eq. (4) puts it: the torque of a force
    at r = a e1 is a F sin(beta), as printed; at -a e1 it would be -a F sin(beta).

    ``force_scale`` is metres of arrow per newton. Returns the figure.

    Parameters
    ----------
    x, y : float
        Position of C (m).
    phi : float
        Heading (rad).
    body : Body
        The body.
    F : float, optional
        Force (N).
    beta : float, optional
        Its angle to the axis (rad).
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (default new ones).
    force_scale : float
        Arrow length per newton (m/N).
    scale : float
        Drawing scale.
    color : str
        Colour.
    axes_arrows : bool
        Draw the body axes.

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    fig, ax = new_axes(ax)
    ax.add_patch(Polygon(body_outline(body, x, y, phi, scale), closed=True, fc=color, ec="k", alpha=0.35, lw=1))
    ax.plot([x], [y], "k.", ms=4)
    e1 = np.array([np.cos(phi), np.sin(phi)])
    e2 = np.array([-np.sin(phi), np.cos(phi)])
    if axes_arrows:
        for e, lab in ((e1, "$v_1$"), (e2, "$v_2$")):
            tip = np.array([x, y]) + 1.3 * body.a * scale * e
            ax.add_patch(FancyArrowPatch((x, y), tip, arrowstyle="->", mutation_scale=12, color="k"))
            ax.annotate(lab, tip, textcoords="offset points", xytext=(4, 4))
    if F is not None and beta is not None and F > 0:
        p = np.array([x, y]) + body.a * scale * e1
        d = np.array([np.cos(phi + beta), np.sin(phi + beta)])
        ax.add_patch(FancyArrowPatch(tuple(p), tuple(p + force_scale * F * d), arrowstyle="-|>",
                                     mutation_scale=10, color="C3", lw=1.5))
    ax.set_aspect("equal")
    return fig


# ---------------------------------------------------------------- tracking (Chapters 3-4)

def plot_path(res, body: Body, *, ax=None, n_bodies: int = 10, force_scale: float = 0.12, t_from: float = 0.0,
              scale: float = 1.0, reference: bool = True, endpoint: bool = True):
    """Fig. 2a/3a: the reference path (dashed), the path of C, and the body with its
    force vector at ``n_bodies`` regular instants from ``t_from`` (s) to the end
    (excluded when ``endpoint`` is False, e.g. over one whole period, where the
    first and last instants coincide). Returns the figure.

    Parameters
    ----------
    res : SimulationResult
        A run.
    body : Body
        The body.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (default new ones).
    n_bodies : int
        Bodies drawn.
    force_scale : float
        Arrow length per newton (m/N).
    t_from : float
        Start (s).
    scale : float
        Drawing scale.
    reference, endpoint : bool
        Draw the reference; include the last instant.

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    fig, ax = new_axes(ax)
    if reference:
        ax.plot(res.z_d[:, 0], res.z_d[:, 1], "k--", lw=1, label="reference")
    ax.plot(res.z[:, 0], res.z[:, 1], "C0", lw=1.2, label="body (C)")
    idx = np.linspace(np.searchsorted(res.t, t_from), res.t.size - 1, n_bodies, endpoint=endpoint).astype(int)
    for i in idx:
        draw_body(res.z[i, 0], res.z[i, 1], res.z[i, 2], body, F=res.F[i], beta=res.beta[i], ax=ax,
                  force_scale=force_scale, scale=scale)
    ax.set(xlabel="x (m)", ylabel="y (m)", aspect="equal")
    ax.legend(loc="upper right", fontsize=8)
    return fig


def plot_errors(res, *, ax=None, p=None):
    """Fig. 2b/3b: position errors e_x, e_y (m) and the rotation error p = phi - phi_d (rad)
    against time. ``p`` overrides the rotation error (e.g. a continuous version).

    Parameters
    ----------
    res : SimulationResult
        A run.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (default new ones).
    p : array_like, optional
        The rotation error to plot (rad).

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    fig, ax = new_axes(ax)
    e = res.error
    ax.plot(res.t, e[:, 0], "C0", label=r"$e_x$ (m)")
    ax.plot(res.t, e[:, 1], "C1", label=r"$e_y$ (m)")
    ax.plot(res.t, res.rotation_error() if p is None else p, "C2", label=r"$p=\varphi-\varphi_d$ (rad)")
    ax.axhline(0, color="k", lw=0.5)
    ax.set(xlabel="t (s)", ylabel="error")
    ax.legend(fontsize=8)
    return fig


def plot_force(res, cap: float | None = None, *, ax=None, intervals=None):
    """Force magnitude F (N) against time, with the cap and the saturated intervals shaded.

    Parameters
    ----------
    res : SimulationResult
        A run.
    cap : float, optional
        The cap (N).
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (default new ones).
    intervals : list of tuple, optional
        Saturated intervals (s).

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    fig, ax = new_axes(ax)
    ax.plot(res.t, res.F, "C3", lw=1)
    if cap is not None:
        ax.axhline(cap, color="k", ls=":", lw=1, label=f"cap {cap:g} N")
        for a, b in intervals or []:
            ax.axvspan(a, b, color="C3", alpha=0.15, lw=0)
        ax.legend(fontsize=8)
    ax.set(xlabel="t (s)", ylabel="F (N)")
    return fig


def plot_bifurcation(angle_limits, sections, column: int = 4, *, ax=None, label: str = r"$p$ at $t=kT$ (rad)"):
    """Bifurcation diagram: for each angle limit (rad, plotted in degrees), the chosen
    column of its stroboscopic section (default the rotation error p).

    Parameters
    ----------
    angle_limits : array_like
        beta_max (rad).
    sections : sequence of numpy.ndarray
        One section (n, 6) per limit.
    column : int
        The error state's column.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (default new ones).
    label : str
        The y label.

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    fig, ax = new_axes(ax)
    for b, sec in zip(angle_limits, sections):
        ax.plot(np.full(len(sec), np.rad2deg(b)), sec[:, column], "k.", ms=2)
    ax.set(xlabel=r"angle limit $\beta_{max}$ (deg)", ylabel=label)
    return fig


def plot_section(section, i: int = 0, j: int = 4, *, ax=None, color: str = "k", label=None):
    """Stroboscopic (Poincaré) section: column ``j`` against column ``i`` of an error-state
    array [e_x, e_y, de_x, de_y, p, dp].

    Parameters
    ----------
    section : array_like
        Error states (n, 6).
    i, j : int
        Columns plotted.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (default new ones).
    color : str
        Colour.
    label : str, optional
        Legend label.

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    names = [r"$e_x$ (m)", r"$e_y$ (m)", r"$\dot e_x$ (m/s)", r"$\dot e_y$ (m/s)", r"$p$ (rad)", r"$\dot p$ (rad/s)"]
    fig, ax = new_axes(ax)
    ax.plot(section[:, i], section[:, j], ".", color=color, ms=3, label=label)
    ax.set(xlabel=names[i], ylabel=names[j])
    return fig


#: how each non-periodic regime of :func:`lib.rotation_verdicts.rotation_verdicts` is drawn on the maps
REGIME_COLORS = {"slipping": "C3", "chaotic": "0.15", "quasiperiodic": "C0", "undecided": "0.7"}


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
    points of a rectangular (R, Theta) grid (:func:`lib.rotation_verdicts.rotation_verdicts`), the
    other regimes in flat colours (:data:`REGIME_COLORS`), and the points where stability
    is lost (column ``lost``) ringed, as the paper's empty circles. Returns the figure.

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
    :func:`lib.circle_rotation.circle_final_state`), with the analytic boundary R_crit(theta) of (36)
    and, if given, the points where slipping coexists with the stable equilibrium.

    Parameters
    ----------
    frame : pandas.DataFrame
        End states of :func:`lib.circle_rotation.circle_final_state`.
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
    one period (``orbits``: label -> :class:`lib.rotation_attractor.RotationAttractor`) with the
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


#: colours of the regimes of :func:`lib.limits.limit_verdicts` on Chapter 4's figures
LIMIT_COLORS = {"periodic": "C2", **REGIME_COLORS}


def plot_limit_sweep(frame: pd.DataFrame, sections, *, axes, column: int = 4,
                     label: str = r"$p$ at $t=kT$ (rad)", title: str | None = None):
    """A bifurcation diagram over the angle limit with the largest Lyapunov exponent beneath
    it, on two axes sharing the angle axis: ``axes`` = (top, bottom). Top: the chosen column
    of each run's section (error states at t = kT, ``sections`` (N, L, 6)), coloured by the
    regime in ``frame`` (:func:`lib.limits.limit_verdicts`); bottom: lambda_1 (1/s) with
    +-3 standard errors, and zero. Returns the figure.

    Parameters
    ----------
    frame : pandas.DataFrame
        Verdicts of :func:`lib.limits.limit_verdicts`.
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
    """Regime map over (angle limit, force cap) from :func:`lib.limits.limit_verdicts`: one
    cell per run, coloured by regime, periodic cells labelled with their period; the
    uncapped runs (force_limit inf) form the top row. Returns the figure.

    Parameters
    ----------
    frame : pandas.DataFrame
        Verdicts of :func:`lib.limits.limit_verdicts`.
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
    :func:`lib.circle_rotation.bistable_window`; over it the grid points of
    :func:`lib.circle_rotation.circle_final_state` (``grid``, with R_crit per point ``grid_r_crit``) where a
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
