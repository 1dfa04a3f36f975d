"""The price of exactness: the peak force that exact tracking needs (lib.optimal.studies.demand)."""

import math

import numpy as np
import pandas as pd
import pytest
from scipy.optimize import minimize_scalar

from lib import percussion as pc, trajectories as tr
from lib.optimal.studies import demand as dm
from lib.params import Body
from lib.percussion.engine import HeadingEngine
from lib.rotation.verdicts import FIG5_GRID

BODY = Body()
R0, TH0 = 2.0, math.pi / 4
# 4th-order Magnus at DENSE_STEPS = 2048 steps a period: the orbit's (and the peak's) relative
# error is 3.2e-7 at the grid's fastest corner of the circle (R = 4 m, Theta = 1.5 rad/s), 16
# times below its value at 1024 steps; 3x margin.
MAGNUS_RTOL = 1e-6


def _force_C(R, Th, t):
    """|m C_d'' + c C_d'| (N) on the eight at times t, from lib.trajectories' kinematics."""
    ref = tr.eight(R, Th)
    return np.hypot(*(BODY.m * ref.ddz(t)[..., :2] + BODY.c * ref.dz(t)[..., :2]).T)


def _force_P_along(ref, t, phi):
    """F = |(u1, u2)| with P on the path and heading phi(t), from lib.percussion's zero dynamics."""
    eps, s = pc.lateral_drag_speed(BODY), pc.centre_of_percussion(BODY)
    w, dw = pc.path_drive(BODY, ref, t)
    om = pc.heading_rate(BODY, phi, w)
    e1 = np.stack([np.cos(phi), np.sin(phi)], -1)
    e2 = np.stack([-e1[:, 1], e1[:, 0]], -1)
    dom = ((dw * e2).sum(-1) - (w * e1).sum(-1) * om) / eps
    return np.hypot(BODY.m * ((w * e1).sum(-1) + s * om**2), (BODY.I * dom + BODY.c_phi * om) / BODY.a)


def _sampling_bound(F, h):
    """The largest amount a max of samples spaced h can miss a smooth peak by: (h/2)^2/2 max|F''|,
    |F''| from the samples' second differences, cyclic (x2 for the difference's own error)."""
    d2 = np.abs(np.roll(F, 1) - 2 * F + np.roll(F, -1)).max() / h**2
    return 2 * (h / 2) ** 2 / 2 * d2


def test_peak_force_of_C_on_the_circle_is_R_Theta_sqrt_m2_Theta2_plus_c2():
    R = np.array([[0.25], [1.0], [2.0], [4.0]])
    Th = np.array([0.05, 0.3, math.pi / 4, 1.5])
    got = dm.exact_force_map(BODY, R, Th, kind="circle", point="C")
    assert got.shape == (4, 4)
    want = R * Th * np.sqrt(BODY.m**2 * Th**2 + BODY.c**2)
    np.testing.assert_allclose(got, want, rtol=1e-13)  # exact: |v| is constant on the circle, rounding only


def test_peak_force_of_P_on_the_circle_is_the_closed_form_steady_force():
    cases = [(R0, TH0), (1.0, 0.5), (4.0, 1.5), (0.5, 0.05)]
    got = dm.exact_force_map(BODY, [c[0] for c in cases], [c[1] for c in cases], kind="circle", point="P")
    want = [pc.circle_steady_motion(BODY, R, Th).F for R, Th in cases]
    np.testing.assert_allclose(got, want, rtol=MAGNUS_RTOL)  # accuracy: Magnus at 2048 steps, see MAGNUS_RTOL


def test_peak_force_of_C_on_the_eight_is_an_extreme_not_a_sample():
    for R, Th in ((R0, TH0), (0.25, 0.05), (4.0, 1.5)):
        F_C = float(dm.exact_force_map(BODY, R, Th))
        T = 2 * math.pi / Th
        t = np.arange(2**16) * T / 2**16
        F = _force_C(R, Th, t)
        # at or above every one of 2^16 samples, by no more than the samples can miss
        assert F_C >= F.max()
        assert F_C - F.max() <= _sampling_bound(F, t[1])
        # and the same peak by another route: scipy's bounded Brent around the samples' best
        j = int(np.argmax(F))
        r = minimize_scalar(lambda x: -_force_C(R, Th, np.array([x]))[0], bounds=(t[j] - t[1], t[j] + t[1]),
                            method="bounded", options=dict(xatol=1e-14 * T))
        assert F_C == pytest.approx(-r.fun, rel=1e-12)  # accuracy: both maximise one closed form to rounding


def test_peak_force_of_P_on_the_eight_tops_the_steady_samples_and_an_independent_dense_run():
    F_P = float(dm.exact_force_map(BODY, R0, TH0, kind="eight", point="P"))
    sm = pc.percussion_steady(BODY, "eight", R0, TH0)
    # percussion_steady's orbit is Magnus at 512 steps: its samples may sit 256 x MAGNUS_RTOL off
    assert F_P >= sm.F.max() * (1 - 256 * MAGNUS_RTOL)
    assert F_P > sm.F.max()
    # an independent route: the zero dynamics by adaptive DOP853 from the verdict's orbit point,
    # two periods to settle, then 2^16 samples of the third
    v = pc.heading_sweep(BODY, [R0], [TH0], kind="eight")
    ref = tr.eight(R0, TH0)
    T = ref.period
    t = np.concatenate([[0.0], 2 * T + np.arange(2**16) * T / 2**16])
    phi = pc.zero_dynamics_run(BODY, ref, t, HeadingEngine("eight", 2).H0 + float(v.orbit_p[0]))[1:]
    F = _force_P_along(ref, t[1:], phi)
    tol = MAGNUS_RTOL * F_P + 1e-9 * F_P  # Magnus' orbit and DOP853 at rtol 1e-11 (x100)
    assert F_P >= F.max() - tol
    assert F_P - F.max() <= _sampling_bound(F, t[2] - t[1]) + tol


def test_map_has_the_fig5_layout_and_NaN_exactly_where_the_heading_is_not_held():
    n = 4
    frame = pc.percussion_fig5_map(BODY, n=n)
    frame.loc[[1, 6], "regime"] = "quasi-periodic"
    frame.loc[9, "lost"] = True
    m = dm.exact_force_maps(BODY, n, frame=frame)
    assert list(m.columns) == ["R", "Theta", "F_C", "F_P", "ratio"]
    assert len(m) == n * n
    R, Th = np.meshgrid(np.linspace(*FIG5_GRID["R"], n), np.linspace(*FIG5_GRID["Theta"], n))
    np.testing.assert_array_equal(m.R, R.ravel())  # exact: the same grid (Theta slowest)
    np.testing.assert_array_equal(m.Theta, Th.ravel())  # exact: the same grid
    bad = np.zeros(n * n, bool)
    bad[[1, 6, 9]] = True
    assert np.isnan(m.F_P[bad]).all() and np.isfinite(m.F_P[~bad]).all() and np.isfinite(m.F_C).all()
    np.testing.assert_array_equal(m.ratio, m.F_P / m.F_C)  # exact: one division
    assert (m.ratio[~bad] > 0).all()


def test_P_below_the_circle_lock_radius_is_NaN_and_the_frame_changes_nothing_elsewhere():
    R = [0.1, 2.0]
    Th = [0.05, TH0]
    assert 0.1 < pc.circle_lock_radius(BODY, 0.05)
    got = dm.exact_force_map(BODY, R, Th, kind="circle", point="P")
    assert np.isnan(got[0]) and np.isfinite(got[1])
    frame = pc.heading_sweep(BODY, R, Th, kind="circle")
    again = dm.exact_force_map(BODY, R, Th, kind="circle", point="P", frame=frame)
    np.testing.assert_array_equal(got, again)  # exact: the same verdicts, one code path


def test_peak_search_refines_every_local_maximum_candidate():
    # two equal peaks in each row and a lower third: the candidates hold the two highest
    v = np.zeros((2, 16))
    v[:, [3, 11]] = 5.0
    v[:, 7] = 4.0
    idx = dm._candidates(v, k=2)
    assert sorted(idx[0]) == [3, 11] and sorted(idx[1]) == [3, 11]
    best = dm._golden_max(lambda s: -(s - 0.3) ** 2, np.array([0.0]), np.array([1.0]))
    # accuracy: 0.618^36 bracket (3e-8 in s), squared (~1e-15); an iteration's result, so held at
    # the floor 1e-12
    assert best[0] == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize("call, name", [
    (lambda: dm.exact_force_map("body", 1.0, 0.5), "body"),
    (lambda: dm.exact_force_map(BODY, -1.0, 0.5), "R"),
    (lambda: dm.exact_force_map(BODY, 1.0, float("nan")), "Theta"),
    (lambda: dm.exact_force_map(BODY, [1.0, 2.0], [0.5, 0.6, 0.7]), "R and Theta"),
    (lambda: dm.exact_force_map(BODY, 1.0, 0.5, kind="square"), "kind"),
    (lambda: dm.exact_force_map(BODY, 1.0, 0.5, point="Q"), "point"),
    (lambda: dm.exact_force_map(BODY, 1.0, 0.5, point="P", frame="frame"), "frame"),
    (lambda: dm.exact_force_map(BODY, 1.0, 0.5, point="P", frame=pd.DataFrame({"R": [1.0]})), "frame"),
    (lambda: dm.exact_force_map(BODY, [1.0, 2.0], 0.5, point="P",
                                frame=pc.heading_sweep(BODY, [1.0], [0.5])), "frame"),
    (lambda: dm.exact_force_map(BODY, 1.0, 0.5, point="P",
                                frame=pc.heading_sweep(BODY, [1.5], [0.5])), "frame"),
    (lambda: dm.exact_force_maps(BODY, 1), "n"),
    (lambda: dm.exact_force_maps(BODY, 2.0), "n"),
    (lambda: dm.exact_force_maps(None), "body"),
])
def test_bad_arguments_are_named(call, name):
    with pytest.raises((TypeError, ValueError), match=name):
        call()
