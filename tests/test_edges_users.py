"""The library at its edges, tried as a new user would (issue 52): each call is refused before any
work, with a message that names the argument as the user wrote it, and where the message advises a
call, that call works."""

import re
import time

import numpy as np
import pytest

from lib import trajectories as T
from lib.limits.verdicts import limit_verdicts
from lib.machinery import checks
from lib.params import Body, Gains
from lib.percussion.sweep import heading_sweep, percussion_fig5_map
from lib.rotation import fig5
from lib.rotation.verdicts import eight_rotation_sweep
from lib.simulate import Integration, simulate
from lib.tracking.mismatch import mismatch_sweep
from lib.tracking.runs import steady_summary
from lib.weighting.verdicts import closed_loop_verdicts

B, G = Body(), Gains()
#: a refusal is a check, not a run (the first call of a module may compile or import it)
FAST = 2.0


def _refused(call, pattern, exc=(TypeError, ValueError)):
    t = time.perf_counter()
    with pytest.raises(exc, match=pattern) as info:
        call()
    assert time.perf_counter() - t < FAST, str(info.value)          # reason: a refusal, not a run
    return str(info.value)


def _advised(msg, name):
    """The number the message advises for ``name`` (``name <= x`` or ``name to x``)."""
    return float(re.search(rf"{name} (?:<=|to) ([0-9.e+-]+)", msg).group(1))


def test_a_run_too_long_for_its_output_grid_is_refused_before_the_grid_is_built():
    # the 20-a-second output times of t_end = 1e9 s (149 GiB) were built before the budget check
    msg = _refused(lambda: simulate(B, G, T.circle(), 1e9), r"^ref \(R = 2 m.*t_end = 1e\+09 s")
    assert "MemoryError" not in msg and "Radau" not in msg      # the mode oscillates: no method steps over it


class _Still:
    """A reference of the user's own making that stands still (no path's speed to bound)."""
    def z(self, t):
        return np.zeros(np.shape(t) + (3,))
    dz = ddz = z


def test_a_default_output_grid_beyond_its_budget_is_refused_and_t_eval_instead_works():
    # an overdamped loop on a still reference under Radau passes the budget of steps at any t_end;
    # its default output times alone would then be 2e10 samples
    overdamped, radau = Gains(kp=1.0, kv=10.0), Integration(method="Radau")
    msg = _refused(lambda: simulate(B, overdamped, _Still(), 1e9, integration=radau),
                   r"^t_end = 1e\+09 s: the default output times .* give t_eval")
    res = simulate(B, overdamped, _Still(), 1e9, integration=radau, t_eval=[0.0, 1e9])
    assert res.t.size == 2 and np.all(np.abs(res.z[-1, :2]) < 1e-6)   # reason: the position settled at 0
    assert _advised(msg, "t_end") * 20 + 1 <= checks.MAX_SAMPLES


@pytest.mark.parametrize("call", [lambda n: fig5.fig5_map(B, n), lambda n: percussion_fig5_map(B, n=n)],
                         ids=["fig5_map", "percussion_fig5_map"])
def test_a_map_grid_beyond_its_budget_is_refused_naming_n(call):
    msg = _refused(lambda: call(10 ** 6), r"^n = 1000000: an n x n grid would hold 1e\+12 points")
    side = int(_advised(msg, "n"))
    checks.grid_budget(side)                                     # the advised n is inside
    with pytest.raises(ValueError, match="^n = "):
        checks.grid_budget(side + 1)


def test_a_summary_of_something_other_than_a_run_names_what_it_lacks():
    _refused(lambda: steady_summary({"t": [0, 1]}), r"^res must be a run of lib\.simulate\.simulate .* got dict, which "
             r"has no attribute t, z, z_d, F, ref$", TypeError)


def test_fig5_map_takes_one_confirmation_as_a_string():
    # "perturbed" was read letter by letter ("got 'p'")
    one, tup = fig5.fig5_map(B, 2, confirm="perturbed"), fig5.fig5_map(B, 2, confirm=("perturbed",))
    assert one.equals(tup)
    _refused(lambda: fig5.fig5_map(B, 2, confirm="perturb"), r"^confirm must be one of .* got 'perturb'$")
    _refused(lambda: fig5.fig5_map(B, 2, confirm=5), r"^confirm must be a key of .* got int 5$", TypeError)


def test_gains_too_stiff_for_the_loop_verdicts_steps_are_refused_and_the_advised_steps_run():
    # kp = 1e6 blew up the 128 RK4 steps a period and was reported as a lost heading ("the run
    # diverged"); simulate refuses the same gains
    _refused(lambda: simulate(B, Gains(kp=1e6), T.eight(), 8), r"^body and gains: ")
    msg = _refused(lambda: closed_loop_verdicts(B, Gains(kp=1e6), "eight", [1.0], [0.5]),
                   r"^gains: a period would need about 3\.55e\+03 RK4 steps .* raise the option steps to")
    _refused(lambda: mismatch_sweep(B, Gains(kp=1e6), "eight", [1.0], [0.5], {"m": 0.1}),
             r"^gains: a period would need .* raise the option steps to")      # the same flow, a wrong model
    v = closed_loop_verdicts(B, Gains(kp=1e6), "eight", [1.0], [0.5], steps=int(_advised(msg, "steps")),
                             transient=1, periods=24, block=8, max_period=1).iloc[0]
    assert "diverged" not in v.reason and np.isfinite(v.pos_max)


@pytest.mark.parametrize("call, name", [
    (lambda: limit_verdicts(B, G, T.circle(theta=1e-9), [1.0]), r"^ref\.theta = 1e-09 rad/s"),
    (lambda: limit_verdicts(B, G, T.eight(theta=1e-9), [1.0]), r"^ref\.theta = 1e-09 rad/s"),
    (lambda: closed_loop_verdicts(B, G, "eight", [1.0], [1e-9]), r"^Theta = 1e-09 rad/s"),
    (lambda: closed_loop_verdicts(B, G, "eight", [1.0], [0.004]), r"^Theta = 0\.004 rad/s"),
    (lambda: eight_rotation_sweep(B, [1.0], [1e-9]), r"^Theta = 1e-09 rad/s"),
    (lambda: heading_sweep(B, [1.0], [1e-9]), r"^Theta = 1e-09 rad/s"),
], ids=["limits circle", "limits eight", "loop verdicts", "loop verdicts steps", "Fig. 5", "law for P"])
def test_a_rate_far_below_the_bodys_is_blamed_on_theta_not_on_the_gains(call, name):
    # a period of 200 years needs billions of steps because of Theta, with the book's own gains
    assert "gains" not in _refused(call, name).split(":")[0]


def test_the_law_for_ps_sweep_refuses_the_rates_fig5_refuses_and_takes_its_printed_floor():
    msg = _refused(lambda: heading_sweep(B, [1.0], [1e-9]), r"verdicts need \|Theta\| >= ")
    floor = float(re.search(r"\|Theta\| >= ([0-9.e+-]+)", msg).group(1))
    assert heading_sweep(B, [1.0], [floor], max_period=1, lyapunov_periods=0).regime[0] != ""
    _refused(lambda: eight_rotation_sweep(B, [1.0], [floor / 2]), r"^Theta = ")


def test_advice_to_raise_steps_is_given_only_where_the_steps_would_be_inside_the_domain():
    # R = 1e9 needs 1.07e9 Magnus steps a period: not "raise the option steps"
    msg = _refused(lambda: heading_sweep(B, [1e9], [0.5]), r"^R = 1e\+09 m: .* beyond the budget of 16384; outside")
    assert "steps" not in msg.split(";")[1]
    msg = _refused(lambda: heading_sweep(B, [1000.0], [0.5]), r"^R = 1000 m: .* raise the option steps to 1067")
    v = heading_sweep(B, [1000.0], [0.5], steps=int(_advised(msg, "steps")), max_period=1, lyapunov_periods=0)
    assert v.regime[0] != ""


def test_a_stiff_method_is_advised_only_where_it_would_be_inside_the_budget_and_the_advised_t_end_runs():
    # circle(R = 1e9) advised Radau, which then ran for over 270 s: the heading driven by the path
    # oscillates at 8.3e4 rad/s, and every method follows an oscillation step by step
    radau = Integration(method="Radau")
    msg = _refused(lambda: simulate(B, G, T.circle(R=1e9), 8), r"^ref \(R = 1e\+09 m.* oscillates .* t_end <= ")
    assert "Radau" not in msg
    _refused(lambda: simulate(B, G, T.circle(R=1e9), 8, integration=radau), r"^ref \(R = 1e\+09 m.* steps of Radau")
    res = simulate(B, G, T.circle(R=1e9), _advised(msg, "t_end"))
    assert res.t[-1] == _advised(msg, "t_end")
    # a stiff body's decaying mode is where Radau helps: advised, and inside the budget
    msg = _refused(lambda: simulate(Body(m=1e-6), G, T.circle(), 60.0), r"method='Radau'")
    _advised(msg, "t_end")


def test_a_bad_force_limit_is_named_by_its_argument_and_index():
    _refused(lambda: limit_verdicts(B, G, T.eight(), [1.0], force_limits=-1),
             r"^force_limits must be positive \(N\), or inf or None for no force limit, got -1\.0$")
    _refused(lambda: limit_verdicts(B, G, T.eight(), [1.0, 1.0], force_limits=[2.0, -1.0]),
             r"^force_limits\[1\] must be positive")


def test_an_unknown_integration_method_is_refused_naming_the_methods_before_any_run():
    # issue 59: Integration(method="Foo") was accepted, and simulate then raised scipy's own message
    msg = _refused(lambda: Integration(method="Foo"), r"Integration\.method")
    assert "'Foo'" in msg and "DOP853" in msg and "Radau" in msg
    assert Integration(method="Radau").method == "Radau"



@pytest.mark.parametrize("call, option", [
    (lambda g: limit_verdicts(B, g, T.eight(), [1.0]), "steps_per_period"),
    (lambda g: __import__("lib.tracking.runs", fromlist=["x"]).force_cap_sweep(B, g, T.eight(), [4.0]),
     "samples_per_period"),
    (lambda g: closed_loop_verdicts(B, g, "eight", [2.0], [np.pi / 4]), "steps"),
])
def test_gains_too_stiff_for_a_runs_fixed_steps_are_refused_at_once_naming_the_gains(call, option):
    # issue 59: limit_verdicts with kp = 1e6 ran 58 s, then said "the state became non-finite"
    # without naming the gains, and force_cap_sweep ran silently; each now refuses before any run
    msg = _refused(lambda: call(Gains(kp=1e6)), r"^gains: ")
    assert re.search(rf"raise (the option )?{option} to \d+", msg), msg
    assert not re.search("non-finite", msg)


def test_an_angle_limited_run_locates_its_switching_by_default_and_finishes():
    # issue 59: simulate(Body(), Gains(), eight(1.5, 0.6), 2 T, limits=Limits(angle=40 deg)) ran for
    # minutes without a word under the step-size control; by default it now locates the switching
    from lib.allocation import Limits
    ref = T.eight(1.5, 0.6)
    lim = Limits(angle=np.radians(40))
    t = time.perf_counter()
    res = simulate(B, G, ref, 2 * ref.period, limits=lim)
    assert time.perf_counter() - t < 60.0                    # measured about 1 s; minutes before
    assert res.mode is not None                              # the event-located loop ran
    ev = simulate(B, G, ref, 2 * ref.period, limits=lim, integration=Integration(switching="events"))
    np.testing.assert_array_equal(res.z, ev.z)               # exact: the same code path
    assert Integration().switching == "auto"
    # where the event-located loop does not apply (no angle limit), the default is the adaptive run
    assert simulate(B, G, ref, 1.0).mode is None


def test_a_run_too_long_because_its_path_is_slow_names_the_paths_rate_not_the_gains():
    # issue 59: simulate(..., circle(theta=1e-9), ...) was refused as "body and gains: ...", although
    # Theta is what is wrong (lib.machinery.domain.rate_culprit decides, as the sweeps do)
    ref = T.circle(theta=1e-9)
    msg = _refused(lambda: simulate(B, G, ref, 2 * ref.period), r"^ref\.theta = 1e-09 rad/s")
    assert "t_end <= " in msg
    # stiff gains on an ordinary path are still named as the gains
    _refused(lambda: simulate(B, Gains(kp=1e6), T.circle(), 10.0), r"^body and gains: ")
