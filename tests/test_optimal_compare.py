"""lib.optimal.studies.compare and the study's tables: the paper's law measured as Chapter 4 measures it,
and the page's tables from a table of rows."""

import math

import numpy as np
import pandas as pd
import pytest

from lib import trajectories
from lib.allocation import Limits
from lib.integrators.smooth import SimulationError
from lib.limits.runs import switched_runs
from lib.optimal.studies import compare, study
from lib.optimal.bound import cap_bound
from lib.optimal.loop import BLOWUP, FlowMap
from lib.optimal.held import held_force_motion
from lib.optimal.tracker import periodic_lqr, track_motion
from lib.optimal.verdict import ORBIT_SHIFT_TOL
from lib.params import PAPER_DZ0, PAPER_Z0, Body, Gains
from lib.tracking.runs import force_cap_sweep

BODY, GAINS = Body(), Gains()


def test_the_paper_law_under_the_cap_is_periodic_and_measures_as_the_cap_sweep():
    ref = trajectories.eight(2.0, math.pi / 4)
    row = compare.paper_rows(BODY, GAINS, ref, [(None, 4.0)])[0]
    sweep = force_cap_sweep(BODY, GAINS, ref, [4.0], n_periods=10)
    assert row["regime"] == "periodic"
    # reason: one period of the located orbit against the sweep's last two of ten periods (its
    # transient settled to 0.67^8), both sampled 200-400 times a period and refined
    assert row["max_error"] == pytest.approx(float(sweep.pos_err_max.iloc[0]), abs=2e-3)
    assert row["F_peak"] == 4.0                      # exact: the applied force is clipped at the cap
    assert 0.0 < row["rms_error"] < row["max_error"]


def test_a_chaotic_row_of_the_paper_law_carries_the_standard_error_of_its_rms():
    """Without an orbit the paper's law is measured on one chaotic run; the next PAPER_MEASURED
    periods of the same run, another stretch of the same attractor, give its RMS again within
    the two stretches' combined standard errors."""
    ref = trajectories.eight(2.0, math.pi / 4)
    chaotic, periodic = compare.paper_rows(BODY, GAINS, ref, [(30, None), (None, 4.0)])
    assert chaotic["regime"] == "chaotic" and periodic["regime"] == "periodic"
    assert math.isnan(periodic["rms_stderr"])      # exact: an orbit's period has no sampling error
    se = chaotic["rms_stderr"]
    assert 0.0 < se < 0.1 * chaotic["rms_error"]  # measured: 4 % of the RMS over 100 periods
    H, M = compare.PAPER_HORIZON, compare.PAPER_MEASURED
    run = switched_runs(BODY, GAINS, ref, math.radians(30), None, s0=np.concatenate([PAPER_Z0, PAPER_DZ0]),
                        n_periods=H + M, samples_per_period=200)
    m = run.t >= H * ref.period - 1e-9
    t, st = run.t[m][:-1], run.states[0, m][:-1]
    assert t.size == 200 * M
    later = math.sqrt(np.mean(np.sum((st[:, :2] - ref.z(t)[:, :2]) ** 2, axis=1)))
    # reason: 5 combined standard errors; the batch means' own estimate of it varies by about 10 %
    # over 50 blocks and an intermittent stretch fattens the tails (measured up to 2.3 over 20-45 deg)
    assert abs(later - chaotic["rms_error"]) < 5 * math.sqrt(2) * se


@pytest.mark.parametrize("law", ["percussion", "weighted"])
@pytest.mark.parametrize("angle, cap", [(None, None), (None, 4.0), (30, None), (30, 4.0)])
def test_a_law_s_compiled_period_is_the_numpy_rk4_steps(law, angle, cap):
    """The law for P's and the weighted law's compiled period (LawLoop.period_end) against FlowMap's
    RK4 steps of the same field in numpy, on rows far enough from the path that the clip (and the
    anti-windup) act; the period's recorded steps too."""
    ref = trajectories.eight(2.0, math.pi / 4)
    loop = compare.law_loop(BODY, GAINS, ref, law, Limits(cap, None if angle is None else math.radians(angle)))
    rng = np.random.default_rng(3)
    d = loop.s0.size
    x = loop.s0 + rng.normal(scale=[0.5, 0.5, 1.0, 0.5, 0.5, 1.0, 1.0][:d], size=(5, d))
    fast = FlowMap(loop.rates, ref.period, steps=256, period_end=loop.period_end)
    slow = FlowMap(loop.rates, ref.period, steps=256)
    a, b = fast.advance(np.zeros(5, int), x, 2), slow.advance(np.zeros(5, int), x, 2)
    # accuracy: the same stage sums in the same order on the same compiled field, to rounding over
    # 512 steps: 1e-10 relative (measured 0 here; a compiler may fuse a multiply-add elsewhere)
    np.testing.assert_allclose(a, b, rtol=1e-10, atol=1e-10)
    (ea, ta, ya), (eb, tb, yb) = fast.one(x), slow.one(x)
    np.testing.assert_allclose(ta, tb, rtol=1e-12, atol=1e-12)  # accuracy: k h against a running sum of h (the floor)
    # accuracy: as above, over one period's 256 recorded steps
    np.testing.assert_allclose(ya, yb, rtol=1e-10, atol=1e-10)
    np.testing.assert_allclose(ea, eb, rtol=1e-10, atol=1e-10)  # accuracy: as above
    assert ya.shape == (256, 5, d) and np.array_equal(ya[0], x)  # exact: the first record is the start
    F, _ = loop.inputs(np.zeros(5), x)
    if cap is not None:
        assert (F >= cap * (1 - 1e-12)).any()    # the cap binds at some start (exact: the clip's own value)


def test_the_law_for_p_compiled_period_names_a_blow_up_as_the_numpy_steps_do():
    ref = trajectories.eight(2.0, math.pi / 4)
    loop = compare.law_loop(BODY, GAINS, ref, "percussion", Limits(4.0, None))
    x = loop.s0[None, :] + 0.0
    x[0, 3] = 2 * BLOWUP
    for flow in (FlowMap(loop.rates, ref.period, steps=64, period_end=loop.period_end),
                 FlowMap(loop.rates, ref.period, steps=64)):
        with pytest.raises(SimulationError, match=r"a state beyond 1e\+08 at t = 0 s"):
            flow.end(x)
    x[0, 3] = np.nan
    for flow in (FlowMap(loop.rates, ref.period, steps=64, period_end=loop.period_end),
                 FlowMap(loop.rates, ref.period, steps=64)):
        with pytest.raises(SimulationError, match="non-finite at t = .* s for point 0"):
            flow.end(x)


@pytest.mark.parametrize("kw, match", [(dict(horizon=0), "horizon"), (dict(measured=3), "measured"),
                                       (dict(horizon=10, measured=20), "measured must be at most horizon"),
                                       (dict(measured=4.0), "measured must be an integer")])
def test_paper_rows_names_a_horizon_it_cannot_measure(kw, match):
    with pytest.raises((ValueError, TypeError), match=match):
        compare.paper_rows(BODY, GAINS, trajectories.eight(), [(30, None)], **kw)


def test_law_row_names_a_law_it_does_not_decide():
    with pytest.raises(ValueError, match="law"):
        compare.law_row(BODY, GAINS, trajectories.eight(), "paper", Limits(4.0))


def test_the_weighted_law_under_the_cap_is_periodic_on_two_maps_whose_orbits_agree():
    # the orbit moves by 1.8e-4 from 128 to 256 steps a period and by 9e-5 from 256 to 512
    # (measured): the steps are doubled once and the row says so
    row = compare.law_row(BODY, GAINS, trajectories.eight(2.0, math.pi / 4), "weighted", Limits(4.0))
    assert row["regime"] == "periodic" and row["reason"] == ""
    assert compare.LAW_STEPS["weighted"] <= row["steps_a_period"] <= compare.LAW_MAX_STEPS["weighted"] // 2
    assert row["orbit_shift"] <= ORBIT_SHIFT_TOL and row["floquet"] < 1.0


def _rows():
    rows = []
    for a, c in [(None, 4.0), (30, None)]:
        base = dict(setting=study.setting_label(a, c), angle_deg=a, cap=c)
        for law, err in (("paper", 0.4), ("weighted", np.inf), ("percussion", 1.1), ("optimal", 0.1)):
            rows.append(dict(base, law=law, regime="periodic", max_error=err, rms_error=err / 2, floquet=0.5,
                             floquet_error=0.0123, starts_reached=3, starts=7, paper_start_reached=law == "optimal"))
        if c is not None:
            rows.append(dict(base, law="bound", regime="", max_error=0.05, rms_error=0.02))
    return pd.DataFrame(rows)


def test_the_error_table_has_a_row_a_setting_and_says_where_a_run_diverged_or_no_bound_exists():
    t = compare.error_table(_rows())
    assert list(t.index) == ["4 N", "30 deg"]
    assert list(t.columns) == list(compare.LAW_NAMES.values())
    assert t.loc["4 N", "paper's law"] == "0.4 / 0.2"
    assert t.loc["30 deg", "weighted (Ch. 6)"] == "diverges"
    assert t.loc["30 deg", "bound"] == "-" and t.loc["4 N", "bound"] == "0.05 / 0.02"
    rows = _rows().assign(rms_stderr=np.nan)
    rows.loc[(rows.law == "paper") & (rows.setting == "30 deg"), "rms_stderr"] = 0.0123
    t = compare.error_table(rows)
    assert t.loc["30 deg", "paper's law"] == "0.4 / 0.20 ± 0.02"    # an estimate, its error rounded up
    assert t.loc["4 N", "paper's law"] == "0.4 / 0.2"                # NaN: no error shown
    # the bound is written rounded down, the controller of the best motion found up (a motion that
    # exists), the rest to nearest: 0.107693 -> 0.107 and 0.107761 -> 0.108, where both read 0.108
    rows.loc[rows.law == "bound", "max_error"] = 0.107693
    rows.loc[rows.law.isin(["optimal", "percussion"]), "max_error"] = 0.107761
    t = compare.error_table(rows)
    assert t.loc["4 N", "bound"].startswith("0.107 /")
    assert t.loc["4 N", "best motion + LQR"].startswith("0.108 /")
    assert t.loc["4 N", "law for P (Ch. 7)"].startswith("0.108 /")
    r = compare.regime_table(_rows())
    assert "bound" not in r.columns and (r == "periodic").all().all()


def test_the_tracker_table_reads_the_optimal_rows():
    t = compare.tracker_table(_rows())
    assert len(t) == 2 and list(t["starts reached"]) == ["3 of 7", "3 of 7"]
    assert list(t["paper's start"]) == ["yes", "yes"]
    # a numerical estimate with its stated error (rounded up), as the prose and the report write it
    assert list(t["largest |multiplier|"]) == ["0.500 ± 0.013"] * 2
    rows = _rows().assign(paper_start_reached=False, paper_start_settled=[True] * 8 + [False])
    t = compare.tracker_table(rows)          # not reached: "no" when both maps agree, else undecided
    assert list(t["paper's start"]) == ["no", "undecided"]


def test_setting_labels():
    assert study.setting_label(None, 4.0) == "4 N"
    assert study.setting_label(30, 4.0) == "30 deg + 4 N"
    assert study.setting_label(None, None) == "none"
    assert len(study.SETTINGS) == 9 and study.SETTINGS[0] == (None, study.PAPER_CAP)


@pytest.mark.parametrize("objective", ["max", "rms"])
def test_the_tracker_at_the_cap_holds_the_convex_optimum_within_a_millimetre_of_its_bracket(objective):
    """The periodic LQR about the convex problem's achieved motion (a held world force, the heading
    on its orbit: lib.optimal.held.held_force_motion), started 5 cm and 0.3 rad off it under the
    4 N cap, leaves over its third period a largest (or RMS) distance within 1e-3 m of the bound's
    bracket at 128 nodes: a controller at the physical limit."""
    b = cap_bound(BODY, 2.0, math.pi / 4, 4.0, nodes=128)
    m = held_force_motion(BODY, b, objective)
    T = m.period
    z0, dz0 = m.state(np.array(0.0))
    res = track_motion(BODY, m, 3 * T, limits=Limits(4.0, None), z0=z0 + [0.05, -0.05, 0.3], dz0=dz0,
                       lqr=periodic_lqr(BODY, m, samples=256), t_eval=np.arange(3 * 1024) * (T / 1024))
    last = res.t >= 2 * T - 1e-9
    d = np.hypot(*(res.z[last, :2] - res.z_d[last, :2]).T)
    assert res.F.max() <= 4.0                                   # exact: the loop clips at the cap
    got, lo, hi = ((d.max(), b.max_error, b.max_error_achieved) if objective == "max"
                   else (math.sqrt((d ** 2).mean()), b.rms_error, b.rms_error_achieved))
    # reason: the 1e-3 m (the bracket itself is 1.4e-3 m wide for the largest distance here)
    assert lo - 1e-3 <= got <= hi + 1e-3, (got, lo, hi)
    # and the loop has reached the motion itself: the start's offset, shrunk by two periods of
    # multipliers below 0.01, is gone (measured 2e-7 m from the achieved value)
    assert got == pytest.approx(hi, abs=1e-5)
