"""Interactive versions of two of the book's maps, for the HTML pages: Fig. 5 over (R, Theta)
(Chapter 5) and the bifurcation diagrams over the angle limit (Chapter 4). The static
Matplotlib figures of :mod:`lib.figures.maps` stay for print; these add a tooltip that names
each point's verdict and numbers.

The figures are drawn with plotly and shown as an HTML fragment that does not carry plotly.js
(:func:`to_html`): the book ships the plotly.js of the pinned plotly wheel once
(:func:`plotly_js_path`, copied into the build's ``_static`` by ``_ext/plotly_local.py``) and
loads it on the pages that hold such a figure, so that no page reaches for a network. Numbers
travel as typed arrays (plotly's base64 encoding), strings only in the hover templates: one
trace for each regime and each pattern of defined numbers, so that an undefined number reads
"n/a", never "NaN".
"""

from __future__ import annotations

import html
import uuid
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
import plotly
import plotly.graph_objects as go
from matplotlib.colors import to_hex
from plotly.subplots import make_subplots

from .maps import LIMIT_COLORS, REGIME_COLORS

__all__ = ["HoverField", "FIG5_HOVER", "LIMIT_HOVER", "fig5_figure", "limit_sweep_figure", "to_html",
           "show", "plotly_js_path"]


@dataclass(frozen=True)
class HoverField:
    """One line of a tooltip: ``label: value unit``, the value from ``column`` in the d3
    format ``fmt``; ``stderr`` names a column shown as ``± value``; ``zero`` is what a value
    of zero reads (a period of 0 means no period).

    Parameters
    ----------
    label : str
        The name shown.
    column : str
        The frame's column.
    fmt : str
        A d3 number format (``.3g``, ``d``).
    unit : str
        Appended after the value (and its standard error).
    stderr : str, optional
        A column holding the value's standard error.
    zero : str, optional
        The text shown for a value of zero.
    """
    label: str
    column: str
    fmt: str = ".3g"
    unit: str = ""
    stderr: str | None = None
    zero: str | None = None


#: the tooltip of Fig. 5's points (columns of :func:`lib.rotation.verdicts.rotation_verdicts`)
FIG5_HOVER = (HoverField("R", "R", ".4g", "m"), HoverField("Θ", "Theta", ".4g", "rad/s"),
              HoverField("period (reference periods)", "period", "d", zero="none"),
              HoverField("largest |μ|", "floquet", ".3g"),
              HoverField("exponent", "lyapunov", ".3g", "1/s", stderr="lyapunov_stderr"),
              HoverField("range of p", "range", ".3g", "rad"))

#: the tooltip of the angle-limit sweep (columns of :func:`lib.limits.verdicts.limit_verdicts`)
LIMIT_HOVER = (HoverField("angle limit", "angle_deg", ".0f", "deg"),
               HoverField("period (reference periods)", "period", "d", zero="none"),
               HoverField("largest |μ|", "floquet", ".3g"),
               HoverField("exponent", "lyapunov", ".3g", "1/s", stderr="lyapunov_stderr"),
               HoverField("range of p", "p_range", ".3g", "rad"))


def _defined(frame: pd.DataFrame, fields) -> pd.DataFrame:
    """Per row, which of the fields' numbers are shown: finite, and non-zero where zero has a name."""
    out = {}
    for f in fields:
        v = frame[f.column].to_numpy(float)
        out[f.column] = np.isfinite(v) & ((v != 0) if f.zero is not None else True)
        if f.stderr:
            out[f.stderr] = np.isfinite(frame[f.stderr].to_numpy(float))
    return pd.DataFrame(out, index=frame.index)


def _template(fields, shown: Mapping[str, bool], verdict: str, verdict_at: int) -> str:
    """The hover template of one group: a line per field, the verdict's line at ``verdict_at``;
    customdata holds the shown numbers in the order of the fields."""
    lines, k = [], 0
    for f in fields:
        if not shown[f.column]:
            lines.append(f"{f.label}: {f.zero if f.zero is not None else 'n/a'}")
            continue
        text, note = f"%{{customdata[{k}]:{f.fmt}}}", ""
        k += 1
        if f.stderr:
            if shown[f.stderr]:
                text += f" ± %{{customdata[{k}]:.2g}}"
                k += 1
            else:
                note = " (no standard error)"
        lines.append(f"{f.label}: {text} {f.unit}".rstrip() + note)
    lines.insert(verdict_at, f"verdict: {verdict}")
    return "<br>".join(lines) + "<extra></extra>"


def _groups(frame: pd.DataFrame, fields, verdict_at: int, extra: tuple[str, ...] = ()):
    """Split ``frame`` by regime, ``extra`` boolean columns and the pattern of shown numbers.
    Yields (regime, key of extra, rows, customdata (float32), hover template)."""
    shown = _defined(frame, fields)
    keys = [frame.regime.astype(str)] + [frame[c].astype(bool) for c in extra] + \
        [shown[c] for c in shown.columns]
    for key, rows in frame.groupby(keys, sort=True).groups.items():
        regime, flags, pattern = key[0], key[1:1 + len(extra)], dict(zip(shown.columns, key[1 + len(extra):]))
        sub = frame.loc[rows]
        cols = []
        for f in fields:
            if pattern[f.column]:
                cols.append(f.column)
                if f.stderr and pattern[f.stderr]:
                    cols.append(f.stderr)
        verdict = regime + (", heading lost" if dict(zip(extra, flags)).get("lost") else "")
        data = sub[cols].to_numpy(np.float32) if cols else np.zeros((len(sub), 0), np.float32)
        yield regime, flags, sub, data, _template(fields, pattern, verdict, verdict_at)


def _colour(regime: str, palette: Mapping[str, str]) -> str:
    return to_hex(palette.get(regime, "0.5"))


def fig5_figure(frame: pd.DataFrame, *, height: int = 620) -> go.Figure:
    """Fig. 5 as an interactive map: one square marker per point of the (R, Theta) grid, the
    periodic points coloured by the log10 of the rotation error's range on their orbit, the
    other regimes in the flat colours of :data:`lib.figures.maps.REGIME_COLORS`, the points
    where the heading is lost ringed in white. The tooltip shows :data:`FIG5_HOVER` and the verdict.

    Parameters
    ----------
    frame : pandas.DataFrame
        Verdicts of :func:`lib.rotation.fig5.fig5_map` (columns R, Theta, regime, period,
        floquet, lyapunov, lyapunov_stderr, range, lost).
    height : int
        The figure's height (px).

    Returns
    -------
    plotly.graph_objects.Figure
        The figure.
    """
    n_R, n_T = frame.R.nunique(), frame.Theta.nunique()
    size = max(3.0, min(12.0, 560.0 / max(n_R, n_T)))
    counts = frame.regime.value_counts()
    periodic = frame[frame.regime == "periodic"]
    log_range = np.log10(periodic["range"].to_numpy(float))
    lo, hi = (np.nanmin(log_range), np.nanmax(log_range)) if np.isfinite(log_range).any() else (0.0, 1.0)
    fig = go.Figure()
    seen = set()
    for regime, (lost,), sub, data, template in _groups(frame, FIG5_HOVER, 2, extra=("lost",)):
        marker = dict(symbol="square", size=size, line=dict(width=1.2 if lost else 0, color="white"))
        if regime == "periodic":
            marker.update(color=np.log10(sub["range"].to_numpy(float)), colorscale="Viridis", cmin=lo, cmax=hi,
                          showscale="periodic" not in seen, colorbar=dict(
                              title=dict(text="log10 range of p (rad)", side="right"), len=0.75, y=0.6))
        else:
            marker.update(color=_colour(regime, REGIME_COLORS))
        fig.add_trace(go.Scatter(
            x=sub.R.to_numpy(float), y=sub.Theta.to_numpy(float), mode="markers", marker=marker,
            customdata=data, hovertemplate=template, name=f"{regime} ({counts[regime]})",
            legendgroup=regime, showlegend=regime not in seen))
        seen.add(regime)
    n_lost = int(frame.lost.sum())
    fig.add_trace(go.Scatter(x=[None], y=[None], mode="markers", name=f"lost ({n_lost}), ringed",
                             marker=dict(symbol="square-open", size=10, color="grey"), hoverinfo="skip"))
    fig.update_layout(
        height=height, margin=dict(l=60, r=20, t=20, b=40), plot_bgcolor="#808080", hovermode="closest",
        legend=dict(orientation="h", yanchor="top", y=-0.1, x=0.0),
        xaxis=dict(title="R (m)", showgrid=False, zeroline=False),
        yaxis=dict(title="Θ (rad/s)", showgrid=False, zeroline=False))
    return fig


def limit_sweep_figure(sweeps: Mapping[str, tuple[pd.DataFrame, np.ndarray]], *, column: int = 4,
                       height: int = 640) -> go.Figure:
    """The bifurcation diagrams over the angle limit as an interactive figure, one column per
    sweep: on top the chosen column of each run's section, coloured by the regime
    (:data:`lib.figures.maps.LIMIT_COLORS`); beneath, the largest Lyapunov exponent with
    +-3 standard errors. Every point's tooltip shows :data:`LIMIT_HOVER`, the verdict, and
    (on top) the section value.

    Parameters
    ----------
    sweeps : Mapping
        Title -> (verdicts of :func:`lib.limits.verdicts.limit_verdicts`, sections (N, L, 6)
        after the transient).
    column : int
        The error state's column shown on top (4: the rotation error p).
    height : int
        The figure's height (px).

    Returns
    -------
    plotly.graph_objects.Figure
        The figure.
    """
    fig = make_subplots(rows=2, cols=len(sweeps), shared_xaxes=True, row_heights=[2, 1],
                        vertical_spacing=0.06, horizontal_spacing=0.07, subplot_titles=list(sweeps))
    seen = set()
    for col, (frame, sections) in enumerate(sweeps.values(), start=1):
        frame = frame.reset_index(drop=True)
        sections = np.asarray(sections, float)
        for regime, _, sub, data, template in _groups(frame, LIMIT_HOVER, 1):
            colour, L = _colour(regime, LIMIT_COLORS), sections.shape[1]
            rows = sub.index.to_numpy()
            top_data = np.column_stack([np.repeat(data, L, axis=0),
                                        sections[rows, :, column].ravel().astype(np.float32)])
            top_template = template.replace("<extra>", f"<br>p at t = kT: %{{customdata[{data.shape[1]}]:.3g}} rad<extra>")
            fig.add_trace(go.Scatter(
                x=np.repeat(sub.angle_deg.to_numpy(float), L), y=sections[rows, :, column].ravel(),
                mode="markers", marker=dict(size=3, color=colour), customdata=top_data,
                hovertemplate=top_template, name=regime, legendgroup=regime,
                showlegend=regime not in seen), row=1, col=col)
            seen.add(regime)
            fig.add_trace(go.Scatter(
                x=sub.angle_deg.to_numpy(float), y=sub.lyapunov.to_numpy(float), mode="markers",
                marker=dict(size=5, color=colour), customdata=data, hovertemplate=template, name=regime,
                legendgroup=regime, showlegend=False,
                error_y=dict(type="data", array=3 * np.nan_to_num(sub.lyapunov_stderr.to_numpy(float)),
                             thickness=0.8, width=0, color=colour)), row=2, col=col)
        fig.add_hline(y=0.0, line=dict(color="black", width=0.6), row=2, col=col)
        fig.update_xaxes(title_text="angle limit β_max (deg)", row=2, col=col)
    fig.update_yaxes(title_text="p at t = kT (rad)", row=1, col=1)
    fig.update_yaxes(title_text="λ1 (1/s), ±3 SE", row=2, col=1)
    fig.update_layout(height=height, margin=dict(l=60, r=20, t=40, b=40), hovermode="closest",
                      plot_bgcolor="white", legend=dict(orientation="h", yanchor="bottom", y=1.04, x=0.0))
    fig.update_xaxes(showgrid=True, gridcolor="#e5e5e5")
    fig.update_yaxes(showgrid=True, gridcolor="#e5e5e5")
    return fig


#: plotly's options for the book's figures (no logo link, no cloud export, resize with the page)
PLOTLY_CONFIG = {"displaylogo": False, "responsive": True,
                 "modeBarButtonsToRemove": ["sendDataToCloud", "select2d", "lasso2d"]}


def to_html(fig: go.Figure, *, div_id: str | None = None, alt: str) -> str:
    """The figure as an HTML fragment without plotly.js (the page loads the book's copy,
    :func:`plotly_js_path`), wrapped in a ``div.interactive-figure`` whose ``aria-label`` is
    ``alt``.

    Parameters
    ----------
    fig : plotly.graph_objects.Figure
        The figure.
    div_id : str, optional
        The plot's element id (default a fresh one); the wrapper gets ``<div_id>-figure``.
    alt : str
        A sentence saying what the figure shows, for readers who cannot see it.

    Returns
    -------
    str
        The HTML.
    """
    div_id = div_id or f"plotly-{uuid.uuid4().hex[:12]}"
    body = fig.to_html(full_html=False, include_plotlyjs=False, div_id=div_id, config=PLOTLY_CONFIG,
                       include_mathjax=False, validate=True)
    return (f'<div class="interactive-figure" id="{html.escape(div_id)}-figure" role="img" '
            f'aria-label="{html.escape(alt)}">{body}</div>')


def show(fig: go.Figure, *, div_id: str | None = None, alt: str):
    """The figure for a notebook cell's output: :func:`to_html` as an ``IPython.display.HTML``
    (myst-nb renders it as raw HTML; plotly's own MIME bundle would need require.js).

    Parameters
    ----------
    fig : plotly.graph_objects.Figure
        The figure.
    div_id : str, optional
        As in :func:`to_html`.
    alt : str
        As in :func:`to_html`.

    Returns
    -------
    IPython.display.HTML
        The object to display.
    """
    from IPython.display import HTML     # the notebooks' kernel only; not a dependency of lib

    return HTML(to_html(fig, div_id=div_id, alt=alt))


def plotly_js_path() -> Path:
    """The plotly.js bundled in the installed plotly wheel (the version pinned in
    requirements.txt), which the book's build copies into its ``_static``.

    Parameters
    ----------
    None

    Returns
    -------
    pathlib.Path
        Path of ``plotly.min.js``.
    """
    path = Path(plotly.__file__).parent / "package_data" / "plotly.min.js"
    if not path.is_file():
        raise FileNotFoundError(f"plotly.min.js not found in the plotly package at {path.parent}")
    return path
