"""Benchmark: the book's build from scratch, as ``make book`` runs it, its wall and CPU time.

Run with ``make benchmark`` (or ``.venv/bin/python benchmarks/bench_book.py``). The book's
sources are copied into a temporary folder (``benchmarks/book_times.py``: nothing cached by an
earlier build is reused, and this checkout's ``_build`` is left alone), then built as ``make
book`` builds them: the pages executed two at a time into the execution cache
(``tools/preexecute.py``), then ``jupyter-book build --all -W -n --keep-going``. Printed: each
stage's wall time and CPU time (the processes it started and waited for: the kernels, the workers,
Sphinx), and the load average, since the machine may be shared.

The book is built twice, with a numba cache of its own (``NUMBA_CACHE_DIR``, a temporary folder,
empty at first). First as on a fresh clone: numba compiles every kernel into that cache. Then as
any later build: the kernels are read from it.

Targets (issue 38), on an idle 2-core machine: the pages in at most 150 s, the whole build in at
most 3 minutes.
"""

from __future__ import annotations

import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from book_times import ROOT, copy_book  # noqa: E402

#: the targets (s): the pages executed two at a time, and the whole build
PAGES_TARGET, TARGET = 150.0, 180.0


def _children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def _stage(cmd: list[str], cwd: Path, env: dict) -> tuple[float, float, str]:
    """Run ``cmd``; its wall and CPU time (s) and its output. Stops the benchmark if it fails."""
    w, c = time.perf_counter(), _children_cpu()
    proc = subprocess.run(cmd, cwd=cwd, env=dict(os.environ, PYTHONWARNINGS="default", **env),
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if proc.returncode:
        sys.exit(f"{' '.join(cmd)} failed:\n{proc.stdout[-4000:]}")
    return time.perf_counter() - w, _children_cpu() - c, proc.stdout


def build(label: str, env: dict) -> None:
    """Build a copy of the book as ``make book`` does, with ``env`` added; print its times."""
    bin_ = Path(sys.executable).parent
    with tempfile.TemporaryDirectory(prefix="bench-book-") as tmp:
        book = Path(tmp)
        copy_book(book)
        ex = _stage([sys.executable, str(ROOT / "tools" / "preexecute.py"), "--root", str(book)], book, env)
        bd = _stage([str(bin_ / "jupyter-book"), "build", "--all", "-W", "-n", "--keep-going", "."], book, env)
    wall, cpu = ex[0] + bd[0], ex[1] + bd[1]
    for line in ex[2].splitlines():                   # each page's time, as preexecute printed it
        if line.startswith("  "):
            print(f"book, {label}: {line.strip()}")
    print(f"book, {label}: the pages executed two at a time {ex[0]:.1f} s ({ex[1]:.1f} s of CPU; target <= "
          f"{PAGES_TARGET:.0f} s), the build from their outputs {bd[0]:.1f} s ({bd[1]:.1f} s of CPU)")
    print(f"book, {label}: {wall:.1f} s in all, {cpu:.1f} s of CPU (target <= {TARGET:.0f} s on an idle 2-core "
          f"machine; load average {os.getloadavg()[0]:.1f} at the end)", flush=True)


def main() -> int:
    with tempfile.TemporaryDirectory(prefix="bench-numba-") as numba_cache:
        build("fresh clone (numba compiles its kernels)", {"NUMBA_CACHE_DIR": numba_cache})
        build("a later build (numba's kernels cached)", {"NUMBA_CACHE_DIR": numba_cache})
    return 0


if __name__ == "__main__":
    sys.exit(main())
