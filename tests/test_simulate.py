import numpy as np
import pytest

from lib import control, trajectories as T
from lib.params import Body, Gains
from lib.allocation import Limits
from lib.simulate import Integration, SimulationError, simulate


@pytest.mark.parametrize("ref", [T.circle(), T.eight()], ids=["circle", "eight"])
def test_position_error_follows_eq24_analytically(ref):
    body, gains = Body(), Gains()
    res = simulate(body, gains, ref, 40.0)
    e_exact = control.error_dynamics_solution(body, gains, res.error[0], res.derror[0], res.t)
    assert np.abs(res.error[:, :2] - e_exact[:, :2]).max() < 7e-10  # measured 6.8e-11
    # and the analytic solution has decayed: (29)-(30)
    assert np.abs(e_exact[-1, :2]).max() < 1e-12  # exact: the closed form at 40 s (measured 1.1e-14)
    # accuracy: the simulation's error is then its integration error, 10 x atol = 1e-10 (measured 1.4e-14)
    assert np.abs(res.error[-1, :2]).max() < 1e-9


def test_result_frame_has_one_row_per_sample():
    res = simulate(Body(), Gains(), T.circle(), 2.0, t_eval=np.linspace(0, 2, 11))
    df = res.to_frame()
    assert len(df) == 11 and {"t_s", "x_m", "ex_m", "F_N", "beta_rad"} <= set(df.columns)
    np.testing.assert_allclose(df["ex_m"], res.z_d[:, 0] - res.z[:, 0], rtol=1e-15)  # exact: one code path; measured 0
    np.testing.assert_allclose(res.rotation_error(), -res.error[:, 2], rtol=1e-15)  # exact: one code path; measured 0


def test_default_initial_state_is_the_papers_table():
    res = simulate(Body(), Gains(), T.circle(), 1.0)
    np.testing.assert_allclose(res.z[0], [1.0, 0.0, np.pi / 2], rtol=1e-15)  # exact: the initial value given; measured 0
    np.testing.assert_allclose(res.dz[0], 0.0, atol=1e-15)  # exact: the initial value given; measured 0


def test_force_limit_is_respected_along_the_solution():
    res = simulate(Body(), Gains(), T.eight(), 20.0, limits=Limits(force=4.0), integration=Integration(rtol=1e-8, atol=1e-8))
    assert res.F.max() <= 4.0 and np.isclose(res.F.max(), 4.0, rtol=0, atol=1e-15)  # exact: the clipped value itself; measured 0


class _Exploding:
    period = 1.0

    def z(self, t):
        return np.zeros(np.shape(t) + (3,))

    dz = z

    def ddz(self, t):
        return np.stack(np.broadcast_arrays(np.exp(np.asarray(t) * 50.0), 0.0 * np.asarray(t), 0.0 * np.asarray(t)), -1)


def test_blow_up_raises_with_time_and_variable():
    # a threshold of 1e4 is crossed at t = 0.26 s (the default 1e8 at 0.45 s, after 20 s of
    # ever shorter steps: the property is the same)
    with pytest.raises(SimulationError, match=r"blew up at t = 0\.26\d* s: \|xdot\| reached 10000"):
        simulate(Body(), Gains(), _Exploding(), 5.0, integration=Integration(blowup=1e4))


class _NaNRef(_Exploding):
    def ddz(self, t):
        return np.where(np.asarray(t)[..., None] > 0.5, np.nan, 0.0) * np.ones(3)


def test_non_finite_solution_raises_naming_the_time():
    with pytest.raises(SimulationError, match=r"non-finite at t = 0\.5"):
        simulate(Body(), Gains(), _NaNRef(), 2.0)


@pytest.mark.parametrize("kw,exc,msg", [
    ({"t_end": 0.0}, ValueError, "t_end must be positive"),
    ({"t_end": np.nan}, ValueError, "t_end must be a finite"),
    ({"z0": [1.0, 2.0]}, ValueError, r"z0 must have shape \(3,\)"),
    ({"dz0": [0.0, np.nan, 0.0]}, ValueError, r"dz0\[1\] must be finite"),
    ({"limits": (4.0, 1.0)}, TypeError, "limits must be a lib.allocation.Limits"),
    ({"integration": {"rtol": 1e-8}}, TypeError, "integration must be a lib.integrators.smooth.Integration"),
    ({"t_eval": [0.0, 2.0]}, ValueError, "t_eval"),
    ({"ref": "circle"}, TypeError, "ref must be a reference"),
    ({"body": None}, TypeError, "body must be"),
])
def test_simulate_rejects_bad_input(kw, exc, msg):
    args = dict(body=Body(), gains=Gains(), ref=T.circle(), t_end=1.0)
    args.update(kw)
    with pytest.raises(exc, match=msg):
        simulate(**args)


@pytest.mark.parametrize("make,msg", [
    (lambda: Limits(force=-1.0), "^force must"),
    (lambda: Limits(angle=7.0), "^angle must"),
    (lambda: Limits(force=np.nan), "^force must"),
    (lambda: Integration(rtol=0.0), "rtol"),
    (lambda: Integration(atol=np.nan), "atol"),
    (lambda: Integration(switching="magic"), "switching"),
])
def test_option_groups_reject_bad_values_on_construction(make, msg):
    with pytest.raises(ValueError, match=msg):
        make()


@pytest.mark.parametrize("kind, theta", [("eight", np.pi / 4), ("circle", np.pi / 4), ("eight", -0.6),
                                         ("circle", -1.2)])
@pytest.mark.parametrize("limits", [Limits(), Limits(3.0, None), Limits(None, 0.5), Limits(2.5, 1.2)])
def test_the_compiled_rates_of_the_paper_law_are_the_closed_loop_to_rounding(kind, theta, limits):
    from lib.allocation import Allocation
    from lib.closed_loop import ClosedLoop, paper_rates, reference_of
    from lib.tracking.mismatch import model_of
    body, gains = Body(), Gains()
    rng = np.random.default_rng(5)
    ref = T.make(kind, 2.0, theta)
    for model in (None, model_of(body, m=0.2, c=-0.1)):
        fast = paper_rates(body, gains, ref, None, limits, model)
        loop = ClosedLoop.of(body, gains, reference_of(ref), None, limits, model)
        clipped = 0
        for _ in range(25):
            t, s = rng.uniform(0, 30), rng.normal(size=(4, 6)) * [1, 1, 3, 1, 1, 2]
            want, F = loop.rates(t, s)
            clipped += int(np.sum(F >= (limits.force or np.inf)))                 # exact: F = min(F, cap)
            # accuracy: the same operations in the same order, compiled (libm's atan2, hypot, cos and sin
            # against numpy's): measured 1.1e-13 at most over 3200 states, rates of order 10
            np.testing.assert_allclose(fast(t, s), want, rtol=1e-12, atol=1e-12)
            # accuracy: as above, one state given as a (6,) array
            np.testing.assert_allclose(fast(t, s[0]), want[0], rtol=1e-12, atol=1e-12)
        assert clipped > 0 or limits.force is None
    assert paper_rates(body, gains, ref, Allocation("least_squares", (1.0, 1.0, 0.1))) is None
    assert paper_rates(body, gains, object()) is None               # not a path of lib.trajectories


def test_a_runs_accuracy_bounds_its_error_against_the_closed_form_of_eq24_with_a_margin_of_ten():
    # Integration.accuracy (Methods, "What a computed number is accurate to") is what the book prints
    # in place of round-off; on the paper's circle the simulated position error's deviation from the
    # analytic solution of (24) lies at least ten times below it, and a run ten times looser does not
    # keep that margin under the strict accuracy (the bound is not so wide that it cannot fail)
    from lib.tracking.runs import position_deviation_from_eq24
    ref = T.circle(R=2.0, theta=np.pi / 4)
    strict = Integration().accuracy(2.0)
    assert strict == pytest.approx(10 * (1e-10 + 2 * 1e-10))  # exact: the definition, 10 (atol + rtol scale), in floating point
    res = simulate(Body(), Gains(), ref, 2 * ref.period)
    assert 10 * position_deviation_from_eq24(Body(), Gains(), res) <= strict
    loose = simulate(Body(), Gains(), ref, 2 * ref.period, integration=Integration(rtol=1e-6, atol=1e-6))
    assert 10 * position_deviation_from_eq24(Body(), Gains(), loose) > strict
    with pytest.raises(ValueError, match="scale"):
        Integration().accuracy(0.0)
