import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from lib import trajectories as T

radii = st.floats(0.1, 5.0)
rates = st.floats(0.05, 2.0) | st.floats(-2.0, -0.05)


def _fd_check(ref, t):
    h = 1e-5
    for fun, der in ((ref.z, ref.dz), (ref.dz, ref.ddz)):
        fd = (fun(t + h) - fun(t - h)) / (2 * h)
        np.testing.assert_allclose(fd, der(t), rtol=1e-7, atol=1e-7 * max(1.0, ref.R))  # measured 8.3e-9 over 300 draws: O(h^2) difference


@given(R=radii, theta=rates)
@settings(max_examples=50, deadline=None)
def test_trajectory_derivatives_agree_with_finite_differences(R, theta):
    t = np.linspace(0.0, 3 * 2 * np.pi / abs(theta), 997)
    _fd_check(T.circle(R, theta), t)
    _fd_check(T.eight(R, theta), t)


@given(R=radii, theta=rates)
@settings(max_examples=50, deadline=None)
def test_eight_heading_is_the_tangent_and_continuous(R, theta):
    ref = T.eight(R, theta)
    t = np.linspace(0.0, 4 * ref.period, 40001)
    z, dz = ref.z(t), ref.dz(t)
    tangent = np.arctan2(dz[:, 1], dz[:, 0])
    np.testing.assert_allclose(np.angle(np.exp(1j * (z[:, 2] - tangent))), 0.0, rtol=0, atol=1e-14)  # exact: two closed forms; measured 1.1e-15
    # continuous: steps bounded by max |phi_d'| * dt, far from 2 pi
    step = np.abs(np.diff(z[:, 2]))
    assert step.max() <= np.abs(dz[:, 2]).max() * (t[1] - t[0]) * 1.01
    # exact: a closed form; periodic: no net turn over a period
    np.testing.assert_allclose(ref.z(t[-1])[2], ref.z(0.0)[2], rtol=0, atol=1e-13)  # measured 0; the floor is the rounding of Theta t after four periods


def test_eight_heading_matches_papers_arg_modulo_two_pi():
    ref = T.eight(2.0, 0.7)
    t = np.linspace(0, 30, 3001)
    s = 0.7 * t
    paper = np.angle(np.cos(2 * s) + 1j * np.cos(s))
    np.testing.assert_allclose(np.angle(np.exp(1j * (ref.z(t)[:, 2] - paper))), 0.0, rtol=0, atol=1e-14)  # exact: two closed forms; measured 6.4e-16
    assert np.abs(np.diff(paper)).max() > 6.0  # the printed Arg jumps by 2 pi


def test_circle_is_the_papers_eq27():
    ref = T.circle(2.0, np.pi / 4)
    t = np.array([0.0, 1.0, 2.0])
    s = np.pi / 4 * t
    np.testing.assert_allclose(ref.z(t), np.c_[2 * np.cos(s), 2 * np.sin(s), s + np.pi / 2], rtol=0, atol=1e-15)  # exact: two closed forms; measured 0
    assert ref.z(1.0).shape == (3,) and ref.z(np.zeros((2, 5))).shape == (2, 5, 3)


@pytest.mark.parametrize("R,theta,msg", [(0.0, 1.0, "radius R must be positive"), (-1.0, 1.0, "radius R"),
                                         (1.0, 0.0, "theta must be non-zero"), (np.nan, 1.0, "R must be a finite"),
                                         (1.0, np.inf, "theta must be a finite")])
def test_bad_trajectory_parameters_raise(R, theta, msg):
    for factory in (T.circle, T.eight):
        with pytest.raises(ValueError, match=msg):
            factory(R, theta)


def test_unknown_trajectory_name_raises():
    with pytest.raises(ValueError, match=r"^name must be one of .*got 'square'"):
        T.make("square", 1.0, 1.0)
    assert isinstance(T.make("eight", 1.0, 1.0), T.Eight)


def test_batch_kinematics_equal_the_reference_objects_point_by_point():
    R = np.array([0.5, 2.0, 3.5])
    theta = np.array([0.1, -0.7, 1.4])
    t = np.linspace(0, 20, 7)[:, None]
    for name, kin in T.KINEMATICS.items():
        batch = kin(R, theta, t)
        for j in range(3):
            ref = T.make(name, R[j], theta[j])
            for k, method in enumerate((ref.z, ref.dz, ref.ddz)):
                np.testing.assert_array_equal(batch[k][:, j], method(t[:, 0]))


def test_heading_turns_counts_the_paths_heading_over_a_period():
    # the circle's tangent turns once a period (backwards when run backwards), the eight's returns
    from lib.trajectories import circle, eight, heading_turns
    assert heading_turns(circle(2.0, 0.7)) == 1
    assert heading_turns(circle(2.0, -0.7)) == -1
    assert heading_turns(eight(2.0, 0.7)) == 0
