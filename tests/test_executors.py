"""What a user's own executor may be (issue 37): a thread pool, a dask client's executor and a
process pool that spawns its workers serve every sweep; a process pool that forks them is refused
at once, in one sentence naming the fix (a fork after numba's threads have run aborts and breaks
the pool), and so is a spawning pool asked for from a script's top level outside
``if __name__ == "__main__":`` (each worker would run the script again)."""

from __future__ import annotations

import multiprocessing
import subprocess
import sys
import time
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor

import pytest

from lib.machinery.parallel import check_executor, map_chunks
from lib.params import Body
from lib.rotation.verdicts import eight_rotation_sweep

FAST = 1.0                              # reason: a refusal, not a run (measured < 0.01 s)


def test_a_forking_process_pool_is_refused_at_once_naming_the_fix():
    with ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("fork")) as ex:
        t = time.perf_counter()
        with pytest.raises(ValueError, match=r"^executor is a ProcessPoolExecutor that forks .*"
                                             r"get_context\('spawn'\).*process_pool\(n\)$"):
            eight_rotation_sweep(Body(), [2.0], [0.5], executor=ex)
        assert time.perf_counter() - t < FAST                      # reason: before any work


def test_threads_and_spawning_pools_pass_and_other_objects_are_named():
    check_executor(None)
    with ThreadPoolExecutor(2) as ex:
        check_executor(ex)
    with ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("spawn")) as ex:
        check_executor(ex)                                         # under pytest: no script to guard
    with pytest.raises(TypeError, match="^executor must be a concurrent.futures.Executor"):
        map_chunks(len, 2, ([1, 2],), executor="pool")


_GUARDED = """
import multiprocessing
from concurrent.futures import ProcessPoolExecutor
from lib.params import Body
from lib.rotation.verdicts import eight_rotation_sweep

if __name__ == "__main__":
    args = (Body(), [2.0, 0.25], [0.785398, 1.0])
    serial = eight_rotation_sweep(*args, max_periods=20)          # numba's threads have run here
    try:
        with ProcessPoolExecutor(2) as ex:                        # Linux's default: fork
            eight_rotation_sweep(*args, max_periods=20, executor=ex)
    except ValueError as err:
        print("refused:", err)
    with ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("spawn")) as ex:
        pooled = eight_rotation_sweep(*args, max_periods=20, executor=ex, chunk_size=1)
    print("same:", serial.equals(pooled))
"""

_UNGUARDED = """
import math
import multiprocessing
from concurrent.futures import ProcessPoolExecutor
from lib.machinery.parallel import check_executor, map_chunks
with ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("spawn")) as ex:
    print(map_chunks(math.fsum, 2, ([1.0, 2.0],), executor=ex))
"""


@pytest.mark.skipif(multiprocessing.get_start_method() != "fork", reason="the default pool forks on Linux only")
def test_in_a_guarded_script_the_default_pool_is_refused_and_a_spawning_one_gives_the_serial_frame(tmp_path):
    script = tmp_path / "sweep.py"
    script.write_text(_GUARDED)
    out = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert "refused: executor is a ProcessPoolExecutor that forks" in out.stdout
    assert "same: True" in out.stdout and "OpenMP" not in out.stderr


def test_a_spawning_pool_from_an_unguarded_script_fails_at_once_naming_the_fix(tmp_path):
    script = tmp_path / "sweep.py"
    script.write_text(_UNGUARDED)
    out = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=120)
    assert out.returncode != 0
    assert 'if __name__ == "__main__":' in out.stderr and "sweep.py, line 7" in out.stderr
    assert "bootstrapping" not in out.stderr and out.stderr.count("Traceback") == 1
