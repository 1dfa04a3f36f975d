"""The book's standard errors against series whose error is known exactly, and the ensemble
study that calibrates them (lib.dynamics.statistics, lib.methods.calibration)."""

import math

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from lib.methods import calibration as cal
from lib.dynamics import statistics as st
from lib.params import Body, Gains
from lib.rotation.engine import verdict_steps
from lib.rotation.reduced import _initial, rotation_period_map
from lib.rotation.verdicts import FIG5_GRID, VERDICT_DEFAULTS, eight_rotation_sweep

PHI, N_SERIES, LENGTH = 0.8, 200, 4000


def ar1(phi, n_series, length, seed=0):
    """AR(1) series x_t = phi x_{t-1} + e_t, e standard normal, started in its stationary law."""
    rng = np.random.default_rng(seed)
    e = rng.standard_normal((n_series, length))
    x = np.empty_like(e)
    x[:, 0] = e[:, 0] / math.sqrt(1 - phi ** 2)
    for t in range(1, length):
        x[:, t] = phi * x[:, t - 1] + e[:, t]
    return x


def exact_se(phi, length):
    """The asymptotic standard error of the mean of an AR(1) series: sigma_x sqrt(2 tau_int / n),
    sigma_x^2 = 1 / (1 - phi^2), 2 tau_int = (1 + phi) / (1 - phi)."""
    return math.sqrt((1 + phi) / (1 - phi) / (1 - phi ** 2) / length)


@pytest.fixture(scope="module")
def series():
    return ar1(PHI, N_SERIES, LENGTH)


def test_integrated_time_of_an_ar1_series_is_its_exact_value(series):
    tau = st.integrated_time(series)
    exact = (1 + PHI) / (2 * (1 - PHI))
    # Sokal: var(tau) ~ 2 (2M + 1) / n tau^2 with the window M ~ 5 tau; the window's
    # truncation biases it by about exp(-5) relatively; the mean of N_SERIES estimates
    M = st.SOKAL_WINDOW * exact
    sd = math.sqrt(2 * (2 * M + 1) / LENGTH) / math.sqrt(N_SERIES)
    assert abs(tau.mean() / exact - 1) < math.exp(-st.SOKAL_WINDOW) + 4 * sd + 2 * exact / LENGTH


def test_integrated_time_of_independent_samples_is_one_half():
    x = np.random.default_rng(1).standard_normal((100, 2000))
    tau = st.integrated_time(x)
    assert abs(tau.mean() - 0.5) < 0.05
    assert st.integrated_time(np.ones((2, 10))).tolist() == [0.5, 0.5]      # a constant row


def test_block_statistics_error_matches_the_exact_error_of_an_ar1_mean(series):
    mean, se = st.block_statistics(series, 2)          # a caller asking for blocks of 2 periods
    exact = exact_se(PHI, LENGTH)
    b = st.block_length(series, 2)
    nb = LENGTH // b
    # each error has a relative spread 1 / sqrt(2 (nb - 1)); their mean N_SERIES times less;
    # the blocks of >= BLOCK_TAUS tau_int make it low by at most 1 / (2 BLOCK_TAUS)
    sd = np.mean(1 / np.sqrt(2 * (nb - 1))) / math.sqrt(N_SERIES)
    ratio = se.mean() / exact
    assert 1 - 1 / (2 * st.BLOCK_TAUS) - 4 * sd < ratio < 1 + 4 * sd
    # and the spread of the means themselves agrees with the exact error
    assert abs(mean.std(ddof=1) / exact - 1) < 4 / math.sqrt(2 * (N_SERIES - 1))


def test_blocks_shorter_than_the_memory_would_shrink_the_error(series):
    # the same series in fixed blocks of 2 periods: the error the correlated periods shrink,
    # by sqrt(1 - 2 phi (1 - phi^2) / (2 (1 - phi^2))) = sqrt(1 - phi) for AR(1)
    _, se2 = st.batch_means(series.reshape(N_SERIES, -1, 2).mean(axis=2))
    assert se2.mean() / exact_se(PHI, LENGTH) < 0.6
    assert (st.block_length(series, 2) >= st.BLOCK_TAUS * 4.5 * 0.7).all()


def test_block_length_keeps_the_callers_block_for_a_series_without_memory():
    x = np.random.default_rng(2).standard_normal((50, 120))
    assert (st.block_length(x, 12) == 12).all()
    with pytest.raises(ValueError, match="block"):
        st.block_length(x, 0)
    with pytest.raises(ValueError, match="two blocks"):
        st.block_length(x, 61)


def test_the_ratio_interval_covers_one_as_often_as_its_level():
    rng = np.random.default_rng(3)
    K, trials = 16, 400
    hits = 0
    for _ in range(trials):
        r = cal.ensemble_ratio(rng.normal(0.0, 2.0, K), np.full(K, 2.0))
        hits += r["lo"] <= 1 <= r["hi"]
    assert abs(hits / trials - cal.LEVEL) < 4 * math.sqrt(cal.LEVEL * (1 - cal.LEVEL) / trials)


def test_the_ratio_interval_of_16_starts_is_about_0_7_to_1_5():
    r = cal.ensemble_ratio(np.array([-1.0, 1.0] * 8), np.full(16, 1.0))
    assert r["K"] == 16
    assert 0.68 < r["lo"] / r["ratio"] < 0.76 and 1.45 < r["hi"] / r["ratio"] < 1.6


@pytest.mark.parametrize("estimates, stderrs, level, name", [
    ([1.0, 2.0], [1.0, 1.0], 0.95, "estimates"),
    ([1.0, np.nan, 2.0], [1.0, 1.0, 1.0], 0.95, "estimates"),
    ([1.0, 2.0, 3.0], [1.0, 0.0, 1.0], 0.95, "stderrs"),
    ([1.0, 2.0, 3.0], [1.0, 1.0], 0.95, "stderrs"),
    ([1.0, 2.0, 3.0], [1.0, 1.0, 1.0], 1.5, "level"),
])
def test_ensemble_ratio_refuses_bad_input(estimates, stderrs, level, name):
    with pytest.raises(ValueError, match=name):
        cal.ensemble_ratio(estimates, stderrs, level)


def test_calibration_study_refuses_bad_input_before_any_run():
    with pytest.raises(ValueError, match="limit_starts"):
        cal.calibration_study(Body(), Gains(), limit_starts=2)
    with pytest.raises(ValueError, match="rotation_starts"):
        cal.calibration_study(Body(), Gains(), rotation_starts=0)
    with pytest.raises(ValueError, match="level"):
        cal.calibration_study(Body(), Gains(), level=1.0)
    with pytest.raises(ValueError, match="angle_deg"):
        cal.limit_ensemble(Body(), Gains(), 200.0)
    with pytest.raises(ValueError, match="Theta"):
        cal.rotation_ensemble(Body(), 1.0, -1.0)


def test_starts_moved_by_a_micrometre_are_far_apart_after_the_burn_in():
    # chaos separates them: the smallest distance between two starts' states after the
    # burn-in is many orders above the 1e-6 they started apart
    fr = cal.limit_ensemble(Body(), Gains(), 30.0, 3)
    assert fr.attrs["separation"] > 1e3 * cal.START_SPREAD   # reason: decorrelated by chaos, not a bound
    assert (fr.lyapunov > 3 * fr.lyapunov_stderr).all()
    assert (fr.rms_stderr > 0).all() and (fr.drift_stderr > 0).all()


def test_the_ratio_table_has_a_row_a_setting_and_a_column_an_estimator():
    study = pd.DataFrame([dict(setting="30 deg", estimator="exponent", K=32, ratio=0.97, lo=0.78, hi=1.3),
                          dict(setting="30 deg", estimator="drift", K=32, ratio=0.88, lo=0.7, hi=1.17),
                          dict(setting="R = 1 m", estimator="exponent", K=64, ratio=0.83, lo=0.71, hi=1.01),
                          dict(setting="30 deg", estimator=cal.SHORT_BLOCKS, K=32, ratio=1.0, lo=0.8, hi=1.4)])
    t = cal.ratio_table(study)
    assert list(t.columns) == ["setting", "K starts", "exponent", "drift"]    # the short blocks left out
    assert list(t.setting) == ["30 deg", "R = 1 m"] and list(t["K starts"]) == [32, 64]
    assert t.loc[0, "exponent"] == "0.97 (0.78-1.30)" and t.loc[1, "drift"] == "-"
    with pytest.raises(ValueError, match="study"):
        cal.ratio_table(study.drop(columns="lo"))


def test_heading_variogram_is_the_variance_of_the_section_headings_on_the_period_map():
    # the same starts run by the public period map of (32) (numpy, the same DOP853 steps): the
    # sections agree to the scheme's rounding, so the variances agree far inside 1e-9 turns^2
    # a chaotic point of Fig. 5 after a transient of 2 periods, too short for chaos to amplify rounding
    R, Theta, K, lags = 2.4470, 0.7823, 8, (1, 2)
    got = cal.heading_variogram(Body(), R, Theta, lags, K, seed=3, transient=2)
    rng = np.random.default_rng(3)
    p0, v0 = rng.uniform(-np.pi, np.pi, K), rng.uniform(-0.5, 0.5, K) * Theta
    n = int(verdict_steps(Body(), "eight", [R], [Theta], VERDICT_DEFAULTS["h_verdict"])[0])
    step = rotation_period_map(Body(), "eight", np.full(K, R), np.full(K, Theta), steps=n)
    x = np.column_stack(_initial("eight", np.full(K, Theta), p0, v0))
    for _ in range(2):
        x = step(x)[0]
    sec = []
    for _ in range(2 * max(lags)):
        x = step(x)[0]
        sec.append(x[:, 0])
    sec = np.array(sec) / (2 * np.pi)
    want = [np.var(sec[k:] - sec[:-k]) for k in lags]
    assert got.index.tolist() == list(lags)
    assert min(want) > 1e-4  # reason: the starts spread, so there is a variance to compare
    np.testing.assert_allclose(got.to_numpy(), want, rtol=1e-8, atol=0)  # accuracy: one scheme, two codes; rounding (1e-13 rad) grown over 6 periods against variances above 1e-4 turns^2


@pytest.mark.parametrize("kwargs, name", [(dict(lags=(0, 12)), "lags"), (dict(lags=(1.5,)), "lags"),
                                          (dict(lags=()), "lags"), (dict(starts=2), "starts"),
                                          (dict(R=-1.0), "R"), (dict(Theta=float("nan")), "Theta"),
                                          (dict(transient=-1), "transient")])
def test_heading_variogram_refuses_bad_input(kwargs, name):
    args = dict(R=2.0, Theta=1.0) | kwargs
    with pytest.raises(ValueError, match=name):
        cal.heading_variogram(Body(), **args)


def test_move_counts_expects_the_normal_tail_and_welch_s_t_tail():
    # two pairs beyond 3 combined errors of four; expected counts recomputed from scipy's laws
    lam1, se1, b1 = [0.0, 0.0, 1.0, 5.0], [1.0, 1.0, 0.5, 2.0], [6, 6, 25, 6]
    lam2, se2, b2 = [0.5, 4.5, 1.1, -4.0], [1.0, 1.0, 0.5, 1.0], [6, 6, 25, 12]
    got = cal.move_counts(lam1, se1, b1, lam2, se2, b2)
    v = np.square(se1) + np.square(se2)
    dof = v ** 2 / (np.power(se1, 4) / (np.array(b1) - 1) + np.power(se2, 4) / (np.array(b2) - 1))
    assert dof[0] == 10.0                                                # exact: equal errors, 5 + 5
    assert (got["points"], got["moved"]) == (4, 2)                     # |z| = 0.35, 3.18, 0.14, 4.02
    assert got["normal"] == pytest.approx(4 * 2 * stats.norm.sf(3), rel=1e-12)  # exact: one formula; rounding
    assert got["t"] == pytest.approx(sum(2 * stats.t.sf(3, d) for d in dof), rel=1e-12)  # exact: one formula; rounding
    assert got["t"] > got["normal"]                                    # reason: a t tail is heavier


@pytest.mark.parametrize("bad, name", [(dict(se1=[0.0, 1.0]), "errors"), (dict(blocks2=[1, 6]), "blocks"),
                                       (dict(lam2=[0.0]), "1-D"), (dict(lam1=[np.nan, 0.0]), "finite"),
                                       (dict(sigmas=0.0), "sigmas")])
def test_move_counts_refuses_bad_input(bad, name):
    args = dict(lam1=[0.0, 1.0], se1=[1.0, 1.0], blocks1=[6, 6], lam2=[0.0, 1.0], se2=[1.0, 1.0],
                blocks2=[6, 6]) | bad
    with pytest.raises(ValueError, match=name):
        cal.move_counts(**args)


@pytest.fixture(scope="module")
def chaotic_points():
    n = FIG5_GRID["n"]
    Rg, Tg = np.linspace(*FIG5_GRID["R"], n), np.linspace(*FIG5_GRID["Theta"], n)
    R, Th = zip(*[(Rg[i], Tg[j]) for i, j in cal.FIG5_POINTS[:5]])
    return eight_rotation_sweep(Body(), np.array(R), np.array(Th))


def test_exponents_decided_again_on_the_same_map_do_not_move(chaotic_points):
    assert (chaotic_points.regime == "chaotic").sum() >= 3
    got = cal.exponent_moves(Body(), chaotic_points, steps_factor=1)
    assert got["points"] == got["chaotic"] and got["moved"] == 0 and got["spread"] == 0.0  # exact: the same computation twice


def test_exponents_decided_again_on_a_finer_map_are_counted(chaotic_points):
    got = cal.exponent_moves(Body(), chaotic_points)
    assert got["chaotic"] == (chaotic_points.regime == "chaotic").sum() and 2 <= got["points"] <= got["chaotic"]
    assert 0 <= got["moved"] <= got["points"] and got["spread"] > 0       # reason: another trajectory, another exponent


def test_exponent_moves_refuses_a_frame_without_the_map_s_columns(chaotic_points):
    with pytest.raises(ValueError, match="missing columns"):
        cal.exponent_moves(Body(), chaotic_points.drop(columns=["orbit_p"]))
    with pytest.raises(ValueError, match="steps_factor"):
        cal.exponent_moves(Body(), chaotic_points, steps_factor=0)
