"""``make pdf``'s route, run as CI runs it: the single-page HTML build read from the execution
cache that the book's build filled, printed by headless Chromium (``tools/pdf.py``) as two files,
the book as an article (under 130 A4 pages) and the library reference apart. The book's PDF
holds every page of the table of contents but the reference's in order, and the reference's PDF
those, the front page's findings with their glued
numbers, typeset math (no TeX source left), every figure of the book as an image, the
interactive ones as static PNGs, and nothing cut off at the right edge.

Needs Debian's ``chromium`` and poppler's ``pdftotext`` and ``pdfimages`` (``.ci/run`` installs
both); without them the tests are skipped with a message saying so.
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.browser

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools"))
from pdf import CHROMIUM, OUT, REFERENCE_NAME, REFERENCE_PAGE, SINGLE, root_page  # noqa: E402  (tools/ is not a package)
from preexecute import toc_pages  # noqa: E402

GLUE_ROLE = re.compile(r"\{glue(?::text)?\}`([^`]+)`")
#: the book as an article, the library reference apart: at most MAX_PAGES A4 pages (issue 59: it
#: was 297 with the reference, 106 without), at least MIN_PAGES (fewer means whole parts missing);
#: the reference at least MIN_REFERENCE_PAGES (191 when it was printed with the book)
MIN_PAGES, MAX_PAGES, MIN_REFERENCE_PAGES = 80, 130, 100


def read_pdf(out: Path, record: str = "figures.json") -> dict:
    """What poppler reads in the PDF ``out``: its page count, its text (``pdftotext -layout``,
    and with its whitespace collapsed), its images (``pdfimages -list`` rows), and what the
    printed HTML held (``record`` beside it, written by ``tools/pdf.py``)."""
    info = subprocess.run(["pdfinfo", str(out)], capture_output=True, text=True, check=True).stdout
    text = subprocess.run(["pdftotext", "-layout", str(out), "-"], capture_output=True, text=True,
                          check=True).stdout
    listing = subprocess.run(["pdfimages", "-list", str(out)], capture_output=True, text=True, check=True).stdout
    rows = [line.split() for line in listing.splitlines()[2:] if line.strip()]
    return {"pages": int(re.search(r"^Pages:\s+(\d+)", info, re.M).group(1)), "text": text,
            "flat": " ".join(text.split()), "images": [row for row in rows if row[2] == "image"],
            "held": json.loads((out.parent / record).read_text())}


@pytest.fixture(scope="module")
def book_pdf(built_book) -> dict:
    """The PDF printed now by ``tools/pdf.py`` from the current build's execution cache, as
    :func:`read_pdf` reads it."""
    if built_book.returncode != 0:
        pytest.fail("the book did not build; see test_book.py")
    missing = [tool for tool in (CHROMIUM, "pdftotext", "pdfimages", "pdfinfo") if not shutil.which(tool)]
    if missing:
        pytest.skip(f"{', '.join(missing)} not installed: PDF test skipped; run .ci/run or "
                    "`apt-get install chromium poppler-utils` to enable it")
    proc = subprocess.run([sys.executable, str(ROOT / "tools" / "pdf.py")], cwd=ROOT, capture_output=True,
                          text=True, timeout=1800)
    assert proc.returncode == 0, proc.stdout[-4000:] + proc.stderr[-4000:]
    return read_pdf(OUT)


@pytest.fixture(scope="module")
def reference_pdf(book_pdf) -> dict:
    """The library reference's PDF, printed beside the book's by the same run."""
    return read_pdf(OUT.with_name(REFERENCE_NAME), "reference.json")


def _title(page: str) -> str:
    """The page's first heading, as its Markdown source writes it."""
    src = (ROOT / f"{page}.md").read_text()
    return re.search(r"^# (.+)$", src, re.M).group(1).strip()


def _plain(title: str) -> str:
    """A heading's words as printed: Markdown's emphasis and code marks dropped."""
    return " ".join(re.sub(r"[*_`]", "", title).split())


def _is_reference(page: str) -> bool:
    return page == REFERENCE_PAGE or page.startswith(REFERENCE_PAGE + "/")


def test_the_book_prints_as_an_article_and_the_reference_apart(book_pdf, reference_pdf):
    assert MIN_PAGES <= book_pdf["pages"] <= MAX_PAGES, book_pdf["pages"]
    assert reference_pdf["pages"] >= MIN_REFERENCE_PAGES, reference_pdf["pages"]
    pages = toc_pages(ROOT)
    assert book_pdf["held"]["pages"] == sum(not _is_reference(p) for p in pages[1:])     # the root has no anchor
    assert reference_pdf["held"]["pages"] == sum(_is_reference(p) for p in pages) >= 5
    # the book's printed contents list no page of the reference, and the reference's none at all
    first = book_pdf["text"].split("\f")[0]
    assert "Errata" in first and "Library reference" not in first
    assert "Contents" not in reference_pdf["text"].split("\f")[0]


def _opens_in_order(pdf: dict, pages: list[str], first: int) -> None:
    """Each of ``pages`` opens a printed page of ``pdf`` with its title, in order, after page ``first``."""
    heads = [" ".join(" ".join([ln for ln in pg.splitlines() if ln.strip()][:3]).split())
             for pg in pdf["text"].split("\f")]                     # a long title wraps: three lines
    at = first
    for page in pages:
        title = _plain(_title(page))
        found = next((i for i in range(at + 1, len(heads)) if title in heads[i]), None)
        assert found is not None, f"{page}: no printed page after page {at + 1} opens with {title!r}"
        at = found


def test_every_page_of_the_table_of_contents_starts_a_printed_page_in_order(book_pdf, reference_pdf):
    """Each page of ``_toc.yml`` after the front page (every chapter, the report, Methods, the
    errata and the bibliography) opens a printed page of the book's PDF with its title, in the
    order of the table of contents (the contents list on the first page does not count: it opens
    no page); the reference's pages open pages of the reference's PDF, in order."""
    pages = toc_pages(ROOT)
    _opens_in_order(book_pdf, [p for p in pages[1:] if not _is_reference(p)], 0)
    _opens_in_order(reference_pdf, [p for p in pages if _is_reference(p)], -1)


def _glued(doc: str) -> list[str]:
    """The text each glue role of ``doc`` renders to, from the executed notebook."""
    from myst_nb.core.variables import format_plain_text

    glued = json.loads((ROOT / "_build" / "jupyter_execute" / f"{doc}.glue.json").read_text())
    values = {key: out["data"]["text/plain"] for key, out in glued.items()}
    out = []
    for role in GLUE_ROLE.findall((ROOT / f"{doc}.md").read_text()):
        key, _, fmt = role.partition(":")
        out.append(format_plain_text(values[key], fmt))
    return out


def test_the_findings_are_printed_with_their_computed_numbers(book_pdf):
    """The front page's section of findings, its nine headlines, and every number glued into
    it, as the build computed them."""
    flat = book_pdf["flat"]
    start = flat.find("What this book found")
    assert start >= 0
    findings = flat[start:flat.find("What the paper claims", start)]
    for headline in ("A sign error in the model", "Theorem 6 is false as printed", "Two mirror orbits",
                     "Chaos under an angle limit", "The circle is not globally stable", "What the limits allow"):
        assert headline in findings, headline
    numbers = _glued("intro")
    assert len(numbers) >= 20
    missing = [n for n in numbers if n.replace("-", "−") not in findings and n not in findings]
    assert not missing, f"glued numbers of the findings not printed: {missing}"


def test_math_is_typeset_and_no_tex_source_is_left(book_pdf):
    """MathJax typeset every math node of the page before printing, and the text holds none of
    the delimiters Sphinx writes around TeX for MathJax (code cells show TeX in strings, which
    is code, not math)."""
    held = book_pdf["held"]
    assert held["mathNodes"] > 500 and held["math"] >= held["mathNodes"], (held["math"], held["mathNodes"])
    assert not held["untypeset"], f"math left as TeX: {held['untypeset'][:10]}"
    left = re.findall(r"\\\(|\\\[", book_pdf["text"])
    assert not left, f"TeX delimiters printed as text: {left[:10]}"


def _figure_labels() -> dict[int, int]:
    """{chapter number: figures it labels} (``name: fig-...`` of its cells' metadata)."""
    out = {}
    for md in sorted(ROOT.glob("chapters/[0-9][0-9]_*.md")):
        n = len(re.findall(r"^\s*name: fig-", md.read_text(), re.M))
        if n:
            out[int(md.name[:2])] = n
    return out


def _figures_in_the_html() -> tuple[int, int]:
    """Images in the single-page HTML's content (each ``<img``: a notebook's figures, an
    animation's frame) and interactive plotly figures."""
    html = (SINGLE / f"{root_page(ROOT)}.html").read_text()
    main = html[html.find("<main"):html.rfind("</main>")]
    return len(re.findall(r"<img\b", main)), len(re.findall(r'class="plotly-graph-div"', main))


def test_every_figure_is_printed_as_an_image_the_interactive_ones_as_static_png(book_pdf):
    """Every figure the chapters label is printed under its number (Fig. 4.1, ...); ``pdfimages``
    finds an image for each image of the HTML and for each interactive figure, which the print
    replaced by a PNG of itself; no image failed to load, and nothing was asked of a network."""
    labels = _figure_labels()
    printed = set(re.findall(r"Fig\. (\d+\.\d+)", book_pdf["flat"]))
    expected = {f"{ch}.{k}" for ch, n in labels.items() for k in range(1, n + 1)}
    assert sum(labels.values()) >= 25 and expected <= printed, sorted(expected - printed)
    images, interactive = _figures_in_the_html()
    assert interactive >= 2 and book_pdf["held"]["interactive"] == interactive
    assert images + interactive >= sum(labels.values())
    assert len(book_pdf["images"]) >= images + interactive, (len(book_pdf["images"]), images, interactive)
    assert not book_pdf["held"]["broken"] and not book_pdf["held"]["requests"]


def test_nothing_is_cut_off_at_the_right_edge(book_pdf):
    """What the screen scrolls sideways (a wide table, a long code line, a wide formula) was made
    to fit the printed column: no element of the printed page still clips its content sideways."""
    fitted = book_pdf["held"]["fitted"]
    assert fitted["nClipped"] == 0, fitted["clipped"]
