"""Chapter 7: the heading's verdicts under the law for P (lib.percussion.sweep, .engine)."""

import math

import numpy as np
import pytest

from lib import percussion as pc, stability, trajectories as tr
from lib.params import Body

BODY = Body()


def test_sweep_has_the_columns_of_the_papers_fig5_sweep():
    ours = pc.heading_sweep(BODY, [2.0], [0.5])
    theirs = stability.eight_rotation_sweep(BODY, [2.0], [0.5], engine="numpy", steps=64, max_periods=20)
    assert list(ours.columns) == list(theirs.columns)


def test_orbit_point_is_where_the_adaptive_zero_dynamics_settle():
    R, Th = 1.5, 0.6
    v = pc.heading_sweep(BODY, [R], [Th], steps=1024)
    assert v.regime[0] == "periodic" and v.period[0] == 1 and not v.lost[0]
    ref = tr.eight(R, Th)
    T = ref.period
    H0 = ref.z(0.0)[2]
    phi = pc.zero_dynamics_run(BODY, ref, np.array([0.0, 8 * T]), H0)
    # Magnus at 1024 steps: about 1e-9 rad per period (fourth order, see the engine's check);
    # the adaptive run at rtol 1e-11
    assert phi[-1] - H0 == pytest.approx(v.orbit_p[0], abs=1e-6)  # accuracy: the adaptive run's and the Magnus map's errors, each below 1e-8


def test_magnus_map_converges_at_fourth_order():
    from lib.percussion.engine import HeadingEngine, coefficients
    cA, cV = coefficients(BODY, [2.0], [math.pi / 4])
    ends = []
    for n in (128, 256, 512):
        eng = HeadingEngine("eight", n)
        ends.append(eng.flow(np.array([eng.H0]), cA, cV, 3)["phi"][0])
    ratio = abs(ends[0] - ends[1]) / abs(ends[1] - ends[2])
    assert 10 < ratio < 24           # 2^4 = 16 for a fourth-order method, once asymptotic


def test_below_the_lock_radius_the_circle_heading_is_lost_at_the_closed_form_drift():
    Th = 0.5
    R = 0.6 * pc.circle_lock_radius(BODY, Th)
    v = pc.heading_sweep(BODY, [R], [Th], kind="circle", steps=256)
    assert bool(v.lost[0])
    assert v.regime[0] != "chaotic"
    # slip measured over the Lyapunov run (batch means) or exact on an orbit
    assert v.slip[0] == pytest.approx(pc.circle_slip(BODY, R, Th), abs=max(3 * v.slip_stderr[0], 1e-3) + 1e-6)


def test_no_point_of_a_coarse_fig5_map_is_chaotic_and_all_are_held():
    df = pc.percussion_fig5_map(BODY, n=8)
    assert not (df.regime == "chaotic").any()
    assert (df.regime == "periodic").all() and not df.lost.any()
    # every held orbit contracts: a Moebius map's attracting fixed point
    assert (df.floquet < 1).all()


def test_sweep_validates_its_inputs():
    with pytest.raises(ValueError, match="R"):
        pc.heading_sweep(BODY, [-1.0], [0.5])
    with pytest.raises(TypeError, match="steps"):
        pc.heading_sweep(BODY, [1.0], [0.5], steps=1.5)
    with pytest.raises(TypeError, match="unknown option"):
        pc.heading_sweep(BODY, [1.0], [0.5], bogus=1)
