"""lib.optimal.loop: any closed loop decided by the book's orbit procedure, against closed forms."""

import math

import numpy as np
import pytest
from scipy.optimize import linear_sum_assignment

from lib import trajectories
from lib.allocation import Limits
from lib.closed_loop import ClosedLoop, reference_of
from lib.machinery import checks
from lib.optimal.loop import (LOOP_OPTIONS, FlowMap, LoopVerdict, _orbit_shift, halved_verdict, loop_verdict,
                              run_periods, steady_measures)
from lib.optimal.floquet import MULTIPLIER_TOL
from lib.optimal.verdict import ORBIT_SHIFT_TOL
from lib.params import PAPER_DZ0, PAPER_Z0, Body, Gains
from lib.rotation.circle import circle_eigenvalues, circle_equilibria

BODY, GAINS = Body(), Gains()
R0, TH0 = 2.0, math.pi / 4


def _rates(ref, limits=None):
    loop = ClosedLoop.of(BODY, GAINS, reference_of(ref), limits=limits)
    return loop, (lambda t, s: loop.rates(t, s)[0])


def test_the_paper_circle_is_periodic_with_the_closed_form_multipliers():
    # uncapped, the position error obeys (24) and the heading (33): the 6-state Jacobian of the
    # period map is block triangular, its multipliers exp(lambda T) of (24)'s and (35)'s roots
    ref = trajectories.circle(R0, TH0)
    _, rates = _rates(ref)
    v = loop_verdict(rates, ref.period, np.r_[PAPER_Z0, PAPER_DZ0], reference_turns=1)
    assert v.regime == "periodic" and v.period == 1 and v.turns == 0
    p0 = circle_equilibria(BODY, R0, TH0)[0]
    # accuracy: 100 x Newton's tolerance 1e-8: the orbit is C on the circle, p = p0 (measured 2.8e-14)
    assert v.orbit[:2] == pytest.approx([R0, 0.0], abs=1e-6)
    # accuracy: 100 x Newton's tolerance 1e-8, as above
    assert math.remainder(v.orbit[2] - math.pi / 2 - p0, 2 * math.pi) == pytest.approx(0.0, abs=1e-6)
    m, kv, kp = BODY.m, GAINS.kv[0], GAINS.kp[0]
    pos = np.roots([m, kv, kp]).astype(complex)
    expected = np.exp(np.r_[pos, pos, circle_eigenvalues(BODY, R0, TH0)] * ref.period)
    got = np.asarray(v.multipliers)
    # a forward-difference Jacobian (step 1e-6) of a map integrated at 1e-10: errors ~1e-5 of
    # the map's derivatives; the pairs matched one to one (linear_sum_assignment)
    rows, cols = linear_sum_assignment(np.abs(got[:, None] - expected[None, :]))
    # accuracy: 10 x the difference Jacobian's ~1e-5 (measured 1.8e-7)
    assert np.abs(got[rows] - expected[cols]).max() < 1e-5 * 10
    assert v.floquet < 1.0


def test_the_capped_eight_is_periodic_and_measures_as_the_cap_sweep():
    # Fig. 4's setting: the compiled cap sweep's largest distance (its own integrator) agrees
    ref = trajectories.eight(R0, TH0)
    loop, rates = _rates(ref, Limits(force=4.0))
    v = loop_verdict(rates, ref.period, np.r_[PAPER_Z0, PAPER_DZ0])
    assert v.regime == "periodic" and v.turns == 0
    _, t, st = run_periods(FlowMap(rates, ref.period), v.orbit, 1, samples=1024)
    _, F, beta = loop.inputs(t, st[:, :3], st[:, 3:])
    meas = steady_measures(t, st, F, beta, ref.z(t), F_cap=4.0)
    from lib.tracking.runs import force_cap_sweep
    sweep = force_cap_sweep(BODY, GAINS, ref, [4.0], n_periods=10)
    # both sample a period (400 and 1024 points, refined): a parabola's O(h^3) on errors of
    # 0.4 m, and the sweep's 8 transient periods settled to its slowest multiplier (0.67^8);
    # reason: a margin for those two, not an error bound (measured 1.6e-5)
    assert meas["max_error"] == pytest.approx(float(sweep.pos_err_max.iloc[0]), abs=2e-3)
    # reason: the cap binds: the peak reaches it (the clip returns 4.0 itself; measured 0)
    assert meas["F_peak"] <= 4.0 and meas["F_peak"] == pytest.approx(4.0, abs=1e-9)
    assert 0.0 < meas["rms_error"] < meas["max_error"]


def test_a_diverging_loop_is_undecided_with_its_time():
    v = loop_verdict(lambda t, s: s * 50.0, 1.0, np.ones(6), transient=2, history=3)
    assert v.regime == "undecided" and "diverged" in v.reason


def test_a_loop_that_never_settles_is_undecided_not_periodic():
    # a conservative oscillator at an irrational frequency ratio: no attracting orbit exists
    w = math.sqrt(2.0)

    def rates(t, s):
        out = np.zeros_like(s)
        out[:, 0], out[:, 1] = s[:, 1], -(2 * math.pi * w) ** 2 * s[:, 0] + np.cos(2 * math.pi * t)
        return out

    v = loop_verdict(rates, 1.0, np.r_[1.0, 0.0, 0.0, 0.0, 0.0, 0.0], transient=4, history=6)
    assert v.regime == "undecided"


@pytest.mark.parametrize("kw, name", [({"period": 0.0}, "period"), ({"s0": [np.nan] * 6}, "s0"),
                                      ({"reference_turns": 0.5}, "reference_turns"),
                                      ({"transient": 0}, "transient"), ({"bogus": 1}, "bogus"),
                                      ({"rates": 3.0}, "rates"), ({"period_end": 3.0}, "period_end")])
def test_bad_arguments_are_refused_before_any_integration(kw, name):
    args = dict(rates=lambda t, s: pytest.fail("integrated"), period=1.0, s0=np.zeros(6))
    args.update(kw)
    with pytest.raises((TypeError, ValueError), match=name):
        loop_verdict(args.pop("rates"), args.pop("period"), args.pop("s0"), **args)


def test_halving_the_step_decides_the_paper_circle_periodic_once_the_orbit_stops_moving():
    # from 32 RK4 steps a period the orbit still moves when the step is halved (measured 8e-4), so
    # the steps are doubled; the pair that agrees has moved the orbit by less than the tolerance
    ref = trajectories.circle(R0, TH0)
    _, rates = _rates(ref)
    v = halved_verdict(rates, ref.period, np.r_[PAPER_Z0, PAPER_DZ0], reference_turns=1, steps=32, max_steps=256)
    assert v.regime == "periodic" and v.period == 1 and v.turns == 0 and v.reason == ""
    assert v.steps > 32 and v.orbit_shift <= ORBIT_SHIFT_TOL and v.floquet_change <= MULTIPLIER_TOL
    # the finer map's orbit against the closed form (C on the circle, p = p0): RK4's error on a
    # smooth field falls 2^4 = 16 times when the step is halved, so the finer map's error is
    # about the shift / 15, and the shift itself bounds it
    p0 = circle_equilibria(BODY, R0, TH0)[0]
    heading = math.remainder(v.orbit[2] - math.pi / 2 - p0, 2 * math.pi)
    err = max(abs(v.orbit[0] - R0), abs(v.orbit[1]), abs(heading))
    assert err <= v.orbit_shift + 1e-6  # accuracy: the shift (measured 4.9e-5; error 3.2e-6) + 100 x Newton's 1e-8


@pytest.mark.parametrize("steps, said", [(8, "the verdict changed when the step was halved from 8 to 16"),
                                         (16, "the orbit moved by")])
def test_a_map_too_coarse_to_converge_is_undecided_because_halving_the_step_changed_it(steps, said):
    # 8 steps a period find no orbit and 16 find one; 16 and 32 find it 0.025 apart (measured):
    # with no doubling allowed (max_steps = 2 steps) neither pair agrees
    ref = trajectories.circle(R0, TH0)
    _, rates = _rates(ref)
    v = halved_verdict(rates, ref.period, np.r_[PAPER_Z0, PAPER_DZ0], reference_turns=1, steps=steps)
    assert v.regime == "undecided" and v.steps == steps
    assert said in v.reason and "when the step was halved" in v.reason


def test_the_orbit_shift_is_to_the_nearest_point_of_the_cycle_with_the_heading_modulo_2pi():
    # a rotation by pi a period in the plane of columns 0 and 1: every point is on a cycle of
    # period 2, {x, -x}; a's point is b's second point, and a heading 2 pi apart is the same one
    def rates(t, s):
        out = np.zeros_like(s)
        out[:, 0], out[:, 1] = -math.pi * s[:, 1], math.pi * s[:, 0]
        return out
    flow = FlowMap(rates, 1.0, steps=256)
    x = np.array([0.3, 0.4, 1.0, 0.0, 0.0, 0.0])

    def said(orbit, period):
        return LoopVerdict("periodic", period, 0, orbit, np.zeros(6, complex), 1.0, 0.0, "", np.empty((0, 6)))
    half_turn = x * [-1, -1, 1, 1, 1, 1]
    shift = _orbit_shift(flow, said(half_turn + [0, 0, 2 * math.pi, 0, 0, 0], 1), said(x, 2))
    # accuracy: RK4 over a half turn in 256 steps, pi (pi / 256)^4 / 120 x 0.5 m ~ 3e-10 (measured 2.4e-10)
    assert shift < 1e-8
    # exact: |-0.4 - 0.4|, one point of a period-1 orbit against one (no integration)
    assert _orbit_shift(flow, said(half_turn, 1), said(x, 1)) == pytest.approx(0.8, abs=1e-15)


@pytest.mark.parametrize("kw, name", [({"steps": 0}, "steps"), ({"steps": 2.0}, "steps"),
                                      ({"steps": 8, "max_steps": 8}, "max_steps"),
                                      ({"steps": 8, "max_steps": 2 * checks.MAX_STEPS}, "max_steps"),
                                      ({"steps": 8, "transient": 0}, "transient"),
                                      ({"steps": 8, "period": -1.0}, "period")])
def test_halved_verdict_refuses_bad_arguments_before_any_integration(kw, name):
    args = dict(rates=lambda t, s: pytest.fail("integrated"), period=1.0, s0=np.zeros(6))
    args.update(kw)
    with pytest.raises((TypeError, ValueError), match=name):
        halved_verdict(args.pop("rates"), args.pop("period"), args.pop("s0"), **args)


def test_options_are_documented_defaults():
    assert set(LOOP_OPTIONS) >= {"transient", "history", "max_period", "newton_tol", "reach_tol"}
