"""Properties of the core modules that mutation testing (``make mutation``, mutation/REPORT.md)
found unchecked: each test here kills mutants that survived the rest of the suite."""

from __future__ import annotations

import math

import numpy as np
import pytest

from lib.angles import state_difference, wrap_angle
from lib.params import Body, Gains


# ------------------------------------------------------------------ params


def test_gains_are_float_arrays_whatever_the_number_type_given():
    # integer gains are stored as floats, per axis or scalar (a gain is a real number)
    for g in (Gains(kp=[1, 2, 3], kv=4), Gains(kp=np.array([5, 6, 7]), kv=np.array([1, 1, 2]))):
        assert g.kp.dtype == float and g.kv.dtype == float
        assert g.kp.shape == g.kv.shape == (3,)


def test_gains_are_equal_only_when_both_gains_are():
    assert Gains(kp=1.0, kv=2.0) == Gains(kp=[1.0, 1.0, 1.0], kv=2.0)
    assert Gains(kp=1.0, kv=2.0) != Gains(kp=1.0, kv=3.0)       # same kp, different kv
    assert Gains(kp=1.0, kv=2.0) != Gains(kp=[1.0, 1.0, 1.5], kv=2.0)  # same kv, different kp
    assert Gains() != Body()  # not a Gains: NotImplemented, then identity


# ------------------------------------------------------------------ angles


def test_state_difference_wraps_the_heading_entry_only():
    a = np.array([1.0, 2.0, 3.0, 4.0, 5.0, 6.0])
    b = np.array([0.5, -1.0, -3.0, 10.0, 0.0, -6.0])
    d = state_difference(a, b)
    # x, y and the rates: plain differences (the rates 6 - (-6) = 12 rad/s stay 12)
    np.testing.assert_array_equal(d[[0, 1, 3, 4, 5]], (a - b)[[0, 1, 3, 4, 5]])
    # the heading: 3 - (-3) = 6 rad is the turn 6 - 2 pi
    assert d[2] == pytest.approx(6.0 - 2 * math.pi, abs=1e-15)
    assert d.dtype == float


def test_state_difference_works_on_batches_of_states_and_leaves_its_inputs_alone():
    rng = np.random.default_rng(0)
    a, b = rng.normal(size=(4, 5, 6)) * 10, rng.normal(size=(4, 5, 6)) * 10
    a0, b0 = a.copy(), b.copy()
    d = state_difference(a, b)
    assert d.shape == (4, 5, 6)
    np.testing.assert_array_equal(a, a0)
    np.testing.assert_array_equal(b, b0)
    np.testing.assert_array_equal(d[..., 2], wrap_angle(a[..., 2] - b[..., 2]))
    np.testing.assert_array_equal(np.delete(d, 2, axis=-1), np.delete(a - b, 2, axis=-1))
    # integer states: the heading's wrapped difference is not truncated to an integer
    di = state_difference([0, 0, 4, 0, 0, 0], [0, 0, 0, 0, 0, 0])
    assert di[2] == pytest.approx(4 - 2 * math.pi)
