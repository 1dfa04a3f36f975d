"""The entry manoeuvre from the paper's start onto a best motion found (lib.optimal.entry
.entry_motion), and the periodic LQR's verdict from where it ends (lib.optimal.studies.entries.entry_rows)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from lib.optimal import motion as mo
from lib.optimal.studies import entries
from lib.optimal.studies import study
from lib.optimal.entry import ENTRY_PERIODS, entry_motion
from lib.params import PAPER_DZ0, PAPER_Z0, Body

BODY, R, THETA, DEG = Body(), 2.0, math.pi / 4, math.pi / 180


@pytest.fixture(scope="module")
def capped30():
    """The eight under beta_max = 30 deg and F_max = 4 N at the default mesh."""
    return mo.periodic_motion(BODY, R, THETA, F_max=4.0, beta_max=30 * DEG, starts=("paper", "force"))


@pytest.fixture(scope="module")
def entry30(capped30):
    return entry_motion(BODY, capped30)


def test_the_entry_keeps_to_the_limits_and_its_integrated_inputs_end_on_the_motion(capped30, entry30):
    e = entry30
    assert e.F.shape == e.beta.shape == (ENTRY_PERIODS * e.nodes,)
    # exact: the bounds of the NLP, met by IPOPT to its bound tolerance (1e-8 relative)
    assert e.F.min() >= -1e-6 and e.F.max() <= 4.0 + 1e-6 and np.abs(e.beta).max() <= 30 * DEG + 1e-6
    # accuracy: degree-3 collocation at 80 intervals a period, the inputs integrated at rtol 1e-10;
    # the motion's own return error at this mesh is about 1e-7 (measured end gap 6e-8 m)
    assert e.end_gap["position"] < 1e-5 and e.end_gap["heading"] < 1e-5
    assert e.end_gap["velocity"] < 1e-4 and e.end_gap["rate"] < 1e-4   # accuracy: as the line above
    # the entry starts 1 m from the path (the paper's start against C_d(0) = 0), so its largest
    # distance is that, and its RMS lies between the motion's and it
    d0 = float(np.hypot(*PAPER_Z0[:2]))
    assert e.max_error == pytest.approx(d0, abs=0.05)     # reason: the first collocation point, h/9 in
    assert capped30.rms_error < e.rms_error < d0


def test_the_paper_start_reaches_the_orbit_after_the_entry(capped30):
    rows = entries.entry_rows(BODY, {(30, 4.0): capped30})
    r = rows.iloc[0]
    assert r.setting == study.setting_label(30, 4.0) and r.regime == "periodic"
    assert r.reached and r.settled
    assert r.entry_time == pytest.approx(ENTRY_PERIODS * capped30.period, rel=1e-12)  # exact: a product
    assert r.end_position < 1e-5                           # accuracy: as the test above


def test_an_entry_from_another_start_over_more_periods_ends_on_the_motion(capped30):
    start = np.concatenate([np.asarray(PAPER_Z0) + [0.3, -0.2, 0.5], PAPER_DZ0])
    e = entry_motion(BODY, capped30, start, periods=3)
    assert e.F.size == 3 * e.nodes and e.end_gap["position"] < 1e-5   # accuracy: as above


@pytest.mark.parametrize("kw, match", [
    (dict(periods=0), "periods"), (dict(nodes=4), "nodes"), (dict(degree=6), "degree"),
    (dict(start=[0.0, 1.0]), "start"), (dict(start=[np.nan] * 6), "start"),
])
def test_a_bad_entry_is_refused_naming_its_argument(capped30, kw, match):
    with pytest.raises((TypeError, ValueError), match=match):
        entry_motion(BODY, capped30, **kw)


def test_an_entry_onto_a_motion_of_another_body_is_refused_as_the_tracker_refuses_it(capped30):
    # issue 59: entry_motion(Body(m=3.0), a motion planned for Body()) planned without complaint, where
    # track_motion and motion_verdict refuse the same pair
    with pytest.raises(ValueError, match=r"motion is not a periodic motion of body = Body\(m=3.0"):
        entry_motion(Body(m=3.0), capped30)


def test_an_entry_onto_something_else_than_a_motion_is_refused():
    with pytest.raises(TypeError, match="motion"):
        entry_motion(BODY, object())
    with pytest.raises(TypeError, match="body"):
        entry_motion("body", object())


def test_the_entry_table_rounds_its_distances_up_and_says_where_the_maps_disagree():
    import pandas as pd
    rows = pd.DataFrame([dict(setting="30 deg", reached=True, settled=True, entry_rms=0.1195, entry_max=0.98231,
                              end_position=2.7e-6),
                         dict(setting="4 N", reached=False, settled=False, entry_rms=0.19, entry_max=0.98,
                              end_position=5e-8),
                         dict(setting="90 deg", reached=False, settled=True, entry_rms=0.1, entry_max=0.9,
                              end_position=1e-6)])
    t = entries.entry_table(rows)
    assert list(t["paper's start reaches"]) == ["yes", "undecided", "no"]
    assert list(t["entry RMS (m)"]) == ["0.120", "0.190", "0.100"] and t["entry largest (m)"][0] == "0.983"
    assert t["end gap (m)"][0] == "3e-06"


def test_the_entry_figure_draws_the_path_the_entry_and_the_motion(capped30, entry30):
    import matplotlib
    matplotlib.use("Agg")
    from lib.figures.optimal import plot_entry
    from lib.trajectories import eight
    fig = plot_entry(entry30, capped30, eight(R, THETA), "30 deg + 4 N")
    lines = fig.axes[0].get_lines()
    assert len(lines) == 5
    # the entry's drawn path starts at the paper's start (exact: the NLP's bounds fix it)
    assert lines[1].get_xdata()[0] == PAPER_Z0[0] and lines[1].get_ydata()[0] == PAPER_Z0[1]


def test_entry_rows_refuse_what_is_not_a_dict_of_motions():
    with pytest.raises(TypeError, match="motions"):
        entries.entry_rows(BODY, [1, 2])
    with pytest.raises(TypeError, match="motions"):
        entries.entry_rows(BODY, {(30, 4.0): "a motion"})


def test_the_basin_with_the_entry_reaches_the_orbit_from_moved_starts(capped30):
    from lib.allocation import Limits
    fr = entries.entry_basin(BODY, capped30, Limits(4.0, 30 * DEG), heading_offsets=[0.0, math.pi / 2],
                           position_offsets=[0.5])
    assert list(fr.columns) == ["heading_offset", "x_offset", "entry", "reached", "settled"]
    assert fr.entry.all() and fr.reached.all() and fr.settled.all()
    with pytest.raises(TypeError, match="limits"):
        entries.entry_basin(BODY, capped30, None)
