"""Every derivative the integrators use is the derivative of the quantity below it; the
angle wrap lands in (-pi, pi]; the Lyapunov estimator returns a rate in 1/s.

``tests/test_trajectories.py`` checks the references' z, dz and ddz; the jerk (the rate of
the switching function of the switched integrators needs it) and the compiled kernel's
own copy of the kinematics are checked here, each derivative against a central
difference of the one below it (h = 1e-5 s: truncation and rounding both about 1e-10).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg import expm

from lib import trajectories as T
from lib.angles import wrap_angle
from lib.dynamics import largest_lyapunov
from lib.integrators import switched_compiled
from lib.trajectories import Reference

H = 1e-5
SHAPES = [(2.0, math.pi / 4), (0.7, -1.3)]  # the paper's (R, Theta), and a small, fast, reversed one
#: tolerance of a central difference of the position's derivative d (1, 2, 3), relative to
#: R |Theta|^d: measured at most 7.1e-10 (the eight's x jerk at Theta = -1.3), most 1e-10
POS_RTOL = 7e-9  # about 10x the largest measured


def _compiled_position(kind):
    def position(R, theta, t):
        P = np.zeros(13)
        P[9], P[10], P[12] = R, theta, 0.0 if kind == "circle" else 1.0
        return tuple(np.array([switched_compiled._kin(P, float(ti)) for ti in np.ravel(t)]).T)
    return position


SOURCES = {
    "circle_position": (T.circle_position, 2001),
    "eight_position": (T.eight_position, 2001),
    # the compiled switched integrator keeps its own scalar copy of (27) and (28)
    "compiled circle": (_compiled_position("circle"), 301),
    "compiled eight": (_compiled_position("eight"), 301),
}


@pytest.mark.parametrize("R, theta", SHAPES)
@pytest.mark.parametrize("source", SOURCES)
def test_velocity_acceleration_and_jerk_are_derivatives_of_the_one_below(source, R, theta):
    position, n = SOURCES[source]
    t = np.linspace(0.0, 2 * 2 * math.pi / abs(theta), n)
    v = np.array(position(R, theta, t))
    fd = (np.array(position(R, theta, t + H)) - np.array(position(R, theta, t - H))) / (2 * H)
    for d in (1, 2, 3):  # velocity, acceleration, jerk: entries 2d, 2d + 1 (x, y)
        for axis in (0, 1):
            err = np.abs(fd[2 * (d - 1) + axis] - v[2 * d + axis]).max()
            assert err < POS_RTOL * R * abs(theta) ** d, (source, d, axis, err)


@pytest.mark.parametrize("R, theta", SHAPES)
@pytest.mark.parametrize("kind", ["circle", "eight"])
def test_heading_rate_and_acceleration_are_derivatives_of_the_heading(kind, R, theta):
    # measured: rate 1.0e-9 |Theta| and 2.0e-9 |Theta| (eight), acceleration 5.5e-9 Theta^2
    # and 1.35e-8 Theta^2 (eight; the circle's is 0 exactly); tolerances about 10x
    kin = T.KINEMATICS[kind]
    t = np.linspace(0.0, 2 * 2 * math.pi / abs(theta), 2001)
    z, dz, ddz = kin(R, theta, t)
    zp, dzp, _ = kin(R, theta, t + H)
    zm, dzm, _ = kin(R, theta, t - H)
    rate_err = np.abs((zp[:, 2] - zm[:, 2]) / (2 * H) - dz[:, 2]).max()
    acc_err = np.abs((dzp[:, 2] - dzm[:, 2]) / (2 * H) - ddz[:, 2]).max()
    assert rate_err < 2e-8 * abs(theta), rate_err  # measured 2.0e-9 |Theta|
    assert acc_err < 1.5e-7 * theta**2, acc_err  # measured 1.35e-8 Theta^2
    # and the reference objects serve the same arrays
    ref = T.make(kind, R, theta)
    np.testing.assert_array_equal(ref.dz(t)[:, 2], dz[:, 2])
    np.testing.assert_array_equal(ref.ddz(t)[:, 2], ddz[:, 2])


def test_position_kinematics_of_the_references_is_their_position_and_derivatives():
    # the scalar path the switched integrator calls (math.cos / math.sin) against the
    # array definitions: equal to rounding
    for kind in ("circle", "eight"):
        ref = T.make(kind, 1.7, 0.6)
        kin = T.position_kinematics(ref)
        for t in np.linspace(0.0, 20.0, 41):
            np.testing.assert_allclose(kin(t), T.POSITIONS[kind](1.7, 0.6, t), rtol=0, atol=1e-14)  # exact: one closed form, two code paths; measured 0


class _Wrapped(Reference):
    """The eight seen only through z, dz, ddz: a reference that is no circle or eight."""

    def __init__(self, inner):
        self.inner, self.period = inner, inner.period

    def z(self, t):
        return self.inner.z(t)

    def dz(self, t):
        return self.inner.dz(t)

    def ddz(self, t):
        return self.inner.ddz(t)


def test_jerk_of_a_generic_reference_is_the_exact_jerk():
    # position_kinematics falls back on a fourth-order central difference of ddz (h = 1e-3 s)
    # for other references; against the eight's exact jerk it is within 1.9e-12 m/s^3
    # (measured at the paper's shape, 37 times over a period), tolerance 2e-11
    ref = T.eight()
    generic, exact = T.position_kinematics(_Wrapped(ref)), T.position_kinematics(ref)
    for t in np.linspace(0.0, ref.period, 37):
        g, e = np.array(generic(t)), np.array(exact(t))
        np.testing.assert_array_equal(g[:6], e[:6])
        np.testing.assert_allclose(g[6:], e[6:], rtol=0, atol=2e-11)  # measured 1.9e-12


# ------------------------------------------------------------------ wrap_angle


def test_wrap_angle_keeps_pi_and_sends_minus_pi_to_pi():
    assert wrap_angle(np.pi) == np.pi
    assert wrap_angle(-np.pi) == np.pi
    assert wrap_angle(0.0) == 0.0
    # just inside the upper end stays where it is (just inside the lower one, -pi + 4e-16,
    # rounds to pi: the same angle to 4e-16, and inside the interval)
    assert wrap_angle(np.nextafter(np.pi, 0)) == np.nextafter(np.pi, 0)
    w = wrap_angle(np.nextafter(-np.pi, 0))
    assert -np.pi < w <= np.pi and abs(np.angle(np.exp(1j * (w - np.nextafter(-np.pi, 0))))) < 1e-15  # exact: a closed form; measured 2.4e-16


def test_wrap_angle_of_an_angle_a_hair_above_pi_is_pi_not_minus_pi():
    # pi - a is then a hair below zero and its remainder mod 2 pi rounds to 2 pi itself:
    # the bare formula gave -pi, outside (-pi, pi] (hypothesis found it through
    # control.allocate with tau = [-1, 0, 0], phi = -3.5e-16)
    for a in (np.pi + 3.5e-16, np.nextafter(np.pi, 4), 3 * np.pi + 1e-15, -np.pi + 1e-17):
        w = wrap_angle(a)
        assert -np.pi < w <= np.pi, (a, w)
    assert wrap_angle(np.array([np.pi + 3.5e-16]))[0] == np.pi


def test_wrap_angle_lands_in_the_half_open_interval_for_large_multiples():
    k = np.array([1, 2, 3, 10, 1000, 10**6, -1, -2, -3, -10, -1000, -10**6])
    for base in (0.3, -2.9, np.pi - 1e-9):
        a = base + 2 * np.pi * k
        w = wrap_angle(a)
        assert np.all((w > -np.pi) & (w <= np.pi)), w
        # the error of the input itself is |2 pi k| ulp: 1e-9 at k = 1e6
        np.testing.assert_allclose(w, base, rtol=0, atol=4 * np.spacing(2 * np.pi * np.abs(k).max()))  # measured 4.5e-10 at k = 1e6, 0.12 of the bound
    # odd multiples of pi land on pi or (after the rounding of k pi) next to -pi, inside the interval
    odd = np.pi * np.array([3, 5, -3, -5, 101, -101])
    w = wrap_angle(odd)
    assert np.all((w > -np.pi) & (w <= np.pi)) and np.allclose(np.abs(w), np.pi, rtol=0, atol=1e-13)  # exact: a closed form; measured 1.4e-14


def test_wrap_angle_keeps_array_shape_and_removes_whole_turns_only():
    a = np.linspace(-50.0, 50.0, 24).reshape(2, 3, 4)
    w = wrap_angle(a)
    assert w.shape == a.shape and w.dtype == float
    turns = (a - w) / (2 * np.pi)
    np.testing.assert_allclose(turns, np.round(turns), rtol=0, atol=1e-14)  # exact: a closed form; measured 8.9e-16
    assert np.all((w > -np.pi) & (w <= np.pi))
    assert wrap_angle([[4.0]]).shape == (1, 1)
    assert np.ndim(wrap_angle(4.0)) == 0


# ------------------------------------------------------------------ the Lyapunov estimator's scale


@pytest.mark.parametrize("a", [0.3, -0.7])
def test_lyapunov_estimate_of_exponential_growth_is_its_rate_in_per_second(a):
    # x' = a x: every interval of dt = 0.5 s stretches the separation by exp(a dt), so the
    # estimate is a (1/s); the log growth per interval, not divided by dt, would be a / 2.
    # Measured error 1.1e-16 (from x0 = 0, so that the companion's offset is not lost in
    # the rounding of a growing state); tolerance 2e-15, a floor near the rounding
    flow = lambda x, t0, t1: np.asarray(x) * math.exp(a * (t1 - t0))  # noqa: E731
    est = largest_lyapunov(flow, np.zeros(1), 0.5, 20, d0=1e-3)
    assert abs(est.value - a) < 2e-15, est.value  # exact: a closed-form flow, rounding of 20 logarithms; measured 1.1e-16
    assert est.stderr < 2e-15  # exact: a closed-form flow, rounding of 20 logarithms; measured 2.5e-17
    np.testing.assert_allclose(est.running, a, rtol=0, atol=2e-15)  # exact: a closed-form flow, rounding of 20 logarithms; measured 2.2e-16


def test_lyapunov_estimate_of_a_linear_system_is_its_largest_eigenvalue():
    # x' = A x, eigenvalues 0.2 (eigenvector v1 = [1, 0]) and -0.5 (v2 = [1, -0.7]). Started
    # along u = [0, 1] = (v1 - v2) / 0.7, the separation after time T is e^{0.2 T} v1 / 0.7 up
    # to e^{-0.5 T}: the estimate over n intervals of dt is 0.2 + ln(1 / 0.7) / (n dt) (1/s).
    # Measured error 1.1e-10 (dt = 0.7 s, n = 40: the decaying mode's tail); tolerance 1e-9
    A = np.array([[0.2, 1.0], [0.0, -0.5]])
    flow = lambda x, t0, t1: expm(A * (t1 - t0)) @ np.asarray(x)  # noqa: E731
    dt, n = 0.7, 40
    est = largest_lyapunov(flow, np.zeros(2), dt, n, d0=1e-3, direction=[0.0, 1.0])
    assert abs(est.value - (0.2 + math.log(1 / 0.7) / (n * dt))) < 1e-9, est.value  # measured 1.1e-10
