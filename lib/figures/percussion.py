"""Chapter 7's figures: the Fig. 5 map under the law for P, and one period of the two laws'
steady motions side by side."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

__all__ = ["plot_percussion_map", "plot_steady_pair"]


def plot_percussion_map(frame, ax=None):
    """The range of the heading error p (rad) over (R, Theta) from a
    :func:`lib.percussion.heading_sweep` frame; lost points as black crosses. Returns the figure.

    Parameters
    ----------
    frame : pandas.DataFrame
        A frame of :func:`lib.percussion.heading_sweep` (or
        :func:`lib.percussion.percussion_fig5_map`): columns R (m), Theta (rad/s), range (rad), lost.
    ax : matplotlib.axes.Axes, optional
        Where to draw; a new figure when None.

    Returns
    -------
    matplotlib.figure.Figure
        The figure of ``ax``, with a colour bar of the range of p (rad).
    """
    fig, ax = (plt.subplots(figsize=(6.4, 4.2)) if ax is None else (ax.figure, ax))
    sc = ax.scatter(frame.R, frame.Theta, c=frame["range"], s=6, cmap="viridis", marker="s")
    lost = frame[frame.lost]
    if len(lost):
        ax.scatter(lost.R, lost.Theta, c="k", s=10, marker="x", label="heading lost")
        ax.legend(loc="upper right")
    fig.colorbar(sc, ax=ax, label="range of p (rad)")
    ax.set_xlabel("R (m)")
    ax.set_ylabel("Theta (rad/s)")
    return fig


def plot_steady_pair(paper, ours, ax=None):
    """One period of the steady motions of the paper's law (C on the path) and of the law for P
    (P on the path): the heading error p (rad) and the force F (N) against t / T. ``ax``: two axes.

    Parameters
    ----------
    paper : SteadyMotion
        The paper's law, :func:`lib.percussion.paper_steady`: t (s), p (rad), F (N).
    ours : SteadyMotion
        The law for P, :func:`lib.percussion.percussion_steady`.
    ax : sequence of matplotlib.axes.Axes, optional
        Two axes, for p (rad) and F (N); a new figure of two when None.

    Returns
    -------
    matplotlib.figure.Figure
        The figure; t / T is t over each motion's last sample time (its period T, s), p is
        unwrapped, and a dotted line marks F = 4 N.
    """
    if ax is None:
        fig, ax = plt.subplots(1, 2, figsize=(9, 3.4))
    else:
        fig = ax[0].figure
    for sm, label, style in ((paper, "track C (paper)", "-"), (ours, "track P", "--")):
        x = sm.t / sm.t[-1]
        ax[0].plot(x, np.unwrap(sm.p), style, label=label)
        ax[1].plot(x, sm.F, style, label=label)
    ax[0].set_ylabel("p (rad)")
    ax[1].set_ylabel("F (N)")
    for a in ax:
        a.set_xlabel("t / T")
    ax[1].axhline(4.0, color="grey", lw=0.8, ls=":")
    ax[0].legend()
    fig.tight_layout()
    return fig
