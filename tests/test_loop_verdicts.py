"""One verdict for both laws (Chapter 6): :func:`lib.weighting.verdicts.closed_loop_verdicts` on the full
closed loop, against Chapter 5's verdicts on the reduced rotation (32) and a long adaptive run."""

import numpy as np
import pytest

from lib.weighting import verdicts as loop_verdicts, comparison as weighting
from lib import trajectories as T
from lib.allocation import Allocation, Limits
from lib.closed_loop import ClosedLoop
from lib.params import Body, Gains
from lib.rotation.verdicts import REGIMES, rotation_verdicts
from lib.simulate import Integration, simulate

# three decided points of Chapter 5's map of the eight (the grid of Chapter 6's map): a strongly
# attracting orbit (Floquet modulus 2e-7), a chaotic heading (lambda T = 1.4, many standard errors
# above zero) and a heading that slips one turn per period (Floquet modulus 0.37)
R_GRID, TH_GRID = np.linspace(0.25, 4.0, 14), np.linspace(0.2, 1.5, 14)
POINTS = {"periodic": (R_GRID[2], TH_GRID[0]), "chaotic": (R_GRID[1], TH_GRID[3]), "slipping": (R_GRID[0], TH_GRID[8])}


@pytest.fixture(scope="module")
def both_laws():
    R, Th = np.array([v[0] for v in POINTS.values()]), np.array([v[1] for v in POINTS.values()])
    ch5 = rotation_verdicts(Body(), "eight", R, Th)
    W = np.r_[[(1.0, 1.0, 0.0)] * 3, [(1.0, 1.0, 0.1)] * 3]
    loop = weighting.closed_loop_verdicts(Body(), Gains(), "eight", np.r_[R, R], np.r_[Th, Th], W)
    return ch5, loop


def test_paper_law_through_the_loop_verdict_agrees_with_chapter_5(both_laws):
    ch5, loop = both_laws
    paper = loop.iloc[:3]
    assert ch5.regime.tolist() == list(POINTS) == paper.regime.tolist()
    # lost (the heading slips): only the slipping heading; the chaotic one turns right round
    # against the path (a range of 22 rad in Chapter 5's run) without a net drift, which the
    # other reading, turns_round, counts
    assert ch5.lost.tolist() == paper.lost.tolist() == [False, False, True]
    assert ch5.turns_round.tolist() == paper.turns_round.tolist() == [False, True, True]
    assert paper.period.tolist()[::2] == ch5.period.tolist()[::2] == [1, 1]
    # the same orbits: their Floquet moduli agree (the full loop adds the position errors'
    # multipliers, exp(-1.6 T) < 2e-3, below the rotation's here)
    np.testing.assert_allclose(paper.floquet.iloc[[0, 2]], ch5.floquet.iloc[[0, 2]], rtol=0.03, atol=0)  # measured 3.0e-3 relative: the full loop's own multipliers
    # the chaotic point: lambda T clear of the band by many standard errors in both
    lam = paper.lyapunov.iloc[1] * 2 * np.pi / TH_GRID[3]
    assert lam > max(5 * paper.lyapunov_stderr.iloc[1] * 2 * np.pi / TH_GRID[3], 0.1)
    assert abs(paper.slip.iloc[2]) == 1.0 and (paper.pos_rms.iloc[:3] < 7e-5).all()  # measured 6.7e-6


def test_both_laws_are_classified_by_the_same_function_from_the_same_start(both_laws):
    _, loop = both_laws
    assert set(loop.regime) <= set(REGIMES)
    assert loop.w_phi.tolist() == [0.0] * 3 + [0.1] * 3
    assert (loop.periods == loop.periods.iloc[0]).all()          # the same horizon for every point
    # every verdict is decided or carries its reason
    assert ((loop.regime != "undecided") | (loop.reason != "")).all()
    # the weighted law (w_phi = 0.1) keeps the strongly attracting orbit, centimetres off the
    # path; on the fast tight eight (R = 0.25 m, Theta = 1 rad/s) it loses the body, which ends
    # tens of metres from a path 0.25 m across
    w = loop.iloc[3:]
    assert w.regime.iloc[0] == "periodic" and w.pos_rms.iloc[0] < 0.05 and not w.position_lost.iloc[0]
    assert w.position_lost.iloc[2] and w.pos_max.iloc[2] > 10 * w.R.iloc[2]
    assert not loop.iloc[:3].position_lost.any()


def test_a_periodic_verdict_agrees_with_a_long_adaptive_run():
    # Fig. 3's eight with the weighted law w_phi = 1, from the paper's start: periodic with period 1
    body, gains, w = Body(), Gains(), (1.0, 1.0, 1.0)
    z0, dz0 = np.array([1.0, 0.0, np.pi / 2]), np.zeros(3)
    v = weighting.closed_loop_verdicts(body, gains, "eight", 2.0, np.pi / 4, w, z0=z0, dz0=dz0).iloc[0]
    assert v.regime == "periodic" and v.period == 1 and v.floquet < 0.05 and not v.lost and not v.position_lost  # measured |mu_1| = 0.017
    # an independent route: solve_ivp (DOP853, tolerance 1e-10) for 12 periods, sampled at the
    # sections (|mu_1| < 0.05: the transient is below 1e-10 of the start after 8 periods)
    Tp = 8.0
    ref = T.make("eight", 2.0, np.pi / 4)
    run = simulate(body, gains, ref, 12 * Tp, z0, dz0, allocation=Allocation("least_squares", w),
                   t_eval=np.arange(0, 12 * Tp + 1e-9, Tp / 128), integration=Integration(rtol=1e-10, atol=1e-10))
    e = np.concatenate([run.z - run.z_d, run.dz - ref.dz(run.t)], axis=1)[::128]
    assert np.abs(e[-1] - e[-2]).max() < 2e-11                     # measured 1.7e-12; the section repeats every period
    last = run.t > run.t[-1] - 4 * Tp + 1e-9                       # the last 4 whole periods, each sample once
    p = run.z[last, 2] - run.z_d[last, 2]
    pos = np.hypot(*(run.z[last, :2] - run.z_d[last, :2]).T)
    # the verdict's steady measures (RK4, 128 steps per period) against the long run's
    assert abs(v.p_range - np.ptp(p)) < 2.5e-4 and abs(v.pos_rms - np.sqrt(np.mean(pos ** 2))) < 1.2e-5  # measured 2.4e-5 and 1.2e-6: RK4 at 128 steps a period


def test_lean_field_is_the_closed_loop_of_eqs_23_and_2_4():
    rng = np.random.default_rng(3)
    N = 40
    for kind in ("eight", "circle"):
        R, Th, W = rng.uniform(0.3, 4, N), rng.uniform(-1.5, 1.5, N), rng.uniform(0.1, 2, (N, 3))
        W[:8, 2] = 0.0
        flow = loop_verdicts._PeriodFlow(Body(), Gains(), np.full(N, kind), R, Th, W, "least_squares", Limits(), 64)
        idx = np.arange(N)
        loop = ClosedLoop.of(Body(), Gains(), flow.kin(idx), Allocation("least_squares", W))
        for tau in (0.0, 1 / 128, 3 + 17 / 128, 7.5):
            y = np.concatenate(flow.kin(idx)(tau * flow.T)[:2], axis=1) + rng.normal(size=(N, 6))
            lean = flow.field(idx, tau, y)
            full = flow.T[:, None] * loop.rates(tau * flow.T, y)[0]
            assert np.abs(lean - full).max() <= 1e-13 * np.abs(full).max()  # exact: one closed form, two code paths; measured 1.1e-14 max |full|


@pytest.mark.parametrize("kw,exc,msg", [
    ({"kind": "square"}, ValueError, r"^kind must be one of .*got 'square'"),
    ({"kind": ["eight", "circle", "eight"]}, ValueError, "3 entries for 1 points"),
    ({"R": [-1.0]}, ValueError, r"R\[0\] must be positive"),
    ({"weights": (0.0, 0.0, 0.0)}, ValueError, "not all zero"),
    ({"z0": [1.0, 2.0]}, ValueError, "z0 must have shape"),
    ({"z0": [np.nan, 0.0, 0.0]}, ValueError, "must be finite"),
    ({"periods": 20}, ValueError, "periods must be an integer >= 24"),
    ({"periods": 30, "block": 12}, ValueError, "at least 3 blocks"),
    ({"newton_tol": 0.0}, ValueError, "newton_tol must be positive"),
    ({"lyapunov": 3}, TypeError, "unknown option"),
    ({"allocation": "exact"}, ValueError, "allocation must be"),
])
def test_loop_verdicts_reject_bad_input(kw, exc, msg):
    args = dict(body=Body(), gains=Gains(), kind="eight", R=[1.0], Theta=[1.0], weights=(1, 1, 1))
    args.update(kw)
    with pytest.raises(exc, match=msg):
        weighting.closed_loop_verdicts(**args)
