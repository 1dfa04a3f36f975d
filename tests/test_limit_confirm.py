"""Chapter 4's verdicts decided again from moved starts (lib.limits.confirm): runs that reach
their attractor directly keep their verdict, a recorded attractor that the start does not
reach becomes ``transient``, runs that claim no attractor are left alone, and bad frames and
options are refused before any run."""

import math

import numpy as np
import pandas as pd
import pytest

from lib import trajectories as T
from lib.limits import confirm as C
from lib.limits import verdicts as L
from lib.params import Body, Gains

BODY, GAINS, EIGHT = Body(), Gains(), T.eight(2.0, math.pi / 4)


@pytest.fixture(scope="module")
def decided():
    # without a cap: 90 deg periodic, period 1 (|mu| 0.44), 60 deg periodic, period 2 (|mu| 0.11),
    # both reached within 10 periods; 30 deg chaotic by more than 6 standard errors (Chapter 4)
    return L.limit_verdicts(BODY, GAINS, EIGHT, np.radians([90.0, 60.0, 30.0]))[0]


def test_runs_reaching_their_attractor_directly_keep_their_verdicts(decided):
    assert list(decided.regime) == ["periodic", "periodic", "chaotic"] and list(decided.period) == [1, 2, 0]
    out = C.confirm_limit_verdicts(BODY, GAINS, EIGHT, decided)
    assert list(out.confirmed) == [len(C.MOVES)] * 3
    pd.testing.assert_frame_equal(out.drop(columns="confirmed"), decided)


def test_a_recorded_orbit_the_start_does_not_reach_makes_the_run_transient(decided):
    # the 90 deg row with its orbit moved far off (0.5 m in x): the moved starts reach the true
    # orbit, which is not the recorded one, so the attractor is not determined
    wrong = decided.iloc[[0]].copy()
    wrong.at[wrong.index[0], "orbit"] = decided.orbit.iloc[0] + np.array([0.5, 0, 0, 0, 0, 0])
    out = C.confirm_limit_verdicts(BODY, GAINS, EIGHT, wrong).iloc[0]
    assert out.regime == "transient" and out.period == 0 and out.orbit is None
    assert "another orbit" in out.reason and out.reason.count("periodic, period 1") == 1 + len(C.MOVES)


def test_an_orbit_recorded_for_a_chaotic_run_makes_it_transient(decided):
    # the 30 deg row said to be chaotic is told to have reached the 90 deg row's orbit: its
    # moved starts reach no orbit at all
    row = decided.iloc[[0]].copy()
    row["angle_limit"] = decided.angle_limit.iloc[2]
    out = C.confirm_limit_verdicts(BODY, GAINS, EIGHT, row).iloc[0]
    assert out.regime == "transient" and out.reason.endswith("start + 1e-12: chaotic)")


def test_a_chaotic_verdict_whose_moved_start_reaches_an_orbit_is_transient(decided):
    # the 90 deg row said to be chaotic: the moved start reaches the period-1 orbit, another
    # regime, so the attractor is not determined
    row = decided.iloc[[0]].copy()
    row["regime"], row["period"], row["turns"] = "chaotic", 0, 0
    row.at[row.index[0], "orbit"] = None
    out = C.confirm_limit_verdicts(BODY, GAINS, EIGHT, row).iloc[0]
    assert out.regime == "transient" and out.reason.endswith("start + 1e-12: periodic, period 1)")


def test_runs_claiming_no_attractor_and_confirmed_rows_are_left_alone(decided):
    fr = decided.copy()
    fr["regime"] = ["undecided", "quasiperiodic", "chaotic"]
    fr["confirmed"] = [0, 0, 2]
    out = C.confirm_limit_verdicts(BODY, GAINS, EIGHT, fr)
    pd.testing.assert_frame_equal(out, fr)


def test_same_orbit_finds_every_point_of_an_orbit_and_nothing_off_it(decided):
    x = decided.orbit.iloc[1]                                     # the period-2 orbit at 60 deg
    b = decided.angle_limit.iloc[1]
    px = L.switched_runs(BODY, GAINS, EIGHT, b, None, s0=x, n_periods=1).states[0, -1]
    px[2] += 2 * math.pi                                          # the heading counts modulo 2 pi
    # the orbit's two points are 0.1 and more apart (distinct points of Chapter 4's orbits lie
    # 0.5 apart or more; the tolerance is 1e-6): 1e-3 off the orbit is another orbit
    off = x + np.array([1e-3, 0, 0, 0, 0, 0])
    got = C.same_orbit(BODY, GAINS, EIGHT, [b] * 3, [np.inf] * 3, [x] * 3, [x, px, off], [2] * 3)
    assert list(got) == [True, True, False]


def test_confirmed_limit_verdicts_is_the_two_steps(decided):
    fr, runs = C.confirmed_limit_verdicts(BODY, GAINS, EIGHT, np.radians([90.0, 60.0, 30.0]))
    pd.testing.assert_frame_equal(fr.drop(columns="confirmed"), decided)
    assert runs.states.shape[0] == 3


@pytest.mark.parametrize("change, match", [
    (lambda fr: fr.drop(columns="orbit"), "lacks the columns"),
    (lambda fr: fr.assign(horizon=[130, 120, 120]), "whole multiple"),
])
def test_a_frame_that_is_not_a_verdict_frame_is_refused(decided, change, match):
    with pytest.raises(ValueError, match=match):
        C.confirm_limit_verdicts(BODY, GAINS, EIGHT, change(decided))


@pytest.mark.parametrize("kwargs, match", [
    (dict(locator="nearest"), "locator"),
    (dict(steps_per_period=8), "steps_per_period"),
    (dict(periodz=120), "periodz"),
    (dict(periods=24, block=16), "two blocks"),                # the first decision's check, shared
])
def test_bad_options_are_refused_before_any_run(decided, kwargs, match):
    with pytest.raises((ValueError, TypeError), match=match):
        C.confirm_limit_verdicts(BODY, GAINS, EIGHT, decided, **kwargs)


def test_verdicts_without_the_measures_are_the_same_verdicts(decided):
    # measure=False skips only the measures over the run: every verdict, period,
    # multiplier, exponent and orbit is the same to the bit, the unmeasured columns are NaN or NA
    lean = L.limit_verdicts(BODY, GAINS, EIGHT, np.radians([90.0, 60.0, 30.0]), measure=False)[0]
    same = ["regime", "period", "turns", "floquet", "lyapunov", "lyapunov_stderr", "returns", "crossings", "reason"]
    pd.testing.assert_frame_equal(lean[same], decided[same])
    assert all(np.array_equal(a, b) for a, b in zip(lean.orbit[:2], decided.orbit[:2])) and lean.orbit[2] is None
    assert lean[["p_range", "pos_err"]].isna().all().all()
    # the orbits' drift is n / k without a run; the chaotic row's is not measured
    assert list(lean.drift[:2]) == [0.0, 0.0] and np.isnan(lean.drift[2])
    assert list(lean.lost[:2]) == [False, False] and lean.lost.isna()[2] and lean.turns_round.isna().all()


def test_measure_must_be_a_flag():
    with pytest.raises((TypeError, ValueError), match="measure"):
        L.limit_verdicts(BODY, GAINS, EIGHT, np.radians([90.0]), measure="no")


def test_same_orbit_refuses_bad_limits_and_periods(decided):
    x = decided.orbit.iloc[0]
    with pytest.raises(ValueError, match="angle_limits"):
        C.same_orbit(BODY, GAINS, EIGHT, [4.0], [np.inf], [x], [x], [1])
    with pytest.raises(ValueError, match="period"):
        C.same_orbit(BODY, GAINS, EIGHT, [1.0], [np.inf], [x], [x], [0])
