"""Where the book's build time goes: each page's and each heavy cell's wall and CPU time.

Run with ``make book-times`` (or ``.venv/bin/python benchmarks/book_times.py [page ...]``, pages
as in ``_toc.yml``: ``chapters/04_limits``, ``report``). Each page that is a notebook is read
with jupytext and executed with nbclient, one after another in the order in which the book's
build executes them (sorted by name, as Sphinx reads its pages): in a fresh copy of the book's sources in a temporary folder,
so that nothing computed by an earlier build is reused (the report and the errata still read
what the chapters before them cached in that copy, as in a build).

The machine may be shared, so the wall time says little alone: the CPU time is measured inside
the kernel, ``time.process_time`` (every thread of the kernel, numba's included) plus the
children it waited for (``resource.getrusage(RUSAGE_CHILDREN)``: the processes of a pool), around
each cell; a page's total is the kernel's whole CPU time, its start and imports included.

Every page has a budget of :data:`BUDGET` s of CPU (issue 28); the pages above it are flagged.

Options: ``--min SECONDS`` lists the cells above that CPU or wall time (default 1 s);
``--json FILE`` also writes every cell's times.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

import jupytext
import nbformat
from nbclient import NotebookClient

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools"))
from preexecute import notebook_pages, toc_pages  # noqa: E402  (the build's one reading of _toc.yml)
#: what a page's execution may read besides its own source
BOOK_FILES = ("_config.yml", "_toc.yml", "references.bib")
BOOK_DIRS = ("_static", "_ext")

#: every page's budget, s of CPU on the idle 2-core machine (issue 28); a page above it is flagged
BUDGET = 30.0

_HOOK = "# book_times: hook"
_SETUP = _HOOK + """
import json as _bt_json, resource as _bt_res, time as _bt_time
_bt_cells, _bt_start = [], None
def _bt_children():
    r = _bt_res.getrusage(_bt_res.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime
def _bt_pre(info):
    global _bt_start
    _bt_start = (info.raw_cell, _bt_time.perf_counter(), _bt_time.process_time(), _bt_children())
def _bt_post(result):
    if _bt_start is None or _bt_start[0].startswith(%r):
        return
    src, w, c, ch = _bt_start
    _bt_cells.append((_bt_time.perf_counter() - w, _bt_time.process_time() - c + _bt_children() - ch))
get_ipython().events.register("pre_run_cell", _bt_pre)
get_ipython().events.register("post_run_cell", _bt_post)
""" % _HOOK
_REPORT = _HOOK + """
_bt_self = _bt_res.getrusage(_bt_res.RUSAGE_SELF)
print(_bt_json.dumps({"cells": _bt_cells,
                      "cpu": _bt_self.ru_utime + _bt_self.ru_stime + _bt_children()}))
"""


def copy_book(dest: Path, root: Path = ROOT) -> None:
    """The book's sources (pages, configuration, static files) into ``dest``."""
    for f in BOOK_FILES:
        shutil.copy2(root / f, dest / f)
    for d in BOOK_DIRS:
        if (root / d).is_dir():
            shutil.copytree(root / d, dest / d)
    for page in toc_pages(root):                      # every page the table of contents names
        (dest / page).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(root / f"{page}.md", dest / f"{page}.md")


def run_page(md: Path, timeout: int = 900, setup: str = "") -> dict:
    """Execute one page in its folder; its wall and CPU time and every code cell's. ``setup``:
    code run first in the kernel, not timed as a cell (a benchmark's variant)."""
    nb = jupytext.read(md)
    code = [c for c in nb.cells if c.cell_type == "code"]
    nb.cells.insert(0, nbformat.v4.new_code_cell(_SETUP + "\n" + setup))
    nb.cells.append(nbformat.v4.new_code_cell(_REPORT))
    client = NotebookClient(nb, timeout=timeout, kernel_name="python3",
                            resources={"metadata": {"path": str(md.parent)}})
    tic = time.perf_counter()
    client.execute()
    wall = time.perf_counter() - tic
    out = json.loads("".join(o.get("text", "") for o in nb.cells[-1].outputs if o.output_type == "stream"))
    assert len(out["cells"]) == len(code), (len(out["cells"]), len(code))
    cells = [{"index": i, "source": c.source, "wall": w, "cpu": cpu}
             for i, (c, (w, cpu)) in enumerate(zip(code, out["cells"]), start=1)]
    return {"page": str(md), "wall": wall, "cpu": out["cpu"], "cells": cells}


def _first_line(src: str) -> str:
    lines = [ln.strip() for ln in src.splitlines() if ln.strip() and not ln.lstrip().startswith(("#", "---"))]
    lines = [ln for ln in lines if not ln.startswith(("mystnb:", "tags:", "caption:", "name:", "alt:",
                                                      "figure:", "image:"))]
    return (lines[0] if lines else "")[:64]


def main(argv: list[str] | None = None) -> int:
    # the kernels' environment of the build (tools/preexecute.py: BLAS single-threaded)
    os.environ["OPENBLAS_NUM_THREADS"] = "1"
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("pages", nargs="*", help="pages of _toc.yml (default: every notebook page, in its order)")
    ap.add_argument("--min", type=float, default=1.0, help="list cells above this CPU or wall time (s)")
    ap.add_argument("--json", type=Path, help="write every cell's times to this file")
    args = ap.parse_args(argv)
    notebooks = notebook_pages()
    pages = ([p.removesuffix(".md") for p in args.pages if p.removesuffix(".md") in notebooks]
             if args.pages else notebooks)
    results = []
    with tempfile.TemporaryDirectory(prefix="book-times-") as tmp:
        book = Path(tmp)
        copy_book(book)
        # the order of the build (Sphinx reads its pages sorted by name): the chapters, then the
        # errata and the report, which read what the chapters cached
        order = sorted(pages)
        for page in order:
            res = run_page(book / f"{page}.md")
            res["page"] = page
            results.append(res)
            over = f"   over its {BUDGET:g} s budget" if res["cpu"] > BUDGET else ""
            print(f"{page:<28} wall {res['wall']:6.1f} s   CPU {res['cpu']:6.1f} s{over}", flush=True)
            for c in res["cells"]:
                if max(c["wall"], c["cpu"]) >= args.min:
                    print(f"    cell {c['index']:>3}  wall {c['wall']:6.1f} s  CPU {c['cpu']:6.1f} s   "
                          f"{_first_line(c['source'])}", flush=True)
    wall, cpu = sum(r["wall"] for r in results), sum(r["cpu"] for r in results)
    print(f"{'all pages, one after another':<28} wall {wall:6.1f} s   CPU {cpu:6.1f} s "
          f"(load average {os.getloadavg()[0]:.1f} at the end)")
    over = [r["page"] for r in results if r["cpu"] > BUDGET]
    print(f"pages over the {BUDGET:g} s budget: {', '.join(over) or 'none'}")
    if args.json:
        args.json.write_text(json.dumps(results, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
