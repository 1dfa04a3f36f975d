"""Sphinx extension of the book: plotly.js ships with the build, no CDN.

The interactive figures (:mod:`lib.figures.interactive`) are HTML fragments without
plotly.js. At the end of an HTML build this extension copies the ``plotly.min.js`` of the
installed plotly wheel (the version pinned in requirements.txt) into ``_build/html/_static``
once, and adds a ``<script>`` for it to the head of the pages that hold a plotly figure,
only those: the 4.8 MB script is not loaded by the other pages. It is loaded synchronously,
before the page's body runs ``Plotly.newPlot``. The file is not kept in ``_static/`` of the
source tree, where Jupyter Book would load every ``.js`` file on every page."""

from __future__ import annotations

import shutil
from pathlib import Path

#: the class of the element each plotly figure draws into
MARK = 'class="plotly-graph-div"'
JS = "plotly.min.js"


def _add_script(app, pagename, templatename, context, doctree) -> None:
    if MARK in context.get("body", ""):
        app.add_js_file(JS)


def _copy_plotly_js(app, exception) -> None:
    if exception is not None or app.builder.format != "html":
        return
    from lib.figures.interactive import plotly_js_path

    dest = Path(app.outdir) / "_static" / JS
    dest.parent.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(plotly_js_path(), dest)


def setup(app):
    app.connect("html-page-context", _add_script)
    app.connect("build-finished", _copy_plotly_js)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
