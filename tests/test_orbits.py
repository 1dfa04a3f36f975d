"""Periodic orbits by Newton on a period map, and their Floquet multipliers (lib.orbits)."""

import math

import numpy as np
import pytest

from lib.rotation import reduced as rotation
from lib import stability
from lib.dynamics import orbits
from lib.params import Body

BODY = Body()


def circle_map(k: int, eps: float = 0.1):
    """x -> x + 2 pi / k + eps sin(k x), y -> y / 2 + sin(x) / 10: the points with sin(k x) = 0
    are orbits of period k that advance by 2 pi per k steps (slipping), with multipliers
    (1 + eps k cos(k x))^k along x and 2^-k along y."""
    def step(x):
        X, Y = x[:, 0], x[:, 1]
        out = np.column_stack([X + 2 * np.pi / k + eps * np.sin(k * X), 0.5 * Y + 0.1 * np.sin(X)])
        J = np.zeros((x.shape[0], 2, 2))
        J[:, 0, 0] = 1 + eps * k * np.cos(k * X)
        J[:, 1, 0] = 0.1 * np.cos(X)
        J[:, 1, 1] = 0.5
        return out, J
    return step


@pytest.mark.parametrize("k", [1, 3, 6])
def test_newton_finds_known_orbits_of_period_1_3_and_6(k):
    eps = 0.1
    # the attracting orbit passes through x = pi / k (cos(k x) = -1); start 0.2 rad away
    # Newton stops at a residual of tol = 1e-11 (newton_orbit's default); the orbit point is
    # then within |(DP - I)^-1| tol <= 10 tol of the exact one (the multipliers are at most
    # 0.9, so |1 - mu| >= 0.1), and the multipliers, at cos(k x) = -1 where they are flat in x,
    # move by the square of that: no more than the floor
    orb = orbits.newton_orbit(circle_map(k, eps), [[np.pi / k + 0.2, 0.3]], k, shift=[2 * np.pi, 0.0])
    assert orb.converged[0] and orb.residual[0] <= 1e-11  # accuracy: newton_orbit's tol (measured 8.9e-16)
    assert math.remainder(orb.x[0, 0] - np.pi / k, 2 * np.pi / k) == pytest.approx(0.0, abs=1e-10)  # accuracy: 10 x tol (measured 4.4e-15)
    expected = sorted([abs(1 - eps * k) ** k, 0.5 ** k], reverse=True)
    np.testing.assert_allclose(np.abs(orb.multipliers[0]), expected, rtol=1e-12)  # accuracy: the floor, second order in the point's error (measured 0)
    assert orb.attracting[0]
    # the repelling orbit through x = 0 is found too (from nearby: it repels by up to 17 per
    # k steps, so a far start leaves the region where the map is nearly linear), and is not attracting
    rep = orbits.newton_orbit(circle_map(k, eps), [[0.005, 0.0]], k, shift=[2 * np.pi, 0.0])
    # accuracy: |1 - mu| >= 0.1 again (mu >= 1.1): within 10 x tol (measured 3.3e-15), and the
    # multiplier flat in x at sin(k x) = 0: the floor (measured 2.0e-16)
    assert rep.converged[0] and abs(math.remainder(rep.x[0, 0], 2 * np.pi / k)) < 1e-10
    assert abs(rep.multipliers[0, 0]) == pytest.approx((1 + eps * k) ** k, rel=1e-12, abs=0)  # accuracy: as above
    assert not rep.attracting[0]


def test_newton_finds_the_henon_fixed_point():
    a, b = 1.4, 0.3

    def henon(x):
        X, Y = x[:, 0], x[:, 1]
        J = np.zeros((x.shape[0], 2, 2))
        J[:, 0, 0], J[:, 0, 1], J[:, 1, 0] = -2 * a * X, 1.0, b
        return np.column_stack([1 - a * X**2 + Y, b * X]), J

    xs = (-(1 - b) + math.sqrt((1 - b) ** 2 + 4 * a)) / (2 * a)
    orb = orbits.newton_orbit(henon, [[0.5, 0.1]], 1)
    # accuracy: Newton's residual tol 1e-11 times |(J - I)^-1| (multipliers -1.92 and 0.16:
    # below 2), 2e-11 (measured 1.1e-16); the multipliers move by |dJ/dX| = 2a = 2.8 times that,
    # 6e-11 (measured 2.3e-16 relative)
    np.testing.assert_allclose(orb.x[0], [xs, b * xs], rtol=0, atol=2e-11)
    lam = np.linalg.eigvals(np.array([[-2 * a * xs, 1.0], [b, 0.0]]))
    np.testing.assert_allclose(np.sort(np.abs(orb.multipliers[0])), np.sort(np.abs(lam)), rtol=1e-10)  # accuracy: as above


def test_rotation_period_map_jacobian_matches_finite_differences():
    step = rotation.rotation_period_map(BODY, "eight", [2.0, 1.0], [math.pi / 4, 1.1], steps=256)
    x = np.array([[2.5, -0.3], [3.0, 0.4]])
    _, J = step(x)
    h = 1e-6
    fd = np.stack([(step(x + h * e)[0] - step(x - h * e)[0]) / (2 * h) for e in np.eye(2)], axis=-1)
    np.testing.assert_allclose(J, fd, rtol=1e-7, atol=1e-8)  # measured 0.19 of this bound (7.9e-9 abs)


def test_paper_eight_has_an_attracting_period_one_orbit_that_the_transient_reaches():
    # the paper's eight (R = 2 m, Theta = pi/4): Newton from 10 periods of transient finds a
    # period-1 orbit; its slowest multiplier is the rate at which the simulated transient
    # from the reference start closes in on it, period after period. Both at 128 RK4 steps a
    # period (the orbit's point and the gaps agree with 512 steps to 1e-11)
    R, Th, n = 2.0, math.pi / 4, 128
    orb = rotation.rotation_orbit(BODY, "eight", [R], [Th], steps=n)
    assert orb.converged[0] and orb.attracting[0]
    lam1 = abs(orb.multipliers[0, 0])
    assert 0.9 < lam1 < 0.95
    t, p = stability.reduced_rotation(BODY, "eight", R, Th, 100, steps=n)
    p_orbit = orb.x[0, 0] - rotation._shape("eight")[0](0.0)[4]
    gap = np.abs(p[::n] - p_orbit)                  # distance at t = jT from the orbit's point
    assert gap[100] < 2e-2 * gap[20]                # measured 3.8e-3 (lam1^80 = 4.5e-3); reason: a property, a fivefold margin; the transient does reach this orbit
    rate = (gap[100] / gap[60]) ** (1 / 40)
    assert rate == pytest.approx(lam1, abs=2e-3)  # measured 2.3e-4


def test_bad_input_raises_clear_errors():
    step = circle_map(1)
    with pytest.raises(ValueError, match="period k"):
        orbits.newton_orbit(step, [[0.0, 0.0]], 0)
    with pytest.raises(ValueError, match="x0"):
        orbits.newton_orbit(step, [[np.nan, 0.0]], 1)
    with pytest.raises(ValueError, match="kind"):
        rotation.rotation_period_map(BODY, "square", [1.0], [1.0])
    with pytest.raises(ValueError, match="R"):
        rotation.rotation_period_map(BODY, "eight", [-1.0], [1.0])
    with pytest.raises(ValueError, match="shape"):
        rotation.rotation_period_map(BODY, "eight", [1.0], [1.0], steps=64)(np.zeros((2, 2)))
    with pytest.raises(ValueError, match="jacobian"):
        orbits.floquet_multipliers(np.zeros(3))


def test_rotation_lyapunov_has_the_sign_of_the_motion(perturb):
    # one point of each sign, in one vectorised run: the paper's eight settles on its
    # period-1 orbit, so its exponent is ln|slowest multiplier| / T; the fast wide eight
    # (R = 3.13 m, Theta = 0.8 rad/s, 'irregular' in Chapter 5) is chaotic, its exponent
    # positive by the verdicts' own rule, 3 standard errors (measured 0.18 and 0.20 1/s, 7.3 and
    # 6.3 SE over 60 periods from the two starts; 5.3 to 8.4 SE over 50 to 80 periods)
    R, Th = np.array([2.0, 3.134615]), np.array([math.pi / 4, 0.8])
    dp0 = perturb(np.zeros(2))
    ly = rotation.rotation_lyapunov(BODY, "eight", R, Th, periods=60, transient=20, steps=256, p0=dp0)
    orb = rotation.rotation_orbit(BODY, "eight", R[:1], Th[:1], steps=256)   # the run's steps (512: the same to 1e-12)
    expected = math.log(abs(orb.multipliers[0, 0])) * Th[0] / (2 * math.pi)
    assert ly.value[0] == pytest.approx(expected, abs=9e-4)  # measured 8.8e-5 (60 periods, 256 steps)
    assert ly.value[0] < -6 * ly.stderr[0]  # reason: a property (measured -12 SE)
    assert ly.value[1] > 3 * ly.stderr[1] and ly.value[1] > 0.05  # reason: a property, margins above
    with pytest.raises(ValueError, match="periods"):
        rotation.rotation_lyapunov(BODY, "eight", R, Th, periods=1)
