"""lib.machinery.cache: one computation shared by two pages of one build, never a stale one."""

import time
from pathlib import Path
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

from lib.machinery import cache as book_cache


CALLS = []


def _square(x, scale=1.0):
    CALLS.append(1)
    return np.asarray(x) ** 2 * scale


@pytest.fixture
def book(tmp_path, monkeypatch):
    (tmp_path / "_config.yml").write_text("title: t\n")
    (tmp_path / "_toc.yml").write_text("root: intro\n")
    (tmp_path / "chapters").mkdir()
    monkeypatch.chdir(tmp_path / "chapters")          # notebooks run in their own folder
    CALLS.clear()
    return tmp_path


def test_a_second_call_reads_what_the_first_computed_with_its_time(book):
    a, t1 = book_cache.cached_timed(_square, np.arange(3.0))
    b, t2 = book_cache.cached_timed(_square, np.arange(3.0))
    assert len(CALLS) == 1 and np.array_equal(a, b) and t1 == t2 >= 0
    assert book_cache.cache_dir() == book / "_build" / ".cache"
    assert len(list((book / "_build" / ".cache").glob("_square-*.pkl"))) == 1


def test_the_page_that_computed_a_result_is_named_beside_it(book, monkeypatch):
    """The ``.page`` file names the page that computed (BOOK_PAGE), not one that read it."""
    monkeypatch.setenv(book_cache.PAGE_VARIABLE, "chapters/04_limits")
    book_cache.cached(_square, np.arange(3.0))
    monkeypatch.setenv(book_cache.PAGE_VARIABLE, "report")
    book_cache.cached(_square, np.arange(3.0))
    book_cache.cached(_square, np.arange(5.0))
    pages = sorted(f.read_text() for f in (book / "_build" / ".cache").glob("_square-*.page"))
    assert pages == ["chapters/04_limits", "report"] and len(CALLS) == 2


def test_other_arguments_compute_afresh(book):
    book_cache.cached(_square, np.arange(3.0))
    book_cache.cached(_square, np.arange(3.0), scale=2.0)
    book_cache.cached(_square, np.arange(4.0))
    book_cache.cached(_square, np.arange(3.0).astype(np.float32))
    assert len(CALLS) == 4


def test_a_change_to_the_library_computes_afresh(book, monkeypatch):
    book_cache.cached(_square, 2.0)
    monkeypatch.setattr(book_cache, "_LIB", book)       # another library: another key
    (book / "mod.py").write_text("x = 1\n")
    book_cache.cached(_square, 2.0)
    assert len(CALLS) == 2


def test_outside_a_book_it_simply_computes(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    CALLS.clear()
    assert book_cache.cached(_square, 3.0) == 9.0 and book_cache.cached(_square, 3.0) == 9.0
    assert len(CALLS) == 2 and not (tmp_path / "_build").exists()
    with pytest.raises(FileNotFoundError, match="no book"):
        book_cache.cache_dir()


def _slow_square(x):
    CALLS.append(1)
    time.sleep(0.3)          # long enough for the second caller to arrive while it computes
    return np.asarray(x) ** 2


def test_two_callers_at_once_compute_the_key_once(book):
    # the book's notebooks and the tests run at the same time and share the cache: the second
    # caller of a key waits for the first instead of computing it again
    with ThreadPoolExecutor(2) as ex:
        a, b = ex.map(lambda _: book_cache.cached(_slow_square, np.arange(3.0)), range(2))
    assert len(CALLS) == 1 and np.array_equal(a, b)


def test_the_key_reads_every_folder_of_the_library():
    # a change to a chapter's module (lib/rotation/verdicts.py, say) must compute afresh: the key
    # hashes the whole package, not the folder the cache module sits in
    import lib
    assert book_cache._LIB == Path(lib.__file__).resolve().parent
    hashed = {p.relative_to(book_cache._LIB).parts[0] for p in book_cache._LIB.rglob("*.py")}
    assert {"rotation", "limits", "weighting", "dynamics", "params.py"} <= hashed


def test_source_stamp_follows_the_contents_of_the_files(tmp_path):
    """The stamp a compiled kernel closes over changes when a file it names changes, and only
    then: the same contents give the same stamp, in any folder."""
    from lib.machinery.cache import source_stamp
    a, b = tmp_path / "a.py", tmp_path / "b.py"
    a.write_text("x = 1\n")
    b.write_text("y = 2\n")
    first = source_stamp(a, b)
    assert first == source_stamp(a, b) and 0 <= first < 2**60
    (tmp_path / "c").mkdir()
    (tmp_path / "c" / "a.py").write_text("x = 1\n")
    assert source_stamp(tmp_path / "c" / "a.py", b) == first
    a.write_text("x = 2\n")
    assert source_stamp(a, b) != first
