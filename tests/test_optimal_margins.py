"""Chapter 8's tracker on a wrong plant, under a push, with a margin, and on a second eight, and
the entry run open loop on a wrong plant or from a disturbed start (:mod:`lib.optimal.studies.margins`;
the pushed verdict, :func:`lib.optimal.pushed.pushed_verdict`).

The wrong plant reuses the tracker's loops by moving the plant's input matrix into the Riccati
solution (:func:`plant_lqr`): the tests prove, through the numpy and the compiled loop, that the
gain applied is the model's and the accelerations the plant's, each against an independent route
(the model's gain and (2)-(4) on the plant, by hand).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

from lib.allocation import Limits
from lib.model import config_accel
from lib.model import config_from_state, state_from_config
from lib.optimal.studies import entries
from lib.optimal.studies import margins as mg
from lib.optimal.entry import entry_motion
from lib.optimal.motion import periodic_motion
from lib.optimal.riccati import loop_rhs
from lib.optimal.tracker import _loop, _loop_inputs, _reference, periodic_lqr
from lib.optimal.pushed import _pushed_loop, pushed_verdict
from lib.optimal.verdict import motion_verdict
from lib.params import PAPER_DZ0, PAPER_Z0, Body, Gains
from lib.simulate import simulate_open_loop
from lib.tracking.mismatch import model_of

R, THETA, DEG = 2.0, math.pi / 4, math.pi / 180
BODY = Body()


@pytest.fixture(scope="module")
def motion():
    # a best motion found at 30 deg + 4 N on the chapter's mesh, from two named starts (about a second)
    return periodic_motion(BODY, R, THETA, F_max=4.0, beta_max=30 * DEG, starts=("paper", "force"))


@pytest.fixture(scope="module")
def lqr(motion):
    return periodic_lqr(BODY, motion)


def _states(motion, n=5, seed=3):
    """States near the motion at n times of a period, each inside an input piece (t, X (n, 6))."""
    rng = np.random.default_rng(seed)
    h = motion.period / motion.nodes
    t = (np.round(np.linspace(0.1, 0.9, n) * motion.nodes) + 0.37) * h
    return t, _reference(motion, t)[0] + rng.normal(0.0, 0.2, (n, 6))


def _piece(motion, t):
    """The input piece [lo, hi] (s) that holds t."""
    k = int(np.floor(t / (motion.period / motion.nodes)))
    return motion.t[k], motion.t[k] + motion.period / motion.nodes


@pytest.mark.parametrize("plant", [model_of(BODY, m=0.1), model_of(BODY, I=-0.1), model_of(BODY, a=0.1, c=-0.1)])
def test_plant_lqr_applies_the_models_gain_exactly(lqr, motion, plant):
    t = np.linspace(0.0, motion.period, 11)
    moved = mg.plant_lqr(lqr, plant)
    # measured 9e-16 on gains up to 1.9 (the same product R^-1 B' P regrouped, rounding only): 1e-12,
    # the floor, bounds it
    np.testing.assert_allclose(moved.gain(t), lqr.gain(t), rtol=0, atol=1e-12)
    # reason: without the rescaling of P the gain moves with B's rows, by about the plant's 10 % (a mutant)
    assert np.abs(replace(lqr, body=plant).gain(t) - lqr.gain(t)).max() > 1e-3


@pytest.mark.parametrize("route", ["tracker", "kernel"])
def test_wrong_plant_loop_moves_by_the_plants_parameters_under_the_models_gain(lqr, motion, route):
    # the tracker's loop (compiled for a collocation motion) and the kernel called directly
    plant = model_of(BODY, m=0.1, I=-0.1, c=0.1, c_phi=-0.1, a=0.1)
    moved = mg.plant_lqr(lqr, plant)
    F_max, beta_max = 4.0, 30 * DEG
    for t, x in zip(*_states(motion)):
        lo, hi = _piece(motion, t)
        if route == "kernel":
            rates = loop_rhs(moved, F_max, beta_max)(t, x[None], t)[0]
        else:
            rates = _loop(moved, F_max, beta_max, 1)(lo, hi)(t, x)
        # independent route: the model's gain by hand, clipped, then (2)-(4) with the plant's parameters
        F, beta = _loop_inputs(lqr, t, x[None], F_max, beta_max)
        want = np.r_[x[3:], config_accel(plant, x[None, :3], x[None, 3:], F, beta)[0]]
        # measured 1.4e-14 through both routes (rounding of the regrouped gain and of the kernel's sums);
        # 1e-12 would do, 1e-9 leaves the accelerations' other summation orders room
        np.testing.assert_allclose(rates, want, rtol=0, atol=1e-9)


def test_push_adds_its_force_over_the_mass_to_the_loops_rates(lqr, motion):
    push = (0.2, -0.1)
    for t, x in zip(*_states(motion, n=3)):
        lo, hi = _piece(motion, t)
        free = _pushed_loop(lqr, 4.0, 30 * DEG, 1, (0.0, 0.0), {})(lo, hi)(t, x)
        pushed = _pushed_loop(lqr, 4.0, 30 * DEG, 1, push, {})(lo, hi)(t, x)
        # measured 6e-15: numpy's rates against the compiled loop's, the same formulas summed apart
        np.testing.assert_allclose(free, _loop(lqr, 4.0, 30 * DEG, 1)(lo, hi)(t, x), rtol=0, atol=1e-12)
        # exact: one addition of F / m to each acceleration, rounding only
        np.testing.assert_allclose(pushed - free, [0, 0, 0, push[0] / BODY.m, push[1] / BODY.m, 0], rtol=0,
                                   atol=1e-14)


def test_pushed_verdict_without_a_push_is_motion_verdict(lqr, motion):
    limits = Limits(4.0, 30 * DEG)
    one = motion_verdict(BODY, motion, limits=limits, lqr=lqr, steps=2, periods=4)
    two = pushed_verdict(BODY, motion, (0.0, 0.0), limits=limits, lqr=lqr, steps=2, periods=4)
    assert one.regime == two.regime == "periodic" and one.steps == two.steps
    # the same RK4 maps, compiled against numpy, the same Newton steps: rounding apart (measured 3e-15);
    # Newton's tolerance (1e-7) ten times bounds any other path to the orbit
    np.testing.assert_allclose(two.x, one.x, rtol=0, atol=1e-6)
    # |mu_1| by differences of step 1e-5: rounding of the maps over the step (measured 2e-10), 1e-6 bounds it
    assert abs(np.abs(two.multipliers[0]) - np.abs(one.multipliers[0])) < 1e-6


def test_a_plant_off_by_nothing_is_the_nominal_case(lqr, motion):
    limits = Limits(4.0, 30 * DEG)
    nominal = mg.tracked_case(BODY, motion, limits, lqr=lqr)
    tiny = mg.tracked_case(BODY, motion, limits, plant=model_of(BODY, m=1e-9), lqr=lqr)
    assert nominal["regime"] == tiny["regime"] == "periodic"
    # accuracy: a 1e-9 relative change moves the orbit by about 1e-9 (sensitivity of order 1), and each
    # orbit is located to Newton's tolerance 1e-7: 10 x that bounds the RMS errors' difference
    assert abs(tiny["rms_error"] - nominal["rms_error"]) < 1e-6
    # the heavier plant is pushed off the plan: the loop's error grows (measured 0.12 m to 0.33 m RMS)
    heavy = mg.tracked_case(BODY, motion, limits, plant=model_of(BODY, m=0.1), lqr=lqr)
    assert heavy["rms_error"] > nominal["rms_error"] + 0.05


def test_margin_plans_under_the_reduced_cap_and_leaves_the_loop_its_full_cap(motion):
    out = mg.margin_cases(BODY, {(30, 4.0): motion}, fraction=0.9)
    table = out["table"].set_index("margin")
    plan = out["plans"][(30, 4.0), True][0]
    # accuracy: IPOPT meets its bounds to about 1e-7 N (its constraint tolerance), 10 x that
    assert plan.F.max() <= 3.6 + 1e-6 and plan.F_max == pytest.approx(3.6)  # exact: the cap as given
    # reason: a smaller cap allows no better motion (the margined plan is admissible without the
    # margin), to the optimiser's tolerance
    assert table.plan_rms[True] >= table.plan_rms[False] - 1e-6
    # the loop may raise the force above the plan, to the full cap (measured 3.75 N against 3.6)
    assert table.F_peak[True] <= 4.0 + 1e-9
    assert (table.regime == "periodic").all()


def test_edges_refused_naming_the_argument(lqr, motion, entry):
    with pytest.raises(ValueError, match="cap"):
        mg.eight_comparison(BODY, Gains(), 0.5, 0.3)          # needs far below 4 N: the cap does not bind
    with pytest.raises(ValueError, match="fraction"):
        mg.margin_cases(BODY, {(30, 4.0): motion}, fraction=1.5)
    with pytest.raises(ValueError, match="motions"):
        mg.margin_cases(BODY, {(30, None): motion})
    with pytest.raises(ValueError, match="push"):
        pushed_verdict(BODY, motion, (0.2,), lqr=lqr)
    with pytest.raises(TypeError, match="plant"):
        mg.plant_lqr(lqr, "body")
    with pytest.raises(ValueError, match="parameters"):
        mg.wrong_model_cases(BODY, {}, parameters=("mass",))
    with pytest.raises(ValueError, match="first"):
        mg.entry_margin(BODY, motion, Limits(4.0, None), first={"mass": 0.1})
    with pytest.raises(ValueError, match="first"):
        mg.entry_margin(BODY, motion, Limits(4.0, None), first={"m": -0.1})
    with pytest.raises(ValueError, match="start"):
        entries.entry_end(BODY, motion, entry, np.zeros(5))
    with pytest.raises(TypeError, match="entry"):
        entries.entry_end(BODY, motion, "plan")


@pytest.fixture(scope="module")
def entry(motion):
    return entry_motion(BODY, motion)


def _entry_end_by_solve_ivp(plant, motion, entry, start):
    """An independent route to where the entry's inputs bring ``plant`` from ``start``: the book's
    open-loop integrator (DOP853, rtol 1e-10) piece by piece, as entry_motion checks its own end."""
    h, q = motion.period / entry.nodes, state_from_config(start[:3], start[3:])
    for F, beta in zip(entry.F, entry.beta):
        q = simulate_open_loop(plant, lambda t, F=F: F, lambda t, b=beta: b, q, h, form="config",
                               t_eval=np.array([h]), rtol=1e-10, atol=1e-10)[1][-1]
    z, dz = config_from_state(q)
    lap = 2 * np.pi * round((start[2] - motion.state(0.0)[0][2]) / (2 * np.pi))
    return np.concatenate([z, dz]) - [0, 0, lap + 2 * np.pi * motion.turns * entry.periods, 0, 0, 0]


def _reaches_alone(plant, motion, lqr, end):
    """The verdict's reach test run by itself on ``plant`` from ``end`` (the chapter's steps, periods)."""
    v = motion_verdict(plant, motion, limits=Limits(4.0, 30 * DEG), lqr=mg.plant_lqr(lqr, plant),
                       starts=end[None], steps=2, periods=8)
    return bool(v.reached[0])


def test_the_entry_run_open_loop_ends_where_an_independent_integration_does(motion, entry):
    paper = np.concatenate([PAPER_Z0, PAPER_DZ0])
    # accuracy: RK4 at 4 steps a piece of 0.1 s against DOP853 at 1e-10; measured 1.1e-6, falling 14
    # times a halving (fourth order): 1e-5 bounds it with the order's room
    np.testing.assert_allclose(entries.entry_end(BODY, motion, entry), entry.end, rtol=0, atol=1e-5)
    plant = model_of(BODY, m=0.1, a=-0.1)
    np.testing.assert_allclose(entries.entry_end(plant, motion, entry), _entry_end_by_solve_ivp(plant, motion, entry, paper),
                               rtol=0, atol=1e-5)     # accuracy: as above
    # rows at once: each row its own run (exact up to the RK4 sums' rounding)
    starts = paper + np.array([[0, 0, 0, 0, 0, 0], [0.1, 0, 0.2, 0, 0, 0]])
    both = entries.entry_end(BODY, motion, entry, starts)
    np.testing.assert_allclose(both[1], entries.entry_end(BODY, motion, entry, starts[1]), rtol=0, atol=1e-12)  # exact: the same RK4 rows, run alone or in a batch
    # a push along x moves the end along x by about F t^2 / (2 m) without drag: clearly
    assert entries.entry_end(BODY, motion, entry, push=(0.2, 0.0))[0] - both[0, 0] > 0.1


def test_the_entry_reach_on_each_wrong_plant_is_the_verdicts_on_that_plant_alone(motion, lqr):
    rows = mg.wrong_model_cases(BODY, {((30, 4.0), False): (motion, lqr)}, parameters=("m", "a"), push=None)
    assert len(rows) == 4 and rows.entry_reached.dtype == bool
    plan, paper = entry_motion(BODY, motion), np.concatenate([PAPER_Z0, PAPER_DZ0])
    for r in rows.itertuples():
        plant = model_of(BODY, **{r.parameter: r.delta})
        # the same decision from an end integrated by another route (they differ by about 1e-6,
        # a thousandth of the reach tolerance)
        assert r.entry_reached == _reaches_alone(plant, motion, lqr, _entry_end_by_solve_ivp(plant, motion, plan, paper))
    # the seven starts' counts are those without the eighth (the entry's end)
    alone = mg.tracked_case(BODY, motion, Limits(4.0, 30 * DEG), plant=model_of(BODY, m=0.1), lqr=lqr)
    first = rows.iloc[0]
    assert (alone["starts_reached"], alone["starts"], alone["settled"]) == (first.starts_reached, 7, first.settled)


def test_the_entry_margin_brackets_a_reach_boundary(motion, lqr):
    first = {"m": 0.025, "heading": 0.05}
    em = mg.entry_margin(BODY, motion, Limits(4.0, 30 * DEG), first=first)
    assert list(zip(em.quantity, em.sign)) == [("m", 1), ("m", -1), ("heading", 1), ("heading", -1)]
    bracketed = em[np.isfinite(em.failed)]
    assert len(bracketed) > 0
    plan, paper = entry_motion(BODY, motion), np.concatenate([PAPER_Z0, PAPER_DZ0])
    for r in bracketed.itertuples():
        # the first bracket, [L, 2L] after a doubling or [0, first] before any, is halved twice: a
        # quarter of its width, itself at most the level that failed or the first
        assert 0 < r.failed - r.reached <= max(r.failed, first[r.quantity]) / 4 + 1e-12  # reason: a bisection's bracket, a quarter of the first level, rounding aside
        for level, want in ((r.reached, True), (r.failed, False)):
            if level == 0:
                continue                  # nothing reached: the undisturbed start is no level tried
            if r.quantity == "m":
                plant, start = model_of(BODY, m=r.sign * level), paper
            else:
                plant, start = BODY, paper + r.sign * level * np.eye(6)[2]
            end = _entry_end_by_solve_ivp(plant, motion, plan, start)
            assert _reaches_alone(plant, motion, lqr, end) == want, (r, level)


def test_the_entry_margin_table_writes_each_direction_its_levels_and_none_failed():
    em = pd.DataFrame(dict(quantity=["heading", "m"], sign=[1, -1], reached=[0.4, 0.0875], failed=[0.5, np.nan],
                           tried=[7, 5]))
    t = mg.entry_margin_table(em)
    assert list(t["disturbance"]) == ["heading + (rad)", "m - (%)"]
    # exact levels, the mass in per cent
    assert list(t["reaches at"]) == ["0.4", "8.75"] and list(t["fails at"]) == ["0.5", "none failed"]
