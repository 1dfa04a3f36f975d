"""Benchmark: the fast Fig. 5 sweep against per-point tight-tolerance solve_ivp on the full closed loop.

Run with ``make benchmark`` (or ``.venv/bin/python benchmarks/bench_eight_sweep.py``).

Fast: :func:`lib.stability.eight_rotation_sweep` on the chapter's 40 x 40 grid
(R in [0.25, 4] m, Theta in [0.05, 1.5] rad/s), timed after one warm-up call that
compiles the kernel; its time per grid point is total / 1600.
Reference: :func:`lib.simulate.simulate` (DOP853, rtol = atol = 1e-10) on the
full 6-state closed loop (2)-(4), (23), (25)-(26), started on the reference, for
60 periods, on a sample of grid points the fast sweep classifies as periodic;
the range is taken over the last period from samples at the same phases as the
sweep's, with the same Hermite refinement of the extremes.
Prints the speed-up ratio per grid point and the largest range difference.
Target: >= 200 x, <= 1e-6 rad.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from lib import simulate, stability, trajectories
from lib.params import Body, Gains


def reference_range(body: Body, R: float, Theta: float, steps: int, periods: int = 60) -> float:
    ref = trajectories.eight(R, Theta)
    T = 2 * math.pi / Theta
    t_last = T * (periods - 1) + T * np.arange(1, steps + 1) / steps
    res = simulate.simulate(body, Gains(), ref, float(t_last[-1]), z0=ref.z(0.0), dz0=ref.dz(0.0), t_eval=t_last)
    p = res.rotation_error()
    dp_ds = (res.dz[:, 2] - res.dz_d[:, 2]) / Theta
    # the same refinement of the extremes (cubic Hermite) as the sweep
    return float(stability.sampled_range(p[None], cyclic=True, dy=dp_ds[None], h=2 * math.pi / steps)[0])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--grid", type=int, default=40, help="points per axis of the fast sweep (default 40)")
    ap.add_argument("--sample", type=int, default=6, help="grid points solved per point with solve_ivp (default 6)")
    args = ap.parse_args()

    body = Body()
    Rg, Tg = np.meshgrid(np.linspace(0.25, 4.0, args.grid), np.linspace(0.05, 1.5, args.grid))
    R, Th = Rg.ravel(), Tg.ravel()

    stability.eight_rotation_sweep(body, R[:2], Th[:2], max_periods=5)      # compile (cached on disk)
    t0 = time.perf_counter()
    df = stability.eight_rotation_sweep(body, R, Th)
    t_fast = time.perf_counter() - t0
    per_fast = t_fast / len(df)
    print(f"fast sweep: {len(df)} points in {t_fast:.2f} s = {1e3 * per_fast:.2f} ms per point; "
          f"regimes {df.regime.value_counts().to_dict()}")

    periodic = df.index[df.regime == "periodic"]
    rng = np.random.default_rng(5)
    sample = np.sort(rng.choice(periodic, size=min(args.sample, periodic.size), replace=False))
    diffs, times = [], []
    for i in sample:
        row = df.loc[i]
        t0 = time.perf_counter()
        r_ref = reference_range(body, row.R, row.Theta, int(row.steps))
        times.append(time.perf_counter() - t0)
        diffs.append(abs(r_ref - row["range"]))
        print(f"  R = {row.R:.3f} m, Theta = {row.Theta:.3f} rad/s: range fast {row['range']:.9f}, "
              f"solve_ivp {r_ref:.9f} rad, |diff| {diffs[-1]:.1e}; solve_ivp {times[-1]:.1f} s")
    per_ref = float(np.mean(times))
    print(f"solve_ivp per point (mean of {len(sample)}): {per_ref:.2f} s")
    print(f"SPEED-UP per grid point: {per_ref / per_fast:.0f}x (target >= 200x)")
    print(f"LARGEST RANGE DIFFERENCE: {max(diffs):.2e} rad (target <= 1e-6)")


if __name__ == "__main__":
    main()
