"""The compiled field of the weighted law under limits (lib.closed_loop.limited_weighted_field) against the numpy
closed loop it compiles (lib.closed_loop.ClosedLoop with the limited allocation)."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from lib import trajectories
from lib.allocation import Allocation, Limits
from lib.closed_loop import ClosedLoop, limited_weighted_field, reference_of
from lib.params import Body, Gains

BODY, GAINS = Body(), Gains()


@pytest.mark.parametrize("kind, theta", [("eight", math.pi / 4), ("circle", math.pi / 4), ("eight", -0.6)])
@pytest.mark.parametrize("force, angle_deg", [(None, None), (4.0, None), (None, 30.0), (2.5, 60.0), (3.0, 120.0)])
@pytest.mark.parametrize("weights", [(1.0, 1.0, 1.0), (1.0, 2.0, 0.3), (1.0, 0.0, 0.0)])
def test_the_compiled_weighted_field_is_the_closed_loop_to_rounding(kind, theta, force, angle_deg, weights):
    rng = np.random.default_rng(11)
    ref = trajectories.make(kind, 2.0, theta)
    limits = Limits(force, None if angle_deg is None else math.radians(angle_deg))
    loop = ClosedLoop.of(BODY, GAINS, reference_of(ref), Allocation("limited", weights), limits)
    field = limited_weighted_field(BODY, GAINS, ref, limits, weights)
    clipped = 0
    for _ in range(12):
        t, Y = rng.uniform(0, 20), rng.normal(size=(5, 6)) * [1, 1, 3, 1, 1, 2]
        want, F = loop.rates(t, Y)
        beta = loop.inputs(t, Y[:, :3], Y[:, 3:])[2]
        if force is not None:
            clipped += int(np.sum(F >= force))                                  # exact: F <= cap by construction
        if angle_deg is not None:
            clipped += int(np.sum(np.abs(beta) >= math.radians(angle_deg) - 1e-12))   # reason: on the ray, to rounding
        # accuracy: the same formulas in the same order, compiled (libm's cos and sin against numpy's, the
        # einsums' sums written out), so they agree to rounding: measured 2.8e-14 at most over 2250 states
        # of these settings (rates of order 10); the arc's Newton steps end at machine precision
        np.testing.assert_allclose(field(t, Y), want, rtol=1e-12, atol=1e-12)
        # accuracy: as above, for one state given as a (6,) array
        np.testing.assert_allclose(field(t, Y[0]), want[0], rtol=1e-12, atol=1e-12)
    assert clipped > 0 or (force is None and angle_deg is None)


def test_the_weighted_field_refuses_what_it_cannot_compile():
    ref = trajectories.make("eight", 2.0, math.pi / 4)
    with pytest.raises(ValueError, match="kind"):
        limited_weighted_field(BODY, GAINS, SimpleNamespace(_kind="ellipse", R=2.0, theta=0.5))
    with pytest.raises(ValueError, match="weights"):
        limited_weighted_field(BODY, GAINS, ref, Limits(), (0.0, 0.0, 0.0))
    with pytest.raises(ValueError, match="weights"):
        limited_weighted_field(BODY, GAINS, ref, Limits(), (1.0, -1.0, 0.0))
    with pytest.raises(TypeError, match="limits"):
        limited_weighted_field(BODY, GAINS, ref, (4.0, 0.5))
