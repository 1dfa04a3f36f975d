"""The batch integrator (lib.integrators.batch): its schemes have their stated order and
advance many points as one array."""

import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from lib.integrators import batch


def test_rk4_on_a_linear_equation_is_its_degree_4_taylor_polynomial_per_step():
    lam = np.array([-1.0, -0.3 + 2.0j, 0.5])
    h, n = 0.1, 37
    _, y = batch.integrate(lambda t, y: lam * y, np.ones(3, complex), 0.0, n * h, h, batch.RK4)
    z = lam * h
    np.testing.assert_allclose(y[-1], (1 + z + z**2 / 2 + z**3 / 6 + z**4 / 24) ** n, rtol=1e-13)  # exact: RK4's closed form on a linear equation, rounding of 37 steps; measured 3.5e-15


@pytest.mark.parametrize("tableau,order", [(batch.RK4, 4), (batch.dop853(), 8)])
def test_global_error_falls_with_the_order_of_the_scheme(tableau, order):
    # y' = cos(t) y, y(0) = 1: y = exp(sin t); halving the step divides the error by 2^order
    errors = []
    for n in (8, 16):
        _, y = batch.integrate(lambda t, y: math.cos(t) * y, np.ones(1), 0.0, 3.0, 3.0 / n, tableau)
        errors.append(abs(y[-1, 0] - math.exp(math.sin(3.0))))
    rate = math.log2(errors[0] / errors[1])
    assert order - 0.6 < rate < order + 1.5, (errors, rate)


def test_points_are_independent_rows():
    # two points with their own parameter, integrated together, equal each run alone
    k = np.array([[0.5], [2.0]])
    rates = lambda t, y: -k * y + np.sin(t)  # noqa: E731
    _, both = batch.integrate(rates, np.ones((2, 1)), 0.0, 2.0, 0.01, batch.RK4)
    for i in range(2):
        _, one = batch.integrate(lambda t, y, i=i: -k[i] * y + np.sin(t), np.ones(1), 0.0, 2.0, 0.01, batch.RK4)
        np.testing.assert_array_equal(both[:, i], one)


def test_recording_and_blow_up():
    t, y = batch.integrate(lambda t, y: y, np.ones(1), 0.0, 1.0, 0.1, batch.RK4, record_every=3)
    np.testing.assert_allclose(t, [0.0, 0.3, 0.6, 0.9, 1.0], rtol=0, atol=1e-15)  # exact: the record times, sums of the step; measured 1.1e-16
    with pytest.raises(FloatingPointError, match="non-finite at t = .* for point 1"), np.errstate(over="ignore",
                                                                                              invalid="ignore"):
        batch.integrate(lambda t, y: np.array([[0.0], [1.0]]) * y**2, np.ones((2, 1)), 0.0, 5.0, 0.05)


@settings(max_examples=80, deadline=None)
@given(t0=st.floats(-50.0, 50.0), length=st.floats(1e-3, 100.0), ratio=st.floats(0.5, 400.0))
def test_the_step_never_exceeds_the_requested_dt_and_is_the_largest_that_divides_the_interval(t0, length, ratio):
    # integrate's contract: the largest step h <= dt with n h = t_end - t0 (n = ceil((t_end - t0) / dt));
    # a step count rounded down instead would take steps longer than the dt the caller asked for
    dt, t_end = length / ratio, t0 + length
    t, _ = batch.integrate(lambda t, y: -y, np.ones(1), t0, t_end, dt, batch.RK4)
    n = len(t) - 1                                       # record_every = 1: one record a step
    h = (t_end - t0) / n
    eps = np.finfo(float).eps
    assert h <= dt * (1 + 4 * eps)  # exact: h = L / ceil(fl(L / dt)) <= dt up to the rounding of two divisions
    if n > 1:                                            # and one step fewer would exceed dt
        assert (t_end - t0) / (n - 1) > dt * (1 - 4 * eps)  # exact: as above
    # the recorded times advance by h (each t0 + k h, rounded)
    np.testing.assert_allclose(np.diff(t), h, rtol=0, atol=8 * eps * max(abs(t0), abs(t_end), h))  # exact: t0 + k h rounded, a few ulp of |t|


def test_an_interval_that_is_not_a_multiple_of_dt_takes_the_next_whole_count_of_steps():
    t, _ = batch.integrate(lambda t, y: -y, np.ones(1), 0.0, 1.0, 0.3, batch.RK4)
    np.testing.assert_allclose(t, [0.0, 0.25, 0.5, 0.75, 1.0], rtol=0, atol=1e-15)  # exact: sums of the step 1 / 4; measured 0
