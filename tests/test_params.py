import math

import numpy as np
import pytest

from lib.params import Body, Gains


def test_defaults_are_the_papers_table():
    b = Body()
    assert (b.m, b.I, b.a, b.c, b.c_phi) == (2.0, 0.1, 0.4, 0.6, 0.1)
    g = Gains()
    np.testing.assert_array_equal(g.kp, [5.2] * 3)
    np.testing.assert_allclose(g.kv, [math.sqrt(10.4)] * 3, rtol=0, atol=0)  # exact: one expression; measured 0: the same expression


@pytest.mark.parametrize("field", ["m", "I", "a", "c", "c_phi"])
@pytest.mark.parametrize("value", [0.0, -1.0, float("nan"), float("inf")])
def test_body_rejects_non_positive_or_non_finite_values_naming_the_field(field, value):
    with pytest.raises(ValueError, match=rf"Body\.{field}\b"):
        Body(**{field: value})


@pytest.mark.parametrize("value", ["2", None, True])
def test_body_rejects_non_numbers(value):
    with pytest.raises(TypeError, match=r"Body\.m"):
        Body(m=value)


def test_body_is_frozen():
    with pytest.raises(AttributeError):
        Body().m = 3.0


@pytest.mark.parametrize("field", ["kp", "kv"])
@pytest.mark.parametrize("value", [0.0, -2.0, float("nan"), [1.0, 2.0, -1.0], [1.0, float("inf"), 1.0]])
def test_gains_reject_non_positive_or_non_finite_values_naming_the_field(field, value):
    with pytest.raises(ValueError, match=rf"Gains\.{field}\b"):
        Gains(**{field: value})


def test_gains_reject_wrong_length():
    with pytest.raises(ValueError, match=r"Gains\.kp.*length 3"):
        Gains(kp=[1.0, 2.0])


def test_gains_accept_per_axis_values_and_are_read_only():
    g = Gains(kp=[1.0, 2.0, 3.0], kv=4.0)
    np.testing.assert_array_equal(g.kp, [1.0, 2.0, 3.0])
    np.testing.assert_array_equal(g.kv, [4.0, 4.0, 4.0])
    with pytest.raises(ValueError):
        g.kp[0] = 10.0
    assert g == Gains(kp=(1, 2, 3), kv=4) and hash(g) == hash(Gains(kp=(1, 2, 3), kv=4))
