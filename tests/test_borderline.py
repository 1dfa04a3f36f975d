"""The calibration where the verdicts are decided (lib.methods.borderline): the sign test, the t
law of an error read from a few batches, the choice of the borderline points, and the verdicts the
t law would change."""

import math

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from lib.methods import borderline as bl
from lib.methods import calibration as cal
from lib.params import Body
from lib.rotation.verdicts import FIG5_GRID, VERDICT_DEFAULTS


def c4(n):
    """E[s] / sigma for the sample standard deviation of n normal values (closed form)."""
    return math.sqrt(2 / (n - 1)) * math.exp(math.lgamma(n / 2) - math.lgamma((n - 1) / 2))


def iid_batch_runs(runs, batches, seed=0):
    """``runs`` estimates, each the mean of ``batches`` independent standard normal batch means, with
    its batch-means standard error: errors honest by construction."""
    m = np.random.default_rng(seed).standard_normal((runs, batches))
    return m.mean(axis=1), m.std(axis=1, ddof=1) / math.sqrt(batches)


# ---- the sign test


def test_sign_test_counts_the_ratios_above_and_is_the_binomial_tail():
    ratios = [1.02, 1.10, 0.90, 1.05, 1.00, 1.30]       # one tie with 1, left out: 4 above of 5
    got = bl.sign_test(ratios)
    assert (got["above"], got["n"]) == (4, 5)
    # P(X >= 4), X binomial (5, 1/2): (5 + 1) / 32, in closed form and by scipy
    assert got["pvalue"] == pytest.approx(6 / 32, rel=1e-12)  # exact: a binomial tail's closed form
    assert got["pvalue"] == pytest.approx(stats.binomtest(4, 5, 0.5, alternative="greater").pvalue, rel=1e-12)  # exact: scipy's binomtest on the same counts
    two = bl.sign_test(ratios, alternative="two-sided")
    assert two["pvalue"] == pytest.approx(stats.binomtest(4, 5, 0.5).pvalue, rel=1e-12)  # exact: scipy's binomtest on the same counts


def test_nine_ratios_of_nine_above_one_is_a_lean_at_p_one_in_512():
    got = bl.sign_test(np.linspace(1.02, 1.10, 9))
    assert got == dict(above=9, n=9, pvalue=pytest.approx(0.5 ** 9, rel=1e-12))  # exact: 0.5 ** 9 in closed form


def test_sign_test_takes_a_reference_per_ratio():
    ratios = np.array([1.02, 1.10, 1.04, 1.06])
    honest = np.array([1.05, 1.05, 1.05, 1.05])
    got = bl.sign_test(ratios, honest)
    assert (got["above"], got["n"]) == (2, 4)
    assert got["pvalue"] == pytest.approx(11 / 16, rel=1e-12)         # exact: P(X >= 2), X binomial (4, 1/2)


@pytest.mark.parametrize("args, name", [
    (([],), "ratios"), (([1.0, np.nan],), "ratios"), (([1.1, 0.9], [1.0, 1.0, 1.0]), "reference"),
    (([1.1, 0.9], 1.0, "up"), "alternative"), (([1.0, 1.0],), "ratios"),
])
def test_sign_test_refuses_bad_input(args, name):
    with pytest.raises(ValueError, match=name):
        bl.sign_test(*args)


# ---- the t law of an error read from a few batches


@pytest.mark.parametrize("batches", [2, 6, 7, 11, 25, 1000])
def test_the_t_line_has_the_normal_tail_of_three_errors(batches):
    q = bl.t_threshold(batches)
    assert stats.t.sf(q, batches - 1) == pytest.approx(stats.norm.sf(3.0), rel=1e-9)  # accuracy: scipy's t quantile, solved to about 1e-12
    assert q > 3.0


def test_the_t_line_falls_to_three_errors_with_many_batches():
    q = bl.t_threshold(np.array([6, 25, 10 ** 6]))
    assert q[0] == pytest.approx(5.507, abs=1e-3) and q[1] == pytest.approx(3.345, abs=1e-3)  # reason: the quantiles quoted to three decimals
    assert abs(q[2] - 3.0) < 1e-4 and np.all(np.diff(q) < 0)  # accuracy: the t quantile at 10^6 degrees of freedom is the normal's within 1e-5


def test_the_t_line_gives_honest_errors_from_six_batches_the_normal_false_alarms():
    # a known calibrated case: estimates whose true value is 0, errors honest by construction;
    # the 3-error line is crossed as often as the t law says, the t line as often as 3 normal errors
    N, B = 400_000, 6
    est, se = iid_batch_runs(N, B, seed=1)
    z = np.abs(est) / se
    for line, rate in ((3.0, 2 * stats.t.sf(3.0, B - 1)), (bl.t_threshold(B), 2 * stats.norm.sf(3.0))):
        assert abs((z > line).mean() - rate) < 4 * math.sqrt(rate * (1 - rate) / N)
    assert 2 * stats.t.sf(3.0, B - 1) > 10 * 2 * stats.norm.sf(3.0)       # the t tail is the heavier one


def test_honest_errors_from_six_batches_lean_by_one_over_c4():
    # the same calibrated case: the spread over the starts against the mean error leans above 1 by
    # 1 / c4(6) = 1.051, and the ratio ensemble_ratio calls honest is that lean
    K, B = 40_000, 6
    est, se = iid_batch_runs(K, B, seed=2)
    r = cal.ensemble_ratio(est, se)
    assert abs(r["ratio"] - bl.honest_lean(B)) < 4 / math.sqrt(2 * K) / c4(B)     # its spread 1/sqrt(2K)
    assert abs(r["honest"] - 1 / c4(B)) < 4 / math.sqrt(2 * K)
    assert r["lo"] > 1.0                                                   # an honest error, yet clearly above 1


# ---- the map's statistics, the borderline points, the verdicts the t law changes


def frame_of(lost_z, chaotic_z, regime=None, drift_periods=300, periods=120):
    """A Fig. 5 frame whose points have the given statistics (standard errors), no orbit."""
    n = len(lost_z)
    Theta = np.full(n, 1.0)
    T = 2 * np.pi / Theta
    se, lse = np.full(n, 0.01), np.full(n, 0.05)
    band = VERDICT_DEFAULTS["slip_band"]
    return pd.DataFrame(dict(
        R=np.full(n, 2.0), Theta=Theta, regime=regime or ["chaotic"] * n,
        lyapunov=np.asarray(chaotic_z) * lse / T, lyapunov_stderr=lse / T,
        slip=np.asarray(lost_z) * se + band, slip_stderr=se,
        lost=np.asarray(lost_z) > 3, periods=np.broadcast_to(periods, (n,)),
        drift_periods=np.broadcast_to(drift_periods, (n,))))


def test_verdict_statistics_are_the_rule_s_standard_errors_and_batches():
    fr = frame_of([2.5, 3.5], [4.0, 6.0], drift_periods=[300, 1200], periods=[120, 348])
    st = bl.verdict_statistics(fr)
    assert np.allclose(st.lost_z, [2.5, 3.5], rtol=1e-12) and np.allclose(st.chaotic_z, [4.0, 6.0], rtol=1e-12)  # exact: the same arithmetic on the frame's columns
    # 25 blocks of 12 periods: 6 batches of 4 blocks; 100 blocks: 25 batches; 6 blocks: 6; 25: 6
    assert st.lost_batches.tolist() == [6, 25] and st.chaotic_batches.tolist() == [6, 6]


def test_an_orbit_and_an_exponent_inside_the_band_have_no_statistic():
    fr = frame_of([5.0, 5.0], [6.0, 6.0], regime=["slipping", "undecided"])
    fr.loc[1, "lyapunov"] = 0.5 * VERDICT_DEFAULTS["lyapunov_band"] / (2 * np.pi)     # lambda T inside the band
    st = bl.verdict_statistics(fr)
    assert np.isnan(st.lost_z[0]) and np.isnan(st.chaotic_z[0]) and np.isfinite(st.lost_z[1])
    assert np.isnan(st.chaotic_z[1])


def test_the_borderline_points_lie_within_one_error_of_the_line_nearest_first():
    z = [1.5, 2.2, 2.9, 2.95, 3.05, 3.9, 4.5, 3.5, 4.01]
    regime = ["chaotic"] * 7 + ["transient", "chaotic"]          # a transient point is left out
    fr = frame_of(z, z, regime=regime)
    for test in bl.TESTS:
        got = bl.borderline_points(fr, test)
        assert got.tolist() == [2, 3, 4, 5]                       # 3.05, 3.9 above; 2.95, 2.9 below
        assert np.all(np.abs(np.asarray(z)[got] - 3.0) <= bl.WIDTH)
    assert bl.borderline_points(fr, "lost", per_side=3).tolist() == [1, 2, 3, 4, 5]


def test_borderline_points_refuse_bad_input():
    fr = frame_of([3.0], [3.0])
    with pytest.raises(ValueError, match="test"):
        bl.borderline_points(fr, "slipping")
    with pytest.raises(ValueError, match="per_side"):
        bl.borderline_points(fr, "lost", per_side=0)
    with pytest.raises(ValueError, match="missing columns"):
        bl.verdict_statistics(fr.drop(columns=["slip"]))
    with pytest.raises(ValueError, match="batches"):
        bl.t_threshold(1)


def test_the_t_law_withdraws_only_the_verdicts_between_the_two_lines():
    # lost over 1200 periods (25 batches, line 3.345): 3.3 withdrawn, 3.5 kept; chaotic from 6 batches
    # (line 5.51): 5.2 withdrawn, 6.0 kept; a point not lost or not chaotic is never made so
    fr = frame_of([3.3, 3.5, 2.0, 2.0], [5.2, 6.0, 6.0, 2.0], regime=["chaotic"] * 3 + ["undecided"],
                  drift_periods=1200)
    got = bl.verdict_changes(fr)
    assert {k: got[k] for k in ("lost", "lost_drift", "lost_changed", "chaotic", "chaotic_changed",
                                "chaotic_early")} == dict(lost=2, lost_drift=2, lost_changed=1, chaotic=3,
                                                          chaotic_changed=1, chaotic_early=1)
    assert set(got["lines"]) == {6, 25}
    # with the normal line the rule is the map's own: nothing changes
    fr.lost = fr.slip.abs().sub(VERDICT_DEFAULTS["slip_band"]).div(fr.slip_stderr) > 3
    assert bl.verdict_changes(fr, sigmas=40.0)["lost_changed"] == 2


def test_the_borderline_study_runs_each_point_over_the_horizon_its_verdict_rests_on():
    n = FIG5_GRID["n"]
    i, j = cal.FIG5_POINTS[1]
    R, Theta = np.linspace(*FIG5_GRID["R"], n)[i], np.linspace(*FIG5_GRID["Theta"], n)[j]
    fr = frame_of([3.2, 2.8], [9.0, 9.0], drift_periods=[1200, 300])
    fr["R"], fr["Theta"] = R, Theta
    got = bl.borderline_study(Body(), fr, starts=6, per_side=1)
    lost = got[got.test == "lost"]
    assert lost.side.tolist() == ["above"] * 2 + ["below"] * 2
    assert lost.horizon.tolist() == [1200, 1200, 300, 300]
    above = lost[lost.side == "above"]
    assert (above.early == 0).all()                         # the longer run has no early exit, as confirm_lost's
    assert set(got.estimator) == {"exponent", "drift"} and (got.free <= 6).all() and (got.K <= got.free).all()
    assert (got.honest >= 1.0).all()                        # sqrt(mean s^2) >= mean s


def test_the_honest_lean_is_one_over_c4():
    assert bl.honest_lean(6) == pytest.approx(1 / c4(6), rel=1e-12)  # exact: the same closed form (gamma functions)
    assert bl.honest_lean(np.array([25, 10 ** 6])) == pytest.approx([1 / c4(25), 1.0], rel=1e-6)  # accuracy: 1/c4 tends to 1 as 1 + 1/(4B): 2.5e-7 at 10^6 batches
    with pytest.raises(ValueError, match="batches"):
        bl.honest_lean(1)


def test_the_borderline_table_has_a_row_a_point_and_a_column_an_estimator():
    study = pd.DataFrame([dict(test="lost", side="above", setting="P", z=3.4, horizon=1200, free=64, early=0,
                               estimator=e, ratio=r, lo=r - 0.1, hi=r + 0.2)
                          for e, r in (("exponent", 1.0), ("drift", 0.95))])
    got = bl.borderline_table(study)
    assert got.columns.tolist() == ["line, side", "point", "z (errors)", "horizon (periods)", "starts: no orbit, early",
                                    "exponent", "drift"]
    assert got.iloc[0].tolist() == ["lost, above", "P", "3.40", 1200, "64, 0", "1 (0.9-1.2)", "0.95 (0.85-1.15)"]
    with pytest.raises(ValueError, match="missing columns"):
        bl.borderline_table(study.drop(columns=["early"]))
