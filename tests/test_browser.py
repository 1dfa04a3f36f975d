"""Read every page of the built book in headless Chromium at 1280 px, offline, in one
browser session, and check that it reads correctly:

- math typeset by the bundled MathJax, every image loaded, no request leaving the
  loopback address;
- every glued number present in the text, and no raw ``{glue``, ``nan`` or ``None``
  in the prose;
- every Markdown table (in the text or emitted by a cell) rendered as a table;
- no code line wider than its code block;
- every figure's alt text a sentence, not a file name;
- on the report page, every status one of those its legend defines, and its table within
  the content area with every column at least 120 px wide;
- hovering known points of the interactive figures (Fig. 5 in Chapter 5, the angle-limit
  diagram in Chapter 4) with the mouse shows a tooltip with their verdict, and plotly.js
  comes from the book's ``_static``.

The pages are visited once (fixture ``pages``); each check is its own test, so a
failure names the page and the check. Needs Debian's ``chromium`` (``.ci/run``
installs it); without it the tests are skipped with a message saying so.
"""

from __future__ import annotations

import functools
import http.server
import json
import re
import shutil
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from urllib.parse import urlparse

import pytest
import yaml

pytestmark = pytest.mark.browser

ROOT = Path(__file__).resolve().parents[1]
BUILD = ROOT / "_build"
HTML = BUILD / "html"
CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"
VIEWPORT = {"width": 1280, "height": 900}
GLUE_ROLE = re.compile(r"\{glue(?::text)?\}`([^`]+)`")
TABLE_RULE = re.compile(r"^\s*\|?\s*:?-{3,}:?\s*(\|\s*:?-{3,}:?\s*)+\|?\s*$")


def toc_documents() -> list[str]:
    toc = yaml.safe_load((ROOT / "_toc.yml").read_text())
    docs = [toc["root"]]

    def walk(entries):
        for e in entries or []:
            if "file" in e:
                docs.append(e["file"])
            walk(e.get("sections"))
            for part in e.get("parts", []):
                walk(part.get("chapters"))

    walk(toc.get("chapters"))
    for part in toc.get("parts", []):
        walk(part.get("chapters"))
    return docs


DOCS = toc_documents()


def expected_glue_strings(doc: str) -> list[str]:
    """The text each glue role of ``doc`` renders to, from the executed notebook."""
    from myst_nb.core.variables import format_plain_text

    src = (ROOT / f"{doc}.md").read_text()
    roles = GLUE_ROLE.findall(src)
    if not roles:
        return []
    glued = json.loads((BUILD / "jupyter_execute" / f"{doc}.glue.json").read_text())
    values = {key: out["data"]["text/plain"] for key, out in glued.items()}
    expected = []
    for role in roles:
        key, _, fmt = role.partition(":")
        assert key in values, f"{doc}: glue key {key!r} is used in the text but never glued"
        expected.append(format_plain_text(values[key], fmt))
    return expected


def count_markdown_tables(text: str) -> int:
    """Markdown tables in ``text``: delimiter rows (``|---|---|``) under a row with a pipe."""
    lines = text.splitlines()
    return sum(1 for i in range(1, len(lines))
               if TABLE_RULE.match(lines[i]) and "|" in lines[i - 1])


def prose_of(source: str) -> str:
    """The Markdown text of a MyST notebook outside its code cells and fenced blocks."""
    out, fence = [], None
    for line in source.splitlines():
        m = re.match(r"^\s*(`{3,}|~{3,})", line)
        if fence is None and m:
            fence = m.group(1)
            continue
        if fence is not None:
            if line.strip() == fence:
                fence = None
            continue
        out.append(line)
    return "\n".join(out)


def expected_tables(doc: str) -> int:
    """Tables the page must show: the Markdown tables of its text and those its cells emit
    as Markdown (``lib.machinery.glue.markdown_table``), read from the executed notebook."""
    n = count_markdown_tables(prose_of((ROOT / f"{doc}.md").read_text()))
    nb = BUILD / "jupyter_execute" / f"{doc}.ipynb"
    if nb.exists():
        for cell in json.loads(nb.read_text()).get("cells", []):
            for out in cell.get("outputs", []):
                md = out.get("data", {}).get("text/markdown")
                if md:
                    n += count_markdown_tables("".join(md) if isinstance(md, list) else md)
    return n


# ---------------------------------------------------------------- one pass over the book

READ_PAGE = r"""() => {
  const main = document.querySelector('main') || document.body;
  const where = (el) => {
    let h = null, n = el;
    for (; n && !h; n = n.parentElement) {
      let s = n.previousElementSibling;
      while (s && !h) {
        h = s.matches('h1,h2,h3,h4') ? s : s.querySelector('h1,h2,h3,h4');
        s = s.previousElementSibling;
      }
    }
    return h ? h.textContent.replace(/[#¶]/g, '').trim() : '(top of page)';
  };
  const copy = main.cloneNode(true);
  copy.querySelectorAll('pre, code, mjx-container, script, style, .cell_input')
      .forEach(e => e.remove());
  const tables = Array.from(main.querySelectorAll('table'))
      .filter(t => !t.closest('.highlight, mjx-container'));
  const pipeParagraphs = Array.from(main.querySelectorAll('p'))
      .map(p => p.textContent.trim())
      .filter(t => t.startsWith('|') && (t.includes('|---') || t.split(' | ').length > 2))
      .map(t => t.slice(0, 100));
  const overflowing = Array.from(main.querySelectorAll('div.cell_input pre, div.highlight pre'))
      .filter(p => p.scrollWidth > p.clientWidth + 1)
      .map(p => {
        const lines = p.textContent.split('\n');
        const longest = lines.reduce((a, b) => (b.length > a.length ? b : a), '');
        return {section: where(p), scrollWidth: p.scrollWidth, clientWidth: p.clientWidth,
                line: longest};
      });
  const images = Array.from(main.querySelectorAll('img')).map(i => ({
      src: i.getAttribute('src'), alt: i.getAttribute('alt'), section: where(i),
      loaded: i.complete && i.naturalWidth > 0}));
  const legend = [];
  main.querySelectorAll('ul').forEach(ul => {
    const items = Array.from(ul.querySelectorAll(':scope > li'));
    const terms = items.map(li => {
      const s = li.querySelector('strong');
      return s && li.textContent.trim().startsWith(s.textContent.trim()) ? s.textContent.trim() : null;
    });
    if (items.length && terms.every(t => t)) legend.push(...terms);
  });
  const statuses = [];
  tables.forEach(t => {
    const head = Array.from(t.querySelectorAll('thead th')).map(th => th.textContent.trim());
    const k = head.indexOf('status');
    if (k < 0) return;
    t.querySelectorAll('tbody tr').forEach(tr => {
      const cells = tr.querySelectorAll('td');
      if (cells[k]) statuses.push({row: cells[0].textContent.trim(), status: cells[k].textContent.trim()});
    });
  });
  return {
    hasMathjax: !!(window.MathJax && MathJax.startup),
    nMath: document.querySelectorAll('mjx-container').length,
    prose: copy.innerText,
    fullText: document.body.innerText,
    nTables: tables.length,
    pipeParagraphs, overflowing, images, legend, statuses,
  };
}"""


@dataclass
class Page:
    """What one visit of a page found."""
    doc: str
    url: str
    data: dict
    requests: list[str] = field(default_factory=list)
    failed: list[str] = field(default_factory=list)


class _QuietHandler(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args) -> None:
        pass


@pytest.fixture(scope="module")
def server(built_book):
    if built_book.returncode != 0:
        pytest.fail("the book did not build; see test_book.py")
    handler = functools.partial(_QuietHandler, directory=str(HTML))
    httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=httpd.serve_forever, daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{httpd.server_address[1]}"
    httpd.shutdown()


@pytest.fixture(scope="module")
def pages(server) -> dict[str, Page]:
    """Every page of the table of contents, read once in one headless Chromium."""
    if not Path(CHROMIUM).exists():
        pytest.skip(f"Debian's chromium is not installed ({CHROMIUM} missing): browser test skipped; "
                    "run .ci/run or `apt-get install chromium` to enable it")
    from playwright.sync_api import TimeoutError as PlaywrightTimeout, sync_playwright

    read: dict[str, Page] = {}
    tic = time.perf_counter()
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, headless=True, args=[
            "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
            "--disable-background-networking", "--disable-component-update", "--disable-sync"])
        context = browser.new_context(viewport=VIEWPORT)
        for doc in DOCS:
            url = f"{server}/{'index' if doc == 'intro' else doc}.html"
            page = context.new_page()
            seen = Page(doc, url, {})
            page.on("request", lambda r, seen=seen: seen.requests.append(r.url))
            page.on("requestfailed", lambda r, seen=seen: seen.failed.append(r.url))
            page.goto(url, wait_until="networkidle")
            # a page that includes MathJax: wait until it has started and typeset (on a heavy page,
            # Chapter 4's plotly figures, the deferred script may still be running at network idle)
            if page.evaluate("() => !!document.querySelector('script[src*=\"mathjax\"]')"):
                try:
                    page.wait_for_function("() => !!(window.MathJax && MathJax.startup && MathJax.startup.promise)",
                                           timeout=60_000)
                    page.evaluate("() => MathJax.startup.promise")
                except PlaywrightTimeout:
                    pass                                  # the math test then says MathJax did not load
            page.wait_for_function("() => Array.from(document.images).every(i => i.complete)")
            seen.data = page.evaluate(READ_PAGE)
            page.close()
            read[doc] = seen
        context.close()
        browser.close()
    print(f"\nread {len(read)} pages in one browser in {time.perf_counter() - tic:.1f} s")
    return read


def _page(pages: dict[str, Page], doc: str) -> Page:
    return pages[doc]


# ---------------------------------------------------------------- the checks, page by page

@pytest.mark.parametrize("doc", DOCS)
def test_math_is_typeset_by_the_bundled_mathjax(doc, pages):
    pg, src = _page(pages, doc), (ROOT / f"{doc}.md").read_text()
    if "$" in src or "{math}" in src:
        assert pg.data["hasMathjax"], f"{doc}: MathJax did not load"
        assert pg.data["nMath"] > 0, f"{doc}: no typeset math (mjx-container) found"
    text = pg.data["prose"]
    for raw in ("$$", "\\[", "\\begin{"):
        assert raw not in text, f"{doc}: raw LaTeX {raw!r} left in the text"
    leftover = re.findall(r"\\(?:frac|varphi|omega|beta|tau|sqrt|mathbb|dot|ddot)\b", text)
    assert not leftover, f"{doc}: untypeset LaTeX commands in the text: {sorted(set(leftover))}"


@pytest.mark.parametrize("doc", DOCS)
def test_images_load_and_no_request_leaves_loopback(doc, pages):
    pg = _page(pages, doc)
    broken = [f"{i['src']} (in '{i['section']}')" for i in pg.data["images"] if not i["loaded"]]
    assert not broken, f"{doc}: images that did not load: {broken}"
    outside = [u for u in pg.requests
               if urlparse(u).scheme not in ("data", "blob", "about") and urlparse(u).hostname != "127.0.0.1"]
    assert not outside, f"{doc}: requests left the loopback address: {outside}"
    assert not pg.failed, f"{doc}: requests failed: {pg.failed}"


@pytest.mark.parametrize("doc", DOCS)
def test_every_glued_value_is_in_the_text(doc, pages):
    full_text = " ".join(_page(pages, doc).data["fullText"].split())
    missing = [e for e in expected_glue_strings(doc) if e not in full_text]
    assert not missing, f"{doc}: glued values not found in the page text: {missing}"


def _english_none(text: str, start: int, end: int) -> bool:
    """A "None" that opens a sentence and goes on with a word ("None of the points ...",
    "None occurs ..."); a None value printed into the text stands anywhere else."""
    before = text[:start].rstrip(" ")
    return (not before or before[-1] in ".!?\n") and re.match(r" [a-z]", text[end:]) is not None


#: pages generated from the library's docstrings (reference.md and its pages): None and NaN
#: there are words of the API (defaults, return values), not missing values; they glue nothing
API_DOCS = tuple(d for d in DOCS if d == "reference" or d.startswith("reference/"))


@pytest.mark.parametrize("doc", [d for d in DOCS if d not in API_DOCS])
def test_no_raw_glue_nan_or_none_in_the_prose(doc, pages):
    text = _page(pages, doc).data["prose"]
    found = []
    for pattern in (r"\{glue", r"\bnan\b", r"\bNaN\b", r"\bNone\b"):
        for m in re.finditer(pattern, text):
            if m.group() == "None" and _english_none(text, m.start(), m.end()):
                continue
            found.append(f"{m.group()!r} in '…{text[max(0, m.start() - 50):m.end() + 30]}…'".replace("\n", " "))
    assert not found, f"{doc}: raw glue or missing values in the prose:\n  " + "\n  ".join(found)


def test_the_prose_check_tells_a_missing_value_from_english():
    text = "None of the six is zero. at None points\tNone\nNone occurs. x: None rad"
    flagged = [m.start() for m in re.finditer(r"\bNone\b", text)
               if not _english_none(text, m.start(), m.end())]
    assert flagged == [text.index("at None") + 3, text.index("\tNone") + 1, text.index(": None") + 2]


@pytest.mark.parametrize("doc", DOCS)
def test_markdown_tables_render_as_tables(doc, pages):
    pg = _page(pages, doc)
    assert not pg.data["pipeParagraphs"], (
        f"{doc}: Markdown tables rendered as paragraphs of pipes (not <table>): {pg.data['pipeParagraphs']}")
    expected = expected_tables(doc)
    assert pg.data["nTables"] >= expected, (
        f"{doc}: {pg.data['nTables']} <table> elements on the page, {expected} Markdown tables in its "
        "source and cell outputs")


@pytest.mark.parametrize("doc", DOCS)
def test_code_lines_fit_their_blocks_at_1280px(doc, pages):
    over = _page(pages, doc).data["overflowing"]
    assert not over, f"{doc}: code blocks wider than their box at {VIEWPORT['width']} px:\n  " + "\n  ".join(
        f"in '{o['section']}': {o['scrollWidth']} > {o['clientWidth']} px, longest line {o['line']!r}"
        for o in over)


ALT_PATH = re.compile(r"_build|\.(png|jpe?g|svg|gif|webp)\b|^\S*[/\\]\S*$", re.IGNORECASE)


@pytest.mark.parametrize("doc", DOCS)
def test_figure_alt_text_is_a_sentence(doc, pages):
    bad = []
    for img in _page(pages, doc).data["images"]:
        alt = (img["alt"] or "").strip()
        if not alt:
            why = "no alt text"
        elif ALT_PATH.search(alt):
            why = "alt text is a file path"
        elif len(alt.split()) < 4 or not alt[0].isupper() or not alt.endswith("."):
            why = "alt text is not a sentence (capitalised, four words or more, ending with '.')"
        else:
            continue
        bad.append(f"{img['src']} in '{img['section']}': {why}: {alt!r}")
    assert not bad, f"{doc}: figures without a descriptive alt text:\n  " + "\n  ".join(bad)


def test_report_statuses_come_from_its_legend(pages):
    data = _page(pages, "report").data
    legend, rows = set(data["legend"]), data["statuses"]
    assert legend, "report: no legend of statuses (a list of **status**: meaning) found"
    assert rows, "report: no table with a 'status' column found"
    off = [f"row {r['row']!r}: status {r['status']!r}" for r in rows
           if re.sub(r"\s*\(.*\)\s*$", "", r["status"]) not in legend]
    assert not off, f"report: statuses outside its legend {sorted(legend)}:\n  " + "\n  ".join(off)


# ---------------------------------------------------------------- hovering the interactive figures

#: where to find the plot of a figure (its plotly div id) and the page it is on
INTERACTIVE = {"interactive-fig5": "chapters/05_stability",
               "interactive-bifurcation": "chapters/04_limits"}

#: points whose verdict the chapters establish, hovered with the mouse: (figure, x axis, y axis,
#: x, y or None for "a point of that trace at x", verdict). Fig. 5's corners: the slow small
#: eight at R = 0.25 m, Theta = 0.05 rad/s is periodic, the large fast one at R = 4 m,
#: Theta = 1.5 rad/s chaotic; the angle-limit sweep (Chapter 4 asserts both): chaotic at 30 deg
#: without a cap (top left, and its exponent beneath), periodic at 60 deg with the cap (top right).
HOVER_POINTS = [
    ("interactive-fig5", "x", "y", 0.25, 0.05, "periodic"),
    ("interactive-fig5", "x", "y", 4.0, 1.5, "chaotic"),
    ("interactive-bifurcation", "x", "y", 30.0, None, "chaotic"),
    ("interactive-bifurcation", "x3", "y3", 30.0, None, "chaotic"),
    ("interactive-bifurcation", "x2", "y2", 60.0, None, "periodic"),
]

#: the page coordinates of data point (x, y) on the axes (xa, ya) of the plot with id `id`;
#: y null: the y of a point of a trace on those axes at that x
POINT_XY = r"""(a) => {
  const gd = document.getElementById(a.id);
  let y = a.y;
  if (y === null) {
    const near = (t) => Array.from(t.x).findIndex(v => Math.abs(v - a.x) < 1e-6);
    const tr = gd._fullData.find(t => t.xaxis === a.xa && t.yaxis === a.ya && t.x && near(t) >= 0);
    if (!tr) return null;
    y = tr.y[near(tr)];
  }
  gd.scrollIntoView({block: 'center'});
  const fl = gd._fullLayout;
  const xa = fl[a.xa.replace('x', 'xaxis')], ya = fl[a.ya.replace('y', 'yaxis')];
  const r = gd.getBoundingClientRect();
  return {x: r.left + xa._offset + xa.l2p(a.x), y: r.top + ya._offset + ya.l2p(y)};
}"""

#: the lines of the tooltip shown
TOOLTIP = r"""() => Array.from(document.querySelectorAll('.hoverlayer .hovertext')).map(h =>
  Array.from(h.querySelectorAll('tspan.line')).map(t => t.textContent).join('\n') || h.textContent)"""

#: the report's table with a 'status' column: its width against the article's, its
#: scrolling box's overflow, and its columns' widths (px)
TABLE_FIT = r"""() => {
  const t = Array.from(document.querySelectorAll('main table')).find(t =>
      Array.from(t.querySelectorAll('thead th')).some(th => th.textContent.trim() === 'status'));
  if (!t) return null;
  const article = t.closest('article') || document.querySelector('main');
  const box = t.closest('.pst-scrollable-table-container') || t.parentElement;
  const a = article.getBoundingClientRect(), r = t.getBoundingClientRect();
  return {tableLeft: r.left, tableRight: r.right, articleLeft: a.left, articleRight: a.right,
          boxScroll: box.scrollWidth, boxClient: box.clientWidth, viewport: window.innerWidth,
          columns: Array.from(t.querySelectorAll('thead th')).map(th =>
              ({name: th.textContent.trim(), width: th.getBoundingClientRect().width}))};
}"""


@dataclass
class Hovered:
    """What hovering the interactive figures and measuring the report's table found."""
    tooltips: dict = field(default_factory=dict)
    table: dict | None = None
    requests: list[str] = field(default_factory=list)
    failed: list[str] = field(default_factory=list)


@pytest.fixture(scope="module")
def hovered(server) -> Hovered:
    """The pages with interactive figures, read again in Chromium at 1280 px: each point of
    HOVER_POINTS hovered with the mouse and its tooltip read; the report's table measured."""
    if not Path(CHROMIUM).exists():
        pytest.skip(f"Debian's chromium is not installed ({CHROMIUM} missing): browser test skipped")
    from playwright.sync_api import sync_playwright

    out = Hovered()
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, headless=True, args=[
            "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
            "--disable-background-networking", "--disable-component-update", "--disable-sync"])
        page = browser.new_context(viewport=VIEWPORT).new_page()
        page.on("request", lambda r: out.requests.append(r.url))
        page.on("requestfailed", lambda r: out.failed.append(r.url))
        for doc in sorted(set(INTERACTIVE.values())):
            page.goto(f"{server}/{doc}.html", wait_until="networkidle")
            for point in HOVER_POINTS:
                fig, xa, ya, x, y, _ = point
                if INTERACTIVE[fig] != doc:
                    continue
                page.wait_for_function("(id) => { const g = document.getElementById(id); "
                                       "return g && g._fullLayout; }", arg=fig, timeout=20_000)
                xy = page.evaluate(POINT_XY, dict(id=fig, xa=xa, ya=ya, x=x, y=y))
                tips = []
                if xy is not None:
                    page.mouse.move(1, 1)
                    page.mouse.move(xy["x"], xy["y"], steps=4)
                    try:
                        page.wait_for_selector(".hoverlayer .hovertext", timeout=5_000)
                    except Exception:
                        pass
                    tips = page.evaluate(TOOLTIP)
                out.tooltips[point] = tips
        page.goto(f"{server}/report.html", wait_until="networkidle")
        out.table = page.evaluate(TABLE_FIT)
        browser.close()
    return out


@pytest.mark.parametrize("point", HOVER_POINTS, ids=lambda p: f"{p[0]}-{p[1]}-{p[3]:g}")
def test_hovering_a_known_point_shows_its_verdict(point, hovered):
    fig, _, _, x, y, verdict = point
    tips = hovered.tooltips.get(point)
    assert tips, f"{INTERACTIVE[fig]}: no tooltip on hovering ({x}, {y}) of #{fig} (did plotly.js load?)"
    lines = tips[0].splitlines()
    shown = [ln.split(": ", 1)[1] for ln in lines if ln.startswith("verdict: ")]
    assert shown and shown[0].split(",")[0] == verdict, f"#{fig} at ({x}, {y}): tooltip {lines}"
    label = "R: " if fig == "interactive-fig5" else "angle limit: "
    value = [ln for ln in lines if ln.startswith(label)]
    assert value and abs(float(value[0][len(label):].split()[0]) - x) < 1e-3, (  # reason: the tooltip's printed digits
        f"#{fig}: hovered ({x}, {y}) but the tooltip is of another point: {lines}")
    for name in ("period", "largest |μ|", "exponent", "range of p"):
        assert any(ln.startswith(name) for ln in lines), f"#{fig}: no {name!r} in the tooltip {lines}"
    assert not any("NaN" in ln or "nan" in ln for ln in lines), lines


def test_interactive_figures_load_plotly_from_the_book_alone(hovered):
    outside = [u for u in hovered.requests
               if urlparse(u).scheme not in ("data", "blob", "about") and urlparse(u).hostname != "127.0.0.1"]
    assert not outside, f"requests left the loopback address: {outside}"
    assert not hovered.failed, f"requests failed: {hovered.failed}"
    assert any(urlparse(u).path.endswith("/_static/plotly.min.js") for u in hovered.requests), (
        "plotly.js was not loaded from the book's _static")


def test_the_report_table_fits_the_content_area_at_1280px(hovered):
    t = hovered.table
    assert t, "report: no table with a 'status' column found"
    assert t["boxScroll"] <= t["boxClient"] + 1, (
        f"report: the table scrolls sideways at {VIEWPORT['width']} px: {t['boxScroll']} > {t['boxClient']} px")
    assert t["articleLeft"] - 1 <= t["tableLeft"] and t["tableRight"] <= t["articleRight"] + 1, (
        f"report: the table ({t['tableLeft']:.0f}-{t['tableRight']:.0f} px) leaves the content area "
        f"({t['articleLeft']:.0f}-{t['articleRight']:.0f} px)")
    narrow = [f"{c['name']} ({c['width']:.0f} px)" for c in t["columns"] if c["width"] < 120]
    assert not narrow, f"report: columns narrower than 120 px at {VIEWPORT['width']} px: {narrow}"
