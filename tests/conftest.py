"""Shared fixtures. The book is built at most once per test session, in the repository's
own ``_build`` (the same output as ``make book``), and not at all when ``make book``
left a current build there."""

from __future__ import annotations

import fcntl
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from lib.machinery.robustness import ROBUST_REL, perturbed

ROOT = Path(__file__).resolve().parents[1]


# What the book is built from: a build of _build/ older than any of these is stale.
# (README.md is not part of the book: _config.yml excludes it.)
BOOK_INPUTS = ("chapters/*.md", "*.md", "reference/*.md", "_config.yml", "_toc.yml", "references.bib",
               "lib/**/*.py", "_static/*", "_ext/*.py", "tools/*.py", "requirements.txt")
BUILD_CMD = ["build", "--all", "-W", "-n", "--keep-going", "."]


def _newest_book_input() -> tuple[float, Path]:
    files = {f for pattern in BOOK_INPUTS for f in ROOT.glob(pattern) if f.is_file()}
    files.discard(ROOT / "README.md")
    newest = max(files, key=lambda f: f.stat().st_mtime)
    return newest.stat().st_mtime, newest


def _current_build() -> subprocess.CompletedProcess | None:
    """The build in ``_build`` as a completed process (its exit status and real log) when
    it is current, else None. ``make book`` and the fixture below both leave
    ``_build/build.log`` (its time set to when the build began) and ``_build/build.rc``
    (written when it ended); the build is current when its HTML was written between the
    two and no input of the book changed after it began."""
    build = ROOT / "_build"
    # searchindex.js is written at the end of every build (index.html only once: a redirect)
    log, rc, html = build / "build.log", build / "build.rc", build / "html" / "searchindex.js"
    if not (log.is_file() and rc.is_file() and html.is_file()):
        return None
    began, ended, written = log.stat().st_mtime, rc.stat().st_mtime, html.stat().st_mtime
    if not began <= written <= ended + 1.0:
        return None                       # the HTML came from another build than the log
    if _newest_book_input()[0] >= began:
        return None                       # an input changed after the build began
    return subprocess.CompletedProcess(["jupyter-book", *BUILD_CMD], int(rc.read_text().strip() or 1),
                                       stdout=log.read_text(), stderr="")


@pytest.fixture(scope="session")
def built_book() -> subprocess.CompletedProcess:
    """The book built as ``make book`` builds it (``tools/preexecute.py``, then
    ``jupyter-book build --all -W -n --keep-going .``): the one
    ``make book`` left in ``_build`` when it is current (see ``_current_build``),
    otherwise built now, leaving the same ``build.log`` and ``build.rc``.
    ``BOOK_REBUILD=1`` forces a build. Under pytest-xdist the workers take a lock on
    ``_build``: one builds, another that needs the book waits and then reuses that build."""
    build = ROOT / "_build"
    build.mkdir(exist_ok=True)
    with open(build / ".build.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        return _build_or_reuse(build, force=os.environ.get("BOOK_REBUILD", "") not in ("", "0"))


#: when this test process started: a build begun since then is this session's own
_SESSION_START = time.time()


def _build_or_reuse(build: Path, force: bool) -> subprocess.CompletedProcess:
    done = _current_build()
    if done is not None and (not force or (build / "build.log").stat().st_mtime >= _SESSION_START):
        return done
    exe = Path(sys.executable).with_name("jupyter-book")
    env = dict(os.environ, PYTHONWARNINGS="default")
    (build / "build.rc").unlink(missing_ok=True)
    began = time.time()
    # as `make book`: the pages executed two at a time into the execution cache, then the build
    pre = subprocess.run([sys.executable, str(ROOT / "tools" / "preexecute.py")], cwd=ROOT, env=env,
                         stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    proc = pre if pre.returncode else subprocess.run([str(exe), *BUILD_CMD], cwd=ROOT, env=env,
                                                     stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    proc = subprocess.CompletedProcess(proc.args, proc.returncode,
                                       stdout=pre.stdout + (proc.stdout if proc is not pre else ""))
    (build / "build.rc").write_text(f"{proc.returncode}\n")
    (build / "build.log").write_text(proc.stdout)
    os.utime(build / "build.log", (began, began))
    return subprocess.CompletedProcess(proc.args, proc.returncode, stdout=proc.stdout, stderr="")


# ------------------------------------------------------------------ robustness mode
#
# Every test that decides a verdict on a chaotic or switched motion takes the
# ``perturb`` fixture and applies it to its initial state. The fixture runs the
# test twice: once from the nominal start, once from the start moved by a relative
# 1e-12 (the size of a few ulps' worth of difference between two CPUs or libms
# after a few operations). A verdict that flips is one that rode on the last bits.

@pytest.fixture(params=[0.0, ROBUST_REL], ids=["nominal", "perturbed-1e-12"])
def perturb(request):
    """The robustness mode: a function x -> x (nominal run) or x perturbed by a relative 1e-12."""
    rel = request.param
    return (lambda x: np.asarray(x, dtype=float)) if rel == 0 else (lambda x: perturbed(x, rel))


@pytest.fixture
def fresh_signatures(tmp_path):
    """``count(code, modules)``: runs ``code`` in a new interpreter on an empty numba cache (as a
    fresh clone's first run compiles) and returns, for every compiled function of ``modules``,
    how many signatures numba compiled for it: {"module name": n}."""
    def count(code: str, modules: tuple[str, ...]) -> dict[str, int]:
        report = ("\nimport importlib\nfor _m in %r:\n    for _n, _f in vars(importlib.import_module(_m)).items():\n"
                  "        if hasattr(_f, 'signatures'):\n            print('signatures', _m, _n, len(_f.signatures))\n"
                  % (tuple(modules),))
        env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path), NUMBA_NUM_THREADS="1")
        out = subprocess.run([sys.executable, "-c", code + report], env=env, capture_output=True, text=True,
                             check=True).stdout
        rows = [line.split() for line in out.splitlines() if line.startswith("signatures ")]
        return {f"{m} {n}": int(k) for _, m, n, k in rows}
    return count


def pytest_collection_modifyitems(config, items):
    """Mark every test that uses the robustness mode, so that ``pytest -m robustness`` runs them alone."""
    for item in items:
        if "perturb" in getattr(item, "fixturenames", ()):
            item.add_marker(pytest.mark.robustness)


# ------------------------------------------------------------------ checkout guard

def pytest_sessionstart(session):
    """Stop at once unless ``lib`` is this checkout's, both in this process and in a fresh
    interpreter whose working directory holds no ``lib`` (as the book's notebook kernels,
    which run in ``chapters/``): the editable install maps ``lib`` to an absolute path, so
    a second checkout sharing the venv would otherwise test and build the first one's code
    (``tests/test_packaging.py::test_lib_is_this_checkouts`` says the same as a test)."""
    import tempfile

    import lib

    probe = subprocess.run([sys.executable, "-s", "-P", "-c",
                            "import importlib.util; print(importlib.util.find_spec('lib').origin)"],
                           cwd=tempfile.gettempdir(), capture_output=True, text=True)
    for who, origin in (("this session", lib.__file__), ("a fresh interpreter", probe.stdout.strip() or None)):
        if origin is None or not Path(origin).resolve().is_relative_to(ROOT):
            pytest.exit(f"{who} imports lib from {origin}, not from this checkout {ROOT}: another checkout "
                        f"shares the venv {sys.prefix}. Run `{sys.executable} -m pip install -e {ROOT}` "
                        f"or give this checkout its own .venv.", returncode=pytest.ExitCode.USAGE_ERROR)
