"""Decisive verdicts on the rotation (lib.rotation.rotation_verdicts, lib.integrators.compiled.rotation_flow)."""

import math

import numpy as np
import pytest

from lib import rotation, simulate, trajectories
from lib.integrators import batch, compiled
from lib.params import Body, Gains

BODY = Body()
EIGHT = (2.0, math.pi / 4)            # the paper's eight
CHAOTIC = (3.134615, 0.8)
SLIPPING = (0.25, 1.0)


def _compiled_map(kind, R, Th, n, x, periods=1):
    h, X1, Y1, X2, Y2, _, _ = rotation._forcing(kind, n)
    tab = batch.dop853()
    A, B, C = rotation.coefficients(BODY, np.asarray(R), np.asarray(Th))
    o = compiled.rotation_flow(x[:, 0], x[:, 1], A, B, C, periods, X1, Y1, X2, Y2, tab.A * h, tab.b * h)
    return np.column_stack([o["phi"], o["w"]]), o["J"]


@pytest.mark.parametrize("kind", ["eight", "circle"])
def test_compiled_period_map_matches_numpy_map_and_its_jacobian_finite_differences(kind):
    R, Th, n = [2.0, 1.0, 3.134615], [math.pi / 4, 1.1, 0.8], 256
    x = np.array([[2.5, -0.3], [3.0, 0.4], [0.1, 0.0]])
    y, J = _compiled_map(kind, R, Th, n, x)
    y_np, J_np = rotation.rotation_period_map(BODY, kind, R, Th, steps=n)(x)
    np.testing.assert_allclose(y, y_np, rtol=0, atol=1e-12)
    np.testing.assert_allclose(J, J_np, rtol=0, atol=1e-11 * max(1.0, np.abs(J_np).max()))
    h = 1e-6
    fd = np.stack([(_compiled_map(kind, R, Th, n, x + h * e)[0] - _compiled_map(kind, R, Th, n, x - h * e)[0])
                   / (2 * h) for e in np.eye(2)], axis=-1)
    np.testing.assert_allclose(J, fd, rtol=1e-6, atol=1e-7)
    # three periods at once are three maps in a row, the Jacobian by the chain rule
    y3, J3 = _compiled_map(kind, R, Th, n, x, periods=3)
    z, Jz = x, np.tile(np.eye(2), (3, 1, 1))
    for _ in range(3):
        z, Jk = _compiled_map(kind, R, Th, n, z)
        Jz = Jk @ Jz
    np.testing.assert_allclose(y3, z, rtol=0, atol=1e-12)
    np.testing.assert_allclose(J3, Jz, rtol=1e-10, atol=1e-12)


def _full_loop_period(R, Th, p, dp, periods=1, steps=512):
    """The full 6-state closed loop (solve_ivp, rtol = atol = 1e-11) from the reference with
    heading error p (rad), dp/dt (rad/s), over ``periods`` periods: (t, p(t), dp/ds(t))."""
    ref = trajectories.eight(R, Th)
    T = 2 * math.pi / Th
    t = np.linspace(0.0, periods * T, periods * steps + 1)
    res = simulate.simulate(BODY, Gains(), ref, float(t[-1]), z0=ref.z(0.0) + [0, 0, p], dz0=ref.dz(0.0) + [0, 0, dp],
                            t_eval=t, integration=simulate.Integration(rtol=1e-11, atol=1e-11))
    return t, res.rotation_error(), (res.dz[:, 2] - res.dz_d[:, 2]) / Th


def test_paper_eight_is_period_one_and_its_orbit_is_an_orbit_of_the_full_closed_loop(perturb):
    p0 = float(perturb([0.0])[0])
    df = rotation.eight_rotation_sweep(BODY, [EIGHT[0]], [EIGHT[1]], p0=p0)
    row = df.iloc[0]
    assert row.regime == "periodic" and row.period == 1 and not row.lost
    assert 0.92 < row.floquet < 0.945 and row.residual <= 1e-10
    # the orbit itself: started on it, the full closed loop (solve_ivp) comes back after one period
    orb = rotation.rotation_attractor(BODY, "eight", *EIGHT, p0=p0)
    assert abs(orb.multipliers[0]) == pytest.approx(row.floquet, rel=1e-9) and abs(orb.multipliers[1]) < 0.01
    t, p, dp = _full_loop_period(*EIGHT, *orb.states[0])
    assert abs(p[-1] - p[0]) < 1e-7
    r_ref = rotation.sampled_range(p[None, 1:], dy=dp[None, 1:], h=2 * math.pi / 512)[0]   # Hermite-refined
    assert r_ref == pytest.approx(row["range"], abs=1e-6)
    assert orb.range == pytest.approx(row["range"], abs=1e-12)
    from scipy.interpolate import CubicSpline

    assert CubicSpline(orb.t, orb.p)(t) == pytest.approx(p, abs=1e-5)    # the orbit's p(t) is the loop's
    # Lyapunov exponent of an orbit: ln of its slowest multiplier per period, negative
    assert row.lyapunov == pytest.approx(math.log(row.floquet) * EIGHT[1] / (2 * math.pi), rel=1e-12)


def test_the_eight_has_two_mirror_image_orbits_and_each_start_reaches_its_own():
    a = rotation.rotation_attractor(BODY, "eight", *EIGHT, p0=0.0)
    b = rotation.rotation_attractor(BODY, "eight", *EIGHT, p0=1.0)
    c = rotation.rotation_attractor(BODY, "eight", *EIGHT, p0=-1.0)
    assert abs(a.states[0, 0] - b.states[0, 0]) > 0.1                  # two different orbits
    np.testing.assert_allclose(b.states, c.states, atol=1e-9)           # +-1 reach the same one
    np.testing.assert_allclose(np.abs(a.multipliers), np.abs(b.multipliers), rtol=1e-8)
    assert a.range == pytest.approx(b.range, abs=1e-9)
    # mirror images: the extremes swap sign
    assert a.p.max() == pytest.approx(-b.p.min(), abs=1e-6) and a.p.min() == pytest.approx(-b.p.max(), abs=1e-6)


def test_slipping_point_loses_one_turn_per_period_as_the_full_closed_loop_does(perturb):
    p0 = float(perturb([0.0])[0])
    row = rotation.eight_rotation_sweep(BODY, [SLIPPING[0]], [SLIPPING[1]], p0=p0).iloc[0]
    assert row.regime == "slipping" and row.period == 1 and row.lost
    assert row.slip == pytest.approx(1.0, abs=1e-12) and row.floquet < 0.9
    # solve_ivp on the full closed loop from the reference start: after the verdict's periods
    # p advances by the same whole turns every period
    n = int(row.periods) + 4
    t, p, _ = _full_loop_period(*SLIPPING, p0, 0.0, periods=n, steps=64)
    per = p[64::64]
    d = np.diff(per[-4:])
    np.testing.assert_allclose(d, 2 * np.pi * row.slip, atol=1e-4)


def test_period_three_orbit_is_found_and_is_an_orbit(perturb):
    p0 = float(perturb([0.0])[0])
    R, Th = 0.553030, 0.372222
    row = rotation.eight_rotation_sweep(BODY, [R], [Th], p0=p0).iloc[0]
    assert row.regime == "periodic" and row.period == 3 and row.floquet < 0.5
    orb = rotation.rotation_attractor(BODY, "eight", R, Th, p0=p0)
    step = rotation.rotation_period_map(BODY, "eight", [R], [Th], steps=int(row.steps))
    x0 = np.array([[orb.states[0, 0] + rotation._shape("eight")[0](0.0)[4],
                    orb.states[0, 1] / Th + rotation._shape("eight")[0](0.0)[5]]])
    x, xs = x0, []
    for _ in range(3):
        x, _ = step(x)
        xs.append(x[0])
    assert np.abs(xs[-1] - x0[0]).max() < 1e-9                         # numpy map: period 3
    assert np.abs(xs[0] - x0[0]).max() > 1e-3                          # and not period 1


def test_chaotic_point_has_a_positive_lyapunov_exponent_like_the_numpy_reference(perturb):
    p0 = float(perturb([0.0])[0])
    row = rotation.eight_rotation_sweep(BODY, [CHAOTIC[0]], [CHAOTIC[1]], p0=p0).iloc[0]
    assert row.regime == "chaotic" and row.period == 0
    assert row.lyapunov > 5 * row.lyapunov_stderr and 0.1 < row.lyapunov < 0.4
    ref = rotation.rotation_lyapunov(BODY, "eight", [CHAOTIC[0]], [CHAOTIC[1]], periods=100, transient=20,
                                     steps=int(row.steps), p0=p0)
    assert abs(row.lyapunov - ref.value[0]) < 4 * math.hypot(row.lyapunov_stderr, 2 * ref.stderr[0])
    with pytest.raises(ValueError, match="no attracting orbit"):
        rotation.rotation_attractor(BODY, "eight", *CHAOTIC, p0=p0)


def test_sweep_columns_and_the_lost_definition(perturb):
    R = np.array([2.0, 3.134615, 0.25, 1.0, 0.553030])
    Th = np.array([math.pi / 4, 0.8, 1.0, 0.8, 0.372222])
    df = rotation.eight_rotation_sweep(BODY, R, Th, p0=perturb(np.zeros(5)))
    for col in ("R", "Theta", "regime", "period", "range", "floquet", "lyapunov", "lyapunov_stderr", "slip",
                "lost", "steps", "residual", "periods", "reason"):
        assert col in df
    np.testing.assert_array_equal(df.R, R)
    assert list(df.regime) == ["periodic", "chaotic", "slipping", "periodic", "periodic"]
    assert set(df.regime) <= set(rotation.REGIMES)
    orbit = df.regime.isin(["periodic", "slipping"])
    drifting = ~orbit & (df.slip.abs() > 3 * df.slip_stderr + 1e-3)
    np.testing.assert_array_equal(df.lost, (df.regime == "slipping") | drifting)
    assert (df.floquet[orbit] < 1).all() and (df.residual[orbit] <= 1e-10).all()


def test_engines_agree_on_the_verdicts():
    R, Th = np.array([3.0, 0.25]), np.array([0.3, 1.0])
    a = rotation.eight_rotation_sweep(BODY, R, Th, max_periods=20)
    b = rotation.eight_rotation_sweep(BODY, R, Th, max_periods=20, engine="numpy")
    assert list(a.regime) == list(b.regime) == ["periodic", "slipping"]
    np.testing.assert_allclose(a["range"], b["range"], atol=1e-9)
    np.testing.assert_allclose(a.floquet, b.floquet, rtol=1e-8)


@pytest.mark.parametrize("kwargs, exc, match", [
    (dict(R=[-1.0], Theta=[0.5]), ValueError, "R must be positive"),
    (dict(R=[np.nan], Theta=[0.5]), ValueError, "finite"),
    (dict(R=[1.0], Theta=[0.5], max_period=0), ValueError, "max_period"),
    (dict(R=[1.0], Theta=[0.5], block=1), ValueError, "block"),
    (dict(R=[1.0], Theta=[0.5], newton_tol=-1.0), ValueError, "newton_tol"),
    (dict(R=[1.0], Theta=[0.5], transient=1.5), TypeError, "transient"),
    (dict(R=[1.0], Theta=[0.5], max_lag=4), TypeError, "unknown option"),
    (dict(R=[1.0], Theta=[0.5], engine="fortran"), ValueError, "engine"),
    (dict(R=[1.0], Theta=[0.5], p0=np.nan), ValueError, "p0"),
])
def test_bad_input_raises_clear_errors(kwargs, exc, match):
    R, Th = kwargs.pop("R"), kwargs.pop("Theta")
    with pytest.raises(exc, match=match):
        rotation.eight_rotation_sweep(BODY, R, Th, **kwargs)


def test_bad_kind_and_bad_attractor_input():
    with pytest.raises(ValueError, match="kind"):
        rotation.rotation_verdicts(BODY, "square", [1.0], [0.5])
    with pytest.raises(TypeError, match="body"):
        rotation.rotation_verdicts(None, "eight", [1.0], [0.5])
    with pytest.raises(TypeError, match="R"):
        rotation.rotation_attractor(BODY, "eight", [2.0], 0.5)
    with pytest.raises(ValueError, match="Theta"):
        rotation.rotation_attractor(BODY, "eight", 2.0, -0.5)


def test_fused_rates_of_the_compiled_variational_equation_are_the_two_definitions_bit_for_bit():
    from lib.rotation_field import rotation_rates, rotation_rates_dphi, rotation_rates_with_dphi

    rng = np.random.default_rng(11)
    phi, w, A, B, C, X1, Y1, X2, Y2 = rng.uniform(-5, 5, (9, 1000))
    dphi, dw, d = rotation_rates_with_dphi(phi, w, A, B, C, X1, Y1, X2, Y2)
    ref = rotation_rates(phi, w, A, B, C, X1, Y1, X2, Y2)
    np.testing.assert_array_equal(dphi, ref[0])
    np.testing.assert_array_equal(dw, ref[1])
    np.testing.assert_array_equal(d, rotation_rates_dphi(phi, B, C, X1, Y1, X2, Y2))


def test_orbits_are_measured_on_the_fine_map_whatever_the_verdict_map():
    # the verdict map (h omega <= 0.25) decides; the orbit's range comes from the fine map
    # (h omega <= 0.125): two verdict maps give the same orbit to Newton's tolerance
    R, Th = np.array([2.0, 0.553030, 0.25]), np.array([math.pi / 4, 0.372222, 1.0])
    a = rotation.eight_rotation_sweep(BODY, R, Th)
    b = rotation.eight_rotation_sweep(BODY, R, Th, h_verdict=0.125)
    assert (a.verdict_steps < a.steps).all() and (b.verdict_steps == b.steps).all()
    assert list(a.regime) == list(b.regime) and list(a.period) == list(b.period)
    np.testing.assert_allclose(a["range"], b["range"], atol=1e-9)
    np.testing.assert_allclose(a.floquet, b.floquet, rtol=1e-8)
