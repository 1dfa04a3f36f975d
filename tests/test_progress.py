"""Long sweeps report progress (a tqdm bar on stderr) when run interactively or when asked,
and stay quiet under pytest and in the book build (lib.machinery.parallel.show_progress)."""

import io
import sys

import numpy as np
import pandas as pd
import pytest

from lib.machinery import parallel
from lib.params import Body
from lib.rotation.verdicts import eight_rotation_sweep


class _Terminal(io.StringIO):
    """A stderr that says it is a terminal."""

    def isatty(self) -> bool:
        return True


def _square(x, *, k):
    return [v * v + k for v in x]


def test_progress_is_quiet_under_pytest_even_on_a_terminal(monkeypatch):
    assert "PYTEST_CURRENT_TEST" in __import__("os").environ
    monkeypatch.setattr(sys, "stderr", _Terminal())
    assert parallel.show_progress() is False
    assert parallel.show_progress(True) is True and parallel.show_progress(False) is False
    with pytest.raises(TypeError, match="progress must be True or False"):
        parallel.show_progress("yes")


def test_progress_shows_on_a_terminal_outside_pytest_and_not_in_a_kernel(monkeypatch):
    monkeypatch.delenv("PYTEST_CURRENT_TEST")
    monkeypatch.setattr(sys, "stderr", _Terminal())
    assert parallel.show_progress() is True
    monkeypatch.setattr(sys, "stderr", io.StringIO())      # a notebook kernel's stderr: no terminal
    assert parallel.show_progress() is False


def test_map_chunks_is_quiet_by_default_and_shows_a_bar_when_asked(capsys):
    x = np.arange(40.0)
    quiet = parallel.map_chunks(_square, 40, (x,), dict(k=1))
    assert capsys.readouterr().err == ""
    shown = parallel.map_chunks(_square, 40, (x,), dict(k=1), progress=True)
    err = capsys.readouterr().err
    assert "40/40" in err and "pt" in err                          # the bar counted every point
    # with the bar and no chunk_size, the points run in PROGRESS_CHUNKS chunks: the same values
    assert len(quiet) == 1 and len(shown) == parallel.PROGRESS_CHUNKS
    assert sum(shown, []) == quiet[0]


def test_map_in_processes_shows_a_bar_when_asked(capsys):
    assert parallel.map_in_processes(abs, [-1, 2, -3], 1) == [1, 2, 3]
    assert capsys.readouterr().err == ""
    assert parallel.map_in_processes(abs, [-1, 2, -3], 1, progress=True) == [1, 2, 3]
    assert "3/3" in capsys.readouterr().err


def test_a_sweep_with_progress_is_the_same_frame(capsys):
    # the Fig. 5 sweep of three points: quiet by default; with progress=True a bar over
    # the points, and to the last bit the frame of the quiet run (each point is decided
    # on its own, whichever chunk it runs in)
    R, Th = np.array([2.0, 1.0, 0.5]), np.array([np.pi / 4, 0.5, 1.0])
    quiet = eight_rotation_sweep(Body(), R, Th, max_periods=24)
    assert capsys.readouterr().err == ""
    shown = eight_rotation_sweep(Body(), R, Th, max_periods=24, progress=True)
    assert "3/3" in capsys.readouterr().err
    pd.testing.assert_frame_equal(shown, quiet, check_exact=True)


def test_the_bar_is_labelled_with_the_sweep_the_user_called(monkeypatch):
    import lib.machinery.parallel as P
    labels = []
    real = P._bar
    monkeypatch.setattr(P, "_bar", lambda total, desc: labels.append(desc) or real(total, desc))

    def my_sweep():
        return P.map_chunks(lambda a: pd.DataFrame({"x": a}), 4, (np.arange(4.0),), progress=True)

    my_sweep()
    assert labels == ["my_sweep"]


@pytest.mark.parametrize("entry", ["eight_rotation_sweep", "fig5_map"])
def test_the_bar_of_a_sweep_that_runs_another_is_labelled_with_the_one_called(monkeypatch, entry):
    # issue 37: the bars of eight_rotation_sweep and fig5_map said rotation_verdicts
    import lib.machinery.parallel as P
    from lib.rotation import fig5
    labels = []
    class Bar:
        def update(self, k):
            pass

        def close(self):
            pass

    monkeypatch.setattr(P, "_bar", lambda total, desc: labels.append(desc) or Bar())
    monkeypatch.setattr(P, "_run_chunks", lambda *a, **k: [pd.DataFrame()])   # the label only, no run
    monkeypatch.setattr(fig5, "confirm_lost", lambda body, kind, frame, factor: frame)
    monkeypatch.setattr(fig5, "confirm_attractors", lambda body, kind, frame, confirm: frame)
    if entry == "fig5_map":
        fig5.fig5_map(Body(), 2, progress=True)
    else:
        eight_rotation_sweep(Body(), [2.0], [0.5], progress=True)
    assert labels == [entry]
