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


def _magnus_period(eng, phi, cA, cV):
    """One period of the engine's Magnus steps written out in numpy, independently of its kernel:
    Omega = [[P, Q + R], [Q - R, -P]] from the two Gauss points, exp(Omega) = c0 I + c1 Omega
    (Omega^2 = d I); the heading phi = 2 theta; log d phi_end / d phi_0 = -2 sum log |E x|."""
    th, log, h, ps, dps, signs = phi / 2, np.zeros_like(phi), eng.h, [], [], set()
    for j in range(eng.n):
        a = cA[:, None] * eng.Y2[j] + cV[:, None] * eng.Y1[j]
        b = cA[:, None] * eng.X2[j] + cV[:, None] * eng.X1[j]
        P, Q = h / 4 * b.sum(1), h / 4 * a.sum(1)
        R = math.sqrt(3) / 24 * h * h * (b[:, 1] * a[:, 0] - a[:, 1] * b[:, 0])
        d = P * P + Q * Q - R * R
        signs |= set(np.sign(d).tolist())
        r = np.sqrt(np.abs(d))
        c0 = np.where(d >= 0, np.cosh(r), np.cos(r))
        c1 = np.where(d >= 0, np.sinh(r), np.sin(r)) / r
        E = np.stack([[c0 + c1 * P, c1 * (Q + R)], [c1 * (Q - R), c0 - c1 * P]])      # (2, 2, N)
        x = np.stack([np.cos(th), np.sin(th)])
        y = np.einsum("ijn,jn->in", E, x)
        th = th + np.arctan2(x[0] * y[1] - x[1] * y[0], x[0] * y[0] + x[1] * y[1])
        log -= 2 * np.log(np.hypot(*y))
        ps.append(2 * th - eng.H[j])
        al, be = cA * eng.eY2[j] + cV * eng.eY1[j], cA * eng.eX2[j] + cV * eng.eX1[j]
        dps.append(al * np.cos(2 * th) - be * np.sin(2 * th) - eng.H1[j])
    assert signs == {-1.0, 1.0}          # both branches of exp(Omega) taken
    return 2 * th - eng.w2pi, log, np.stack(ps, -1), np.stack(dps, -1)


@pytest.mark.parametrize("kind", ["eight", "circle"])
def test_the_compiled_magnus_flow_is_the_step_written_out(kind):
    from lib.percussion.engine import HeadingEngine
    rng = np.random.default_rng(7)
    # coefficients up to 150 on a coarse mesh, so that steps of both signs of d occur
    cA, cV = rng.uniform(0.5, 150.0, 40), rng.uniform(0.1, 20.0, 40)
    eng = HeadingEngine(kind, 16)
    phi0 = rng.uniform(-np.pi, np.pi, 40)
    o = eng.flow(phi0, cA, cV, 2, record=True)
    end1, log1, p1, dp1 = _magnus_period(eng, phi0, cA, cV)
    end2, log2, _, _ = _magnus_period(eng, end1, cA, cV)
    # accuracy: the same operations up to rounding, 16 steps of them: 1e-12 rad (measured 6e-14)
    np.testing.assert_allclose(o["sec"], [end1, end2], rtol=0, atol=1e-12)
    # accuracy: logs up to a few hundred, summed over 16 steps: 1e-12 relative (measured 1.5e-14)
    np.testing.assert_allclose(o["logs"], [log1, log2], rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(o["p"][:, :16], p1, rtol=0, atol=1e-12)       # accuracy: as the headings
    # accuracy: rates of order cA (up to 150) at headings good to 1e-12 (measured 6e-12)
    np.testing.assert_allclose(o["dp"][:, :16], dp1, rtol=0, atol=1e-9)
    assert o["p"].shape == o["dp"].shape == (40, 32)
    np.testing.assert_array_equal(o["phi"], o["sec"][-1])


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
