"""Benchmark: the book's build from scratch, as ``make book`` runs it, its wall and CPU time.

Run with ``make benchmark`` (or ``.venv/bin/python benchmarks/bench_book.py``). The book's
sources are copied into a temporary folder (``benchmarks/book_times.py``: nothing cached by an
earlier build is reused, and this checkout's ``_build`` is left alone), then built as ``make
book`` builds them: the pages executed two at a time into the execution cache
(``tools/preexecute.py``), then ``jupyter-book build --all -W -n --keep-going``. Printed: each
stage's wall time and CPU time (the processes it started and waited for: the kernels, the workers,
Sphinx), and the load average, since the machine may be shared.

Target: at most 2 minutes of wall time on an idle 2-core machine (issue 28).
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

TARGET = 120.0


def _children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def _stage(cmd: list[str], cwd: Path) -> tuple[float, float, str]:
    """Run ``cmd``; its wall and CPU time (s) and its output. Stops the benchmark if it fails."""
    w, c = time.perf_counter(), _children_cpu()
    proc = subprocess.run(cmd, cwd=cwd, env=dict(os.environ, PYTHONWARNINGS="default"),
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if proc.returncode:
        sys.exit(f"{' '.join(cmd)} failed:\n{proc.stdout[-4000:]}")
    return time.perf_counter() - w, _children_cpu() - c, proc.stdout


def main() -> int:
    bin_ = Path(sys.executable).parent
    with tempfile.TemporaryDirectory(prefix="bench-book-") as tmp:
        book = Path(tmp)
        copy_book(book)
        ex = _stage([sys.executable, str(ROOT / "tools" / "preexecute.py"), "--root", str(book)], book)
        bd = _stage([str(bin_ / "jupyter-book"), "build", "--all", "-W", "-n", "--keep-going", "."], book)
    wall, cpu = ex[0] + bd[0], ex[1] + bd[1]
    for line in ex[2].splitlines():                   # each page's time, as preexecute printed it
        if line.startswith("  "):
            print(f"book: {line.strip()}")
    print(f"book: the pages executed two at a time {ex[0]:.1f} s ({ex[1]:.1f} s of CPU), "
          f"the build from their outputs {bd[0]:.1f} s ({bd[1]:.1f} s of CPU)")
    print(f"book: {wall:.1f} s in all, {cpu:.1f} s of CPU (target <= {TARGET:.0f} s on an idle 2-core "
          f"machine; load average {os.getloadavg()[0]:.1f} at the end)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
