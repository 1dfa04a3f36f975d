import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st_

from flows import damped_oscillator_flow, driven_pendulum_flow
from lib.dynamics import verdicts as dv
from lib.limits import verdicts as L
from lib import trajectories as T
from lib.params import Body, Gains
from lib.allocation import Limits
from lib.closed_loop import ClosedLoop, reference_of
from lib.integrators import switched_compiled
from lib.control import computed_torque, computed_torque_rate
from lib.model import config_accel
from lib.simulate import Integration, simulate

S0 = np.array([1.0, 0.0, math.pi / 2, 0.0, 0.0, 0.0])


def test_lyapunov_estimate_is_negative_for_damped_linear_system():
    est = L.largest_lyapunov(damped_oscillator_flow(zeta=0.1), np.array([1.0, 0.0]), 1.0, 60)
    assert est.value < 0
    assert abs(est.value - (-0.1)) < 1.5e-6  # measured 1.5e-7


def test_lyapunov_estimate_is_positive_for_baker_gollub_chaotic_pendulum(perturb):
    # a positive exponent by a margin: the verdict threshold is 3 standard errors and the
    # test asks for 6 (measured 8-10 over 200 periods, nominal and perturbed)
    flow = driven_pendulum_flow(q=2.0, g=1.5, omega_d=2 / 3, rtol=1e-9, atol=1e-9)
    est = L.largest_lyapunov(flow, perturb([0.2, 0.0]), 3 * math.pi, 200, n_transient=10)
    assert est.value > 6 * est.stderr and est.value > 0.05, (est.value, est.stderr)


def test_lyapunov_estimate_is_negative_for_periodic_pendulum(perturb):
    # Baker & Gollub's g = 0.9 (q = 2) is a stable periodic motion: measured -0.24 +- 0.025 1/s
    flow = driven_pendulum_flow(q=2.0, g=0.9, omega_d=2 / 3, rtol=1e-9, atol=1e-9)
    est = L.largest_lyapunov(flow, perturb([0.2, 0.0]), 3 * math.pi, 30, n_transient=10)
    assert est.value < -3 * est.stderr, (est.value, est.stderr)


def test_poincare_section_of_periodic_case_has_one_point(perturb):
    # the circle under a loose angle limit settles on the stable rotation equilibrium;
    # measured spread of the section 6e-12 and position errors 6e-14: margins of 1e5 and more
    loop = L.SwitchedLoop(Body(), Gains(), T.circle(), np.deg2rad(150))
    sec = L.stroboscopic_section(loop, perturb(S0), 15, 5, rtol=1e-10, atol=1e-10)
    assert L.distinct_points(sec, 1e-6) == 1
    # accuracy: 10 x the integration's atol 1e-10 (measured 6.4e-14)
    assert np.abs(sec[:, :4]).max() < 1e-9


def test_distinct_points_counts_a_period_two_orbit():
    pts = np.array([[0.0, 1.0], [1.0, 0.0]] * 5) + 1e-9
    assert L.distinct_points(pts, 1e-6) == 2
    assert L.section_period(pts, 1e-6) == (2, False)


def test_section_period_does_not_call_a_period_two_orbit_a_converging_period_one():
    # a period-2 orbit approached from one side: the lag-1 distances shrink strictly,
    # but towards the orbit's spread 7.35, not towards zero (the 60-degree case of Chapter 4)
    k = np.arange(16)
    pts = np.column_stack([np.where(k % 2, 7.35, 0.0) + 1e-3 * 0.5**k * np.where(k % 2, 1, -1), np.zeros(16)])
    assert L.section_period(pts, 1e-4) == (2, False)


def test_section_period_sees_slow_convergence_and_not_a_rotation():
    conv = np.array([[0.5 + 0.9**k, 1.0] for k in range(20)])
    assert L.section_period(conv, 1e-8) == (1, True)
    k = np.arange(40)
    rot = np.column_stack([np.cos(k * np.sqrt(2)), np.sin(k * np.sqrt(2))])  # quasi-periodic section
    assert L.section_period(rot, 1e-6) == (0, False)


@pytest.mark.parametrize("switching", ["stepsize", "events"])
def test_beta_never_exceeds_angle_limit(switching):
    bmax = np.deg2rad(30)
    res = simulate(Body(), Gains(), T.eight(), 24.0, limits=Limits(angle=bmax),
                   integration=Integration(rtol=1e-8, atol=1e-8, switching=switching))
    assert np.all(np.abs(res.beta) <= bmax + 1e-15)  # exact: a clip; measured 0 over the limit


@pytest.mark.parametrize("deg,t_end,slides", [(30, 16.0, False), (45, 20.0, True)])
def test_event_located_run_converges_as_tolerance_tightens(deg, t_end, slides):
    # after crossings (and a slide at 45 deg) the error against a 1e-13 run stays within
    # 1000 x tol and falls with tol. Measured: 30 deg 27, 37, 64 x tol; 45 deg 120, 130,
    # 33 x tol, so the bound has a margin of 8x or more; successive errors differ by 7x or more.
    loop = L.SwitchedLoop(Body(), Gains(), T.eight(), np.deg2rad(deg))
    ref = loop.integrate(S0, 0.0, t_end, rtol=1e-13, atol=1e-13)
    assert ref.n_crossings > 0 and (ref.n_slides > 0) == slides
    tols = (1e-8, 1e-9, 1e-10)
    errs = []
    for tol in tols:
        run = loop.integrate(S0, 0.0, t_end, rtol=tol, atol=tol)
        assert (run.n_crossings, run.n_slides) == (ref.n_crossings, ref.n_slides)
        errs.append(np.abs(L.state_difference(run.y_end, ref.y_end)).max())
    assert all(e <= 1000 * tol for e, tol in zip(errs, tols)), errs
    assert errs[0] > errs[1] > errs[2], errs


def test_kinks_of_the_clipped_field_are_located(perturb):
    # the clip edges |psi| = beta_max are restart points: just after each, the field's
    # side of the kink is the one the state is on, so no step straddles a kink
    loop = L.SwitchedLoop(Body(), Gains(), T.eight(), np.deg2rad(30), force_limit=4.0)
    seen = []
    orig = loop._segment

    def spy(mode, t0, s0, just_crossed, *rest):
        seen.append(just_crossed)
        return orig(mode, t0, s0, just_crossed, *rest)

    loop._segment = spy
    loop.integrate(perturb(S0), 0.0, 16.0, rtol=1e-9, atol=1e-9)
    kinds = {jc[0] for jc in seen if jc is not None}
    assert kinds == {0, 1, 2}  # both clip edges and the force cap were crossed and located


def test_event_located_and_stepsize_runs_agree_at_tight_tolerance(perturb):
    # no sliding in these 12 s; measured agreement 4e-10..1e-8 m: a margin of 1000 on 1e-5
    ref, bmax = T.eight(), np.deg2rad(60)
    s0 = perturb(S0)
    a = simulate(Body(), Gains(), ref, 12.0, s0[:3], s0[3:], limits=Limits(angle=bmax),
                 integration=Integration(rtol=1e-11, atol=1e-11, switching="events"))
    b = simulate(Body(), Gains(), ref, 12.0, s0[:3], s0[3:], limits=Limits(angle=bmax),
                 integration=Integration(rtol=1e-11, atol=1e-11, switching="stepsize"))
    assert np.all(a.mode != 0)
    assert np.abs(a.z - b.z).max() < 3e-8  # measured 2.9e-9


def test_sliding_motion_stays_on_switching_surface(perturb):
    # the 45-degree transient slides once in its first 20 s (a converged, non-chaotic stretch:
    # see the convergence test); measured |lat| 4e-11 N on the surface, one-sided rates -4.1 and
    # +0.23 N/s
    loop = L.SwitchedLoop(Body(), Gains(), T.eight(), np.deg2rad(45))
    seg = loop.integrate(perturb(S0), 0.0, 20.0, t_eval=np.linspace(0, 20, 4001), rtol=1e-10, atol=1e-10)
    assert seg.n_slides == 1
    sl = seg.mode == 0
    assert sl.any()
    lat = np.array([loop.lateral(t, y) for t, y in zip(seg.t[sl], seg.y[sl])])
    assert np.abs(lat).max() < 4e-10  # measured 4.0e-11 N
    # while sliding both one-sided fields push towards the surface
    rates = np.array([loop.one_sided_rates(t, y) for t, y in zip(seg.t[sl], seg.y[sl])])
    assert np.all(rates[:, 0] <= 1e-6) and np.all(rates[:, 1] >= -1e-6)  # reason: signs of the one-sided rates (measured -4.1 and +0.23 N/s)


def test_classify_reads_sections_and_exponents():
    assert L.classify(1, -0.1, 0.01) == "periodic-1"
    assert L.classify(2, -0.1, 0.01) == "periodic-2"
    assert L.classify(0, 0.3, 0.05) == "chaotic"
    assert L.classify(0, 0.002, 0.002) == "quasi-periodic"
    assert L.classify(0, 0.1, 0.06) == "undecided"


@pytest.mark.parametrize("kw,msg", [
    ({"angle_limit": 0.0}, "angle_limit"), ({"angle_limit": math.pi}, "angle_limit"),
    ({"angle_limit": 0.5, "force_limit": -1.0}, "force_limit"),
])
def test_switched_loop_rejects_bad_limits(kw, msg):
    with pytest.raises(ValueError, match=msg):
        L.SwitchedLoop(Body(), Gains(), T.eight(), **kw)


def test_simulate_events_needs_an_angle_limit():
    with pytest.raises(ValueError, match="angle_limit below pi"):
        simulate(Body(), Gains(), T.eight(), 1.0, integration=Integration(switching="events"))
    with pytest.raises(ValueError, match="switching"):
        simulate(Body(), Gains(), T.eight(), 1.0, integration=Integration(switching="magic"))


def test_angle_limit_60_degrees_gives_a_stable_period_two_motion(perturb):
    # the period-2 example of Chapter 4: two section points and a negative exponent.
    # Measured: lag-2 section defect 2e-7 against the tolerance 1e-4, lag-1 distance 7.35;
    # exponent -0.111 +- 0.024 1/s (4.7 standard errors below zero)
    s0 = perturb(S0)
    (reg,) = L.sweep_angle_limit(Body(), Gains(), T.eight(), [np.deg2rad(60)], n_transient=15, n_points=10,
                                 n_lyap=6, rtol=1e-9, atol=1e-9, z0=s0[:3], dz0=s0[3:])
    assert reg.period == 2 and not reg.converging
    assert np.abs(reg.section[2:] - reg.section[:-2]).max() < 1e-6  # measured 2.0e-7
    assert reg.lyapunov < -3 * reg.lyapunov_stderr and reg.verdict == "periodic-2"


def test_chapter4_verdicts_hold_with_their_margins(perturb):
    # The verdicts Chapter 4 asserts, from the nominal and a perturbed start, with the same
    # margins: chaos at 30 and 45 deg without a cap by 6 standard errors (measured 15-19);
    # period 2 at 60 deg and period 1 at 90 deg, and period 1 at 30-90 deg with the 4 N cap,
    # with multipliers below 0.9 (measured at most 0.65); the quasi-periodic motion at 37 deg
    # with a 6 N cap over the longer horizon, every criterion met by a factor 1.3 or more
    # (measured |lambda T| 0.002, 3 SE T 0.0044, returns 0.0015 against 0.01, 0.01, 0.05)
    ref = T.eight()
    s0 = perturb(S0)
    deg = np.radians([30, 45, 60, 90])
    free, _ = L.limit_verdicts(Body(), Gains(), ref, deg, s0=s0)
    capped, _ = L.limit_verdicts(Body(), Gains(), ref, deg, 4.0, s0=s0)
    for r in free.itertuples():
        if r.angle_deg < 50:
            assert r.regime == "chaotic" and r.lyapunov > 6 * r.lyapunov_stderr
    assert list(free.period[2:]) == [2, 1] and (free.regime[2:] == "periodic").all() and free.floquet[2:].max() < 0.9
    assert (capped.regime == "periodic").all() and (capped.period == 1).all() and capped.floquet.max() < 0.9
    qp = L.extend_undecided(Body(), Gains(), ref, L.limit_verdicts(Body(), Gains(), ref, np.radians([37]), 6.0,
                                                                   s0=s0)[0], s0=s0).iloc[0]
    assert qp.regime == "quasiperiodic" and qp.horizon > L.LIMIT_DEFAULTS["periods"]
    assert abs(qp.lyapunov) * ref.period < 0.0075 and 3 * qp.lyapunov_stderr * ref.period < 0.0075
    assert qp.returns < 0.01 and qp.floquet > 1.1      # a repelling orbit inside the torus (measured 1.21)


def test_section_margin_measures_distance_from_the_tolerance():
    two = np.array([[0.0], [1.0]] * 6) + 1e-9
    assert L.section_margin(two, 1e-4) > 1e4                  # reason: a property (measured 1e296, an exact repeat); repeats every 2 to 1e-9 or better
    k = np.arange(40)
    rot = np.column_stack([np.cos(k * np.sqrt(2)), np.sin(k * np.sqrt(2))])
    assert 1.0 < L.section_margin(rot, 1e-4) < np.inf          # no period: distance at the nearest lag
    conv = np.array([[0.5 + 0.9**j, 1.0] for j in range(20)])
    assert np.isnan(L.section_margin(conv, 1e-8))             # converging: decided by extrapolation


@settings(max_examples=40, deadline=None)
@given(t=st_.floats(0.0, 50.0), s=st_.lists(st_.floats(-5.0, 5.0), min_size=6, max_size=6),
       kind=st_.sampled_from(["circle", "eight"]), F=st_.floats(0.0, 10.0), beta=st_.floats(-3.0, 3.0))
def test_switched_loop_scalar_fast_path_is_eqs_23_and_2_4(t, s, kind, F, beta):
    # SwitchedLoop keeps a scalar fast path of (23), its rate, (2)-(4) and the allocation for
    # speed; it must be the library's single definitions at every state
    ref = T.make(kind, 1.7, 0.6)
    loop = L.SwitchedLoop(Body(), Gains(), ref, 0.5)
    s = np.array(s)
    tx, ty, _ = loop._tau(t, s)
    tau = computed_torque(Body(), Gains(), ref, t, s[:3], s[3:])
    np.testing.assert_allclose([tx, ty], tau[:2], rtol=1e-15, atol=1e-15)  # exact: one definition, two code paths; measured 0
    np.testing.assert_allclose(loop._accel(s, F, beta), config_accel(Body(), s[:3], s[3:], F, beta),
                               rtol=5e-15, atol=5e-15)  # exact: one closed form, two code paths; measured 7.6e-16 (1 + |accel|) over 7000 draws
    kin = T.position_kinematics(ref)(t)
    np.testing.assert_allclose(kin[:6], np.r_[ref.z(t)[:2], ref.dz(t)[:2], ref.ddz(t)[:2]], rtol=1e-15, atol=1e-15)  # exact: one closed form, two code paths; measured 0
    h = 1e-4
    jerk = (ref.ddz(t + h) - ref.ddz(t - h)) / (2 * h)
    np.testing.assert_allclose(kin[6:], jerk[:2], rtol=1.5e-8, atol=1.5e-8)  # measured 3.5e-9: O(h^2) difference
    # the rate of the switching function from the rate of (23)
    ax, ay, _ = loop._accel(s, F, beta)
    dtau = computed_torque_rate(Body(), Gains(), ref.dz(t), ref.ddz(t), np.r_[kin[6:], 0.0], s[3:], [ax, ay, 0.0])
    c, sn = np.cos(s[2]), np.sin(s[2])
    lat_rate = dtau[1] * c - dtau[0] * sn - s[5] * (tau[0] * c + tau[1] * sn)
    rate = loop._lat_rate(t, s, ax, ay, tx, ty, loop._tau(t, s)[2])
    np.testing.assert_allclose(rate, lat_rate, rtol=1e-15, atol=1e-15 * (1 + np.abs(dtau[:2]).max()))  # measured 0
    # off the switching surface, the side field is the closed loop with the angle clipped
    lat = ty * c - tx * sn
    if abs(lat) > 1e-9:
        loop_ref = ClosedLoop.of(Body(), Gains(), reference_of(ref), limits=Limits(angle=0.5))
        np.testing.assert_allclose(loop.rhs(t, s, 1 if lat > 0 else -1), loop_ref.rates(t, s)[0],
                                   rtol=1.2e-12, atol=1.2e-12)  # measured 1.2e-13 (1 + |rates|) over 4000 draws


# ---------------------------------------------------------------- the compiled switched integrator


@pytest.mark.parametrize("deg, cap", [(45, None), (20, None), (30, 4.0), (60, 3.0)])
def test_compiled_switched_runs_match_the_event_located_reference(deg, cap):
    # three periods (two at 20 deg, where the chaotic motion stretches errors by e^(0.3 t))
    # through crossings, a slide (45 deg), the cap's kinks (30 deg / 4 N): the compiled
    # fixed-step integrator against SwitchedLoop at rtol = atol = 1e-11. Measured
    # differences 8e-12 to 5e-8, and 7e-8 at 20 deg (tests/test_integrator_bounds.py bounds
    # them closer)
    ref = T.eight()
    b = np.radians(deg)
    n = 2 if deg == 20 else 3
    runs = L.switched_runs(Body(), Gains(), ref, b, cap, n_periods=n, steps_per_period=400)
    seg = L.SwitchedLoop(Body(), Gains(), ref, b, cap).integrate(S0, 0.0, n * ref.period, rtol=1e-11, atol=1e-11)
    assert np.abs(runs.states[0, -1] - seg.y_end).max() < 7e-7  # measured 7.1e-8 (20 deg, chaotic stretch)
    assert (runs.crossings[0], runs.slides[0]) == (seg.n_crossings, seg.n_slides)
    assert abs(runs.t_sliding[0] - seg.t_sliding) < 2.5e-8  # measured 2.6e-9


def test_a_read_only_start_compiles_no_second_kernel():
    """One start for one run is broadcast to (1, 6) (as limit_verdicts' chunks of one run are), a
    read-only array, which numba types apart from a writable one and would compile into a second
    kernel of the same arithmetic (seconds on a fresh clone). The run reaches the kernel
    writable: the kernel keeps its one signature."""
    ref, b = T.eight(), math.radians(30.0)
    two = L.switched_runs(Body(), Gains(), ref, [b, b], s0=np.tile(S0, (2, 1)), n_periods=1)  # writable
    compiled = len(switched_compiled._run.signatures)
    one = L.switched_runs(Body(), Gains(), ref, b, s0=S0, n_periods=1)
    assert len(switched_compiled._run.signatures) == compiled
    assert np.array_equal(one.states[0], two.states[0])  # exact: each run is computed alone


_SWITCHED_RUNS = """
import numpy as np
from lib.limits import runs
from lib import trajectories
from lib.params import Body, Gains
b = np.radians([30.0, 60.0])
for locator in ("dense", "bracket"):
    runs.switched_runs(Body(), Gains(), trajectories.eight(), b, [np.inf, 4.0], n_periods=3, lyapunov_from=1,
                       locator=locator, record=(1, 4))
runs.switched_runs(Body(), Gains(), trajectories.eight(), b[0], s0=runs._start_states(None, 1)[0], n_periods=2)
"""


def test_the_switched_kernels_compile_once_each_on_a_fresh_clone(fresh_signatures):
    """On an empty numba cache (a fresh clone), every compiled function of the switched integrator
    is compiled for one signature: no constant passed between them as a literal and no read-only
    start makes numba compile a second copy of the same arithmetic (switched_compiled: _LITERALS)."""
    counts = fresh_signatures(_SWITCHED_RUNS, ("lib.integrators.switched_compiled", "lib.integrators.switched_events",
                                               "lib.integrators.switched_field"))
    assert counts["lib.integrators.switched_compiled _run"] == 1
    assert {k: n for k, n in counts.items() if n > 1} == {}


def test_compiled_switched_runs_are_fourth_order_or_better_in_the_step():
    # halving the step on a run with crossings and a slide (45 deg): the error against a
    # run with 4x the steps falls by at least 2^4 (an 8th-order method that loses order at
    # every event would not); measured ratio 128
    ref = T.eight()
    end = [L.switched_runs(Body(), Gains(), ref, np.radians(45), n_periods=2, steps_per_period=n).states[0, -1]
           for n in (100, 200, 800)]
    e1, e2 = np.abs(end[0] - end[2]).max(), np.abs(end[1] - end[2]).max()
    assert e2 < e1 / 16, (e1, e2)


def test_limit_verdicts_at_30_and_45_degrees_hold_from_a_perturbed_start(perturb):
    # Without a cap both angles are chaotic (compiled: 0.27 and 0.22 1/s, 15-17 SE above zero);
    # with the 4 N cap both are period 1 and attract (|mu| 0.45, 0.39), and the slow path
    # (SwitchedLoop, adaptive with event location) returns to the located orbit point after
    # one period to 1.5e-7.
    ref = T.eight()
    s0 = perturb(S0)
    free, _ = L.limit_verdicts(Body(), Gains(), ref, np.radians([30, 45]), s0=s0)
    capped, _ = L.limit_verdicts(Body(), Gains(), ref, np.radians([30, 45]), 4.0, s0=s0)
    for row in free.itertuples():
        assert row.regime == "chaotic" and row.lyapunov > 6 * row.lyapunov_stderr
    for deg, row in zip((30, 45), capped.itertuples()):
        assert row.regime == "periodic" and row.period == 1 and row.floquet < 0.8
        x = row.orbit
        back = L.SwitchedLoop(Body(), Gains(), ref, np.radians(deg), 4.0).flow(x, 0.0, ref.period,
                                                                                rtol=1e-11, atol=1e-11)[0]
        assert np.abs(back - x).max() < 1.5e-7  # measured 1.4e-8


def test_chaotic_exponent_at_30_degrees_agrees_with_a_long_independent_run():
    # The compiled exponent against the slow path: SwitchedLoop (adaptive DOP853 with event
    # location, rtol 1e-9) and the generic Benettin estimator over 24 periods after 16, at the
    # angle limit of 30 deg. The slow run's exponent is positive (measured 9.0 of its SE: positive
    # with room on any machine) and within 4 joint SE of the compiled one (measured 0.9). (The
    # verdicts' robustness to the start is the test above. At 45 deg the exponent is only 2.9 SE
    # over such a run, too close to zero for a sign test on any machine; the flow and the
    # estimator compared are the same, and Chapter 4 checks that exponent's convergence.)
    ref = T.eight()
    free, _ = L.limit_verdicts(Body(), Gains(), ref, np.radians([30]), s0=S0)
    row = free.iloc[0]
    loop = L.SwitchedLoop(Body(), Gains(), ref, np.radians(30))
    slow = L.largest_lyapunov(lambda x, t0, t1, m=None: loop.flow(x, t0, t1, m, rtol=1e-9, atol=1e-9),
                              (S0, None), ref.period, 24, d0=1e-7, n_transient=16,
                              difference=L.state_difference)
    v, se = slow.value, slow.stderr
    assert v > 3 * se  # reason: a property, margin above (measured 9.0 SE)
    assert abs(v - row.lyapunov) < 4 * math.hypot(se, row.lyapunov_stderr), (v, se, row.lyapunov)


def test_limit_verdicts_find_the_period_two_motion_at_60_degrees(perturb):
    # period 2 with multipliers well inside the unit circle (measured 0.108); the exponent
    # agrees with the multiplier, lambda = ln|mu| / (2T) (measured -0.137 against -0.139)
    ref = T.eight()
    df, _ = L.limit_verdicts(Body(), Gains(), ref, np.radians(60), s0=perturb(S0))
    row = df.iloc[0]
    assert row.regime == "periodic" and row.period == 2 and row.floquet < 0.3
    assert abs(row.lyapunov - math.log(row.floquet) / (2 * ref.period)) < 0.015  # measured 1.4e-3


def test_switched_runs_reject_bad_input():
    ref = T.eight()
    with pytest.raises(ValueError, match=r"angle_limits\[1\] must be in"):
        L.switched_runs(Body(), Gains(), ref, [0.5, 4.0], n_periods=1)
    with pytest.raises(ValueError, match="force limit"):
        L.switched_runs(Body(), Gains(), ref, 0.5, -1.0, n_periods=1)
    with pytest.raises(ValueError, match=r"s0\[1\] must be finite"):
        L.switched_runs(Body(), Gains(), ref, 0.5, s0=[1.0, np.nan, 0, 0, 0, 0], n_periods=1)
    with pytest.raises(TypeError, match="Circle or Eight"):
        L.switched_runs(Body(), Gains(), object(), 0.5, n_periods=1)
    with pytest.raises(ValueError, match="n_periods"):
        L.switched_runs(Body(), Gains(), ref, 0.5, n_periods=0)
    with pytest.raises(TypeError, match="unknown option"):
        L.limit_verdicts(Body(), Gains(), ref, 0.5, transients=3)
    with pytest.raises(RuntimeError, match="non-finite"):
        L.switched_runs(Body(), Gains(), ref, 0.5, s0=[0, 0, 0, 1e308, 0, 0], n_periods=1)


@settings(max_examples=200, deadline=None)
@given(t=st_.floats(0.0, 50.0), s=st_.lists(st_.floats(-5.0, 5.0), min_size=6, max_size=6),
       kind=st_.sampled_from(["circle", "eight"]), bdeg=st_.floats(5.0, 180.0), cap=st_.sampled_from([np.inf, 3.0]))
def test_compiled_field_is_the_closed_loop_with_its_limits(t, s, kind, bdeg, cap):
    # the compiled kernel keeps its own scalar copy of (23), (2)-(4) and the clipped, capped
    # allocation (without trigonometry for the clip); off the switching surface its field must
    # be the library's closed loop (lib.closed_loop.ClosedLoop with lib.allocation.Limits),
    # with beta_max = pi meaning no angle limit
    ref = T.make(kind, 1.7, 0.6)
    b, g = Body(), Gains()
    P = np.array([b.m, b.I, b.a, b.c, b.c_phi, g.kp[0], g.kp[1], g.kv[0], g.kv[1], ref.R, ref.theta, 5.0,
                  0.0 if kind == "circle" else 1.0])
    bmax = min(math.radians(bdeg), math.pi)
    s = np.array(s)
    out, ev = np.empty(6), np.empty(4)
    lat, lon = switched_compiled._field(P, (bmax, math.cos(bmax), math.sin(bmax), cap), 1, t, s, out, ev)
    if abs(lat) < 1e-6 and lon < 0:
        return          # on the switching surface each side's field is a continuation
    mode = 1 if lat > 0 else -1
    switched_compiled._field(P, (bmax, math.cos(bmax), math.sin(bmax), cap), mode, t, s, out, ev)
    lim = Limits(force=None if not np.isfinite(cap) else cap, angle=None if bmax >= math.pi else bmax)
    want = ClosedLoop.of(b, g, reference_of(ref), limits=lim).rates(t, s)[0]
    np.testing.assert_allclose(out, want, rtol=5e-13, atol=5e-13)  # exact: one closed form, compiled and numpy, rounding only; measured 5.3e-14 (1 + |rates|) over 4000 draws


def test_regime_edges_pair_the_neighbours_across_a_change_of_chaos():
    import pandas as pd
    fr = pd.DataFrame({"angle_limit": [0.4, 0.1, 0.2, 0.3, 0.1, 0.2],
                       "force_limit": [np.inf] * 4 + [4.0] * 2,
                       "regime": ["periodic", "chaotic", "chaotic", "undecided", "periodic", "periodic"]})
    e = L.regime_edges(fr)
    assert e[["force_limit", "lo", "hi", "below", "above"]].values.tolist() == [[np.inf, 0.2, 0.3, "chaotic", "undecided"]]
    assert L.regime_edges(fr, "periodic").lo.tolist() == [0.3]


def test_switched_runs_sample_within_periods_and_reject_bad_sampling():
    ref = T.eight()
    one = L.switched_runs(Body(), Gains(), ref, np.pi, 4.0, n_periods=2)
    many = L.switched_runs(Body(), Gains(), ref, np.pi, 4.0, n_periods=2, samples_per_period=8)
    assert many.states.shape == (1, 17, 6) and np.allclose(many.t[::8], one.t, rtol=0, atol=1e-14)  # exact: the same grid of times; measured 0
    # accuracy: the same fixed steps, but the switchings are bracketed to 1e-11 s
    # (switched_compiled): a switching placed 1e-11 s apart moves the state by up to
    # 1e-11 s x the jump of the rates (< 10), over two periods; 1e-9 (measured 7.3e-15)
    np.testing.assert_allclose(many.states[0, ::8], one.states[0], rtol=0, atol=1e-9)
    with pytest.raises(ValueError, match="samples_per_period"):
        L.switched_runs(Body(), Gains(), ref, 0.5, n_periods=1, samples_per_period=3)
    with pytest.raises(ValueError, match="companion"):
        L.switched_runs(Body(), Gains(), ref, 0.5, n_periods=4, samples_per_period=2, lyapunov_from=1)


@pytest.mark.parametrize("deg, cap", [(90.0, 4.0), (90.0, None)])
def test_range_and_position_error_are_over_the_whole_orbit_not_its_section(deg, cap):
    # a periodic row's section is one point (range 0 at t = kT); the heading swings within the
    # period. The columns come from the orbit sampled 40 times a period, its extremes refined by
    # Hermite interpolation; an adaptive event-located run over one period from the orbit's
    # point, sampled 2000 times, is the reference (measured differences: 9e-4 rad and 3e-7 m;
    # the raw samples alone fell short by 0.09 rad)
    body, gains, ref = Body(), Gains(), T.eight(R=2.0, theta=math.pi / 4)
    row = L.limit_verdicts(body, gains, ref, [math.radians(deg)], cap)[0].iloc[0]
    assert row.regime == "periodic" and row.period == 1 and row.drift == 0.0 and not row.lost
    loop = L.SwitchedLoop(body, gains, ref, math.radians(deg), cap)
    t = np.linspace(0.0, ref.period, 2001)
    seg = loop.integrate(row.orbit, 0.0, ref.period, t_eval=t)
    p = seg.y[:, 2] - ref.z(seg.t)[:, 2]
    e = L.error_state(ref, seg.t, seg.y)
    assert np.ptp(p) > 3.0                                        # about +-2 rad: far from the section's 0
    assert row.p_range == pytest.approx(np.ptp(p), abs=5e-3)  # measured 8.8e-4: the range read from 2001 samples
    assert row.pos_err == pytest.approx(np.hypot(e[:, 0], e[:, 1]).max(), abs=3e-6)  # measured 2.6e-7


def test_switched_runs_record_the_run_itself_within_its_periods():
    """``record`` = (k, S) keeps the run's own states S times a period from period k on: the run,
    its companion and its statistics are the ones without it, bit for bit, and the recorded
    states at the period ends are its sections, bit for bit."""
    ref = T.eight()
    args = (Body(), Gains(), ref, np.radians([30.0, 90.0]), [np.inf, 4.0])
    plain = L.switched_runs(*args, n_periods=6, lyapunov_from=2)
    rec = L.switched_runs(*args, n_periods=6, lyapunov_from=2, record=(2, 8))
    # exact: recording only copies states at step ends, the arithmetic of the run is unchanged
    assert np.array_equal(rec.states, plain.states) and np.array_equal(rec.log_growth, plain.log_growth)
    assert np.array_equal(rec.locating, plain.locating) and plain.recorded is None
    assert rec.recorded.shape == (2, 4 * 8 + 1, 6)
    assert np.array_equal(rec.recorded[:, ::8], rec.states[:, 2:])          # exact: the same states
    # accuracy: (k S) (T / S) against k T, a rounding or two of each (measured 0)
    np.testing.assert_allclose(rec.recorded_t[::8], rec.t[2:], rtol=1e-12)
    # within the period: the same states as a run sampled S times a period from period 2's start.
    # Its kernel steps from other times, so a run that switches may differ by the bracketing of
    # its events (1e-11 s). A periodic run keeps that difference; a chaotic one (30 deg without a
    # cap) grows it by e^(lambda t), thousands of times over four periods, so this comparison takes
    # both angles under the 4 N cap, where both settle on attracting orbits (Chapter 4)
    capped = (Body(), Gains(), ref, np.radians([30.0, 90.0]), [4.0, 4.0])
    rec = L.switched_runs(*capped, n_periods=6, record=(2, 8))
    again = L.switched_runs(*capped, s0=rec.states[:, 2], n_periods=4, samples_per_period=8)
    assert (rec.locating.sum(axis=-1) > 100).all()   # reason: both switch and kink, hundreds of events
    # accuracy: events bracketed to 1e-11 s x rates below 10, on contracting orbits (measured 1.6e-13)
    np.testing.assert_allclose(rec.recorded, again.states, rtol=0, atol=1e-9)
    with pytest.raises(ValueError, match="record"):
        L.switched_runs(*args, n_periods=6, record=(6, 8))
    with pytest.raises(ValueError, match="record"):
        L.switched_runs(*args, n_periods=6, record=(0, 3))
    with pytest.raises(ValueError, match="record"):
        L.switched_runs(*args, n_periods=6, samples_per_period=2, record=(0, 2))


def test_a_chaotic_rows_measures_are_taken_on_the_run_it_was_decided_on():
    """Without an orbit, the heading's drift and range come from the decided run's own states:
    its block-end headings are the run's sections (recomputed here from ``runs.states``), and
    its range of p covers every section's p."""
    body, gains, ref = Body(), Gains(), T.eight(R=2.0, theta=math.pi / 4)
    o = dict(transient=10, periods=48, block=12)
    fr, runs = L.limit_verdicts(body, gains, ref, [math.radians(30.0)], None, **o)
    row = fr.iloc[0]
    assert row.period == 0 and runs.recorded is None                 # not kept with the runs
    sec = runs.states[0, o["transient"]:]
    p = sec[:, 2] - ref.z(runs.t[o["transient"]:])[:, 2]
    ends = p[::o["block"]]
    drift, se = dv.heading_drift(ends[None], o["block"])
    # accuracy: the same headings; phi_d at k T / S x S against k T, rounding of 1e2 rad
    assert row.drift == pytest.approx(drift[0], rel=0, abs=1e-12)
    assert row.drift_stderr == pytest.approx(se[0], rel=0, abs=1e-12)  # accuracy: as the drift's
    # accuracy: the samples include the sections bit for bit; phi_d read at (k S) (T / S), 1e-9
    assert row.p_range >= np.ptp(p) - 1e-9


def test_a_demand_within_on_limit_of_a_limit_counts_as_on_it_and_one_farther_inside_does_not():
    # sliding keeps the demand on the angle limit to rounding, and a capped force on its cap: the census
    # (lib.limits.switchings.sample_modes) reads a demand within ON_LIMIT of a limit as on it, so that a
    # run sliding at beta_max - 1e-9 rad is not counted free; a demand 2 ON_LIMIT inside is free
    from lib.allocation import allocate
    from lib.limits.switchings import ON_LIMIT, sample_modes
    from lib.params import PAPER_DZ0, PAPER_Z0
    body, gains, ref = Body(), Gains(), T.eight()
    t = np.array([0.3, 1.7])
    states = np.array([np.r_[PAPER_Z0, PAPER_DZ0], np.r_[PAPER_Z0, PAPER_DZ0] + 0.1])
    F, beta = allocate(computed_torque(body, gains, ref, t, states[:, :3], states[:, 3:]), states[:, 2])
    assert np.all(np.abs(beta) > 10 * ON_LIMIT) and np.all(F > 10 * ON_LIMIT)   # reason: demands away from 0
    for i in range(2):
        b, f = abs(beta[i]), F[i]
        on = sample_modes(body, gains, ref, t[i:i + 1], states[i:i + 1], b + 0.5 * ON_LIMIT, f + 0.5 * ON_LIMIT)
        inside = sample_modes(body, gains, ref, t[i:i + 1], states[i:i + 1], b + 2 * ON_LIMIT, f + 2 * ON_LIMIT)
        assert on[0] == int(np.sign(beta[i])) + 3 and inside[0] == 0
