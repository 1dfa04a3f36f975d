"""Embeddable media for the book's pages: an animation of a simulated manoeuvre as
self-contained HTML (frames inlined, plays offline) and a CSV download link whose
data is inlined in the page (a ``data:`` URI), so the built book needs no server.
"""

from __future__ import annotations

import base64
import html
import re

import numpy as np

from ..params import Body
from .tracking import body_outline

__all__ = ["animate", "csv_link", "offline_controls"]


def animate(res, body: Body, *, n_frames: int = 60, t_from: float = 0.0, dpi: int = 60,
            figsize=(4.0, 4.0), force_scale: float = 0.12, fps: int = 12, lim=None) -> str:
    """HTML (``FuncAnimation.to_jshtml``) of the body following its path: outline,
    force arrow (red, applied at distance a ahead of C) and the trace of C, for
    ``n_frames`` instants from ``t_from`` (s) to the end of ``res``.
    Frames are PNGs inlined in the HTML; size grows with ``n_frames``, ``dpi`` and ``figsize``.

    Parameters
    ----------
    res : SimulationResult
        A run.
    body : Body
        The body.
    n_frames : int
        Frames (>= 2).
    t_from : float
        Start (s).
    dpi : int
        Resolution.
    figsize : tuple
        Figure size (in).
    force_scale : float
        Arrow length per newton (m/N).
    fps : int
        Frames per second.
    lim : tuple, optional
        Axis limits (m).

    Returns
    -------
    str
        HTML.
    """
    import matplotlib.pyplot as plt
    from matplotlib.animation import FuncAnimation
    from matplotlib.patches import Polygon

    if n_frames < 2:
        raise ValueError(f"n_frames must be at least 2, got {n_frames}")
    idx = np.linspace(np.searchsorted(res.t, t_from), res.t.size - 1, n_frames).astype(int)
    fig, ax = plt.subplots(figsize=figsize, dpi=dpi)
    ax.plot(res.z_d[:, 0], res.z_d[:, 1], "k--", lw=0.8)
    if lim is None:
        pad = 0.6
        lo = np.minimum(res.z[:, :2].min(0), res.z_d[:, :2].min(0)) - pad
        hi = np.maximum(res.z[:, :2].max(0), res.z_d[:, :2].max(0)) + pad
        lim = (lo[0], hi[0], lo[1], hi[1])
    ax.set(xlim=lim[:2], ylim=lim[2:], aspect="equal", xlabel="x (m)", ylabel="y (m)")
    trace, = ax.plot([], [], "C0", lw=1)
    patch = Polygon(body_outline(body, *res.z[0]), closed=True, fc="C0", ec="k", alpha=0.5)
    ax.add_patch(patch)
    arrow, = ax.plot([], [], "C3", lw=2)
    label = ax.text(0.02, 0.95, "", transform=ax.transAxes, fontsize=8)
    fig.tight_layout()
    start = idx[0]

    def frame(k):
        i = idx[k]
        x, y, phi = res.z[i]
        trace.set_data(res.z[start:i + 1, 0], res.z[start:i + 1, 1])
        patch.set_xy(body_outline(body, x, y, phi))
        p = np.array([x, y]) + body.a * np.array([np.cos(phi), np.sin(phi)])
        d = force_scale * res.F[i] * np.array([np.cos(phi + res.beta[i]), np.sin(phi + res.beta[i])])
        arrow.set_data([p[0], p[0] + d[0]], [p[1], p[1] + d[1]])
        label.set_text(f"t = {res.t[i]:.1f} s")
        return trace, patch, arrow, label

    anim = FuncAnimation(fig, frame, frames=len(idx), interval=1000 / fps, blit=True)
    out = anim.to_jshtml(fps=fps, default_mode="loop")
    plt.close(fig)
    return offline_controls(out)


#: matplotlib's player buttons use Font Awesome 4 icons from a CDN; offline, use plain symbols
_ICONS = {
    "fa fa-minus": "&#8722;", "fa fa-fast-backward": "&#9198;", "fa fa-step-backward": "&#9664;&#10074;",
    "fa fa-play fa-flip-horizontal": "&#9664;", "fa fa-pause": "&#10074;&#10074;", "fa fa-play": "&#9654;",
    "fa fa-step-forward": "&#10074;&#9654;", "fa fa-fast-forward": "&#9197;", "fa fa-plus": "+",
}


def offline_controls(jshtml: str) -> str:
    """Make matplotlib's ``to_jshtml`` output self-contained: drop the stylesheet link
    to the Font Awesome CDN and replace each icon by a Unicode symbol.

    Parameters
    ----------
    jshtml : str
        matplotlib's ``to_jshtml`` output.

    Returns
    -------
    str
        The HTML, self-contained.
    """
    out = re.sub(r"<link[^>]*font-awesome[^>]*>", "", jshtml, flags=re.S)
    for cls, sym in _ICONS.items():
        out = out.replace(f'<i class="{cls}"></i>', f"<span>{sym}</span>")
    if "font-awesome" in out or 'class="fa ' in out:
        raise RuntimeError("animation HTML still refers to Font Awesome; matplotlib's template changed")
    return out


def csv_link(frame, filename: str, label: str | None = None) -> str:
    """An HTML link that downloads ``frame`` (a pandas DataFrame) as ``filename``;
    the CSV is inlined as a base64 ``data:`` URI, so it works offline.

    Parameters
    ----------
    frame : pandas.DataFrame
        The data.
    filename : str
        Must end in ``.csv``.
    label : str, optional
        The link text.

    Returns
    -------
    str
        HTML.
    """
    if not filename.endswith(".csv"):
        raise ValueError(f"filename must end in .csv, got {filename!r}")
    data = base64.b64encode(frame.to_csv(index=False).encode()).decode()
    text = html.escape(label or f"Download the data ({filename}, {len(frame)} rows)")
    return (f'<a download="{html.escape(filename)}" href="data:text/csv;base64,{data}">'
            f'{text}</a>')
