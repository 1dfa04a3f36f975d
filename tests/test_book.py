"""The book builds from scratch, executing every notebook, with Sphinx warnings as errors;
and its sources read at 1280 px (code lines that fit their block)."""

import os
import re
from pathlib import Path

import pytest
import yaml

ROOT = Path(__file__).resolve().parents[1]
# At 1280 px a code block of the book's theme holds 77 monospace characters, the block of
# a hide-input cell (indented in its fold) 76: measured in Debian's chromium by
# tests/test_browser.py, where a 78-character line scrolls by 6 px (77 by 7 px in a fold).
CODE_WIDTH = 77
FOLDED_CODE_WIDTH = 75
HIDDEN_TAGS = {"remove-input", "remove-cell"}


@pytest.mark.book
def test_book_builds_with_no_warnings(built_book):
    log = built_book.stdout + built_book.stderr
    warnings = [line for line in log.splitlines() if re.search(r"\bWARNING\b|\bERROR\b", line)]
    assert built_book.returncode == 0, "jupyter-book build failed:\n" + log[-6000:]
    assert not warnings, "build printed warnings:\n" + "\n".join(warnings[:40])


@pytest.mark.book
def test_no_page_shows_a_warning_or_other_stderr_output(built_book):
    """A page's code writes nothing to stderr: a warning printed on the page (a NaN cast to an
    integer, a deprecation) is a defect the reader sees, and a stderr block also breaks the
    page's width at 1280 px."""
    html = ROOT / "_build" / "html"
    shown = {p.relative_to(html).as_posix(): re.findall(r'class="output stderr.*?<pre>(.*?)</pre>',
                                                       p.read_text(), flags=re.S)
             for p in html.rglob("*.html") if "_static" not in p.parts}
    shown = {page: blocks for page, blocks in shown.items() if blocks}
    assert not shown, "pages with stderr output:\n" + "\n".join(
        f"{page}: {re.sub(r'<[^>]+>', '', blocks[0])[:300]}" for page, blocks in shown.items())


@pytest.mark.book
def test_every_page_was_executed_two_at_a_time_before_the_build(built_book):
    """``tools/preexecute.py`` executed every notebook page into the execution cache, and the
    build found each there: a page whose cache key the build did not match (another reader or
    MyST configuration) would be executed again by the build, one page after another."""
    import sys

    sys.path.insert(0, str(ROOT / "tools"))
    from preexecute import notebook_pages

    log = built_book.stdout + built_book.stderr
    pages = notebook_pages(ROOT)
    assert len(pages) >= 8
    missed = [p for p in pages if not re.search(rf"{re.escape(p)}\.md: Using cached notebook", log)]
    assert not missed, f"pages executed by the build itself, not read from the cache: {missed}"
    assert not re.search(r"Executing notebook", log)


def code_cells(path: Path):
    """(first line number, metadata, code lines) of each ``{code-cell}`` of a MyST notebook."""
    lines = path.read_text().splitlines()
    i = 0
    while i < len(lines):
        if not lines[i].startswith("```{code-cell}"):
            i += 1
            continue
        j, meta = i + 1, {}
        if j < len(lines) and lines[j].strip() == "---":
            k = lines.index("---", j + 1)
            meta = yaml.safe_load("\n".join(lines[j + 1:k])) or {}
            j = k + 1
        while j < len(lines) and lines[j].startswith(":"):
            key, _, value = lines[j][1:].partition(":")
            meta[key.strip()] = yaml.safe_load(value)
            j += 1
        start = j
        while not lines[j].startswith("```"):
            j += 1
        yield start + 1, meta, lines[start:j]
        i = j + 1


NOTEBOOKS = sorted(ROOT.glob("chapters/*.md")) + [ROOT / "report.md", ROOT / "errata.md", ROOT / "intro.md",
                                                 ROOT / "methods.md"]


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.relative_to(ROOT).as_posix())
def test_shown_code_lines_fit_a_code_block_at_1280px(path):
    """Every code line the page shows (cells not tagged remove-input/remove-cell) is
    at most CODE_WIDTH characters (FOLDED_CODE_WIDTH in a hide-input cell), so no cell
    scrolls sideways."""
    long = []
    for first, meta, code in code_cells(path):
        tags = set(meta.get("tags") or [])
        if HIDDEN_TAGS & tags:
            continue
        width = FOLDED_CODE_WIDTH if "hide-input" in tags else CODE_WIDTH
        long += [f"line {first + n}: {len(line)} > {width} characters: {line.strip()[:60]}..."
                 for n, line in enumerate(code) if len(line) > width]
    assert not long, (f"{path.relative_to(ROOT)}: code lines wider than their block at "
                      "1280 px (break the call over lines):\n  " + "\n  ".join(long))


def test_a_build_is_reused_only_when_current(tmp_path, monkeypatch):
    """conftest's reuse rule: the HTML written between the start and the end of the build
    whose log is kept, and no input of the book changed after that build began."""
    import conftest

    monkeypatch.setattr(conftest, "ROOT", tmp_path)
    build = tmp_path / "_build"
    (build / "html").mkdir(parents=True)
    (tmp_path / "chapters").mkdir()
    files = {name: tmp_path / name for name in
             ("chapters/01.md", "_toc.yml", "README.md", "_build/build.log",
              "_build/html/searchindex.js", "_build/build.rc")}
    for f in files.values():
        f.write_text("0\n")

    def at(name, t):
        os.utime(files[name], (t, t))

    for name, t in (("chapters/01.md", 100), ("_toc.yml", 100), ("README.md", 100),
                    ("_build/build.log", 200), ("_build/html/searchindex.js", 250),
                    ("_build/build.rc", 260)):
        at(name, t)
    done = conftest._current_build()
    assert done is not None and done.returncode == 0 and done.stdout == "0\n"
    at("README.md", 300)                       # not part of the book
    assert conftest._current_build() is not None
    at("_toc.yml", 210)                        # an input changed during the build
    assert conftest._current_build() is None
    at("_toc.yml", 100)
    at("_build/html/searchindex.js", 300)      # HTML from a later build than the log
    assert conftest._current_build() is None
    at("_build/html/searchindex.js", 250)
    files["_build/build.rc"].unlink()          # the build did not finish
    assert conftest._current_build() is None


#: the results the reading pages (preexecute.LAST) compute themselves: their own rows
OWN_RESULTS = ("_check_row", "_check_item")


@pytest.mark.book
def test_the_report_errata_and_front_page_computed_none_of_the_chapters_results(built_book):
    """Every result of ``lib.machinery.cache`` in the build's cache (``_build/.cache``, kept from
    build to build while the library is unchanged, so the result may be an earlier build's) that
    a reading page (the report, the errata, the front page) computed is one of their own rows:
    what they share with a chapter was computed by the chapter and read by them. A call whose
    arguments drift from the chapter's would compute it again, silently, and double its time."""
    import sys

    sys.path.insert(0, str(ROOT / "tools"))
    from preexecute import LAST

    made = [(f.stem.rsplit("-", 1)[0], f.read_text()) for f in (ROOT / "_build" / ".cache").glob("*.page")]
    assert any(page.startswith("chapters/") for _, page in made), "no shared result computed by a chapter"
    wrong = sorted(f"{fn} by {page}" for fn, page in made if page in LAST and fn not in OWN_RESULTS)
    assert not wrong, f"reading pages computed chapters' results again (make clean drops old ones): {wrong}"


def test_pages_are_executed_longest_first_and_the_readers_of_other_pages_last():
    """``tools/preexecute.py`` executes every notebook page of ``_toc.yml`` (the front page,
    Methods, chapters, report, errata), Methods, the report, the errata and the front page after the
    chapters whose cached results they read."""
    import sys

    sys.path.insert(0, str(ROOT / "tools"))
    from preexecute import LAST, notebook_pages, order

    pages = notebook_pages(ROOT)
    md = {p.relative_to(ROOT).with_suffix("").as_posix() for p in NOTEBOOKS}
    assert set(pages) == md
    ran = order(pages)
    assert sorted(ran) == sorted(pages) and ran[-len(LAST):] == list(LAST)
    chapters = [i for i, p in enumerate(ran) if p.startswith("chapters/")]
    assert ran.index("methods") > max(chapters)


def test_kernels_run_numba_on_one_thread_only_when_the_pages_fill_the_cores(monkeypatch):
    """``tools/preexecute.py``'s kernel environment: BLAS on one thread always; numba on one
    thread when as many pages run at once as there are cores, its own threads otherwise, and a
    thread count the user set is kept."""
    import sys

    sys.path.insert(0, str(ROOT / "tools"))
    from preexecute import kernel_env

    monkeypatch.delenv("NUMBA_NUM_THREADS", raising=False)
    assert kernel_env(2, 2) == {"OPENBLAS_NUM_THREADS": "1", "NUMBA_NUM_THREADS": "1"}
    assert kernel_env(4, 2)["NUMBA_NUM_THREADS"] == "1"
    assert kernel_env(1, 2) == {"OPENBLAS_NUM_THREADS": "1"}
    monkeypatch.setenv("NUMBA_NUM_THREADS", "2")
    assert "NUMBA_NUM_THREADS" not in kernel_env(2, 2)
