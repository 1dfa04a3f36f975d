"""The interactive figures (lib.figures.interactive): every point's tooltip names its verdict
and shows each of its defined numbers, an undefined one reads "n/a", and the HTML fragment
carries no plotly.js and reaches for no network."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

pytest.importorskip("plotly")

from lib.figures import interactive  # noqa: E402
from lib.figures.interactive import FIG5_HOVER, LIMIT_HOVER, fig5_figure, limit_sweep_figure, to_html  # noqa: E402


def _fig5_frame() -> pd.DataFrame:
    """A 3 x 2 grid with each kind of row: periodic (no standard error), slipping and lost,
    chaotic (no multiplier, no period), undecided with no number at all."""
    R, Th = np.meshgrid([0.25, 1.0, 4.0], [0.05, 1.5])
    return pd.DataFrame(dict(
        R=R.ravel(), Theta=Th.ravel(),
        regime=["periodic", "periodic", "slipping", "chaotic", "chaotic", "undecided"],
        period=[1, 2, 1, 0, 0, 0],
        floquet=[0.83, 0.5, 0.99, np.nan, np.nan, np.nan],
        lyapunov=[-0.0014, -0.2, 0.0, 0.49, 0.3, np.nan],
        lyapunov_stderr=[np.nan, np.nan, np.nan, 0.032, 0.01, np.nan],
        range=[4.52, 0.2, 6.9, 25.4, 30.0, np.nan],
        lost=[False, False, True, False, True, False]))


def _render(template: str, row: np.ndarray) -> str:
    """What plotly shows for one point: each %{customdata[k]:fmt} replaced (Python's format
    language reads d3's .3g and d alike)."""
    def one(m):
        return format(float(row[int(m.group(1))]) if m.group(2) != "d" else int(row[int(m.group(1))]), m.group(2))
    text = re.sub(r"%\{customdata\[(\d+)\]:([^}]+)\}", one, template)
    return text.replace("<extra></extra>", "").replace("<br>", "\n")


def _tooltips(fig) -> dict[tuple[float, float], str]:
    out = {}
    for tr in fig.data:
        if tr.customdata is None:
            continue
        for x, y, row in zip(tr.x, tr.y, np.asarray(tr.customdata)):
            out.setdefault((round(float(x), 6), round(float(y), 6)), _render(tr.hovertemplate, row))
    return out


def test_every_fig5_point_has_a_tooltip_with_its_verdict_and_numbers():
    frame = _fig5_frame()
    tips = _tooltips(fig5_figure(frame))
    assert len(tips) == len(frame)
    for r in frame.itertuples():
        tip = tips[(round(r.R, 6), round(r.Theta, 6))]
        lines = tip.splitlines()
        assert lines[:3] == [f"R: {format(r.R, '.4g')} m", f"Θ: {format(r.Theta, '.4g')} rad/s",
                             f"verdict: {r.regime}" + (", heading lost" if r.lost else "")]
        assert len(lines) == 3 + len(FIG5_HOVER) - 2
        assert "nan" not in tip.lower()
        assert (f"period (reference periods): {r.period}" if r.period else "period (reference periods): none") in lines
        assert (f"largest |μ|: {r.floquet:.3g}" if np.isfinite(r.floquet) else "largest |μ|: n/a") in lines
        if np.isfinite(r.lyapunov_stderr):
            assert f"exponent: {r.lyapunov:.3g} ± {r.lyapunov_stderr:.2g} 1/s" in lines
        elif np.isfinite(r.lyapunov):
            assert f"exponent: {r.lyapunov:.3g} 1/s (no standard error)" in lines
        else:
            assert "exponent: n/a" in lines


def test_every_angle_limit_point_has_a_tooltip_with_its_verdict():
    frame = pd.DataFrame(dict(
        angle_deg=[10.0, 20.0, 30.0], regime=["chaotic", "periodic", "periodic"], period=[0, 1, 2],
        floquet=[np.nan, 0.3, 0.9], lyapunov=[0.29, -0.1, -0.01], lyapunov_stderr=[0.012, np.nan, np.nan],
        p_range=[61.6, 0.5, 0.7]))
    sections = np.random.default_rng(0).normal(size=(3, 4, 6))
    fig = limit_sweep_figure({"no cap": (frame, sections), "cap": (frame, sections)})
    tips = _tooltips(fig)
    for r in frame.itertuples():
        on_top = [t for (x, y), t in tips.items() if x == r.angle_deg and "p at t = kT" in t]
        beneath = tips[(r.angle_deg, round(r.lyapunov, 6))]
        assert len(on_top) == sections.shape[1]
        for tip in on_top + [beneath]:
            assert tip.splitlines()[:2] == [f"angle limit: {r.angle_deg:.0f} deg", f"verdict: {r.regime}"]
            assert f"range of p: {r.p_range:.3g} rad" in tip and "nan" not in tip.lower()
    # the section values on top are the sections' column 4, the rotation error
    top = {round(float(y), 6) for tr in fig.data if tr.yaxis == "y" for y in tr.y}
    assert top == {round(float(v), 6) for v in sections[:, :, 4].ravel()}
    assert len(LIMIT_HOVER) == 5


def test_the_html_fragment_carries_no_plotly_js_and_names_no_host():
    html = to_html(fig5_figure(_fig5_frame()), div_id="fig-test", alt="A map of <verdicts> & ranges.")
    assert 'id="fig-test"' in html and 'class="plotly-graph-div"' in html
    assert 'aria-label="A map of &lt;verdicts&gt; &amp; ranges."' in html
    assert len(html) < 50_000                      # no 4.8 MB bundle inlined
    assert not re.search(r"https?://|require\(|cdn", html, re.I)


def test_plotly_js_is_the_pinned_wheels():
    import plotly

    js = interactive.plotly_js_path()
    assert js.stat().st_size > 1_000_000
    head = js.read_text(encoding="utf-8", errors="replace")[:400]
    assert re.search(r"plotly\.js v\d", head), head[:200]
    pinned = re.search(r"^plotly==(\S+)", (Path(__file__).parents[1] / "requirements.txt").read_text(),
                       re.M)
    assert pinned and pinned.group(1) == plotly.__version__
