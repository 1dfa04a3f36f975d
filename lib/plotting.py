"""Matplotlib helpers. Each takes an optional ``ax`` and returns the figure,
so notebooks can compose them."""

from __future__ import annotations

import numpy as np
import matplotlib.pyplot as plt
from matplotlib.patches import FancyArrowPatch, Polygon

from .params import Body

__all__ = ["body_outline", "draw_body", "new_axes"]


def new_axes(ax=None, **subplot_kw):
    """Return (fig, ax), creating them when ``ax`` is None."""
    if ax is None:
        fig, ax = plt.subplots(**subplot_kw)
        return fig, ax
    return ax.figure, ax


def body_outline(body: Body, x: float, y: float, phi: float, scale: float = 1.0) -> np.ndarray:
    """Corners (m) of a boat-shaped outline of the body: symmetric about its axis,
    length 2.5 a, bow forward, so that the force point (a ahead of C) lies inside it."""
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
