"""Benchmark: the compiled switched integrator against the event-located adaptive one.

Run with ``make benchmark`` (or ``.venv/bin/python benchmarks/bench_switched.py``).

Today's path (before issue 12): :class:`lib.integrators.switched.SwitchedLoop`,
scipy's adaptive DOP853 with event location, one run at a time, at the tolerance
Chapter 4 used (rtol = atol = 1e-9). New path: :func:`lib.limits.runs.switched_runs`
(:mod:`lib.integrators.switched_compiled`, numba, 200 fixed DOP853 steps per period,
every event located by redoing the step), all runs in one parallel call, timed after
a warm-up call that compiles the kernels (cached on disk).

Workload: the eight of Chapter 4 from the paper's start at angle limits 20, 30, 45, 60 and
90 degrees, each without a cap and with the 4 N cap (10 runs):
1. speed: 10 periods of every run by both paths; the time per run-period and the
   speed-up (target >= 20 x on 2 cores);
2. accuracy: the state after 2 periods against SwitchedLoop at rtol = atol = 1e-11, with
   the book's 200 steps per period and with 400 (target <= 1e-6 with 400; at 200 the
   violent start at 20 degrees costs more, which the verdicts do not feel: Chapter 4
   re-decides its table with 400 steps);
3. decisions: Chapter 4's earlier verdicts (:func:`lib.limits.sections.sweep_angle_limit`, 15 + 16
   periods of section and 48 of Lyapunov renormalisation at rtol 1e-9, one angle at a
   time on 2 processes) against :func:`lib.limits.verdicts.limit_verdicts` (60 + 120 periods,
   Newton and Floquet multipliers) at 20, 40, 60 and 90 degrees: time per decided limit;
4. the whole of Chapter 4's two 81-angle sweeps, decided (target <= 60 s on 2 cores).
"""

from __future__ import annotations

import math
import time

import numpy as np

from lib.limits import verdicts as limits
from lib import trajectories
from lib.params import PAPER_DZ0, PAPER_Z0, Body, Gains

DEG = [20, 30, 45, 60, 90]
CAPS = [None, 4.0]
PERIODS = 10


def main() -> None:
    body, gains, ref = Body(), Gains(), trajectories.eight()
    s0 = np.concatenate([PAPER_Z0, PAPER_DZ0])
    T = ref.period
    pairs = [(d, c) for c in CAPS for d in DEG]
    b = np.radians([d for d, _ in pairs])
    f = np.array([np.inf if c is None else c for _, c in pairs])
    limits.switched_runs(body, gains, ref, b[:1], f[:1], n_periods=1)          # compile (or load the cache)
    tic = time.perf_counter()
    limits.switched_runs(body, gains, ref, b, f, n_periods=PERIODS)
    t_fast = time.perf_counter() - tic
    tic = time.perf_counter()
    for (d, c) in pairs:
        limits.SwitchedLoop(body, gains, ref, math.radians(d), c).integrate(s0, 0.0, PERIODS * T, rtol=1e-9,
                                                                            atol=1e-9)
    t_slow = time.perf_counter() - tic
    n = len(pairs) * PERIODS
    print(f"1. SwitchedLoop (adaptive, rtol 1e-9): {t_slow:.2f} s = {1e3 * t_slow / n:.2f} ms per run-period")
    print(f"   switched_runs (compiled, {limits.STEPS_PER_PERIOD} steps/period, all runs at once): {t_fast:.3f} s = "
          f"{1e3 * t_fast / n:.3f} ms per run-period")
    print(f"   SPEED-UP: {t_slow / t_fast:.0f}x (target >= 20x)")
    ref2 = np.array([limits.SwitchedLoop(body, gains, ref, math.radians(d), c).integrate(
        s0, 0.0, 2 * T, rtol=1e-11, atol=1e-11).y_end for d, c in pairs])
    for steps in (limits.STEPS_PER_PERIOD, 2 * limits.STEPS_PER_PERIOD):
        st = limits.switched_runs(body, gains, ref, b, f, n_periods=2, steps_per_period=steps).states[:, -1]
        err = np.abs(st - ref2).max(axis=1)
        worst = pairs[int(err.argmax())]
        print(f"2. LARGEST STATE DIFFERENCE after 2 periods, {steps} steps/period: {err.max():.1e} (at {worst[0]} deg, "
              f"cap {worst[1]}); median {np.median(err):.1e}" + ("  (target <= 1e-6)" if steps > limits.STEPS_PER_PERIOD
                                                                 else ""))
    ang = np.radians([20, 40, 60, 90])
    tic = time.perf_counter()
    old = limits.sweep_angle_limit(body, gains, ref, ang, n_transient=15, n_points=16, n_lyap=48, rtol=1e-9,
                                   atol=1e-9, workers=2)
    t_old = time.perf_counter() - tic
    tic = time.perf_counter()
    new, _ = limits.limit_verdicts(body, gains, ref, ang)
    t_new = time.perf_counter() - tic
    print(f"3. DECISIONS at 20/40/60/90 deg: earlier path {t_old:.1f} s ({t_old / 4:.1f} s per limit: "
          f"{[r.verdict for r in old]}); limit_verdicts {t_new:.2f} s ({t_new / 4:.2f} s per limit: "
          f"{[r.regime + (f'-{r.period}' if r.period else '') for r in new.itertuples()]}); "
          f"{t_old / t_new:.0f}x faster over a horizon {180 / 79:.1f}x longer")
    tic = time.perf_counter()
    for cap in CAPS:
        limits.limit_verdicts(body, gains, ref, np.radians(np.arange(10, 91)), cap)
    print(f"4. CHAPTER 4 SWEEPS (2 x 81 angle limits, decided): {time.perf_counter() - tic:.1f} s (target <= 60 s)")


if __name__ == "__main__":
    main()
