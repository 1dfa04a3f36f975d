"""Benchmark: the compiled switched integrator against the event-located adaptive one.

Run with ``make benchmark`` (or ``.venv/bin/python benchmarks/bench_switched.py``).

Today's path (before issue 12): :class:`lib.integrators.switched.SwitchedLoop`,
scipy's adaptive DOP853 with event location, one run at a time, at the tolerance
Chapter 4 used (rtol = atol = 1e-9). New path: :func:`lib.limits.switched_runs`
(:mod:`lib.integrators.switched_compiled`, numba, 200 fixed DOP853 steps per period,
every event located by redoing the step), all runs in one parallel call, timed after
a warm-up call that compiles the kernels (cached on disk).

Workload: the eight of Chapter 4 from the paper's start, 40 periods, at angle limits
20, 30, 45, 60 and 90 degrees, each without a cap and with the 4 N cap (10 runs).
Prints the time per run-period of each path, the speed-up (target >= 50 x) and the
largest state difference after 2 periods between the two (target <= 1e-6: before the
chaotic runs have stretched the difference; after 40 periods only the verdicts can be
compared, which ``tests/test_limits.py`` does).
Then the whole of Chapter 4's decision workload, timed: the two 81-angle sweeps of
:func:`lib.limits.limit_verdicts` (target <= 60 s on 2 cores).
"""

from __future__ import annotations

import math
import time

import numpy as np

from lib import limits, trajectories
from lib.params import PAPER_DZ0, PAPER_Z0, Body, Gains

DEG = [20, 30, 45, 60, 90]
CAPS = [None, 4.0]
PERIODS = 40


def main() -> None:
    body, gains, ref = Body(), Gains(), trajectories.eight()
    s0 = np.concatenate([PAPER_Z0, PAPER_DZ0])
    T = ref.period
    pairs = [(d, c) for c in CAPS for d in DEG]
    b = np.radians([d for d, _ in pairs])
    f = np.array([np.inf if c is None else c for _, c in pairs])
    limits.switched_runs(body, gains, ref, b[:1], f[:1], n_periods=1)          # compile (or load the cache)
    tic = time.perf_counter()
    fast = limits.switched_runs(body, gains, ref, b, f, n_periods=PERIODS)
    t_fast = time.perf_counter() - tic
    tic = time.perf_counter()
    slow_end, slow2 = [], []
    for (d, c) in pairs:
        loop = limits.SwitchedLoop(body, gains, ref, math.radians(d), c)
        seg = loop.integrate(s0, 0.0, PERIODS * T, t_eval=np.array([2 * T, PERIODS * T]), rtol=1e-9, atol=1e-9)
        slow2.append(seg.y[0])
        slow_end.append(seg.y_end)
    t_slow = time.perf_counter() - tic
    n = len(pairs) * PERIODS
    diff2 = float(np.abs(np.array(slow2) - fast.states[:, 2]).max())
    print(f"SwitchedLoop (adaptive, rtol 1e-9): {t_slow:.2f} s = {1e3 * t_slow / n:.2f} ms per run-period")
    print(f"switched_runs (compiled, {limits.STEPS_PER_PERIOD} steps/period): {t_fast:.3f} s = "
          f"{1e3 * t_fast / n:.3f} ms per run-period")
    print(f"SPEED-UP: {t_slow / t_fast:.0f}x (target >= 50x)")
    print(f"LARGEST STATE DIFFERENCE after 2 periods: {diff2:.1e} (target <= 1e-6; the slow path's own "
          "tolerance is 1e-9)")
    tic = time.perf_counter()
    for cap in CAPS:
        limits.limit_verdicts(body, gains, ref, np.radians(np.arange(10, 91)), cap)
    print(f"CHAPTER 4 SWEEPS (2 x 81 angle limits, decided): {time.perf_counter() - tic:.1f} s (target <= 60 s)")


if __name__ == "__main__":
    main()
