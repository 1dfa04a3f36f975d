"""The whole book as one PDF (``make pdf``): the single-page HTML build printed by headless Chromium.

Two steps:

1. ``jupyter-book build --builder singlehtml -n .`` writes the book as one HTML page into
   ``_build/singlehtml``. It reads every notebook page's outputs from the execution cache that
   ``make book`` filled (``execute_notebooks: cache`` in ``_config.yml``); a page missing from
   that cache is executed by this build, one after another, as a bare ``jupyter-book build``
   would. The cache is neither emptied nor rebuilt here. ``-n`` as ``make book``'s build: the
   two share Sphinx's environment (``_build/.doctrees``), which a change of configuration would
   make Sphinx read again.
2. Debian's ``chromium``, driven by Playwright with the browser test's offline flags, opens that
   page from a server on the loopback address, waits until MathJax has typeset the math and every
   image has loaded, replaces each interactive plotly figure (:mod:`lib.figures.interactive`) by a
   PNG of itself (``Plotly.toImage``: the static image a printed page needs, and one that
   ``pdfimages`` counts), and prints the page to A4 with page numbers.

Output, two files: ``_build/pdf/book.pdf`` (``--out``), the book as an article to read, cite or
review (the front page, the report, Methods, every chapter, the errata and the bibliography), and
beside it ``reference.pdf``, the library reference (its pages, which the HTML also holds, cut from
the article: they were two thirds of its pages). Beside each, ``figures.json`` and
``reference.json``: what the printed HTML held (images, interactive figures, typeset formulas and
any math left untypeset), which ``tests/test_pdf.py`` compares with the PDF. ``--no-build``
prints the existing ``_build/singlehtml`` again; ``--root`` names another copy of the book.
"""

from __future__ import annotations

import argparse
import functools
import http.server
import json
import shutil
import subprocess
import sys
import threading
import time
from contextlib import contextmanager
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: the single-page build and the PDF, under a book's folder
SINGLE_DIR = Path("_build") / "singlehtml"
OUT_FILE = Path("_build") / "pdf" / "book.pdf"
#: the library reference's PDF, beside the book's
REFERENCE_NAME = "reference.pdf"
SINGLE, OUT = ROOT / SINGLE_DIR, ROOT / OUT_FILE
#: the table of contents' page whose pages (it and its sections) make the reference
REFERENCE_PAGE = "reference"
CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"
#: the browser test's launch flags (tests/test_browser.py): no sandbox (root), no GPU, nothing
#: that reaches for a network
CHROMIUM_ARGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync"]
#: the window the page is laid out in before printing: the printed column is the theme's print
#: layout at this width, scaled by SCALE onto the A4 page
VIEWPORT = {"width": 1100, "height": 1400}
SCALE = 0.72
MARGIN = {"top": "15mm", "bottom": "15mm", "left": "14mm", "right": "14mm"}
FOOTER = ('<div style="font-size:8px;width:100%;text-align:center;color:#555">'
          '<span class="pageNumber"></span> / <span class="totalPages"></span></div>')

#: each interactive figure replaced by a PNG of itself, at its laid-out size, twice the pixels;
#: its modebar (zoom buttons) is not drawn by toImage. Returns how many were replaced.
STATIC_PLOTLY = """async () => {
  const divs = Array.from(document.querySelectorAll('.plotly-graph-div'));
  for (const gd of divs) {
    const w = Math.round(gd.getBoundingClientRect().width) || 700;
    const h = Math.round(gd.getBoundingClientRect().height) || 450;
    const url = await Plotly.toImage(gd, {format: 'png', width: w, height: h, scale: 2});
    const img = document.createElement('img');
    img.src = url;
    img.style.width = w + 'px';
    img.style.maxWidth = '100%';
    img.className = 'plotly-static';
    const wrap = gd.closest('.interactive-figure');
    img.alt = wrap ? wrap.getAttribute('aria-label') : 'interactive figure';
    Plotly.purge(gd);
    gd.replaceWith(img);
  }
  await Promise.all(Array.from(document.images).map(i => i.complete ? null : i.decode().catch(() => null)));
  return divs.length;
}"""

#: the part of the single page to print: "book" drops the reference's pages (a ``document-``
#: anchor of the reference page or of one below it, and the section after it) and their lines of
#: the printed contents, "reference" keeps them alone under the book's title, without the
#: contents. Returns how many pages were kept (their anchors: the root page has none).
SELECT_PART = """([part, ref]) => {
  const isRef = id => id === 'document-' + ref || id.startsWith('document-' + ref + '/');
  const anchors = Array.from(document.querySelectorAll('span[id^="document-"]'));
  const refs = anchors.filter(a => isRef(a.id));
  const toc = document.getElementById('jb-print-toc');      // the printed title page's contents
  if (part === 'book') {
    for (const a of refs) { const s = a.nextElementSibling; if (s) s.remove(); a.remove(); }
    if (toc) toc.querySelectorAll('a[href^="#document-' + ref + '"]').forEach(l => l.closest('li').remove());
    return anchors.length - refs.length;
  }
  const main = document.querySelector('main .bd-article') || document.querySelector('main') || document.body;
  const top = refs.find(a => a.id === 'document-' + ref);
  main.replaceChildren(top, top.nextElementSibling);
  if (toc) toc.remove();
  const title = document.querySelector('#jb-print-docs-body h1');
  if (title) title.textContent += ': the library reference';
  return refs.length;
}"""
#: what the printed page holds: every image in the book's content (the matplotlib figures, the
#: animations' first frames, the interactive figures' PNGs) and the figure environments; the math
#: nodes of Sphinx (``.math``) and those MathJax left untypeset (no ``mjx-container`` inside)
COUNT_FIGURES = """() => {
  const main = document.querySelector('main') || document.body;
  const all = Array.from(main.querySelectorAll('img'));
  const nodes = Array.from(main.querySelectorAll('.math'));
  return {images: all.filter(i => i.naturalWidth > 0).length,
          broken: all.filter(i => !i.naturalWidth).map(i => i.src.slice(0, 200)),
          figures: main.querySelectorAll('figure').length,
          math: document.querySelectorAll('mjx-container').length,
          mathNodes: nodes.length,
          untypeset: nodes.filter(n => !n.querySelector('mjx-container')).map(n => n.textContent.slice(0, 80))};
}"""

#: what the screen scrolls sideways, made to fit the printed column, where paper cannot scroll: a
#: table wider than its box laid out at the column's width (smaller type, words and code names
#: broken at need), a code line wrapped, a display formula scaled down to the column; then every element that still
#: clips its content sideways is listed (none should be)
FIT_WIDE = r"""() => {
  const main = document.querySelector('main') || document.body;
  const wide = (el, box) => el.scrollWidth > (box || el).clientWidth + 1;
  const fitted = {tables: 0, code: 0, math: 0};
  for (const t of main.querySelectorAll('table')) {
    const box = t.closest('.pst-scrollable-table-container, .table-wrapper') || t.parentElement;
    if (!wide(t, box) && !wide(box)) continue;
    Object.assign(t.style, {width: '100%', tableLayout: 'fixed', fontSize: '85%'});
    t.querySelectorAll('td, th').forEach(c => Object.assign(c.style, {overflowWrap: 'anywhere', wordBreak: 'break-word'}));
    t.querySelectorAll('code, span.pre').forEach(c => Object.assign(c.style, {whiteSpace: 'normal', wordBreak: 'break-all'}));
    fitted.tables++;
  }
  for (const p of main.querySelectorAll('pre')) {
    if (wide(p)) { Object.assign(p.style, {whiteSpace: 'pre-wrap', overflowWrap: 'anywhere'}); fitted.code++; }
  }
  for (const m of main.querySelectorAll('mjx-container[display="true"], td mjx-container, th mjx-container')) {
    const box = m.closest('td, th, div.math') || m.parentElement;
    if (box.clientWidth > 0 && m.scrollWidth > box.clientWidth + 1) {
      m.style.fontSize = Math.floor(100 * box.clientWidth / m.scrollWidth) + '%';
      fitted.math++;
    }
  }
  const clipped = [];
  for (const el of main.querySelectorAll('*')) {
    if (el.closest('span.math, mjx-container')) continue;   // MathJax's hidden assistive MathML widens these
    const css = getComputedStyle(el);
    if (['auto', 'scroll', 'hidden'].includes(css.overflowX) && css.display !== 'inline' && el.clientWidth > 0
        && wide(el))
      clipped.push(`${el.tagName.toLowerCase()}.${el.className} by ${el.scrollWidth - el.clientWidth} px: ` +
                   (el.innerText || '').replace(/\s+/g, ' ').slice(0, 60));
  }
  return {...fitted, clipped: clipped.slice(0, 50), nClipped: clipped.length};
}"""

#: for print: the theme's navigation hidden, the content the full width; each page of the book
#: (a ``document-`` anchor before its section) starts a printed page; figures, formulas and table
#: rows are not split; shadows, which Chromium prints as raster images, are dropped; an
#: animation prints its first frame without its controls; a cell's folded source (hide-input),
#: which paper cannot unfold, is left out with its "Show code cell source" toggle
PRINT_CSS = """
@media print {
  .bd-header, .bd-sidebar-primary, .bd-sidebar-secondary, .bd-footer, .bd-footer-content,
  .header-article, .prev-next-area, .headerlink, .toggle-button, #pst-back-to-top,
  .anim-controls, details.hide.above-input { display: none !important; }
  .bd-main .bd-content .bd-article-container, .bd-page-width { max-width: 100% !important; }
  span[id^="document-"] + section { break-before: page; }
  figure, img, .plotly-static, tr, mjx-container[display="true"] { break-inside: avoid; }
  h1, h2, h3, h4 { break-after: avoid; }
  /* :not(#id) weighs as an id: above the theme's own !important shadows on classes */
  body *:not(#no-such-id) { box-shadow: none !important; text-shadow: none !important; }
}
"""


def build_singlehtml(root: Path, log: Path) -> int:
    """Run ``jupyter-book build --builder singlehtml -n --keep-going .`` in ``root``; its output
    to ``log``.

    Parameters
    ----------
    root : pathlib.Path
        The book's folder.
    log : pathlib.Path
        Where the build's output is written.

    Returns
    -------
    int
        The build's exit status.
    """
    exe = Path(sys.executable).with_name("jupyter-book")
    log.parent.mkdir(parents=True, exist_ok=True)
    with open(log, "w") as out:
        proc = subprocess.run([str(exe), "build", "--builder", "singlehtml", "-n", "--keep-going", "."],
                              cwd=root, stdout=out, stderr=subprocess.STDOUT, text=True)
    return proc.returncode


def root_page(root: Path) -> str:
    """The root page of the book's ``_toc.yml`` (``intro``): the single-page build writes the
    whole book into ``<root page>.html`` (its ``index.html`` only redirects there).

    Parameters
    ----------
    root : pathlib.Path
        The book's folder.

    Returns
    -------
    str
        The page's name, without suffix.
    """
    import yaml

    return str(yaml.safe_load((root / "_toc.yml").read_text())["root"]).removesuffix(".md")


class _QuietHandler(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args) -> None:
        pass


@contextmanager
def _serve(folder: Path):
    """A server for ``folder`` on the loopback address, for as long as the block runs."""
    handler = functools.partial(_QuietHandler, directory=str(folder))
    httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=httpd.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{httpd.server_address[1]}"
    finally:
        httpd.shutdown()


def print_pdf(html_dir: Path, out: Path, page_name: str = "intro", part: str = "book") -> dict:
    """Print ``html_dir/<page_name>.html`` to ``out`` in headless Chromium, once MathJax has
    typeset and every image loaded, each interactive figure replaced by a PNG of itself; ``part``
    ``"book"`` without the library reference's pages, ``"reference"`` those alone.

    Parameters
    ----------
    html_dir : pathlib.Path
        The single-page build (``_build/singlehtml``).
    out : pathlib.Path
        The PDF to write.
    page_name : str
        The book's root page (:func:`root_page`), which holds the whole book.
    part : str
        ``"book"`` or ``"reference"``.

    Returns
    -------
    dict
        What the printed page held: ``images``, ``figures``, ``interactive`` (replaced by PNGs),
        ``math`` (typeset formulas), ``broken`` (images that did not load), ``requests`` (URLs
        asked for off the loopback address, which must be none), ``pages`` (the book's pages kept).
    """
    if part not in ("book", "reference"):
        raise ValueError(f"part must be 'book' or 'reference', got {part!r}")
    from playwright.sync_api import sync_playwright

    if not Path(CHROMIUM).exists():
        raise FileNotFoundError(f"Debian's chromium is not installed ({CHROMIUM}): apt-get install chromium")
    index = html_dir / f"{page_name}.html"
    if not index.is_file():
        raise FileNotFoundError(f"no single-page build at {index}: run without --no-build")
    out.parent.mkdir(parents=True, exist_ok=True)
    outside: list[str] = []
    with _serve(html_dir) as url, sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, headless=True, args=CHROMIUM_ARGS)
        page = browser.new_context(viewport=VIEWPORT).new_page()
        page.on("request", lambda r: None if r.url.startswith(("http://127.0.0.1", "data:", "blob:"))
                else outside.append(r.url))
        page.goto(f"{url}/{index.name}", wait_until="networkidle", timeout=300_000)
        page.wait_for_function("() => !!(window.MathJax && MathJax.startup && MathJax.startup.promise)",
                               timeout=120_000)
        page.evaluate("() => MathJax.startup.promise")
        page.wait_for_function("() => Array.from(document.images).every(i => i.complete)", timeout=120_000)
        kept = page.evaluate(SELECT_PART, [part, REFERENCE_PAGE])
        interactive = page.evaluate(STATIC_PLOTLY)
        page.add_style_tag(content=PRINT_CSS)
        page.emulate_media(media="print")
        fitted = page.evaluate(FIT_WIDE)
        held = {**page.evaluate(COUNT_FIGURES), "fitted": fitted}
        page.pdf(path=str(out), format="A4", print_background=True, margin=MARGIN, scale=SCALE,
                 display_header_footer=True, header_template="<span></span>", footer_template=FOOTER)
        browser.close()
    return {**held, "interactive": interactive, "requests": outside, "pages": kept}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--root", type=Path, default=ROOT, help="the book's folder (default: this checkout)")
    ap.add_argument("--out", type=Path, help=f"the PDF (default {OUT_FILE} under the book's folder)")
    ap.add_argument("--no-build", action="store_true", help="print the existing _build/singlehtml again")
    args = ap.parse_args(argv)
    root = args.root.resolve()
    out = (args.out or root / OUT_FILE).resolve()
    tic = time.perf_counter()
    if not args.no_build:
        log = out.parent / "singlehtml.log"
        print(f"Building the single-page HTML (it reads the execution cache; log: {log})", flush=True)
        rc = build_singlehtml(root, log)
        if rc != 0:
            print(log.read_text()[-4000:])
            print(f"the single-page build failed (exit {rc}); see {log}", file=sys.stderr)
            return 1
    problems = []
    for part, pdf, record in (("book", out, "figures.json"), ("reference", out.with_name(REFERENCE_NAME),
                                                              "reference.json")):
        print(f"Printing the {part} of {root / SINGLE_DIR / root_page(root)}.html in headless Chromium", flush=True)
        held = print_pdf(root / SINGLE_DIR, pdf, root_page(root), part)
        (out.parent / record).write_text(json.dumps(held, indent=1) + "\n")
        problems += ([f"{part}: images that did not load: {held['broken']}"] if held["broken"] else []) + \
                    ([f"{part}: requests off the loopback address: {held['requests']}"] if held["requests"] else [])
        print(f"{pdf}: {held['pages']} pages of the book, {held['images']} images ({held['interactive']} "
              f"interactive figures as PNG), {held['math']} formulas, {time.perf_counter() - tic:.0f} s", flush=True)
    for problem in problems:
        print("ERROR: " + problem, file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
