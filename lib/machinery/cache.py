"""A result computed once per build and shared by the book's notebooks.

Two pages sometimes need the same expensive computation: the reproduction report
quotes the Fig. 5 map that Chapter 5 draws, and the angle-limit sweep that
Chapter 4 draws. Each notebook runs in its own kernel, so :func:`cached` keeps the
result on disk, under ``_build/.cache`` of the book being built, keyed by the
function, its arguments and the source of every module of ``lib``: a change to
the library or to the arguments computes afresh (``make clean`` removes the cache).
The time the computation took is kept with it (:func:`cached_timed`), so that a page
quoting it quotes the computation, not the reading of the cache. Beside each result a file
``.page`` names the page that computed it (the environment's ``BOOK_PAGE``, which
``tools/preexecute.py`` sets for each page; empty outside a page): a test of the built book
checks that the pages that read others' results (the report, the errata, the front page)
computed none of the chapters' (:data:`PAGE_VARIABLE`).
"""

from __future__ import annotations

import hashlib
import os
import pickle
import time
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Callable

import numpy as np

try:
    import fcntl
except ImportError:  # not POSIX: no lock, a key may then be computed twice at once
    fcntl = None

__all__ = ["cached", "cached_timed", "cache_dir", "source_stamp", "PAGE_VARIABLE"]

#: the environment variable that names the page being executed (``chapters/04_limits``)
PAGE_VARIABLE = "BOOK_PAGE"

_LIB = Path(__file__).resolve().parents[1]          # the package lib/, every folder of it


def source_stamp(*files: Path) -> int:
    """A hash of the contents of ``files`` as a 60-bit integer. Numba keys a kernel cached on
    disk on its own file, not on the compiled functions it calls from other files: a kernel
    made in a closure over this stamp of those files is keyed on them too, and compiled again
    when one of them changes.

    Parameters
    ----------
    *files : pathlib.Path
        The source files.

    Returns
    -------
    int
        The stamp, >= 0.
    """
    h = hashlib.sha256()
    for f in files:
        h.update(Path(f).read_bytes())
    return int(h.hexdigest()[:15], 16)

def cache_dir(start: Path | None = None) -> Path:
    """``_build/.cache`` of the book that contains ``start`` (default: the working directory):
    the nearest folder upwards that holds ``_config.yml``. Raises FileNotFoundError outside a book.

    Parameters
    ----------
    start : pathlib.Path, optional
        Where to start looking.

    Returns
    -------
    pathlib.Path
        The cache folder.
    """
    here = Path(start or os.getcwd()).resolve()
    for d in (here, *here.parents):
        if (d / "_config.yml").is_file() and (d / "_toc.yml").is_file():
            return d / "_build" / ".cache"
    raise FileNotFoundError(f"no book (_config.yml and _toc.yml) at or above {here}")


def _feed(h, value) -> None:
    if isinstance(value, np.ndarray):
        h.update(repr((value.dtype.str, value.shape)).encode())
        h.update(np.ascontiguousarray(value).tobytes())
    elif isinstance(value, (list, tuple)):
        h.update(f"{type(value).__name__}{len(value)}".encode())
        for v in value:
            _feed(h, v)
    elif isinstance(value, dict):
        for k in sorted(value):
            h.update(repr(k).encode())
            _feed(h, value[k])
    else:
        h.update(repr(value).encode())


def _key(fn: Callable, args, kwargs) -> str:
    h = hashlib.sha256()
    h.update(f"{fn.__module__}.{fn.__qualname__}".encode())
    for path in sorted(_LIB.rglob("*.py")):
        h.update(path.relative_to(_LIB).as_posix().encode())
        h.update(path.read_bytes())
    _feed(h, list(args))
    _feed(h, dict(kwargs))
    return h.hexdigest()[:32]


def cached(fn: Callable, *args, **kwargs) -> Any:
    """``fn(*args, **kwargs)``, computed once per state of the library and shared between the
    notebooks of one book build (a pickle under :func:`cache_dir`). The arguments must have a
    faithful ``repr`` (numbers, strings, arrays, the frozen parameter dataclasses).

    Parameters
    ----------
    fn : callable
        A module-level function.
    *args, **kwargs
        Its arguments.

    Returns
    -------
    Any
        ``fn(*args, **kwargs)``.
    """
    return cached_timed(fn, *args, **kwargs)[0]


def cached_timed(fn: Callable, *args, **kwargs) -> tuple[Any, float]:
    """:func:`cached`, and the wall time (s) the computation took when it was done. Outside a
    book (no ``_config.yml`` above the working directory) it simply computes.

    Parameters
    ----------
    fn : callable
        A module-level function.
    *args, **kwargs
        Its arguments.

    Returns
    -------
    result : Any
        ``fn(*args, **kwargs)``.
    seconds : float
        The wall time (s) of the computation.
    """
    try:
        path = cache_dir() / f"{fn.__name__}-{_key(fn, args, kwargs)}.pkl"
    except FileNotFoundError:
        tic = time.perf_counter()
        result = fn(*args, **kwargs)
        return result, time.perf_counter() - tic
    if path.is_file():
        return _load(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    # one computation per key at a time: a second process (another notebook, or the tests
    # beside the book's build) waits for the first and reads its result
    with _locked(path.with_suffix(".lock")):
        if path.is_file():
            return _load(path)
        tic = time.perf_counter()
        result = fn(*args, **kwargs)
        out = (result, time.perf_counter() - tic)
        tmp = path.with_suffix(f".{os.getpid()}.tmp")
        with tmp.open("wb") as fh:
            pickle.dump(out, fh)
        tmp.replace(path)
        path.with_suffix(".page").write_text(os.environ.get(PAGE_VARIABLE, ""))
    return out


def _load(path: Path):
    with path.open("rb") as fh:
        return pickle.load(fh)


@contextmanager
def _locked(lock: Path):
    """An exclusive advisory lock on ``lock`` (POSIX ``flock``; none where there is no fcntl)."""
    with lock.open("a") as fh:
        if fcntl is not None:
            fcntl.flock(fh, fcntl.LOCK_EX)
        try:
            yield
        finally:
            if fcntl is not None:
                fcntl.flock(fh, fcntl.LOCK_UN)
