"""Run independent pieces of work elsewhere: the points of a sweep in chunks through any
:class:`concurrent.futures.Executor` (a process pool, or a dask cluster's
``Client.get_executor()``), and the slow one-run-at-a-time integrations (the adaptive
switched integrator, the adaptive tracking runs) in a pool of processes.

A sweep reports its progress (a tqdm bar on stderr, in points) when run interactively;
see :func:`show_progress`.

Processes are *spawned*, never forked: numba's threads (the compiled engines run
``prange`` loops over points) make a fork of the parent unsafe once they have run
("fork() called from a process already using GNU OpenMP"). A function sent to another
process must be module-level, so that it can be pickled.
"""

from __future__ import annotations

import ast
import math
import multiprocessing
import os
import sys
from concurrent.futures import Executor, ProcessPoolExecutor, as_completed
from typing import Callable, Sequence

import pandas as pd

from . import checks

__all__ = ["map_in_processes", "process_pool", "check_executor", "map_chunks", "chunk_slices", "executor_workers", "concat_frames",
           "show_progress", "PROGRESS_CHUNKS"]

#: with progress shown and no ``chunk_size`` nor executor, a sweep runs in about this many
#: chunks one after another, so that the bar moves (the frame is the same: every point is
#: decided on its own)
PROGRESS_CHUNKS = 20


def _check_workers(workers) -> int:
    return checks.integer("workers", workers, minimum=1)


def show_progress(progress: bool | None = None) -> bool:
    """Whether a sweep reports its progress on stderr.

    Parameters
    ----------
    progress : bool or None
        True or False decides; None (the default of every sweep) means: only when run
        interactively, that is when stderr is a terminal and the code is not running under
        pytest (``PYTEST_CURRENT_TEST`` set) or in a notebook kernel (the book build, whose
        stderr is not a terminal). In a notebook of your own, pass ``progress=True``.

    Returns
    -------
    bool
        True if a progress bar is to be shown.
    """
    if progress is not None:
        return checks.flag("progress", progress)
    if "PYTEST_CURRENT_TEST" in os.environ:
        return False
    try:
        return bool(sys.stderr.isatty())
    except (AttributeError, ValueError):   # no stderr, or a closed one
        return False


def _caller() -> str:
    """The progress bar's label: the sweep the user called, that is the outermost public function
    of ``lib`` (outside :mod:`lib.machinery`) on the way to :func:`map_chunks`
    (``eight_rotation_sweep`` or ``fig5_map``, not the ``rotation_verdicts`` they run), or the
    caller's own function when ``map_chunks`` is called from outside ``lib``."""
    f = sys._getframe(2)
    name = f.f_code.co_name
    while f is not None and f.f_globals.get("__name__", "").startswith("lib."):
        if not f.f_code.co_name.startswith("_") and not f.f_globals["__name__"].startswith("lib.machinery"):
            name = f.f_code.co_name
        f = f.f_back
    return name


def _bar(total: int, desc: str | None):
    """A tqdm bar over ``total`` points on stderr (tqdm imported only when a bar is shown)."""
    from tqdm.auto import tqdm

    return tqdm(total=total, desc=desc, unit="pt", file=sys.stderr, dynamic_ncols=True)


def process_pool(workers: int) -> ProcessPoolExecutor:
    """A pool of ``workers`` *spawned* processes (safe after numba has run in this one).

    Parameters
    ----------
    workers : int
        Processes (>= 1).

    Returns
    -------
    concurrent.futures.ProcessPoolExecutor
        The pool (use it in a ``with`` block).
    """
    workers = _check_workers(workers)
    _refuse_unguarded_script()
    return ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("spawn"))


def _is_main_test(test: ast.expr) -> bool:
    """Whether an ``if`` test reads ``__name__ == "__main__"`` (either way round), alone or as
    one term of an ``and``."""
    if isinstance(test, ast.BoolOp) and isinstance(test.op, ast.And):
        return any(_is_main_test(v) for v in test.values)
    if not (isinstance(test, ast.Compare) and len(test.ops) == 1 and isinstance(test.ops[0], ast.Eq)):
        return False
    sides = [test.left, test.comparators[0]]
    return ({type(x) for x in sides} == {ast.Name, ast.Constant}
            and {getattr(x, "id", None) for x in sides} >= {"__name__"}
            and {getattr(x, "value", None) for x in sides} >= {"__main__"})


def _unguarded_line(path: str, line: int) -> bool:
    """Whether ``line`` of the script ``path``, run at its top level, lies outside every
    ``if __name__ == "__main__":`` block, at any depth (inside another ``if``, a ``with``, a
    ``try``: a block that runs only in the main process guards whatever it holds)."""
    try:
        tree = ast.parse(open(path, encoding="utf-8").read())
    except (OSError, SyntaxError, ValueError):
        return False
    return not any(isinstance(node, ast.If) and _is_main_test(node.test)
                   and any(s.lineno <= line <= s.end_lineno for s in node.body)
                   for node in ast.walk(tree))


def _refuse_unguarded_script() -> None:
    """Raise at once, with the fix, when worker processes are asked for from the top level of
    a script outside ``if __name__ == "__main__":``. Spawned workers import the script again,
    so its body would run in each of them and multiprocessing would fail with pages of
    ``bootstrapping phase`` and ``BrokenProcessPool`` tracebacks. Notebooks, the interactive
    interpreter and guarded scripts pass."""
    path = getattr(sys.modules.get("__main__"), "__file__", None)
    if not path:
        return
    path = os.path.realpath(path)
    frame, lines = sys._getframe(1), []
    # the script's frames on the way up, innermost first: the call is guarded when any of them stands
    # in a guard, a function's body included (def main(): if __name__ == "__main__": ...; main())
    while frame is not None:
        if frame.f_globals.get("__name__") == "__main__" and os.path.realpath(frame.f_code.co_filename) == path:
            lines.append(frame.f_lineno)
            if frame.f_code.co_name == "<module>":
                if all(_unguarded_line(path, line) for line in lines):
                    raise RuntimeError(
                        f"{path}, line {frame.f_lineno}: worker processes are spawned and import this script "
                        "again, so a sweep with workers > 1 (or a process pool) must be called under "
                        "`if __name__ == \"__main__\":`; put the script's work in that block, or use workers=1")
                return
        frame = frame.f_back


def map_in_processes(fn: Callable, items: Sequence, workers: int, progress: bool | None = None) -> list:
    """``[fn(x) for x in items]``, shared among ``workers`` spawned processes when more than
    one (``fn`` must be a module-level function, so that it can be sent to them).

    Parameters
    ----------
    fn : callable
        A module-level function of one item.
    items : sequence
        The items, one call each.
    workers : int
        Processes (>= 1); 1 runs the items here, one after another.
    progress : bool or None
        Show a progress bar over the items (:func:`show_progress`; None: only interactively).

    Returns
    -------
    list
        ``fn(x)`` for each item, in order.
    """
    _check_workers(workers)
    if not show_progress(progress):
        if workers == 1 or len(items) <= 1:
            return [fn(x) for x in items]
        with process_pool(min(workers, len(items))) as ex:
            return list(ex.map(fn, items))
    with _bar(len(items), _caller()) as bar:
        if workers == 1 or len(items) <= 1:
            out = []
            for x in items:
                out.append(fn(x))
                bar.update(1)
            return out
        with process_pool(min(workers, len(items))) as ex:
            futures = [ex.submit(fn, x) for x in items]
            for f in as_completed(futures):
                bar.update(1)
            return [f.result() for f in futures]


def executor_workers(executor: Executor) -> int:
    """How many tasks ``executor`` runs at once, as far as it tells: a process or thread
    pool's ``max_workers``, a dask ``ClientExecutor``'s threads over all its workers;
    otherwise the CPUs of this machine.

    Parameters
    ----------
    executor : concurrent.futures.Executor
        The executor.

    Returns
    -------
    int
        Tasks it runs at once (>= 1).
    """
    n = getattr(executor, "_max_workers", None)
    client = getattr(executor, "_client", None)
    if n is None and client is not None:
        try:
            n = sum(client.nthreads().values())
        except Exception:  # noqa: BLE001 - any client that cannot tell: fall back to the CPUs
            n = None
    return max(1, int(n or os.cpu_count() or 1))


def chunk_slices(n: int, chunk_size: int) -> list[slice]:
    """Consecutive slices of ``range(n)``, each ``chunk_size`` long (the last shorter).

    Parameters
    ----------
    n : int
        Points.
    chunk_size : int
        Points per chunk.

    Returns
    -------
    list of slice
        ceil(n / chunk_size) slices covering range(n) in order.
    """
    return [slice(a, min(a + chunk_size, n)) for a in range(0, n, chunk_size)]


def check_executor(executor) -> None:
    """Refuse, in one sentence naming the fix, an executor the sweeps cannot use safely: not a
    :class:`concurrent.futures.Executor`; a :class:`~concurrent.futures.ProcessPoolExecutor`
    that *forks* its workers (Linux's default before Python 3.14: a fork after numba's threads
    have run aborts, "fork() called from a process already using GNU OpenMP", and breaks the
    pool); or one that spawns them from a script's top level outside
    ``if __name__ == "__main__":`` (each worker would run the script again). A spawn or
    forkserver pool in a guarded script, a notebook or the interpreter, a thread pool and a dask
    ``Client.get_executor()`` pass; :func:`process_pool` builds the safe pool.

    Parameters
    ----------
    executor : concurrent.futures.Executor or None
        The executor a sweep was given (None passes).

    Returns
    -------
    None
        Raises instead when the executor is refused.

    Raises
    ------
    TypeError
        If ``executor`` is not an Executor.
    ValueError
        If it is a process pool that forks.
    RuntimeError
        If it spawns from an unguarded script.
    """
    if executor is None:
        return
    if not isinstance(executor, Executor):
        raise TypeError(f"executor must be a concurrent.futures.Executor (e.g. a process pool, or a dask "
                        f"Client.get_executor()), got {type(executor).__name__}")
    if isinstance(executor, ProcessPoolExecutor):
        ctx = getattr(executor, "_mp_context", None) or multiprocessing.get_context()
        if ctx.get_start_method() == "fork":
            raise ValueError("executor is a ProcessPoolExecutor that forks its workers, and a fork after numba's "
                             "threads have run aborts; give it mp_context=multiprocessing.get_context('spawn'), "
                             "or use lib.machinery.parallel.process_pool(n)")
        _refuse_unguarded_script()


def _check_chunking(n, executor, chunk_size) -> int | None:
    checks.integer("n", n, minimum=1)
    check_executor(executor)
    return None if chunk_size is None else checks.integer("chunk_size", chunk_size, minimum=1)


def map_chunks(fn: Callable, n: int, arrays: Sequence, kwargs: dict | None = None,
               executor: Executor | None = None, chunk_size: int | None = None,
               progress: bool | None = None) -> list:
    """The one scatter and gather of the sweeps: cut the first axis (length ``n``, the points)
    of each of ``arrays`` (arrays or lists; a None passes to every chunk as None) into
    consecutive chunks of ``chunk_size`` points, call ``fn(*chunk, **kwargs)`` on each,
    through ``executor`` when given (its ``submit``), and return the results in the order
    of the chunks.

    ``chunk_size`` defaults to ceil(n / (2 workers)) with an executor (two chunks per worker,
    :func:`executor_workers`), and to all n points without one: then ``fn`` runs once, here,
    on the arrays as given. ``fn`` must be module-level and its arguments picklable. If a
    chunk raises, the chunks not yet started are cancelled and the error is raised here.

    ``progress``: a bar over the points, advanced as each chunk returns
    (:func:`show_progress`: None shows it only interactively, never under pytest or in the
    book build). With the bar and neither ``chunk_size`` nor an executor, the points run
    here in about :data:`PROGRESS_CHUNKS` chunks, so that the bar moves.

    Parameters
    ----------
    fn : callable
        A module-level function ``fn(*chunk_arrays, **kwargs)``.
    n : int
        The number of points (the first axis of every array).
    arrays : sequence
        Arrays or lists of ``n`` entries each, or None.
    kwargs : dict, optional
        Keywords passed to every call, the same for all chunks.
    executor : concurrent.futures.Executor, optional
        Where the chunks run (its ``submit``); None runs them here.
    chunk_size : int, optional
        Points per chunk (see above for the default).
    progress : bool or None
        Show a progress bar (see above).

    Returns
    -------
    list
        ``fn``'s result for each chunk, in the order of the chunks.
    """
    kwargs = {} if kwargs is None else kwargs
    _check_chunking(n, executor, chunk_size)
    for a in arrays:
        if a is not None and len(a) != n:
            raise ValueError(f"every array must have the n = {n} points on its first axis, got {len(a)}")
    bar = _bar(n, _caller()) if show_progress(progress) else None
    if chunk_size is None:
        if executor is not None:
            chunk_size = math.ceil(n / (2 * executor_workers(executor)))
        else:
            chunk_size = n if bar is None else math.ceil(n / PROGRESS_CHUNKS)
    try:
        return _run_chunks(fn, n, arrays, kwargs, executor, chunk_size, bar)
    finally:
        if bar is not None:
            bar.close()


def _run_chunks(fn, n, arrays, kwargs, executor, chunk_size, bar) -> list:
    """The chunks of :func:`map_chunks`, run here or through ``executor``, advancing ``bar``."""
    def tick(k: int) -> None:
        if bar is not None:
            bar.update(k)

    if chunk_size >= n and executor is None:
        out = [fn(*arrays, **kwargs)]
        tick(n)
        return out
    slices = chunk_slices(n, chunk_size)
    if executor is None:
        out = []
        for s in slices:
            out.append(fn(*_cut(arrays, s), **kwargs))
            tick(s.stop - s.start)
        return out
    futures = [executor.submit(fn, *_cut(arrays, s), **kwargs) for s in slices]
    size = {f: s.stop - s.start for f, s in zip(futures, slices)}
    try:
        for f in as_completed(futures):
            f.result()
            tick(size[f])
        return [f.result() for f in futures]
    except BaseException:
        for f in futures:
            f.cancel()
        raise


def _cut(arrays, s: slice) -> list:
    return [None if a is None else a[s] for a in arrays]


def concat_frames(parts: Sequence[pd.DataFrame]) -> pd.DataFrame:
    """The frames of the chunks of :func:`map_chunks` as one, indexed from 0 (one frame as it is).

    Parameters
    ----------
    parts : sequence of pandas.DataFrame
        The chunks' frames, in order.

    Returns
    -------
    pandas.DataFrame
        One frame.
    """
    return parts[0] if len(parts) == 1 else pd.concat(list(parts), ignore_index=True)
