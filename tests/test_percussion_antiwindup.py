"""The anti-windup of the law for P under the paper's limits (lib.percussion.simulate, anti_windup)."""

import math

import numpy as np
import pytest

from lib import percussion as pc, trajectories as tr
from lib.allocation import Limits
from lib.integrators.smooth import SimulationError
from lib.params import Body, Gains
from lib.percussion.law import ANTI_WINDUP_TIME, applied_force, closed_loop_rates, error_polynomial, law_inputs
from lib.percussion.run import reference_point_kinematics

BODY, GAINS = Body(), Gains()
R0, TH0 = 2.0, math.pi / 4
EIGHT = tr.eight(R0, TH0)
CAP = 4.0  # N, the paper's Sec. 5 example
RNG = np.random.default_rng(7)


@pytest.mark.parametrize("limits", [Limits(force=CAP), Limits(force=CAP, angle=math.pi / 6)])
def test_without_anti_windup_the_capped_eight_blows_up(limits):
    with pytest.raises(SimulationError, match="blew up"):
        pc.simulate(BODY, GAINS, EIGHT, 60.0, thrust0=0.5, limits=limits)


@pytest.mark.parametrize("limits", [Limits(force=CAP), Limits(force=CAP, angle=math.pi / 6)])
def test_anti_windup_keeps_the_capped_eight_bounded_for_60_s(limits):
    t_eval = np.linspace(0.0, 60.0, 1201)
    res = pc.simulate(BODY, GAINS, EIGHT, 60.0, thrust0=0.5, limits=limits, anti_windup=True, t_eval=t_eval)
    assert res.t[-1] == 60.0
    for arr in (res.z, res.dz, res.thrust, res.F, res.beta):
        assert np.all(np.isfinite(arr))
    assert np.hypot(res.z[:, 0], res.z[:, 1]).max() < 3 * R0
    assert np.abs(res.dz).max() < 50.0          # m/s and rad/s: nothing runs away
    assert np.abs(res.thrust).max() < 10 * CAP  # the thrust state stays near what can be applied
    assert res.F.max() <= CAP * (1 + 1e-12)     # exact: clipped, rounding only
    if limits.angle is not None:
        assert np.abs(res.beta).max() <= limits.angle * (1 + 1e-12)  # exact: clipped, rounding only


@pytest.mark.parametrize("limits", [None, Limits(force=40.0, angle=math.pi)])
def test_anti_windup_changes_nothing_where_no_limit_is_active(limits):
    # no limits, and limits the run never reaches (its force peaks near 15.5 N)
    kw = dict(thrust0=0.5, limits=limits, t_eval=np.linspace(0.0, 12.0, 49))
    off = pc.simulate(BODY, GAINS, EIGHT, 12.0, **kw)
    on = pc.simulate(BODY, GAINS, EIGHT, 12.0, anti_windup=True, **kw)
    assert off.F.max() < 20.0
    for a, b in ((off.z, on.z), (off.dz, on.dz), (off.thrust, on.thrust), (off.F, on.F)):
        np.testing.assert_array_equal(a, b)  # exact: the correction is 0.0 where no limit is active


def test_anti_windup_pulls_the_thrust_state_towards_the_applied_thrust():
    # at omega = 0 (every state saturated here) the only correction is back-calculation,
    # (F cos beta - xi) / T_aw
    coeffs = error_polynomial(BODY, GAINS)
    n = 40
    t = RNG.uniform(0.0, 8.0, n)
    kd = reference_point_kinematics(EIGHT, t)
    y = np.concatenate([RNG.normal(size=(n, 3)), RNG.normal(size=(n, 2)), np.zeros((n, 1)),
                        RNG.uniform(-10.0, 10.0, (n, 1))], -1)
    lim = Limits(force=CAP, angle=math.pi / 4)
    base, F, beta = closed_loop_rates(BODY, coeffs, kd, y, lim)
    aw, F2, beta2 = closed_loop_rates(BODY, coeffs, kd, y, lim, ANTI_WINDUP_TIME)
    np.testing.assert_array_equal(base[:, :6], aw[:, :6])  # exact: the plant's rates are untouched
    np.testing.assert_array_equal(F, F2)  # exact: the same applied force
    _, u2 = law_inputs(BODY, coeffs, kd, y[:, :3], y[:, 3:6], y[:, 6])
    F0, b0 = applied_force(y[:, 6], u2)
    sat = (F0 > CAP) | (np.abs(b0) > math.pi / 4)
    assert sat.all()
    want = (F * np.cos(beta) - y[:, 6]) / ANTI_WINDUP_TIME
    # exact: the back-calculation term in closed form, up to the rounding of nu (N/s) in the difference
    np.testing.assert_allclose(aw[:, 6] - base[:, 6], want, rtol=1e-12, atol=1e-12 * np.abs(base[:, 6]).max())
    # the correction points from xi to the applied thrust
    assert np.all(np.sign(aw[:, 6] - base[:, 6]) == np.sign(F * np.cos(beta) - y[:, 6]))
    # and with a cap these states never reach, there is none
    loose = Limits(force=1e9)
    np.testing.assert_array_equal(closed_loop_rates(BODY, coeffs, kd, y, loose)[0],
                                  closed_loop_rates(BODY, coeffs, kd, y, loose, ANTI_WINDUP_TIME)[0])  # exact: +0.0


@pytest.mark.parametrize("kw, name", [
    (dict(anti_windup="yes"), "anti_windup"),
    (dict(anti_windup=1), "anti_windup"),
    (dict(anti_windup=True, anti_windup_time=-0.5), "anti_windup_time"),
    (dict(anti_windup_time=float("nan")), "anti_windup_time"),
])
def test_bad_anti_windup_arguments_are_named(kw, name):
    with pytest.raises((TypeError, ValueError), match=name):
        pc.simulate(BODY, GAINS, EIGHT, 1.0, **kw)
