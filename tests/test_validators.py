"""One way to check inputs (lib.machinery.checks): every public entry point rejects a str, a bool or
a NaN where a number belongs with an error naming the argument (TypeError for a wrong type,
ValueError for a wrong value), and a NaN inside an array with its index. And the weighted
allocation with a zero weight (w_x w_y = 0) runs instead of failing the batch's SVD."""

import math

import numpy as np
import pandas as pd
import pytest
import sympy as sp

from lib import allocation as A
from lib.machinery import checks
from lib import control, stability, symbolic
from lib.limits import verdicts as limits
from lib.weighting import verdicts as loop_verdicts, comparison as weighting
from lib.tracking import runs as tracking
from lib import trajectories as T
from lib.allocation import Limits
from lib.dynamics.verdicts import REGIMES
from lib.params import Body, Gains
from lib.simulate import simulate

BODY, GAINS = Body(), Gains()
TAU = [1.0, 2.0, 0.3]

# ------------------------------------------------------------------ the validators themselves


def test_number_returns_a_float_and_names_what_is_wrong():
    assert checks.number("R", np.float32(2.5)) == 2.5 and type(checks.number("R", 3)) is float
    assert checks.number("x", np.array(1.5)) == 1.5                     # a 0-d array is a number
    with pytest.raises(TypeError, match=r"^R must be a real number, got str '2'$"):
        checks.number("R", "2")
    with pytest.raises(TypeError, match="^R must be a real number, got bool"):
        checks.number("R", True)
    with pytest.raises(ValueError, match="^R must be a finite number, got nan"):
        checks.number("R", math.nan)
    with pytest.raises(ValueError, match="^R must be positive, got 0"):
        checks.number("R", 0, positive=True)
    with pytest.raises(ValueError, match="^R must be non-negative"):
        checks.number("R", -1e-300, nonnegative=True)
    with pytest.raises(ValueError, match="^theta must be non-zero"):
        checks.number("theta", 0.0, nonzero=True)
    with pytest.raises(ValueError, match="^b must be at most 3"):
        checks.number("b", 3.5, maximum=3.0)
    assert checks.number("F", math.inf, finite=False) == math.inf
    with pytest.raises(ValueError, match="finite"):                    # NaN never passes
        checks.number("F", math.nan, finite=False)


def test_integer_rejects_floats_and_bools_and_checks_the_minimum():
    assert checks.integer("n", np.int64(4), minimum=4) == 4
    for bad in (4.0, True, "4", None):
        with pytest.raises(TypeError, match="^n must be an integer"):
            checks.integer("n", bad)
    with pytest.raises(ValueError, match="^n must be an integer >= 2, got 1$"):
        checks.integer("n", 1, minimum=2)


def test_array_names_the_first_bad_index():
    x = np.ones((3, 4))
    x[2, 1], x[2, 3] = np.nan, -1.0
    with pytest.raises(ValueError, match=r"^x\[2, 1\] must be finite, got nan$"):
        checks.array("x", x)
    x[2, 1] = 1.0
    with pytest.raises(ValueError, match=r"^x\[2, 3\] must be positive, got -1\.0$"):
        checks.array("x", x, positive=True)
    with pytest.raises(ValueError, match=r"^x must have shape \(\.\.\., 3\), got shape \(3, 4\)$"):
        checks.array("x", x, shape=(..., 3))
    with pytest.raises(ValueError, match=r"^z0 must have shape \(3,\), got shape \(2,\)$"):
        checks.array("z0", [1.0, 2.0], shape=(3,))
    for bad in ("1.0", ["a", "b"], [True, False], None, [object()]):
        with pytest.raises(TypeError, match="^x must be an array of real numbers"):
            checks.array("x", bad)
    out = checks.array("x", [1, 2], shape=(None,))
    assert out.dtype == np.float64 and out.tolist() == [1.0, 2.0]
    assert checks.array("F", [np.inf], finite=False)[0] == np.inf


def test_one_of_flag_and_instance():
    assert checks.one_of("kind", "eight", ("eight", "circle")) == "eight"
    with pytest.raises(ValueError, match=r"^kind must be one of \['eight', 'circle'\], got 'square'$"):
        checks.one_of("kind", "square", ("eight", "circle"))
    with pytest.raises(ValueError, match="^kind must be one of"):
        checks.one_of("kind", ["eight"], ("eight", "circle"))          # unhashable
    assert checks.flag("progress", np.bool_(True)) is True
    for bad in (1, "yes", None):
        with pytest.raises(TypeError, match="^progress must be True or False"):
            checks.flag("progress", bad)
    assert checks.instance("body", BODY, Body) is BODY
    with pytest.raises(TypeError, match=r"^body must be a lib\.params\.Body, got str$"):
        checks.instance("body", "body", Body)


# ------------------------------------------------------------------ every public entry point

#: (id, call of the bad value, the argument's name as it appears in the message)
SCALARS = [
    ("Body.m", lambda v: Body(m=v), r"Body\.m"),
    ("Gains.kp", lambda v: Gains(kp=v), r"Gains\.kp"),
    ("circle R", lambda v: T.circle(v, 0.5), r"\bR\b"),
    ("eight theta", lambda v: T.eight(2.0, v), r"\btheta\b"),
    ("Limits force", lambda v: Limits(force=v), r"^force\b"),
    ("Limits angle", lambda v: Limits(angle=v), r"^angle\b"),
    ("allocate force_limit", lambda v: control.allocate(TAU, 0.0, force_limit=v), "force_limit"),
    ("allocate_limited angle_limit", lambda v: control.allocate_limited(TAU, 0.0, BODY, angle_limit=v),
     "angle_limit"),
    ("simulate t_end", lambda v: simulate(BODY, GAINS, T.circle(), v), "t_end"),
    ("fig5_map n", lambda v: stability.fig5_map(BODY, v), r"\bn\b"),
    ("eight_rotation_sweep option", lambda v: stability.eight_rotation_sweep(BODY, [2.0], [0.5], newton_tol=v),
     "newton_tol"),
    ("limit_verdicts option", lambda v: limits.limit_verdicts(BODY, GAINS, T.eight(), 0.5, candidate_tol=v),
     "candidate_tol"),
    ("sweep_angle_limit tol", lambda v: limits.sweep_angle_limit(BODY, GAINS, T.eight(), [0.5], tol=v), "tol"),
    ("closed_loop_verdicts option",
     lambda v: weighting.closed_loop_verdicts(BODY, GAINS, "eight", [2.0], [0.5], reach_tol=v), "reach_tol"),
    ("closed_loop_batch dt",
     lambda v: weighting.closed_loop_batch(BODY, GAINS, "eight", [2.0], [0.5], t_end=1.0, dt=v), r"\bdt\b"),
    ("compare_on_map w_phi", lambda v: weighting.compare_on_map(BODY, GAINS, [2.0], [0.5], v), "w_phi"),
    ("tracking.run R", lambda v: tracking.run(BODY, GAINS, "eight", v, 0.5, 1.0), r"\bR\b"),
    ("tracking.run n_periods", lambda v: tracking.run(BODY, GAINS, "eight", 2.0, 0.5, v), "n_periods"),
    ("eight_sensitivity n_periods",
     lambda v: tracking.eight_sensitivity(BODY, GAINS, [2.0], [0.5], n_periods=v), "n_periods"),
]

#: (id, call of the bad array, a good array to put the NaN in, the argument's name)
ARRAYS = [
    ("Gains.kv", lambda v: Gains(kv=v), [1.0, 2.0, 3.0], r"Gains\.kv"),
    ("allocate tau", lambda v: control.allocate(v, 0.0), TAU, "tau"),
    ("allocate phi", lambda v: control.allocate(np.ones((2, 3)), v), [0.0, 1.0], "phi"),
    ("allocate_least_squares weights", lambda v: control.allocate_least_squares(TAU, 0.0, BODY, v),
     [1.0, 1.0, 0.5], "weights"),
    ("computed_torque z", lambda v: control.computed_torque(BODY, GAINS, T.eight(), 0.0, v, np.zeros(3)),
     [1.0, 0.0, 0.0], r"\bz\b"),
    ("simulate z0", lambda v: simulate(BODY, GAINS, T.circle(), 1.0, z0=v), [1.0, 0.0, 1.5], "z0"),
    ("eight_rotation_sweep Theta", lambda v: stability.eight_rotation_sweep(BODY, [1.0, 2.0], v),
     [0.5, 0.5], "Theta"),
    ("rotation_verdicts R", lambda v: stability.rotation_verdicts(BODY, "circle", v, [0.5, 0.5]),
     [1.0, 2.0], r"\bR\b"),
    ("limit_verdicts angle_limits", lambda v: limits.limit_verdicts(BODY, GAINS, T.eight(), v),
     [0.5, 1.0], "angle_limits"),
    ("sweep_angle_limit angle_limits", lambda v: limits.sweep_angle_limit(BODY, GAINS, T.eight(), v),
     [0.5, 1.0], "angle_limits"),
    ("switched_runs s0", lambda v: limits.switched_runs(BODY, GAINS, T.eight(), 0.5, s0=v, n_periods=1),
     [1.0, 0.0, 1.5, 0.0, 0.0, 0.0], "s0"),
    ("closed_loop_verdicts R", lambda v: weighting.closed_loop_verdicts(BODY, GAINS, "eight", v, 0.5),
     [1.0, 2.0], r"\bR\b"),
    ("closed_loop_verdicts weights",
     lambda v: loop_verdicts.closed_loop_verdicts(BODY, GAINS, "eight", 2.0, 0.5, v), [1.0, 1.0, 0.1], "weights"),
    ("verdict_runs Theta", lambda v: weighting.verdict_runs(BODY, GAINS, {"a": dict(kind="eight", R=2.0, Theta=v)}),
     [0.5, 0.6], "Theta"),
    ("force_cap_sweep caps", lambda v: tracking.force_cap_sweep(BODY, GAINS, T.eight(), v), [3.0, 4.0], "caps"),
    ("eight_sensitivity Rs", lambda v: tracking.eight_sensitivity(BODY, GAINS, v, [0.5]), [1.0, 2.0], "Rs"),
]


@pytest.mark.parametrize("call, name", [c[1:] for c in SCALARS], ids=[c[0] for c in SCALARS])
def test_a_string_or_a_bool_for_a_number_is_a_type_error_naming_it(call, name):
    for bad in ("2", True):
        with pytest.raises(TypeError, match=name):
            call(bad)


@pytest.mark.parametrize("call, name", [c[1:] for c in SCALARS if c[0] != "fig5_map n"],
                         ids=[c[0] for c in SCALARS if c[0] != "fig5_map n"])
def test_a_nan_for_a_number_is_a_value_error_naming_it(call, name):
    with pytest.raises(ValueError, match=name):
        call(math.nan)


@pytest.mark.parametrize("call, good, name", [c[1:] for c in ARRAYS], ids=[c[0] for c in ARRAYS])
def test_a_bad_array_names_the_argument_and_a_nan_its_index(call, good, name):
    for bad in ("2", True, np.array([True, False])):
        with pytest.raises(TypeError, match=name):
            call(bad)
    v = np.array(good, dtype=float)
    v[1] = np.nan
    with pytest.raises(ValueError, match=name + r"\[1\] must be finite"):
        call(v)


def test_lie_bracket_names_a_wrong_type():
    x, y = sp.symbols("x y")
    f, g = sp.Matrix([y, 0]), sp.Matrix([0, x])
    assert symbolic.lie_bracket(f, g, [x, y]).shape == (2, 1)
    with pytest.raises(TypeError, match="sympy column Matrix"):
        symbolic.lie_bracket("f", g, [x, y])
    with pytest.raises(TypeError, match="Symbols"):
        symbolic.lie_bracket(f, g, [x, True])


# ------------------------------------------------------------------ zero weights (issue 20, the bug)


def test_least_squares_kernel_solves_singular_rows_and_leaves_a_blown_up_row_alone():
    # w = (0, 1, 0.5) at phi = 0: B's first column (1, 0, 0) is weighted out, so G = A^T A is
    # singular and the minimum-norm solution is u1 = 0, u2 = (tau_y + w_phi a tau_phi) /
    # (1 + w_phi a^2) (the normal equation of u2 alone). A NaN demand in the same batch (a state
    # that has blown up) once failed the whole batch ('SVD did not converge'); it gets NaN alone.
    body, w = Body(), np.array([0.0, 1.0, 0.5])
    tau = np.array([[1.0, 2.0, 0.3], [1.0, 2.0, 0.3], [np.nan, 1.0, 0.0]])
    phi = np.array([0.7, 0.0, 0.0])
    u, *_ = A._ls_kernel(tau, phi, body, np.sqrt(w))
    assert np.all(np.isnan(u[2])) and np.all(np.isfinite(u[:2]))
    a = body.a
    np.testing.assert_allclose(u[1], [0.0, (2.0 + 0.5 * a * 0.3) / (1 + 0.5 * a * a)], rtol=0,
                               atol=1e-15)                               # exact: a closed form; measured 0
    one, *_ = A._ls_kernel(tau[0], phi[0], body, np.sqrt(w))            # the regular row as alone
    np.testing.assert_array_equal(u[0], one)


def test_closed_loop_verdicts_decide_zero_weights():
    # w_x w_y = 0: the loop runs through ClosedLoop (not the lean field); each point gets a
    # verdict. With w = (0, 0, 1) only the torque is allocated, u = (0, tau_phi / a): the
    # position is not controlled and the body leaves the path (63 m off after 32 periods),
    # so the position is lost.
    o = dict(transient=8, periods=24, block=8)
    f = weighting.closed_loop_verdicts(BODY, GAINS, "eight", 2.0, math.pi / 4,
                                       np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]), **o)
    assert len(f) == 2 and set(f.regime) <= set(REGIMES)
    assert f.position_lost[0] and not f.tracked[0]
    assert np.all(np.isfinite(f[["p_range", "pos_rms", "pos_max"]]))  # reason: both runs stay finite


def test_a_closed_loop_run_that_diverges_is_decided_so_with_no_steady_measures():
    # w = (0, 1, 0.5) at 64 steps a period: the uncontrolled x runs away until RK4's state is
    # no longer finite (at 128 steps it is 3.5e4 m off after 32 periods). The verdict says so,
    # and the steady measures are NaN, not what skipping NaN samples would leave (-inf, 0)
    f = weighting.closed_loop_verdicts(BODY, GAINS, "eight", 2.0, math.pi / 4, np.array([0.0, 1.0, 0.5]),
                                       transient=8, periods=24, block=8, steps=64)
    row = f.iloc[0]
    assert row.regime == "undecided" and "non-finite" in row.reason and row.lost and row.position_lost
    assert np.all(np.isnan(f[["p_range", "p_rms", "pos_rms", "pos_max"]]))


# ---------------------------------------------------------------- inputs outside the methods' range (issue 27)


@pytest.mark.parametrize("kw", [{"m": 1e-300}, {"I": 1e9}, {"c_phi": 1e-7}])
def test_a_body_far_outside_the_methods_range_is_refused_naming_the_range(kw):
    name = next(iter(kw))
    with pytest.raises(ValueError, match=rf"^Body\.{name} must lie in \[1e-06, 1e\+06\]"):
        Body(**kw)
    Body(**{name: 1e-6}), Body(**{name: 1e6})       # the ends are inside


def test_an_explicit_run_that_stiffness_would_make_endless_is_refused_naming_the_fix():
    with pytest.raises(ValueError, match=r"fastest rate, about 3\.8\de\+06 1/s.*method='Radau'"):
        simulate(Body(m=1e-6), GAINS, T.circle(), 60.0)
    # the rate is the closed loop's: (kv + c) / m + sqrt(kp / m) on x, here 3.83e6 1/s


@pytest.mark.parametrize("R, Theta, msg", [(1e9, 1.0, r"^R\[0\] = 1e\+09 m: a period would need .* beyond the budget "
                                                      r"of 16384; outside the verdicts' domain"),
                                           (2.0, 1e9, r"^Theta\[0\] = 1e\+09 rad/s: the heading's damping time .* "
                                                      r"the domain is \|Theta\| <= 50\.27"),
                                           (1.0, 1e-9, r"^Theta\[0\] = 1e-09 rad/s: a period would need")])
def test_a_fig5_point_outside_the_verdicts_domain_is_refused_at_once(R, Theta, msg):
    with pytest.raises(ValueError, match=msg):
        stability.eight_rotation_sweep(BODY, [R, 1.0], [Theta, 1.0])
    # the map's own corner is inside: 2 pi 8 c_phi / I_C = 50.27 rad/s for the Table's body


def test_sweeps_broadcast_one_radius_or_one_rate_alike():
    a = stability.eight_rotation_sweep(BODY, [2.0], [0.5, 1.0])
    b = stability.eight_rotation_sweep(BODY, [2.0, 2.0], [0.5, 1.0])
    pd.testing.assert_frame_equal(a, b)
    with pytest.raises(ValueError, match=r"equal lengths \(or length 1\), got 2 and 3"):
        stability.eight_rotation_sweep(BODY, [1.0, 2.0], [0.5, 1.0, 1.5])


def test_weights_of_the_wrong_length_are_named():
    with pytest.raises(ValueError, match=r"^weights must be \(w_x, w_y, w_phi\).*got shape \(2,\)"):
        loop_verdicts.closed_loop_verdicts(BODY, GAINS, "eight", [2.0], [0.5], weights=(1.0, 1.0))
    with pytest.raises(ValueError, match=r"^Theta\[1\] must be non-zero"):
        loop_verdicts.closed_loop_verdicts(BODY, GAINS, "eight", [2.0, 2.0], [0.5, 0.0])


def test_a_regime_compares_equal_to_its_copy_section_and_nan_included():
    from dataclasses import replace

    from lib.limits.sections import Regime
    r = Regime(0.5, np.array([[1.0, np.nan]]), 1, False, np.nan, 0.1, "periodic", 3, 0.2)
    assert r == replace(r) and r != replace(r, section=np.array([[1.0, 2.0]])) and r != replace(r, period=2)


def test_check_grid_broadcasts_one_value_and_names_a_bad_entry():
    """The one check of every (R, Theta) sweep (lib.rotation.reduced.check_grid, used by
    Chapters 5 and 7): a length-1 array is broadcast, unequal lengths, NaN and non-positive
    entries are refused, each named."""
    from lib.rotation.reduced import check_grid

    R, Th = check_grid(2.0, [0.5, 0.7, 0.9])
    assert R.tolist() == [2.0, 2.0, 2.0] and Th.tolist() == [0.5, 0.7, 0.9]
    assert R.dtype == float and Th.dtype == float
    with pytest.raises(ValueError, match="equal lengths"):
        check_grid([1.0, 2.0], [0.5, 0.7, 0.9])
    with pytest.raises(ValueError, match=r"Theta\[1\]"):
        check_grid([1.0, 2.0], [0.5, -0.7])
    with pytest.raises(ValueError, match=r"R\[0\]"):
        check_grid([math.nan, 2.0], [0.5, 0.7])
    with pytest.raises(ValueError, match="1-D"):
        check_grid(np.ones((2, 2)), np.ones((2, 2)))


def test_options_merge_the_defaults_and_check_each_by_its_kind():
    """checks.options, behind every sweep's **options: integers at their minima, the rest
    positive numbers, unknown names refused with the known ones listed, extra names passed by."""
    defaults = dict(periods=120, block=12, newton_tol=1e-9)
    minima = dict(periods=2, block=2)
    o = checks.options(dict(block=np.int64(6), newton_tol=1e-8), defaults, minima)
    assert o == dict(periods=120, block=6, newton_tol=1e-8)
    assert type(o["block"]) is int and type(o["newton_tol"]) is float
    assert checks.options(dict(max_periods=9), defaults, minima, extra=("max_periods",)) == defaults
    with pytest.raises(TypeError, match=r"unknown option\(s\) \['blocks'\]; known: \['block', 'newton_tol'"):
        checks.options(dict(blocks=6), defaults, minima)
    with pytest.raises(ValueError, match="block must be an integer >= 2, got 1"):
        checks.options(dict(block=1), defaults, minima)
    with pytest.raises(TypeError, match="periods must be an integer"):
        checks.options(dict(periods=12.0), defaults, minima)
    with pytest.raises(ValueError, match="newton_tol"):
        checks.options(dict(newton_tol=0.0), defaults, minima)
    with pytest.raises(ValueError, match="newton_tol"):
        checks.options(dict(newton_tol=math.inf), defaults, minima)
