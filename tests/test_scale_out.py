"""Scale-out: every sweep sends its points in chunks to any concurrent.futures.Executor
(lib.machinery.parallel.map_chunks) and gives back exactly the frame of the single-process run; a
dask cluster is one such executor; processes are spawned, so a pool works after numba's
threads have run in this process."""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pandas as pd
import pytest

from lib.limits import verdicts as L
from lib.weighting import verdicts as LV
from lib.weighting import comparison as W
from lib import trajectories as T
from lib.allocation import Limits
from lib.angles import wrap_angle
from lib.machinery.parallel import (chunk_slices, concat_frames, executor_workers, map_chunks,
                                    map_in_processes, process_pool)
from lib.params import Body, Gains
from lib.rotation.verdicts import FIG5_GRID
from lib.stability import eight_rotation_sweep
from lib.tracking.runs import eight_sensitivity, force_cap_sweep


def _grid(n):
    R, Th = np.meshgrid(np.linspace(*FIG5_GRID["R"], n), np.linspace(*FIG5_GRID["Theta"], n))
    return R.ravel(), Th.ravel()


@pytest.fixture(scope="module")
def fig5_6x6():
    """The 6 x 6 corner-to-corner Fig. 5 grid, decided in one piece in this process (numba's
    threads run here before any pool below starts)."""
    R, Th = _grid(6)
    return R, Th, eight_rotation_sweep(Body(), R, Th)


@pytest.fixture(scope="module")
def pool(fig5_6x6):
    with process_pool(2) as ex:
        yield ex


def _square(x, *, k):
    return [v ** k for v in x]


def test_map_chunks_cuts_in_order_and_passes_none_and_kwargs():
    x = np.arange(10.0)
    parts = map_chunks(_square, 10, (x,), dict(k=2), None, 3)
    assert [len(p) for p in parts] == [3, 3, 3, 1] and sum(parts, []) == list(x ** 2)
    with ThreadPoolExecutor(2) as ex:
        assert executor_workers(ex) == 2
        parts = map_chunks(lambda a, b, c: (list(a), b, c), 5, (range(5), None, "abcde"), None, ex)
    assert [p[0] for p in parts] == [[0, 1], [2, 3], [4]] and all(p[1] is None for p in parts)
    assert "".join(p[2] for p in parts) == "abcde"                     # ceil(5 / (2 workers)) = 2 a chunk
    assert map_chunks(_square, 4, (x[:4],), dict(k=1)) == [list(x[:4])]  # no executor: one call
    assert chunk_slices(5, 5) == [slice(0, 5)]
    assert concat_frames([pd.DataFrame({"a": [1]}), pd.DataFrame({"a": [2]})]).index.tolist() == [0, 1]
    for bad, exc in ((0, ValueError), (-1, ValueError), (1.5, TypeError), (True, TypeError)):
        with pytest.raises(exc, match="chunk_size"):
            map_chunks(_square, 3, (x[:3],), dict(k=1), None, bad)
    with pytest.raises(TypeError, match="executor"):
        map_chunks(_square, 3, (x[:3],), dict(k=1), object(), None)
    with pytest.raises(ValueError, match="first axis"):
        map_chunks(_square, 3, (x,), dict(k=1))


def test_fig5_in_chunks_here_is_the_map_in_one_piece(fig5_6x6):
    # points leave the batch as they are decided, one at a time or with others: each point's
    # numbers do not depend on its companions, to the last bit
    R, Th, whole = fig5_6x6
    pd.testing.assert_frame_equal(eight_rotation_sweep(Body(), R, Th, chunk_size=5), whole, check_exact=True)


def _one_point(R):
    """A numba-parallel run in whichever process calls it: one Fig. 5 point."""
    return eight_rotation_sweep(Body(), np.array([R]), np.array([0.5]), max_periods=16)


def test_map_in_processes_and_a_pool_work_after_numba_has_run(fig5_6x6, pool):
    # fig5_6x6 ran numba's parallel loops in this process: a forked child that runs them
    # too aborts ("fork() called from a process already using GNU OpenMP, this is unsafe",
    # BrokenProcessPool); the pools spawn
    R = [1.0, 2.0]
    here = concat_frames([_one_point(r) for r in R])
    pd.testing.assert_frame_equal(concat_frames(map_in_processes(_one_point, R, 2)), here, check_exact=True)
    pd.testing.assert_frame_equal(concat_frames(list(pool.map(_one_point, R))), here, check_exact=True)
    x = [0.5, 4.0, -7.0]
    assert list(pool.map(wrap_angle, x)) == [wrap_angle(v) for v in x]
    with pytest.raises(ValueError, match="workers"):
        map_in_processes(wrap_angle, x, 0)


def test_fig5_through_a_dask_cluster_is_the_single_process_map(fig5_6x6):
    distributed = pytest.importorskip("distributed")
    R, Th, whole = fig5_6x6
    with distributed.LocalCluster(n_workers=2, processes=True, threads_per_worker=1, dashboard_address=None) \
            as cluster, distributed.Client(cluster) as client:
        ex = client.get_executor()
        assert executor_workers(ex) == 2
        got = eight_rotation_sweep(Body(), R, Th, executor=ex)          # 4 chunks of 9 points
        pd.testing.assert_frame_equal(got, whole, check_exact=True)


def test_limit_verdicts_through_a_process_pool_are_the_single_call(pool):
    ref, o = T.eight(), dict(transient=24, periods=48)
    deg, caps = np.radians([30, 60, 90]), [np.inf, 4.0, np.inf]        # chaotic, period 1, period 1
    whole, runs = L.limit_verdicts(Body(), Gains(), ref, deg, caps, **o)
    got, got_runs = L.limit_verdicts(Body(), Gains(), ref, deg, caps, executor=pool, chunk_size=1, **o)
    assert set(whole.regime) == {"chaotic", "periodic"}
    pd.testing.assert_frame_equal(got, whole, check_exact=True)      # including the located orbits
    for name in L.SwitchedRuns.__dataclass_fields__:
        a, b = getattr(got_runs, name), getattr(runs, name)
        if a is None or b is None:                                     # the samples are not kept
            assert a is None and b is None, name
            continue
        assert np.array_equal(a, b, equal_nan=True), name
    with pytest.raises(ValueError, match="angle_limits"):                # checked here, before any chunk leaves
        L.limit_verdicts(Body(), Gains(), ref, [0.5, 4.0], executor=pool, **o)


POINTS = dict(R=np.array([0.5, 1.5, 2.5, 1.0]), Theta=np.array([0.2, 0.5, 1.0, 0.4]),
              weights=np.array([(1, 1, 0), (1, 1, 0.1), (1, 1, 0), (2, 1, 0.5)], float))
SHORT = dict(steps=64, transient=4, periods=24, block=8)


def test_closed_loop_verdicts_through_a_process_pool_are_the_single_call(pool):
    whole = LV.closed_loop_verdicts(Body(), Gains(), "eight", **POINTS, **SHORT)
    assert (whole.regime == "periodic").any() and whole.lyapunov.notna().all()
    got = LV.closed_loop_verdicts(Body(), Gains(), "eight", **POINTS, executor=pool, chunk_size=1, **SHORT)
    pd.testing.assert_frame_equal(got, whole, check_exact=True)
    # through ClosedLoop itself (limits): the other field, chunked the same
    lim = dict(limits=Limits(force=50.0), R=POINTS["R"][:2], Theta=POINTS["Theta"][:2])
    pd.testing.assert_frame_equal(LV.closed_loop_verdicts(Body(), Gains(), "eight", **lim, chunk_size=1, **SHORT),
                                  LV.closed_loop_verdicts(Body(), Gains(), "eight", **lim, **SHORT), check_exact=True)
    runs = {"a": dict(kind="eight", R=POINTS["R"][:2], Theta=POINTS["Theta"][:2]),
            "b": dict(kind="circle", R=1.0, Theta=0.5)}
    one, chunked = W.verdict_runs(Body(), Gains(), runs, **SHORT), \
        W.verdict_runs(Body(), Gains(), runs, chunk_size=2, **SHORT)
    for name in runs:
        pd.testing.assert_frame_equal(chunked[name], one[name], check_exact=True)


def test_a_chunk_runs_the_field_its_whole_call_chose(monkeypatch):
    # The lean field needs w_x w_y > 0 at *every* point of a call; a chunk of only such
    # points, cut from a call with one point w_y = 0, must still run through ClosedLoop
    # (the two fields agree to rounding, not bit for bit). The spy stops each chunk at
    # its start and records the field its flow runs.
    seen = []

    class Stop(Exception):
        pass

    def spy(flow, s0, o):
        seen.append((flow.R.size, flow.lean))
        raise Stop

    monkeypatch.setattr(LV, "_observe", spy)
    w = np.array([(1, 1, 0), (1, 0, 1)], float)
    for chunk_size, lean in ((1, False), (None, False)):
        with pytest.raises(Stop):
            LV.closed_loop_verdicts(Body(), Gains(), "eight", [1.0, 2.0], 0.5, w, chunk_size=chunk_size)
        assert seen.pop() == (1 if chunk_size else 2, lean)
    with pytest.raises(Stop):
        LV.closed_loop_verdicts(Body(), Gains(), "eight", [1.0, 2.0], 0.5, w[:1], chunk_size=1)
    assert seen.pop() == (1, True)


def test_tracking_sweeps_through_a_process_pool_are_the_single_call(pool):
    ref = T.circle(R=2.0, theta=np.pi / 4)
    o = dict(n_periods=3, n_steady=1, samples_per_period=200)
    whole = force_cap_sweep(Body(), Gains(), ref, [3.0, 4.0, 6.0], **o)
    got = force_cap_sweep(Body(), Gains(), ref, [3.0, 4.0, 6.0], executor=pool, chunk_size=2, **o)
    pd.testing.assert_frame_equal(got, whole, check_exact=True)
    s = dict(n_periods=2.0, n_steady=1.0)
    one = eight_sensitivity(Body(), Gains(), [1.0, 2.0], [0.5], **s)
    pd.testing.assert_frame_equal(eight_sensitivity(Body(), Gains(), [1.0, 2.0], [0.5], executor=pool, **s), one,
                                  check_exact=True)
    with pytest.raises(ValueError, match="not both"):
        eight_sensitivity(Body(), Gains(), [1.0, 2.0], [0.5], workers=2, executor=pool, **s)


_SCRIPT = """
import math
from lib.machinery.parallel import map_in_processes
{body}
"""


@pytest.mark.parametrize("guarded", [False, True, "nested", "not a guard", "in a function", "function unguarded"])
def test_worker_processes_from_an_unguarded_script_fail_at_once_naming_the_fix(tmp_path, guarded):
    # spawned workers import the script again: without the guard its body would run in each of
    # them and multiprocessing would print pages of "bootstrapping phase" tracebacks. A guard
    # inside another block guards too (issue 52); a test that only mentions __main__ does not
    import subprocess
    import sys
    call = "print(map_in_processes(math.sqrt, [1.0, 4.0, 9.0], workers=2))"
    body = {False: call, True: f'if __name__ == "__main__":\n    {call}',
            "nested": f'if math.pi > 3:\n    if __name__ == "__main__":\n        {call}',
            "not a guard": f'if __name__ != "__main__" or math.pi > 3:\n    {call}',
            # issue 59: a guard inside the function that a bare call at the top level runs
            "in a function": f'def main():\n    if __name__ == "__main__":\n        {call}\nmain()',
            "function unguarded": f'def main():\n    {call}\nmain()'}[guarded]
    script = tmp_path / "sweep.py"
    script.write_text(_SCRIPT.format(body=body))
    out = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=120)
    if guarded in (True, "nested", "in a function"):
        assert out.returncode == 0 and out.stdout.strip() == "[1.0, 2.0, 3.0]", out.stderr
    else:
        line = {False: 4, "not a guard": 5, "function unguarded": 6}[guarded]       # the top-level line
        assert out.returncode != 0
        assert 'if __name__ == "__main__":' in out.stderr and f"sweep.py, line {line}" in out.stderr
        assert "bootstrapping" not in out.stderr and out.stderr.count("Traceback") == 1
