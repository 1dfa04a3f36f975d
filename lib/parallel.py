"""Run independent pieces of work elsewhere: the points of a sweep in chunks through any
:class:`concurrent.futures.Executor` (a process pool, or a dask cluster's
``Client.get_executor()``), and the slow one-run-at-a-time integrations (the adaptive
switched integrator, the adaptive tracking runs) in a pool of processes.

Processes are *spawned*, never forked: numba's threads (the compiled engines run
``prange`` loops over points) make a fork of the parent unsafe once they have run
("fork() called from a process already using GNU OpenMP"). A function sent to another
process must be module-level, so that it can be pickled.
"""

from __future__ import annotations

import math
import multiprocessing
import os
from concurrent.futures import Executor, ProcessPoolExecutor
from typing import Callable, Sequence

import pandas as pd

__all__ = ["map_in_processes", "process_pool", "map_chunks", "chunk_slices", "executor_workers", "concat_frames"]


def _check_workers(workers) -> int:
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise ValueError(f"workers must be a positive integer, got {workers!r}")
    return workers


def process_pool(workers: int) -> ProcessPoolExecutor:
    """A pool of ``workers`` *spawned* processes (safe after numba has run in this one)."""
    return ProcessPoolExecutor(max_workers=_check_workers(workers), mp_context=multiprocessing.get_context("spawn"))


def map_in_processes(fn: Callable, items: Sequence, workers: int) -> list:
    """``[fn(x) for x in items]``, shared among ``workers`` spawned processes when more than
    one (``fn`` must be a module-level function, so that it can be sent to them)."""
    _check_workers(workers)
    if workers == 1 or len(items) <= 1:
        return [fn(x) for x in items]
    with process_pool(min(workers, len(items))) as ex:
        return list(ex.map(fn, items))


def executor_workers(executor: Executor) -> int:
    """How many tasks ``executor`` runs at once, as far as it tells: a process or thread
    pool's ``max_workers``, a dask ``ClientExecutor``'s threads over all its workers;
    otherwise the CPUs of this machine."""
    n = getattr(executor, "_max_workers", None)
    client = getattr(executor, "_client", None)
    if n is None and client is not None:
        try:
            n = sum(client.nthreads().values())
        except Exception:  # noqa: BLE001 - any client that cannot tell: fall back to the CPUs
            n = None
    return max(1, int(n or os.cpu_count() or 1))


def chunk_slices(n: int, chunk_size: int) -> list[slice]:
    """Consecutive slices of ``range(n)``, each ``chunk_size`` long (the last shorter)."""
    return [slice(a, min(a + chunk_size, n)) for a in range(0, n, chunk_size)]


def _check_chunking(n, executor, chunk_size) -> int | None:
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise ValueError(f"n must be a positive integer (the points), got {n!r}")
    if executor is not None and not isinstance(executor, Executor):
        raise TypeError(f"executor must be a concurrent.futures.Executor (e.g. a process pool, or a dask "
                        f"Client.get_executor()), got {type(executor).__name__}")
    if chunk_size is not None and (isinstance(chunk_size, bool) or not isinstance(chunk_size, int)
                                   or chunk_size < 1):
        raise ValueError(f"chunk_size must be a positive integer or None, got {chunk_size!r}")
    return chunk_size


def map_chunks(fn: Callable, n: int, arrays: Sequence, kwargs: dict | None = None,
               executor: Executor | None = None, chunk_size: int | None = None) -> list:
    """The one scatter and gather of the sweeps: cut the first axis (length ``n``, the points)
    of each of ``arrays`` (arrays or lists; a None passes to every chunk as None) into
    consecutive chunks of ``chunk_size`` points, call ``fn(*chunk, **kwargs)`` on each,
    through ``executor`` when given (its ``submit``), and return the results in the order
    of the chunks.

    ``chunk_size`` defaults to ceil(n / (2 workers)) with an executor (two chunks per worker,
    :func:`executor_workers`), and to all n points without one: then ``fn`` runs once, here,
    on the arrays as given. ``fn`` must be module-level and its arguments picklable. If a
    chunk raises, the chunks not yet started are cancelled and the error is raised here."""
    kwargs = {} if kwargs is None else kwargs
    _check_chunking(n, executor, chunk_size)
    for a in arrays:
        if a is not None and len(a) != n:
            raise ValueError(f"every array must have the n = {n} points on its first axis, got {len(a)}")
    if chunk_size is None:
        chunk_size = n if executor is None else math.ceil(n / (2 * executor_workers(executor)))
    if chunk_size >= n and executor is None:
        return [fn(*arrays, **kwargs)]
    slices = chunk_slices(n, chunk_size)
    if executor is None:
        return [fn(*_cut(arrays, s), **kwargs) for s in slices]
    futures = [executor.submit(fn, *_cut(arrays, s), **kwargs) for s in slices]
    try:
        return [f.result() for f in futures]
    except BaseException:
        for f in futures:
            f.cancel()
        raise


def _cut(arrays, s: slice) -> list:
    return [None if a is None else a[s] for a in arrays]


def concat_frames(parts: Sequence[pd.DataFrame]) -> pd.DataFrame:
    """The frames of the chunks of :func:`map_chunks` as one, indexed from 0 (one frame as it is)."""
    return parts[0] if len(parts) == 1 else pd.concat(list(parts), ignore_index=True)
