"""Benchmark: the decisive Fig. 5 verdicts against per-point tight-tolerance solve_ivp on the full closed loop.

Run with ``make benchmark`` (or ``.venv/bin/python benchmarks/bench_eight_sweep.py``).

Fast: :func:`lib.stability.eight_rotation_sweep` (:func:`lib.rotation.verdicts.rotation_verdicts`:
Newton on the compiled period map, Lyapunov exponents for the rest) on the 100 x 100
grid R in [0.25, 4] m, Theta in [0.05, 1.5] rad/s, timed after one warm-up call that
compiles the kernels (cached on disk); its time per grid point is total / 10000.
Target: <= 60 s, for these verdicts and for the book's map with its re-decisions (``fig5_map``).
Reference, per point, on a random sample: :func:`lib.simulate.simulate` (DOP853,
rtol = atol = 1e-10) on the full 6-state closed loop (2)-(4), (23), (25)-(26), started
on the reference, for the periods the fast verdict integrated plus 24, at least 48 and
at most ``--periods`` (200), in runs of whole periods that each fit simulate's step budget
(:data:`lib.machinery.domain.MAX_RUN_STEPS`), its verdict decided from its last ten periods: periodic
(or slipping) when the last periods repeat within 1e-6 rad at some lag k <= 8 (up to
whole turns), otherwise irregular; the range over the last k periods from samples at
the sweep's phases with the same Hermite refinement of the extremes.
Prints the speed-up ratio per grid point (target >= 1000 x), the largest range
difference where both find the same orbit (target <= 1e-6 rad), and the share of
sampled points on whose verdict both agree (chaotic, quasiperiodic and undecided all
count as "not periodic" for the reference, which cannot tell them apart).
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from lib import simulate, stability, trajectories
from lib.params import Body, Gains


def reference_verdict(body: Body, R: float, Theta: float, steps: int, periods: int, max_lag: int = 8,
                      tol: float = 1e-6) -> tuple[str, int, float, float]:
    """(verdict, period, slip (turns per period), range (rad)) of the full closed loop by solve_ivp."""
    ref = trajectories.eight(R, Theta)
    T = 2 * math.pi / Theta
    last = max_lag + 2
    t_eval = T * (periods - last) + T * np.arange(1, last * steps + 1) / steps
    # simulate refuses a run beyond its step budget (lib.machinery.domain.MAX_RUN_STEPS): whole
    # periods at a time, halved until a run fits, each from the last one's end (the path and its
    # heading are T-periodic); the last run holds t_eval
    z, dz, done, k = ref.z(0.0), ref.dz(0.0), 0, periods - last
    while done < periods - last:
        n = min(k, periods - last - done)
        try:
            run = simulate.simulate(body, Gains(), ref, n * T, z0=z, dz0=dz, t_eval=[n * T])
        except ValueError as err:
            if "beyond the budget" not in str(err) or n == 1:
                raise
            k = n // 2
            continue
        z, dz, done = run.z[-1], run.dz[-1], done + n
    tail = t_eval - done * T
    res = simulate.simulate(body, Gains(), ref, float(tail[-1]), z0=z, dz0=dz, t_eval=tail)
    p = res.rotation_error().reshape(last, steps)
    dp = ((res.dz[:, 2] - res.dz_d[:, 2]) / Theta).reshape(last, steps)
    for k in range(1, max_lag + 1):
        d = p[-1] - p[-1 - k]
        n = round(d[-1] / (2 * math.pi))
        if np.abs(d - 2 * math.pi * n).max() <= tol:
            if n == 0:      # whole periods of a periodic signal wrap around
                rng = stability.sampled_range(p[-k:].ravel()[None], cyclic=True, dy=dp[-k:].ravel()[None],
                                              h=2 * math.pi / steps)[0]
            else:           # a slipping orbit over [0, kT]: its start is a sample too
                y = np.concatenate([p[-k - 1, -1:], p[-k:].ravel()])
                dy = np.concatenate([dp[-k - 1, -1:], dp[-k:].ravel()])
                rng = stability.sampled_range(y[None], cyclic=False, dy=dy[None], h=2 * math.pi / steps)[0]
            return ("periodic" if n == 0 else "slipping"), k, n / k, float(rng)
    return "irregular", 0, float((p[-1, -1] - p[0, -1]) / (2 * math.pi * max_lag)), float(np.ptp(p))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--grid", type=int, default=100, help="points per axis of the fast sweep (default 100)")
    ap.add_argument("--sample", type=int, default=8, help="grid points solved per point with solve_ivp (default 8)")
    ap.add_argument("--periods", type=int, default=200, help="most periods of a solve_ivp run (default 200)")
    args = ap.parse_args()

    body = Body()
    Rg, Tg = np.meshgrid(np.linspace(0.25, 4.0, args.grid), np.linspace(0.05, 1.5, args.grid))
    R, Th = Rg.ravel(), Tg.ravel()

    stability.eight_rotation_sweep(body, [2.0, 3.134615, 0.25], [math.pi / 4, 0.8, 1.0])   # compile (cached)
    t0 = time.perf_counter()
    df = stability.eight_rotation_sweep(body, R, Th)
    t_fast = time.perf_counter() - t0
    per_fast = t_fast / len(df)
    print(f"fast verdicts: {len(df)} points in {t_fast:.2f} s (target <= 60 s) = {1e3 * per_fast:.2f} ms per point")
    print(f"regimes {df.regime.value_counts().to_dict()}; lost {int(df.lost.sum())}; "
          f"periods of the orbits {df.period[df.period > 0].value_counts().sort_index().to_dict()}")
    if args.grid == 100:
        # the book's map: these verdicts, the lost headings over a longer horizon and the points
        # that saw a chaotic transient decided again (transient chaos), as Chapter 5 computes it
        t0, c0 = time.perf_counter(), time.process_time()
        book = stability.fig5_map(body)
        print(f"the book's Fig. 5 (fig5_map, with its re-decisions): {time.perf_counter() - t0:.1f} s, "
              f"{time.process_time() - c0:.1f} s of CPU (target <= 60 s); "
              f"transient chaos at {int((book.regime == 'transient').sum())} points")
    und = df[df.regime == "undecided"]
    if len(und):
        print(f"undecided reasons {und.reason.value_counts().to_dict()}")

    rng = np.random.default_rng(5)
    sample = np.sort(rng.choice(len(df), size=min(args.sample, len(df)), replace=False))
    diffs, times, agree = [], [], []
    for i in sample:
        row = df.iloc[i]
        t0 = time.perf_counter()
        periods = min(args.periods, max(48, int(row.periods) + 24))
        verdict, k, slip, r_ref = reference_verdict(body, row.R, row.Theta, int(row.steps), periods)
        times.append(time.perf_counter() - t0)
        fast_orbit = row.regime in ("periodic", "slipping")
        same = (verdict == row.regime and k == row.period and abs(slip - row.slip) < 1e-9) if fast_orbit \
            else verdict == "irregular"
        agree.append(same)
        if same and fast_orbit:
            diffs.append(abs(r_ref - row["range"]))
        print(f"  R = {row.R:.3f} m, Theta = {row.Theta:.3f} rad/s: fast {row.regime} (k {row.period}, "
              f"range {row['range']:.9f}), solve_ivp {verdict} (k {k}, range {r_ref:.9f}, {periods} periods); "
              f"{'agree' if same else 'DISAGREE'}; solve_ivp {times[-1]:.1f} s")
    per_ref = float(np.mean(times))
    print(f"solve_ivp per point (mean of {len(sample)}): {per_ref:.2f} s")
    print(f"SPEED-UP per grid point: {per_ref / per_fast:.0f}x (target >= 1000x)")
    print(f"LARGEST RANGE DIFFERENCE (same orbit, {len(diffs)} points): "
          f"{max(diffs) if diffs else float('nan'):.2e} rad (target <= 1e-6)")
    print(f"VERDICTS SHARED: {sum(agree)}/{len(agree)} = {np.mean(agree):.0%}")


if __name__ == "__main__":
    main()
