"""Every public entry that takes R, Theta, gains or a reference refuses, before any computation,
a bad option and a point outside the methods' domain, naming the argument (issue 37): the one
domain check is :func:`lib.machinery.domain.within_budget` (its budgets
:data:`lib.machinery.domain.MAX_RUN_STEPS`, :data:`~lib.machinery.domain.MAX_STEPS`,
:data:`~lib.machinery.domain.MAX_DAMPING_PERIODS`), fed by :func:`lib.machinery.domain.loop_modes`
and :func:`lib.machinery.domain.loop_domain`."""

import time

import numpy as np
import pytest

from lib import stability, trajectories as T
from lib.limits import verdicts as limits
from lib.machinery import checks
from lib.params import Body, Gains
from lib.percussion import sweep as percussion
from lib.rotation import attractor, reduced
from lib.simulate import simulate
from lib.tracking import mismatch, runs as tracking
from lib.weighting import batch as weighting_batch, comparison, verdicts as loop_verdicts
from lib.optimal import bound as optimal_bound, motion as optimal_motion
from lib.optimal.studies import study as optimal_study
from lib.percussion import compare as percussion_compare, zero_dynamics
from lib.percussion.run import simulate as p_simulate
from lib.rotation import circle_global, slow_eight
from lib.rotation.engine import check_domain

B, G = Body(), Gains()
R0, TH0 = 2.0, 0.5                      # a point inside every domain
#: a refusal is a check, not a run: far below any run's time (the first call of a module may import it)
FAST = 1.0                              # reason: a generous bound on a refusal (measured < 0.3 s)

#: (id, call(R, Theta, **options), one bad option) for every public entry over R and Theta
ENTRIES = [
    ("eight_rotation_sweep", lambda R, Th, **o: stability.eight_rotation_sweep(B, [R], [Th], **o), {"transient": 0}),
    ("rotation_verdicts", lambda R, Th, **o: stability.rotation_verdicts(B, "circle", [R], [Th], **o),
     {"engine": "fortran"}),
    ("rotation_attractor", lambda R, Th, **o: attractor.rotation_attractor(B, "eight", R, Th, **o), {"h_lambda": 0.0}),
    ("reduced.rotation_sweep", lambda R, Th, **o: reduced.rotation_sweep(B, "eight", [R], [Th], **o), {"tol": -1.0}),
    ("percussion.heading_sweep", lambda R, Th, **o: percussion.heading_sweep(B, [R], [Th], **o), {"steps": 1}),
    ("percussion_fig5_map", lambda R, Th, **o: percussion.percussion_fig5_map(B, (R, R), (Th, Th), **dict(dict(n=2), **o)),
     {"n": 1}),
    ("closed_loop_verdicts", lambda R, Th, **o: loop_verdicts.closed_loop_verdicts(B, G, "eight", [R], [Th], **o),
     {"reach_tol": -1.0}),
    ("closed_loop_batch", lambda R, Th, **o: weighting_batch.closed_loop_batch(B, G, "eight", [R], [Th],
                                                                              **dict(dict(t_end=1.0), **o)),
     {"dt": 0.0}),
    ("verdict_runs", lambda R, Th, **o: comparison.verdict_runs(B, G, {"a": dict(kind="eight", R=R, Theta=Th)}, **o),
     {"bogus": 1}),
    ("mismatch_sweep", lambda R, Th, **o: mismatch.mismatch_sweep(B, G, "eight", R, Th, {"m": 0.1}, **o),
     {"steps": 1}),
    ("tracking.run", lambda R, Th, **o: tracking.run(B, G, "eight", R, Th, 1.0, **o), {"samples_per_period": 0}),
    ("eight_sensitivity", lambda R, Th, **o: tracking.eight_sensitivity(B, G, [R], [Th], **o), {"n_periods": -1.0}),
    ("simulate", lambda R, Th, **o: simulate(B, G, T.eight(R, Th), 8.0, **o), {"t_eval": [2.0, 1.0]}),
    ("percussion.simulate", lambda R, Th, **o: p_simulate(B, G, T.eight(R, Th), 8.0, **o), {"thrust0": "x"}),
    ("limit_verdicts", lambda R, Th, **o: limits.limit_verdicts(B, G, T.eight(R, Th), [0.5], **o),
     {"locator": "guess"}),
    ("switched_runs", lambda R, Th, **o: limits.switched_runs(B, G, T.eight(R, Th), 0.5, **dict(dict(n_periods=1), **o)),
     {"steps_per_period": 1}),
    ("section_sweep", lambda R, Th, **o: limits.section_sweep(B, G, T.eight(R, Th), [0.5], **o), {"n_points": 0}),
    ("sweep_angle_limit", lambda R, Th, **o: limits.sweep_angle_limit(B, G, T.eight(R, Th), [0.5], **o),
     {"tol": -1.0}),
    ("force_cap_sweep", lambda R, Th, **o: tracking.force_cap_sweep(B, G, T.eight(R, Th), [4.0], **o),
     {"n_steady": 0}),
    ("mismatch_study", lambda R, Th, **o: mismatch.mismatch_study(B, G, R, Th, **o), {"levels": ()}),
    ("compare_on_map", lambda R, Th, **o: comparison.compare_on_map(B, G, [R], [Th], **dict(dict(w_phi=0.5), **o)),
     {"w_phi": -1.0}),
    ("percussion_steady", lambda R, Th, **o: percussion_compare.percussion_steady(B, "eight", R, Th, **o),
     {"steps": 1}),
    ("paper_steady", lambda R, Th, **o: percussion_compare.paper_steady(B, "eight", R, Th, **o), {"transient": 0}),
    ("zero_dynamics_run", lambda R, Th, **o: zero_dynamics.zero_dynamics_run(B, T.eight(R, Th), [0.0, 10.0], 0.0, **o),
     {"rtol": -1.0}),
    ("circle_final_state", lambda R, Th, **o: circle_global.circle_final_state(B, R, Th, **o), {"t_max": -1.0}),
    ("circle_slipping_coexists", lambda R, Th, **o: circle_global.circle_slipping_coexists(B, R, Th, **o),
     {"t_end": 0.0}),
    ("homoclinic_miss", lambda R, Th, **o: circle_global.homoclinic_miss(B, R, Th, **o), {"rtol": 0.0}),
    ("slow_eight_prediction", lambda R, Th, **o: slow_eight.slow_eight_prediction(B, R, Th, **o), {"n_phase": 8}),
    ("cap_bound", lambda R, Th, **o: optimal_bound.cap_bound(B, R, Th, 4.0, **o), {"nodes": 8}),
    ("cap_sweep", lambda R, Th, **o: optimal_study.cap_sweep(B, R, Th, [4.0], **o), {"kind": "square"}),
    ("periodic_motion", lambda R, Th, **o: optimal_motion.periodic_motion(B, R, Th, **o), {"nodes": 4}),
]
IDS = [e[0] for e in ENTRIES]


def _refused(call, name):
    t = time.perf_counter()
    with pytest.raises((TypeError, ValueError), match=name) as info:
        call()
    took = time.perf_counter() - t
    assert took < FAST, (took, str(info.value))                     # reason: a refusal, not a run
    return str(info.value)


@pytest.mark.parametrize("call, bad", [e[1:] for e in ENTRIES], ids=IDS)
def test_a_bad_option_is_refused_at_once_naming_it(call, bad):
    name = next(iter(bad))
    _refused(lambda: call(R0, TH0, **bad), rf"\b{name}\b")


@pytest.mark.parametrize("call, bad", [e[1:] for e in ENTRIES], ids=IDS)
def test_a_radius_far_beyond_the_bodys_scale_is_refused_at_once_naming_R(call, bad):
    _refused(lambda: call(1e9, TH0), r"\bR\b")


@pytest.mark.parametrize("call, bad", [e[1:] for e in ENTRIES], ids=IDS)
def test_a_rate_far_beyond_the_bodys_is_refused_at_once_naming_Theta(call, bad):
    _refused(lambda: call(R0, 1e9), r"\bTheta\b|\btheta\b")


@pytest.mark.parametrize("call, name", [
    (lambda: percussion.heading_sweep(B, [1e9], [0.5]), r"^R = 1e\+09 m"),
    (lambda: percussion.heading_sweep(B, [1.0], [1e9]), r"^Theta = 1e\+09 rad/s"),
    (lambda: loop_verdicts.closed_loop_verdicts(B, G, "eight", [1.0], [1e9]), r"^Theta = 1e\+09 rad/s"),
    (lambda: simulate(Body(), Gains(kp=1e6), T.circle(), 8), r"^body and gains: .*oscillates.*t_end <= 5\.65 s$"),
    (lambda: simulate(Body(), Gains(), T.circle(R=1e9), 8), r"^ref \(R = 1e\+09 m"),
    (lambda: p_simulate(Body(), Gains(kp=1e6), T.circle(), 8), r"^gains and pole: .*oscillates.*t_end <= 5\.65 s$"),
    (lambda: p_simulate(Body(), Gains(), T.circle(R=1e9), 8), r"^ref \(R = 1e\+09 m"),
], ids=["P sweep R", "P sweep Theta", "loop verdicts Theta", "simulate kp", "simulate R", "P simulate kp",
        "P simulate R"])
def test_the_runs_issue_37_found_silent_are_refused_at_once(call, name):
    # each ran for minutes or returned nonsense (quasiperiodic, undecided and tracked, blew up at t = 0.053 s)
    _refused(call, name)


def test_the_budget_names_the_argument_that_costs_most_at_the_first_point_over_it():
    need = {"R": np.array([1.0, 5.0, 9.0]), "Theta": np.array([2.0, 7.0, 1.0])}
    with pytest.raises(ValueError, match=r"^Theta\[1\] = 0\.7 rad/s: costs about 7 units, beyond the budget of 4$"):
        checks.within_budget(need, 4.0, what="costs", unit="units", values={"Theta": ([0.1, 0.7, 0.2], "rad/s")})
    checks.within_budget(need, 9.0, what="costs")                     # at the budget is inside
    with pytest.raises(ValueError, match=r"^gains: "):
        checks.within_budget({"gains": np.nan}, 9.0, what="costs")     # a NaN cost is never inside


def test_the_book_s_own_runs_are_inside_the_budget():
    # the paper's circle and eight over 40 periods, and Fig. 5's corners under both laws and both paths
    for ref in (T.circle(), T.eight()):
        speed, accel = checks.path_extremes(ref)
        modes = checks.loop_modes(B, G, speed=speed, accel=accel, heading_gains=False)
        assert max(checks.run_steps(m, 40 * ref.period) for m in modes.values()) < checks.MAX_RUN_STEPS / 2  # reason: a margin
    for R, Th in ((0.25, 0.05), (4.0, 0.05), (0.25, 1.5), (4.0, 1.5)):
        for kind in ("eight", "circle"):
            check_domain(B, kind, np.array([R]), np.array([Th]))
            percussion._check_domain(B, kind, np.array([R]), np.array([Th]), percussion.SWEEP_DEFAULTS["steps"])
            checks.loop_domain(B, G, T.KINEMATICS[kind], [R], [Th])
