"""Chapter 7's claims as computed: the full 7-state loop of the law for P on Fig. 5's grid
(lib.percussion.full_loop), the law with a wrong model (lib.percussion.wrong_model), and the
steady extremes, the lock radius, the report's circle and the cap's windup (lib.percussion.claims)."""

from __future__ import annotations

import math
from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest
import sympy as sp
from scipy.integrate import solve_ivp

from lib import percussion as pc
from lib import trajectories
from lib.params import PAPER_DZ0, PAPER_Z0, Body, Gains
from lib.percussion import claims, full_loop as fl, wrong_model as wm
from lib.percussion.law import closed_loop_rates, error_polynomial, law_inputs
from lib.rotation.circle import circle_critical_radius
from lib.rotation.verdicts import FIG5_GRID
from lib.trajectories import eight_position

BODY, GAINS = Body(), Gains()
TH0 = math.pi / 4


def _numpy_rates(plant, model, R, Theta, t, y):
    """The loop with the law of ``model`` on ``plant``, from lib.percussion.law (another route)."""
    k = np.array(eight_position(R, Theta, t))
    kin = (k[0:2], k[2:4], k[4:6], k[6:8])
    if plant == model:
        return closed_loop_rates(plant, error_polynomial(plant, GAINS), kin, np.asarray(y))[0]
    nu, u2 = law_inputs(model, error_polynomial(model, GAINS), kin, y[:3], y[3:6], y[6])
    c, s = math.cos(y[2]), math.sin(y[2])
    return np.array([y[3], y[4], y[5], (y[6] * c - u2 * s - plant.c * y[3]) / plant.m,
                     (y[6] * s + u2 * c - plant.c * y[4]) / plant.m, (plant.a * u2 - plant.c_phi * y[5]) / plant.I,
                     nu])


@pytest.mark.parametrize("model", [BODY, replace(BODY, I=0.09), replace(BODY, a=0.44, c=0.66)])
def test_the_compiled_field_is_the_law_for_p_of_lib_percussion_law(model):
    rng = np.random.default_rng(7)
    for _ in range(20):
        y = rng.normal(size=7) * [1, 1, 3, 1, 1, 2, 3]
        R, Th, t = rng.uniform(0.25, 4), rng.uniform(0.05, 1.5), rng.uniform(0, 10)
        got, F = fl.compiled_rates(BODY, GAINS, R, Th, t, y, model=model)
        want = _numpy_rates(BODY, model, R, Th, t, y)
        # accuracy: the same formulas in another order; omega' = r2 / eps (eps = 0.0875 m/s) and
        # nu multiply the rounding of the O(10) terms by up to about 100
        np.testing.assert_allclose(got, want, rtol=1e-10, atol=1e-10)


@pytest.mark.parametrize("kind", ["eight", "circle"])
@pytest.mark.parametrize("force, angle_deg", [(None, None), (4.0, None), (None, 30.0), (2.0, 45.0), (0.5, 12.0)])
@pytest.mark.parametrize("anti_windup", [None, 0.5])
def test_the_limited_compiled_field_is_the_law_for_p_under_limits(kind, force, angle_deg, anti_windup):
    # Chapter 8's fixed-step loops run the law for P under limits on the compiled field: it must be
    # lib.percussion.law's closed loop, clipping and anti-windup included, at states where the
    # law's force is far above the cap and its angle beyond the limit as well as below them
    from lib.allocation import Limits

    rng = np.random.default_rng(11)
    ref = trajectories.make(kind, 2.0, TH0)
    co = error_polynomial(BODY, GAINS)
    limits = Limits(force, None if angle_deg is None else math.radians(angle_deg))
    field = fl.limited_field(BODY, GAINS, ref, limits, anti_windup)
    position = trajectories.POSITIONS[kind]
    clipped = 0
    for _ in range(20):
        t, Y = rng.uniform(0, 20), rng.normal(size=(4, 7)) * [1, 1, 3, 1, 1, 2, 3]
        k = np.array(position(ref.R, ref.theta, t))
        want, F, beta = closed_loop_rates(BODY, co, (k[0:2], k[2:4], k[4:6], k[6:8]), Y, limits, anti_windup)
        if force is not None:
            clipped += int(np.sum(F >= force))                  # exact: the cap is applied by min(F, cap)
        if angle_deg is not None:
            clipped += int(np.sum(np.abs(beta) >= math.radians(angle_deg)))   # exact: clipped by clip
        # accuracy: the same formulas in another order (F cos(phi + beta) against xi cos phi - u2 sin phi
        # where unclipped); omega' = r2 / eps and nu multiply the rounding of O(10) terms by about 100
        np.testing.assert_allclose(field(t, Y), want, rtol=1e-10, atol=1e-10)
    assert clipped > 0 or (force is None and angle_deg is None)


def test_the_limited_compiled_field_refuses_a_path_it_does_not_know():
    with pytest.raises(ValueError, match="kind"):
        fl.limited_field(BODY, GAINS, SimpleNamespace(_kind="ellipse", R=2.0, theta=TH0))


def test_the_grid_sample_spreads_over_fig5_grid_corners_included():
    R, Th, rows = fl.grid_sample(10)
    assert R.size == 100 and np.unique(rows).size == 100
    r_all = np.linspace(*FIG5_GRID["R"], FIG5_GRID["n"])
    t_all = np.linspace(*FIG5_GRID["Theta"], FIG5_GRID["n"])
    np.testing.assert_array_equal(R, r_all[rows % 100])      # exact: the same grid's entries
    np.testing.assert_array_equal(Th, t_all[rows // 100])    # exact: Theta varies slowest
    assert {R.min(), R.max(), Th.min(), Th.max()} == {r_all[0], r_all[-1], t_all[0], t_all[-1]}


#: the corners and the centre of Fig. 5's grid
POINTS = (np.array([0.25, 4.0, 0.25, 4.0, 2.0]), np.array([0.05, 0.05, 1.5, 1.5, TH0]))


@pytest.fixture(scope="module")
def corners():
    return fl.full_loop_verdicts(BODY, GAINS, *POINTS)


def test_the_full_loop_from_the_paper_start_reaches_the_zero_dynamics_orbit(corners):
    assert corners.held.all(), corners[["R", "Theta", "regime", "reason"]]
    for row in corners.itertuples():
        zero = pc.percussion_steady(BODY, "eight", row.R, row.Theta).p[-1]      # p at t = T, i.e. at t = 0
        # accuracy: the zero dynamics' Magnus map at 512 steps and this RK4 (h rate <= 0.25) each
        # resolve the orbit's heading to about 1e-4 rad (measured gaps <= 9e-5 rad over the sample)
        assert abs(math.remainder(row.orbit_p - zero, 2 * math.pi)) < 1e-3
        # accuracy: on the orbit P's error is zero in exact arithmetic; RK4's error at h rate 0.25
        # (measured <= 6e-6 m over the 10 x 10 sample)
        assert row.P_error < 1e-4


def test_twice_the_steps_moves_the_orbits_by_rk4s_error(corners):
    fine = fl.full_loop_verdicts(BODY, GAINS, *POINTS, h_rate=0.125)
    assert ((fine.steps > 2 * corners.steps - 16) & (fine.steps <= 2 * corners.steps)).all()   # multiples of 8
    assert (fine.regime == corners.regime).all()
    # accuracy: RK4's error, about 16 times smaller at half the step (measured 1e-5 rad at most)
    np.testing.assert_allclose(fine.orbit_p, corners.orbit_p, atol=1e-4)


def test_the_comparison_counts_the_points_both_routes_hold(corners):
    zero = corners.assign(orbit_p=corners.orbit_p + 0.01, lost=False)
    out = fl.compare_with_zero_dynamics(corners, zero)
    assert out["points"] == 5 and out["held_full"] == out["held_zero"] == out["same_verdict"] == 5
    assert out["orbit_gap"] == pytest.approx(0.01, abs=1e-12)   # exact: a shift of 0.01 rad, to rounding
    with pytest.raises(ValueError, match="same points"):
        fl.compare_with_zero_dynamics(corners, zero.iloc[::-1])


@pytest.fixture(scope="module")
def study():
    return wm.wrong_model_study(BODY, GAINS, 2.0, TH0, deltas=(-0.1, -0.05, 0.05, 0.1), parameters=("m", "I"))


def test_with_the_right_model_the_tracked_point_is_on_the_path(study):
    nominal = study[study.parameter == "none"].iloc[0]
    assert nominal.held
    assert nominal.P_error < 1e-5          # accuracy: RK4's error at h rate 0.25 (measured 5e-8 m)


def test_a_wrong_mass_moves_the_tracked_point_off_the_path_to_first_order(study):
    m = study[study.parameter == "m"].set_index("delta")
    assert m.held.all()
    assert m.P_error[0.05] > 0.01          # reason: a 5 % mass error is far above RK4's 5e-8 m
    # reason: first order in the error: doubling it doubles the distance (measured ratios 1.97, 2.01)
    assert m.P_error[0.1] / m.P_error[0.05] == pytest.approx(2.0, rel=0.1)
    assert m.P_error[-0.1] / m.P_error[-0.05] == pytest.approx(2.0, rel=0.1)   # reason: the same, below


def test_an_inertia_ten_percent_low_makes_the_law_for_p_diverge_on_two_integrators(study):
    low = study[(study.parameter == "I") & (study.delta == -0.1)].iloc[0]
    assert not low.held and low.reason == "diverged"
    model = replace(BODY, I=0.9 * BODY.I)

    def away(t, y):
        return abs(y[6]) - 1e6
    away.terminal = True
    sol = solve_ivp(lambda t, y: _numpy_rates(BODY, model, 2.0, TH0, t, y), (0.0, 30.0),
                    np.r_[PAPER_Z0, PAPER_DZ0, fl.THRUST0], method="DOP853", rtol=1e-9, atol=1e-9, events=away)
    assert sol.status == 1 and sol.t[-1] < 10.0          # reason: measured 4.4 s, the thrust at 1e6 N


def test_the_wrong_model_table_has_a_row_per_parameter_and_a_column_per_error(study):
    t = wm.error_table(study)
    assert list(t["model's parameter"]) == ["m", "I_C"]
    assert list(t.columns[1:]) == ["-10 %", "-5 %", "+5 %", "+10 %"]
    assert t.loc[1, "-10 %"] == "diverged"
    with pytest.raises(ValueError):
        wm.wrong_model_study(BODY, GAINS, 2.0, TH0, parameters=("mass",))


def test_the_peak_force_is_an_extreme_converged_in_the_samples():
    ext = claims.steady_extremes(BODY, "percussion", "eight", 2.0, TH0, steps=2048)
    dense = pc.percussion_steady(BODY, "eight", 2.0, TH0, steps=8192)
    assert ext.F_peak >= dense.F.max() - 1e-6     # accuracy: the parabola's O(h^3) at 2048 steps
    assert ext.F_peak == pytest.approx(dense.F.max(), abs=1e-4)   # accuracy: measured change 1.6e-5 N
    assert ext.F_change < 1e-4                    # accuracy: O(h^3) of the refinement (measured 1.6e-5 N)


def test_the_force_of_the_law_for_p_points_backwards_while_the_thrust_is_reversed():
    ext = claims.steady_extremes(BODY, "percussion", "eight", 2.0, TH0, steps=1024)
    assert ext.thrust_min < 0 and ext.reversed_time > 0 and ext.backward >= 1
    assert ext.beta_peak == math.pi                       # exact: set to pi where beta passes through it
    paper = claims.steady_extremes(BODY, "paper", "eight", 2.0, TH0, steps=1024)
    assert paper.backward == 0 and paper.beta_peak < 2.0   # reason: measured 1.894 rad, no backward force


def test_the_lock_radius_is_abs_rho_minus_one_times_the_paper_critical_radius():
    ratio, rho = claims.lock_ratio()
    assert sp.simplify(ratio - sp.Abs(rho - 1)) == 0
    rng = np.random.default_rng(3)
    for _ in range(10):
        body = Body(m=rng.uniform(0.5, 5), I=rng.uniform(0.01, 1), a=rng.uniform(0.1, 1), c=rng.uniform(0.05, 2),
                    c_phi=rng.uniform(0.01, 1))
        th = rng.uniform(0.05, 2)
        r = (body.c / body.m) / (body.c_phi / body.I)
        got = pc.circle_lock_radius(body, th) / circle_critical_radius(body, th)
        assert got == pytest.approx(abs(r - 1), rel=1e-12)   # exact: two closed forms, to rounding
        assert (got < 1) == (body.c / body.m < 2 * body.c_phi / body.I)


def test_the_report_circle_puts_c_on_the_paper_circle():
    R_P, st = claims.paper_circle_of_p(BODY, 2.0, TH0)
    assert st.radius_C == pytest.approx(2.0, rel=1e-12)       # exact: closed forms, to rounding
    assert R_P > 2.0 and st.rate < 0


def test_under_the_cap_the_thrust_state_leaves_the_applied_thrust_and_runs_away():
    cap = claims.cap_windup(BODY, GAINS, trajectories.eight(2.0, TH0), 4.0, 30.0)
    assert cap.ran_away and cap.t_end < 30.0
    assert cap.xi_over > 4.0 and cap.t_over < cap.t_end
    assert cap.F_applied <= 4.0 + 1e-12          # exact: the applied force is clipped to the cap
    assert abs(cap.omega_end) < 100.0            # reason: the body turns slowly (measured 5.8 rad/s)


@pytest.mark.parametrize("R, Theta, name", [(1e4, 1.0, "R"), (1.0, 1e-5, "Theta")])
def test_a_point_beyond_the_step_budget_is_refused_naming_its_argument(R, Theta, name):
    with pytest.raises(ValueError, match=f"^{name}"):
        fl.full_loop_verdicts(BODY, GAINS, [R], [Theta])


def test_p_starts_off_the_path_by_the_paper_start_and_s_p():
    # the eight passes the origin at t = 0; the paper's C is at (1, 0) m facing +y, P is s_P along it
    got = fl.start_error(BODY, [0.25, 4.0], [0.05, 1.5])
    want = math.hypot(1.0, pc.centre_of_percussion(BODY))
    np.testing.assert_allclose(got, want, rtol=1e-12)   # exact: closed forms, to rounding



_LOOPS = """
import math, numpy as np
from lib import closed_loop, trajectories
from lib.allocation import Limits
from lib.params import Body, Gains
from lib.percussion import full_loop
body, gains, ref = Body(), Gains(), trajectories.make("eight", 2.0, math.pi / 4)
lim, Y = Limits(force=4.0, angle=math.radians(30)), np.full((3, 6), 0.1)
full_loop.full_loop_verdicts(body, gains, [2.0], [math.pi / 4])
full_loop.compiled_rates(body, gains, 2.0, math.pi / 4, 0.3, np.full(7, 0.1))
full_loop.limited_field(body, gains, ref, lim, 2.0)(0.3, np.full((3, 7), 0.1))
closed_loop.paper_rates(body, gains, ref, limits=lim)(0.3, Y[0])
closed_loop.limited_weighted_field(body, gains, ref, lim, (1.0, 1.0, 0.5))(0.3, Y)
"""


def test_the_loops_kernels_compile_once_each_on_a_fresh_clone(fresh_signatures):
    """On an empty numba cache (a fresh clone), the compiled closed loops (the paper's law and the
    weighted law under limits, the law for P's full loop, free and limited) compile each function
    for one signature: no flag passed as a literal, no default omitted by one caller and given by
    another, makes numba compile a second copy of the same arithmetic."""
    counts = fresh_signatures(_LOOPS, ("lib.allocation", "lib.closed_loop", "lib.percussion.full_loop"))
    assert counts["lib.closed_loop _path"] == 1 and counts["lib.percussion.full_loop _field"] == 1
    assert {k: n for k, n in counts.items() if n > 1} == {}
