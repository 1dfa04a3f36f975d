"""Execute the book's notebook pages two at a time, into the execution cache the build reads.

Jupyter Book 1 executes the pages one after another. ``make book`` runs this script first:
it empties the execution cache (``execute.cache`` of ``_config.yml``, ``_build/.jupyter_cache``),
executes every notebook page of ``_toc.yml`` afresh in ``--jobs`` processes (default 2), each
page in its own kernel in its own folder as the build would, and stores each executed notebook in
that cache (jupyter-cache, the store myst-nb reads with ``execute_notebooks: cache``). The build
that follows then finds every page's outputs there instead of executing it. Each page is read with
myst-nb's own reader and the build's MyST configuration, so its cache key (the code cells and
their metadata) is the one the build looks up; a page it misses is executed by the build itself.

The kernels run with BLAS single-threaded, and numba on one thread when the pages fill the cores
(:func:`kernel_env`). Nothing from an earlier build is
reused: the cache is emptied first, and a page that fails stops
the script with its traceback (the build is then not run). Pages that read other pages' results
(``LAST``: the report, the errata and the front page's findings read the chapters' through :mod:`lib.machinery.cache`) start
last; the others start longest first (``COST``, measured by ``benchmarks/book_times.py``).

One page at a time (``make chapter CH=08``): ``--keep-cache`` with the pages named executes only
those and replaces their entries; the cache is not emptied, so the build that follows reads every
other page's outputs from it as an earlier build left them.
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from multiprocessing import get_context
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]
#: pages that read what other pages cached: started after the others
LAST = ("errata", "report", "intro")
#: pages that compute their own results but also read a chapter's (Methods reads Fig. 5's map, and
#: would otherwise wait on its lock while Chapter 5 computes it, its slot idle): after the chapters.
#: They run at the tail of the build, beside the light pages of LAST or none, so their numba kernels
#: get every core's thread (measured 2026-11-28: Methods 40 s alone on one thread)
AFTER_CHAPTERS = ("methods",)
#: the kernels' environment: BLAS single-threaded. The book's matrices are small (2 x 2 to
#: 6 x 6, stacks of them), so OpenBLAS's threads only spin: measured, Chapter 3's check of (24)
#: (scipy's expm on a stack of 2 x 2 matrices) took 0.72 s of CPU with them and 0.08 s without,
#: on a loaded machine. numba's threads sleep while they wait (OMP_WAIT_POLICY=PASSIVE, set by
#: lib/__init__.py), so that two pages' kernels do not spin against each other (measured: Chapter
#: 5 took 96 s of CPU instead of 176). When as many pages run at once as there are cores, each
#: page's numba kernels run on one thread (:func:`kernel_env`): the cores are busy with pages
#: already, and a second thread only adds its wake-ups and its share of small loops (measured on
#: 2 cores, 2026-11-26: Fig. 5's map 60 s of CPU on one thread, 70 s on two; Chapter 4 118 s
#: instead of 127). Each point of a parallel loop is computed alone, so the results do not
#: depend on the threads (``make test-portable`` runs the tests on one).
KERNEL_ENV = {"OPENBLAS_NUM_THREADS": "1"}
#: a page's CPU time (s), measured (the log of ``make book``, 2026-11-28), to start the longest first
#: (unknown pages first of all)
COST = {"chapters/05_stability": 70, "chapters/04_limits": 69, "chapters/08_optimal": 63,
        "chapters/03_tracking": 13, "chapters/07_percussion": 11, "chapters/06_allocation": 11,
        "chapters/02_controllability": 8, "chapters/01_model": 3, "methods": 40}


def kernel_env(jobs: int, cores: int | None = None) -> dict:
    """The kernels' environment for ``jobs`` pages at once on ``cores`` (default: this machine's):
    :data:`KERNEL_ENV`, and numba on one thread when the pages fill the cores (a variable the user
    set is kept).

    Parameters
    ----------
    jobs : int
        Pages executed at once.
    cores : int, optional
        Cores available; default ``os.cpu_count()``.

    Returns
    -------
    dict
        Environment variables to set.
    """
    cores = (os.cpu_count() or 1) if cores is None else cores
    env = dict(KERNEL_ENV)
    if jobs >= cores and "NUMBA_NUM_THREADS" not in os.environ:
        env["NUMBA_NUM_THREADS"] = "1"
    return env


def _config(root: Path) -> dict:
    return yaml.safe_load((root / "_config.yml").read_text())


def toc_pages(root: Path = ROOT) -> list[str]:
    """Every page of ``_toc.yml`` (root, parts, chapters, sections), in order, without suffix."""

    def files(node):                                  # root, parts, chapters, sections, in order
        if isinstance(node, dict):
            for k, v in node.items():
                if k in ("root", "file") and isinstance(v, str):
                    yield v.removesuffix(".md")
                else:
                    yield from files(v)
        elif isinstance(node, list):
            for v in node:
                yield from files(v)

    return list(dict.fromkeys(files(yaml.safe_load((root / "_toc.yml").read_text()))))


def notebook_pages(root: Path = ROOT) -> list[str]:
    """The pages of ``_toc.yml`` that are MyST notebooks (a jupytext header), without suffix."""
    from myst_nb.core.read import is_myst_markdown_notebook

    return [p for p in toc_pages(root) if (root / f"{p}.md").is_file()
            and is_myst_markdown_notebook((root / f"{p}.md").read_text())]


def resolve_page(name: str, root: Path = ROOT) -> str:
    """The notebook page ``name`` stands for: a page as in ``_toc.yml`` (``chapters/08_optimal``,
    ``report``, with or without ``.md``), or a chapter's number (``08`` or ``8``).

    Parameters
    ----------
    name : str
        What ``make chapter CH=...`` was given.
    root : pathlib.Path
        The book's folder.

    Returns
    -------
    str
        The page, without suffix.
    """
    pages = notebook_pages(root)
    page = name.removesuffix(".md")
    if page.isdigit():
        page = next((p for p in pages if p.startswith(f"chapters/{int(page):02d}_")), page)
    if page not in pages:
        raise ValueError(f"page {name!r} is not a notebook page of _toc.yml; give a chapter's number "
                         f"(01 to 08) or one of: {', '.join(p for p in pages if '/' not in p)}")
    return page


def read_page(md: Path, root: Path = ROOT):
    """The page as the build reads it: myst-nb's reader with the book's MyST extensions."""
    from myst_nb.core.read import read_myst_markdown_notebook
    from myst_parser.config.main import MdParserConfig

    ext = _config(root).get("parse", {}).get("myst_enable_extensions", [])
    return read_myst_markdown_notebook(md.read_text(), config=MdParserConfig(enable_extensions=set(ext)),
                                       add_source_map=True, path=str(md))


def _execute(md: str, root: str, timeout: int, allow_errors: bool, threads: str | None = None):
    """Execute one page in its folder (in a worker process), its numba kernels on ``threads``
    threads if given; the notebook, the error's text, the wall time and the kernel's CPU time (s)."""
    from jupyter_cache.executors.utils import single_nb_execution

    from lib.machinery.cache import PAGE_VARIABLE

    nb = read_page(Path(md), Path(root))
    # the page's name, for lib.machinery.cache to record which page computed a shared result
    os.environ[PAGE_VARIABLE] = Path(md).relative_to(root).with_suffix("").as_posix()
    before = os.environ.get("NUMBA_NUM_THREADS")
    if threads is not None:                  # inherited by this page's kernel only
        os.environ["NUMBA_NUM_THREADS"] = threads
    cpu = _children_cpu()
    try:
        res = single_nb_execution(nb, cwd=str(Path(md).parent), timeout=timeout, allow_errors=allow_errors,
                                  meta_override=True)
    finally:
        if before is None:
            os.environ.pop("NUMBA_NUM_THREADS", None)
        else:
            os.environ["NUMBA_NUM_THREADS"] = before
    # the kernel, a child of this worker, has ended and been waited for: its CPU time
    return nb, (res.exc_string if res.err is not None else None), res.time, _children_cpu() - cpu


def _children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def order(pages: list[str]) -> list[str]:
    """Longest first (by :data:`COST`), then the pages of :data:`AFTER_CHAPTERS`, the pages of
    :data:`LAST` at the end."""
    first = [p for p in pages if p not in LAST and p not in AFTER_CHAPTERS]
    return (sorted(first, key=lambda p: -COST.get(p, float("inf")))
            + [p for p in AFTER_CHAPTERS + LAST if p in pages])


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--jobs", type=int, default=int(os.environ.get("BOOK_JOBS", "2")),
                    help="pages executed at once (default 2, or $BOOK_JOBS)")
    ap.add_argument("--root", type=Path, default=ROOT, help="the book's folder")
    ap.add_argument("--keep-cache", action="store_true",
                    help="keep the cache's other pages and replace only these pages' entries "
                         "(make chapter); without it the cache is emptied first")
    ap.add_argument("pages", nargs="*", help="only these pages (default: every notebook page of _toc.yml): "
                    "as in _toc.yml (chapters/08_optimal, report) or a chapter's number (08)")
    args = ap.parse_args(argv)
    from jupyter_cache import get_cache
    from jupyter_cache.base import CacheBundleIn

    root = args.root.resolve()
    before = dict(os.environ)                             # what the user set
    os.environ.update(kernel_env(args.jobs))              # inherited by the workers' kernels
    execute = _config(root).get("execute", {})
    path = root / execute.get("cache", "_build/.jupyter_cache")
    try:
        wanted = [resolve_page(p, root) for p in args.pages]
    except ValueError as e:
        ap.error(str(e))
    if args.keep_cache and not wanted:
        ap.error("--keep-cache needs the pages to execute (the others are read from the cache)")
    if not args.keep_cache:
        shutil.rmtree(path, ignore_errors=True)           # nothing from an earlier build
    cache = get_cache(path)
    pages = order([p for p in notebook_pages(root) if not wanted or p in wanted])
    timeout, allow = int(execute.get("timeout", 30)), bool(execute.get("allow_errors", False))
    print(f"Executing {len(pages)} pages, {args.jobs} at a time, into {path.relative_to(root)}", flush=True)
    tic, failed = time.perf_counter(), []
    # spawned workers: a fork after numba's threads have run aborts (lib.machinery.parallel)
    with ProcessPoolExecutor(args.jobs, mp_context=get_context("spawn")) as pool:
        tail = str(os.cpu_count() or 1) if "NUMBA_NUM_THREADS" not in before else None
        jobs = {pool.submit(_execute, str(root / f"{p}.md"), str(root), timeout, allow,
                            tail if p in AFTER_CHAPTERS else None): p for p in pages}
        for fut in as_completed(jobs):
            page = jobs[fut]
            nb, err, seconds, cpu = fut.result()
            if err is not None:
                failed.append(page)
                print(f"  {page}: FAILED after {seconds:.1f} s\n{err}", flush=True)
                continue
            md = root / f"{page}.md"
            record = cache.add_nb_to_project(str(md), read_data={"type": "plugin", "name": "myst_nb_md"})
            cache.cache_notebook_bundle(CacheBundleIn(nb, record.uri, data={"execution_seconds": seconds}),
                                        check_validity=False, overwrite=True)
            print(f"  {page}: {seconds:.1f} s ({cpu:.1f} s of CPU)", flush=True)
    print(f"Executed in {time.perf_counter() - tic:.1f} s" + (f"; failed: {', '.join(failed)}" if failed else ""),
          flush=True)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
