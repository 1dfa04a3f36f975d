"""cos and sin of a stage's angle from its step's (lib.integrators.trig), against 40-digit values."""

import math

import mpmath
import numpy as np
import pytest

from lib.integrators.trig import NEAR, cos_sin_near

#: the spacing of doubles at 1
EPS = float(np.finfo(float).eps)


def _exact(x0: float, d: float) -> tuple[float, float]:
    """cos and sin of the exact sum x0 + d (both floats), to 40 digits, rounded."""
    with mpmath.workdps(40):
        x = mpmath.mpf(x0) + mpmath.mpf(d)
        return float(mpmath.cos(x)), float(mpmath.sin(x))


def test_the_addition_formulas_give_cos_and_sin_of_the_exact_sum_within_a_few_ulp():
    rng = np.random.default_rng(3)
    x0 = rng.uniform(-40.0, 40.0, 400)
    d = np.r_[rng.uniform(-NEAR, NEAR, 396), NEAR, -NEAR, 1e-300, 0.0]
    err = 0.0
    for a, b in zip(x0, d):
        c, s = cos_sin_near(math.cos(a), math.sin(a), a, b)
        ce, se = _exact(a, b)
        err = max(err, abs(c - ce), abs(s - se))
    # accuracy: the function's own error budget in units of EPS (|cos|, |sin| <= 1): libm's cos x0
    # and sin x0 within an ulp on any machine, the sum's two roundings another, the polynomials'
    # remainders below 3e-18 (d^13 / 13! at d = 1/4); measured 0.5 EPS. Below the suite's floor,
    # which is for integrations: here the last bits are the quantity tested
    assert err <= 2 * EPS


def test_at_zero_offset_the_pair_is_the_steps_own():
    c0, s0 = math.cos(2.7), math.sin(2.7)
    assert cos_sin_near(c0, s0, 2.7, 0.0) == (c0, s0)  # exact: c0 + (c0 * 0 - s0 * 0) is c0


@pytest.mark.parametrize("d", [NEAR * (1 + 1e-15), -0.3, 2.0, -7.5])
def test_beyond_the_polynomials_range_the_pair_is_libms_of_the_rounded_sum(d):
    x0 = 1.3
    c0, s0 = math.cos(x0), math.sin(x0)
    assert cos_sin_near(c0, s0, x0, d) == (math.cos(x0 + d), math.sin(x0 + d))  # exact: the same call


def test_the_compiled_pair_is_the_python_one():
    import numba

    near = numba.njit(cos_sin_near)
    rng = np.random.default_rng(5)
    for x0, d in zip(rng.uniform(-10, 10, 50), rng.uniform(-0.4, 0.4, 50)):
        c, s = near(math.cos(x0), math.sin(x0), x0, d)
        cp, sp = cos_sin_near(math.cos(x0), math.sin(x0), x0, d)
        # exact: the same operations in the same order, compiled or interpreted; numba contracts
        # no product and sum into a fused multiply-add without fastmath, and both call libm
        assert (c, s) == (cp, sp)
