"""Benchmark: the Fig. 5 map scaled out (README "Scaling out").

Run with ``make benchmark`` (or ``.venv/bin/python benchmarks/bench_scale.py``).

Every process here runs numba on one thread (``NUMBA_NUM_THREADS=1``, set before numba
is imported, and inherited by the spawned workers), so that "one worker" is one core.

1. The cost per point as the map grows: :func:`lib.rotation.fig5.fig5_map` on the
   n x n grid for n in ``--sizes`` (100, 200, 300), in this process, after a warm-up
   call that loads the compiled kernels. The cost is linear in the points when the time
   per point stays flat.
2. One against two workers: the ``--workers-n`` x ``--workers-n`` map (100) through
   :func:`lib.machinery.parallel.process_pool` (spawned processes; ``--dask`` uses a
   ``distributed.LocalCluster`` instead), each pool warmed by a small map first so that
   its start-up is not timed; both frames are checked equal to the single-process one.

Prints seconds, milliseconds per point and the speed-up of two workers over one, with
the machine's load average (the numbers mean little on a busy machine).
"""

from __future__ import annotations

import os

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import argparse  # noqa: E402
import time  # noqa: E402
from contextlib import contextmanager  # noqa: E402

import pandas as pd  # noqa: E402

from lib.params import Body  # noqa: E402
from lib.machinery.parallel import process_pool  # noqa: E402
from lib.rotation.fig5 import fig5_map  # noqa: E402


@contextmanager
def _executor(workers: int, dask: bool):
    if not dask:
        with process_pool(workers) as ex:
            yield ex
        return
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=workers, processes=True, threads_per_worker=1, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        yield client.get_executor()


def _timed(fn):
    t0 = time.perf_counter()
    out = fn()
    return out, time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[100, 200, 300])
    ap.add_argument("--workers-n", type=int, default=100)
    ap.add_argument("--dask", action="store_true", help="a dask LocalCluster instead of a process pool")
    args = ap.parse_args()
    body = Body()
    print(f"load average at start: {os.getloadavg()[0]:.2f} ({os.cpu_count()} CPUs); numba threads "
          f"{os.environ['NUMBA_NUM_THREADS']}")
    fig5_map(body, 8)                                   # warm-up: the compiled kernels from the disk cache
    print("\n1. cost per point as the map grows (one process, one core)")
    single = {}
    for n in args.sizes:
        single[n], dt = _timed(lambda: fig5_map(body, n))
        print(f"   {n:4d} x {n:<4d} {n * n:7d} points  {dt:8.1f} s  {1e3 * dt / (n * n):6.3f} ms a point")
    n = args.workers_n
    ref = single.get(n)
    if ref is None:
        ref, _ = _timed(lambda: fig5_map(body, n))
    kind = "dask LocalCluster" if args.dask else "spawned process pool"
    print(f"\n2. the {n} x {n} map through a {kind} ({n * n} points; start-up not timed)")
    times = {}
    for workers in (1, 2):
        with _executor(workers, args.dask) as ex:
            fig5_map(body, 4, executor=ex)              # start the workers, load their kernels
            got, times[workers] = _timed(lambda: fig5_map(body, n, executor=ex))
        pd.testing.assert_frame_equal(got, ref, check_exact=True)
        print(f"   {workers} worker(s)  {times[workers]:8.1f} s  {1e3 * times[workers] / (n * n):6.3f} ms a point"
              "  (frame identical to the single-process one)")
    print(f"   speed-up of 2 workers over 1: {times[1] / times[2]:.2f}")
    print(f"load average at end: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
