"""Run independent pieces of work in separate processes (the slow, one-run-at-a-time
integrations: the adaptive switched integrator, the adaptive tracking runs)."""

from __future__ import annotations

from concurrent.futures import ProcessPoolExecutor
from typing import Callable, Sequence

__all__ = ["map_in_processes"]


def map_in_processes(fn: Callable, items: Sequence, workers: int) -> list:
    """``[fn(x) for x in items]``, shared among ``workers`` processes when more than one
    (``fn`` must be a module-level function, so that it can be sent to them)."""
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise ValueError(f"workers must be a positive integer, got {workers!r}")
    if workers == 1 or len(items) <= 1:
        return [fn(x) for x in items]
    with ProcessPoolExecutor(max_workers=workers) as ex:
        return list(ex.map(fn, items))
