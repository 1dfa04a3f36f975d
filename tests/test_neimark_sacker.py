"""The quasi-periodic regime of Chapter 4 is born at a Neimark-Sacker bifurcation: along the
force cap, at a fixed angle limit, the period-1 orbit's multipliers leave the unit circle as a
complex pair, and an invariant circle turning by arg(mu) / 2 pi a period grows from it."""

from __future__ import annotations

import math

import numpy as np
import pytest

from lib.limits import switchings, torus
from lib.params import Body, Gains
from lib.trajectories import eight

#: the error of |mu| from the difference Jacobian: forward differences of step 1e-5, 1e-6 and
#: 1e-7, central differences and twice the steps a period move it by 1e-6 to 1.3e-5 at the
#: crossing (measured); |mu| changes by about 1.2 per N there
MU_ERROR = 5e-5


@pytest.fixture(scope="module")
def birth():
    return torus.torus_birth(Body(), Gains(), eight(), math.radians(torus.NS_ANGLE_DEG), torus.NS_START_CAP)


def test_orbit_loses_stability_at_the_located_cap_to_the_root_finders_xtol(birth):
    # one xtol either side of the cap, |mu| - 1 changes sign by more than the error of |mu|
    assert birth.modulus_below < 1.0 - MU_ERROR
    assert birth.modulus_above > 1.0 + MU_ERROR
    caps = birth.path.force_limit.to_numpy()
    assert min(caps[-2:]) <= birth.force_limit <= max(caps[-2:])
    assert (birth.path.residual <= 1e-9).all()  # accuracy: Newton's tolerance on the orbit


def test_crossing_multipliers_are_a_complex_pair_on_the_unit_circle(birth):
    mu = birth.multiplier
    assert mu.imag > 0.1                       # a complex pair, not a real multiplier: not a fold or a flip
    assert abs(abs(mu) - 1.0) <= max(1.0 - birth.modulus_below, birth.modulus_above - 1.0)
    assert 0.0 < birth.rotation < 0.5
    assert birth.rotation == pytest.approx(np.angle(mu) / (2 * np.pi), abs=1e-15)  # exact: the same formula


def test_crossing_is_the_same_with_twice_the_steps_a_period(birth):
    body, gains, ref, b = Body(), Gains(), eight(), math.radians(torus.NS_ANGLE_DEG)
    fine = [torus.cap_orbit(body, gains, ref, b, birth.force_limit + s * birth.xtol, birth.orbit,
                            steps_per_period=2 * torus.STEPS_PER_PERIOD) for s in (-1, 1)]
    assert fine[0].residual <= 1e-9 and fine[1].residual <= 1e-9  # accuracy: Newton's tolerance
    assert fine[0].modulus < 1.0 < fine[1].modulus


def test_rotation_on_the_invariant_circle_tends_to_arg_mu_over_2_pi(birth):
    # measured on the circle itself just past the crossing, extrapolated to it; the bound is the
    # measurement's own (2 / periods: the lift of a circle map turns N rho to within a turn)
    assert abs(birth.circle_rotation - birth.rotation) < birth.circles[0].rotation_error
    for c in birth.circles:
        assert np.sign(c.force_limit - birth.force_limit) == np.sign(birth.modulus_above - birth.modulus_below)


def test_invariant_circle_grows_as_the_square_root_of_the_distance(birth):
    # supercritical: amplitude ~ (F - F_c)^(1/2), to first order in the distances (0.01, 0.03 N)
    assert birth.amplitude_exponent == pytest.approx(0.5, abs=0.1)  # reason: first order in distances 0.01, 0.03 N
    assert all(c.amplitude < 0.5 for c in birth.circles)     # small, born at the orbit


def test_the_difference_companions_meet_the_orbits_switchings_in_the_same_number_and_order(birth):
    # the multipliers come from forward differences across Filippov switchings: at both caps
    # one xtol from the crossing, the orbit and its six companions x + h e_j locate the same
    # number of events, and at every step of the period each companion is in the orbit's mode
    census = switchings.crossing_census(Body(), Gains(), eight(), birth)
    assert census["events_min"] == census["events_max"] > 0
    assert census["differing"] == 0 and census["mode_changes_min"] > 0
    assert census["residual"] <= 1e-9          # accuracy: Newton's tolerance on the orbits
    assert census["spread"] < 1e3              # reason: the quotient stays O(1) along the period (measured 18)


def test_a_companion_across_a_switching_is_caught():
    # the census is not blind: companions 0.2 away in each coordinate (m, rad, m/s, rad/s) leave
    # the orbit's modes somewhere in the period
    body, gains, ref = Body(), Gains(), eight()
    b, f = math.radians(torus.NS_ANGLE_DEG), torus.NS_START_CAP
    x = torus.section_centre(body, gains, ref, b, f)
    census = switchings.switching_census(body, gains, ref, b, f, x, fd_step=0.2)
    assert census.differing.max() > 0
