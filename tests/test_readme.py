"""README.md starts where a newcomer starts, and its instructions stay true: the newcomer's
sections sit in its first 100 lines, every `make` target it names exists, the caches it names
are the ones the code writes, every Python example runs, and the build's measurements live in
benchmarks/README.md, each with its command."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text()
#: the newcomer's path, in the order a newcomer needs it
NEWCOMER = ("Two commands", "Where to read", "One chapter at a time", "Use the library", "How to cite")
FIRST_SCREEN = 100


def _section(title: str) -> str:
    match = re.search(rf"^## {re.escape(title)}\n(.*?)(?=^## |\Z)", README, re.S | re.M)
    assert match, f"README.md has no section '## {title}'"
    return match.group(1)


def _python_blocks(text: str) -> list[str]:
    return re.findall(r"^```python\n(.*?)^```", text, re.S | re.M)


def test_newcomers_path_is_in_the_first_100_lines_in_order():
    """What the book is and found (a paragraph before the first section), then the five
    sections of the newcomer's path, each ending by line 100; the maintainers' sections after."""
    lines = README.splitlines()
    heads = {line[3:]: i for i, line in enumerate(lines) if line.startswith("## ")}
    starts = [heads.get(t, 10**6) for t in NEWCOMER]
    assert starts == sorted(starts) and max(starts) < FIRST_SCREEN, (dict(zip(NEWCOMER, starts)))
    after_last = min([i for i in heads.values() if i > starts[-1]], default=len(lines))
    assert after_last <= FIRST_SCREEN, f"'How to cite' runs to line {after_last}, past the first {FIRST_SCREEN}"
    intro = "\n".join(lines[1:min(heads.values())])
    assert "Korczak" in intro and "found" in intro and "lib/" in intro
    assert len(intro.split()) <= 150, "the opening paragraph is one paragraph, not a chapter"


def test_the_two_commands_are_makes_book_and_test_and_ci_runs_test_then_portable():
    """The two commands come first; `.ci/run` runs `make test`, then `make test-portable`,
    as the section says."""
    text = _section("Two commands")
    assert "make book" in text and "make test" in text and "make test-portable" in text
    ci = (ROOT / ".ci" / "run").read_text()
    calls = re.findall(r"^make (\S+)", ci, re.M)
    assert calls == ["test", "test-portable"], calls


def test_every_make_target_the_readme_names_is_in_the_makefile():
    make = (ROOT / "Makefile").read_text()
    targets = set(re.findall(r"^([a-z][\w-]*):", make, re.M))
    named = set(re.findall(r"\bmake ([a-z][\w-]*)", README))
    assert {"book", "test", "pdf", "chapter", "test-portable"} <= named
    assert named <= targets, f"README names make targets the Makefile lacks: {sorted(named - targets)}"


def test_where_to_read_names_the_html_and_the_pdf_that_the_tools_write():
    sys.path.insert(0, str(ROOT / "tools"))
    from pdf import OUT

    text = _section("Where to read")
    assert "_build/html/index.html" in text
    pdf = OUT.relative_to(ROOT).as_posix()
    assert pdf in text and pdf in _section("How to cite")


def test_one_chapter_section_names_the_caches_the_code_writes_and_the_commands_exist():
    """`make chapter CH=08` resolves to Chapter 8; the section names myst-nb's execution cache
    (`_config.yml`) and lib.machinery.cache's folder as the code computes them; the notebook
    route's commands (what tests/test_notebook_route.py runs) name tools the venv has."""
    from lib.machinery.cache import cache_dir

    sys.path.insert(0, str(ROOT / "tools"))
    from preexecute import resolve_page

    text = _section("One chapter at a time")
    assert "make chapter CH=08" in text and resolve_page("08") == "chapters/08_optimal"
    assert "_build/html/chapters/08_optimal.html" in text
    execution_cache = yaml.safe_load((ROOT / "_config.yml").read_text())["execute"]["cache"]
    assert f"`{execution_cache}`" in text
    assert f"`{cache_dir(ROOT).relative_to(ROOT).as_posix()}`" in text
    assert ".venv/bin/jupytext --to ipynb chapters/01_model.md" in text
    assert ".venv/bin/jupyter execute --inplace chapters/01_model.ipynb" in text
    bin_dir = Path(sys.executable).parent
    assert (bin_dir / "jupytext").is_file() and (bin_dir / "jupyter-execute").is_file()


def test_use_the_library_example_runs_and_prints_what_it_says():
    """The example of "Use the library", run as a script: the capped circle's peak force at the
    4 N cap, then three points of Fig. 5 with their verdicts."""
    (code,) = _python_blocks(_section("Use the library"))
    proc = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    first, header, *rows = proc.stdout.strip().splitlines()
    peak, p_range = map(float, first.split())
    assert peak <= 4.0 and 0.0 <= p_range < 2 * 3.141592653589793   # exact: a clip; F never above its cap
    assert header.split() == ["R", "Theta", "regime", "range", "lost"]
    assert len(rows) == 3 and {r.split()[3] for r in rows} <= {"periodic", "slipping", "chaotic", "transient",
                                                                "quasiperiodic", "undecided"}


def test_scaling_out_example_runs_as_a_script(tmp_path):
    """The dask example of "Scaling out", as a script file (its workers import it), writes its
    map with one row a point."""
    (code,) = _python_blocks(_section("Scaling out"))
    script = tmp_path / "scale.py"
    script.write_text(code)
    proc = subprocess.run([sys.executable, str(script)], cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    n = int(re.search(r"^N = (\d+)", code, re.M).group(1))
    rows = (tmp_path / f"fig5_{n}.csv").read_text().strip().splitlines()
    assert len(rows) == 1 + n * n


def test_every_python_block_is_one_the_tests_run():
    """No example in the README goes unrun: the two above are all there are."""
    assert len(_python_blocks(README)) == 2


def test_how_to_cite_names_the_citation_file_and_it_names_the_paper():
    text = _section("How to cite")
    assert "CITATION.cff" in text and "make pdf" in text
    cff = yaml.safe_load((ROOT / "CITATION.cff").read_text())
    assert cff["title"] and cff["preferred-citation"]["title"] == cff["title"]
    paper = cff["references"][0]
    assert paper["authors"][0]["family-names"] == "Korczak" and paper["year"] == 2014


def test_measurements_live_in_benchmarks_readme_each_with_its_command():
    """The README quotes no build timing; benchmarks/README.md does, and every row of its
    tables of measurements names the command that measures it (in backticks)."""
    assert not re.search(r"\d+ min \d+ s|\d+(\.\d+)? s of CPU", README), "a timing in README.md"
    bench = (ROOT / "benchmarks" / "README.md").read_text()
    rows = [line for line in bench.splitlines() if line.startswith("|") and not set(line) <= set("|- ")]
    measured = [r for r in rows if re.search(r"\d+ (min|s)\b", r)]
    assert len(measured) >= 5
    for row in measured:
        cells = [c.strip() for c in row.strip("|").split("|")]
        assert any(c.startswith("`") and ("make" in c or ".venv/bin" in c or "bash" in c) for c in cells) \
            or cells[0].startswith(("Chapter", "report")), row


def test_readme_fast_tests_command_deselects_the_slow_markers():
    """The fast-tests command names markers that pyproject.toml registers."""
    assert '.venv/bin/python -m pytest -m "not book and not browser"' in README
    pyproject = (ROOT / "pyproject.toml").read_text()
    assert '"book:' in pyproject and '"browser:' in pyproject


def test_ci_runs_the_portable_tests_after_make_test_with_the_emulation_the_readme_states():
    """`.ci/run` runs `make test`, then `make test-portable`; the target sets every variable
    of the emulation the README's section names (issue 28)."""
    ci = (ROOT / ".ci" / "run").read_text().split()
    assert ci.index("test-portable") > ci.index("test")
    make = (ROOT / "Makefile").read_text()
    text = _section("Another machine's arithmetic")
    for var in ("NUMBA_CPU_NAME=generic", "NUMBA_CACHE_DIR=", "OPENBLAS_CORETYPE=Prescott",
                "NPY_DISABLE_CPU_FEATURES=", "OPENBLAS_NUM_THREADS=1", "NUMBA_NUM_THREADS=1"):
        assert var in make, var
    for var in ("NUMBA_CPU_NAME=generic", "NUMBA_CACHE_DIR", "OPENBLAS_CORETYPE=Prescott", "NPY_DISABLE_CPU_FEATURES"):
        assert var in text, var
    # the numpy feature names the Makefile disables are ones this numpy dispatches on
    from numpy._core._multiarray_umath import __cpu_dispatch__, __cpu_baseline__

    names = re.search(r'NPY_DISABLE_CPU_FEATURES="([^"]*)"', make).group(1).split()
    assert names and set(names) <= set(__cpu_dispatch__) - set(__cpu_baseline__), (names, __cpu_dispatch__)


_PAGE = """---
jupytext:
  text_representation:
    extension: .md
    format_name: myst
kernelspec:
  display_name: Python 3
  language: python
  name: python3
---

# Page {name}

```{{code-cell}} ipython3
print("{text}")
```
"""


def test_one_page_mode_replaces_that_page_and_keeps_the_others(tmp_path):
    """What `make chapter` runs (`tools/preexecute.py --keep-cache PAGE`), on a book of two
    small pages: after the full run, the one-page run executes only the page named, whose new
    code the cache then matches, and keeps the other page's entry as it was; a page that is not
    in the book is refused before the cache is touched."""
    from jupyter_cache import get_cache

    sys.path.insert(0, str(ROOT / "tools"))
    from preexecute import read_page

    (tmp_path / "_config.yml").write_text("execute:\n  execute_notebooks: cache\n  cache: _build/.jupyter_cache\n"
                                          "  timeout: 60\n")
    (tmp_path / "_toc.yml").write_text("format: jb-book\nroot: a\nchapters:\n  - file: b\n")
    for name in "ab":
        (tmp_path / f"{name}.md").write_text(_PAGE.format(name=name, text=f"first {name}"))

    def run(*args):
        return subprocess.run([sys.executable, str(ROOT / "tools" / "preexecute.py"), "--root", str(tmp_path),
                               "--jobs", "1", *args], capture_output=True, text=True, timeout=300)

    assert run().returncode == 0
    cache = get_cache(tmp_path / "_build" / ".jupyter_cache")
    a_before = cache.match_cache_notebook(read_page(tmp_path / "a.md", tmp_path)).pk
    (tmp_path / "b.md").write_text(_PAGE.format(name="b", text="second b"))
    refused = run("--keep-cache", "c")
    assert refused.returncode == 2 and "'c' is not a notebook page" in refused.stderr
    one = run("--keep-cache", "b")
    assert one.returncode == 0, one.stdout + one.stderr
    assert "Executing 1 pages" in one.stdout and "  b: " in one.stdout and "  a: " not in one.stdout
    assert cache.match_cache_notebook(read_page(tmp_path / "a.md", tmp_path)).pk == a_before
    b = cache.get_cache_bundle(cache.match_cache_notebook(read_page(tmp_path / "b.md", tmp_path)).pk).nb
    assert "second b" in "".join(o.get("text", "") for c in b.cells for o in c.get("outputs", []))


def test_the_sections_and_names_that_the_package_and_requirements_point_to_exist():
    # issue 59: lib/__init__ named a README section that had been renamed, and requirements.txt a
    # module that had moved (lib.parallel -> lib.machinery.parallel)
    import importlib
    import lib
    headings = set(re.findall(r"^#+ (.+)$", (ROOT / "README.md").read_text(), flags=re.M))
    named = re.findall(r'README\.md\'s "([^"]+)"', lib.__doc__)
    assert named and set(named) <= headings, set(named) - headings
    dotted = re.findall(r"\((lib(?:\.\w+)+)\)", (ROOT / "requirements.txt").read_text())
    assert dotted
    for name in dotted:                          # a module, or a name in one
        module, _, attr = name.rpartition(".")
        try:
            importlib.import_module(name)
        except ModuleNotFoundError:
            assert hasattr(importlib.import_module(module), attr), name


def test_the_front_pages_recipe_for_redrawing_a_figure_runs(tmp_path):
    # issue 59: the front page says how to change a parameter and redraw one figure; its code runs
    # as written, from a folder outside the repository, and writes the figure
    blocks = re.findall(r"```python\n(.*?)```", (ROOT / "intro.md").read_text(), flags=re.S)
    assert len(blocks) == 1 and "savefig" in blocks[0]
    code = "\n".join(line[2:] if line.startswith("  ") else line for line in blocks[0].splitlines())
    out = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=300,
                         env={**__import__("os").environ, "PYTHONPATH": str(ROOT)})
    assert out.returncode == 0, out.stderr
    assert (tmp_path / "fig3_heavier.png").stat().st_size > 10_000
