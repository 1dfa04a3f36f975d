"""Benchmark: Chapter 4's CPU time with the compiled switched integrator's two event
locators (:mod:`lib.integrators.switched_events`), before (``bracket``: real steps only) and
after (``dense``: on a smooth step's dense output, then one real step, the default).

Run with ``make benchmark`` (or ``.venv/bin/python benchmarks/bench_locators.py``). The page
``chapters/04_limits`` is executed twice, as ``make book-times`` executes it (each time in a
fresh copy of the book, so nothing cached is reused; numba's compiled kernels are reused),
the first time with ``locator="bracket"`` made the default of
:func:`lib.limits.runs.switched_runs` and :func:`lib.limits.verdicts.limit_verdicts`. Then
the two locators' cost on the page's largest computation, the 81 angle limits' verdicts
without a cap: real steps an event and the share of dense estimates passed on to the
bracket locator. The chapter's numbers under each locator are compared by
``tests/test_event_locators.py``.

Target: the page's CPU time at least 30 % lower with the dense locator (issue 38).
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from book_times import ROOT, copy_book, run_page  # noqa: E402

sys.path.insert(0, str(ROOT))
PAGE = "chapters/04_limits"
BEFORE = """
import lib.limits.runs as _bt_runs, lib.limits.verdicts as _bt_verdicts
_bt_runs.switched_runs.__kwdefaults__["locator"] = "bracket"
_bt_verdicts.limit_verdicts.__kwdefaults__["locator"] = "bracket"
"""


def page_cpu(setup: str) -> tuple[float, float]:
    """Chapter 4's wall and CPU time (s), executed in a fresh copy of the book after ``setup``."""
    with tempfile.TemporaryDirectory(prefix="bench-locators-") as tmp:
        copy_book(Path(tmp))
        res = run_page(Path(tmp) / f"{PAGE}.md", setup=setup)
    return res["wall"], res["cpu"]


def sweep_costs() -> None:
    """Each locator on the chapter's 81 angle limits (no cap, 180 periods with the companion)."""
    from lib import trajectories
    from lib.limits.runs import switched_runs
    from lib.params import Body, Gains

    b = np.radians(np.arange(10, 91))
    switched_runs(Body(), Gains(), trajectories.eight(), b[:2], n_periods=2)       # compile outside the timing
    for loc in ("bracket", "dense"):
        t = time.process_time()
        r = switched_runs(Body(), Gains(), trajectories.eight(), b, n_periods=180, lyapunov_from=60, locator=loc)
        cpu = time.process_time() - t
        ev, steps, handed = r.locating.sum(axis=0)
        print(f"locators: the 81 angle limits' runs (180 periods) with {loc:<7}: {cpu:6.1f} s of CPU, "
              f"{steps / ev:.2f} real steps an event, {100 * handed / ev:.1f} % of the events handed on")


def main() -> int:
    os.environ["OPENBLAS_NUM_THREADS"] = "1"
    before = page_cpu(BEFORE)
    after = page_cpu("")
    print(f"locators: {PAGE} with the bracket locator (before): wall {before[0]:6.1f} s, CPU {before[1]:6.1f} s")
    print(f"locators: {PAGE} with the dense locator (after):    wall {after[0]:6.1f} s, CPU {after[1]:6.1f} s "
          f"({100 * (1 - after[1] / before[1]):.0f} % less CPU; target >= 30 %)")
    sweep_costs()
    return 0


if __name__ == "__main__":
    sys.exit(main())
