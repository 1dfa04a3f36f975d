"""The body and the tracking figures (Matplotlib, Chapters 1-4): the body drawn with its force,
the path, the errors, the force, and the stroboscopic sections under an angle limit. Each takes
an optional ``ax`` and returns the figure; :mod:`lib.figures.maps` re-exports them beside the
maps of Chapters 4-6."""

from __future__ import annotations

import numpy as np
import matplotlib.pyplot as plt
from matplotlib.patches import FancyArrowPatch, Polygon

from ..params import Body

__all__ = ["body_outline", "draw_body", "new_axes", "plot_path", "plot_errors", "plot_force", "plot_bifurcation",
           "plot_section"]


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
