"""The batch closed loop of Chapter 6 against the adaptive single-run simulation."""

import numpy as np
import pytest

from lib import trajectories as T
from lib.weighting import comparison as weighting
from lib.allocation import Allocation, Limits
from lib.simulate import Integration
from lib.params import PAPER_DZ0, PAPER_Z0, Body, Gains
from lib.simulate import simulate


@pytest.mark.parametrize("kind,w_phi", [("eight", 1.0), ("circle", 0.3), ("eight", 0.0)])
def test_batch_rk4_agrees_with_adaptive_simulation(kind, w_phi):
    body, gains = Body(), Gains()
    t_end = 20.0
    batch = weighting.closed_loop_batch(body, gains, kind, 2.0, np.pi / 4, (1.0, 1.0, w_phi), t_end=t_end,
                                         dt=0.02, record_dt=0.5, z0=PAPER_Z0, dz0=PAPER_DZ0)
    ref = T.make(kind, 2.0, np.pi / 4)
    exact = simulate(body, gains, ref, t_end, t_eval=batch.t, allocation=Allocation("least_squares", (1.0, 1.0, w_phi)),
                     integration=Integration(rtol=1e-11, atol=1e-11))
    assert np.abs(batch.z[:, 0, :] - exact.z).max() < 1e-5  # measured 3.5e-6: RK4 at dt = 20 ms
    np.testing.assert_allclose(batch.F[:, 0], exact.F, rtol=0, atol=3e-5)  # measured 2.7e-6


def test_rk4_error_shrinks_at_fourth_order():
    body, gains = Body(), Gains()
    runs = [weighting.closed_loop_batch(body, gains, "eight", 2.0, 1.0, (1, 1, 1), t_end=10.0, dt=dt,
                                         record_dt=0.4, z0=PAPER_Z0, dz0=PAPER_DZ0) for dt in (0.08, 0.04, 0.02)]
    e1 = np.abs(runs[0].z - runs[2].z).max()
    e2 = np.abs(runs[1].z - runs[2].z).max()
    # against the finest run, the differences of an order-4 scheme shrink by (16 - 1) / (16/16 - 1/16) = 17
    assert 12.0 < e1 / e2 < 22.0


def test_paper_law_from_the_reference_keeps_position_error_at_integration_error():
    res = weighting.closed_loop_batch(Body(), Gains(), "eight", [1.0, 3.0], [0.5, 1.2], (1, 1, 0), t_end=30.0)
    assert res.position_error.max() < 3e-8  # measured 3.2e-9


def test_steady_metrics_flag_a_body_that_leaves_the_circle():
    res = weighting.closed_loop_batch(Body(), Gains(), "circle", 2.0, np.pi / 4, [(1, 1, 0), (1, 1, 10)],
                                       t_end=100.0, dt=0.02, z0=PAPER_Z0, dz0=PAPER_DZ0)
    m = weighting.steady_metrics(res)
    assert m.position_held.tolist() == [True, False]
    assert m.pos_rms[0] < 1e-7 and m.pos_rms[1] > 10.0  # measured 7.7e-9; reason: > 10 is a property (measured 233)


def test_steady_metrics_need_enough_periods():
    res = weighting.closed_loop_batch(Body(), Gains(), "eight", 2.0, 0.1, (1, 1, 0), t_end=20.0)
    with pytest.raises(ValueError, match="shorter than 3 reference periods"):
        weighting.steady_metrics(res)


@pytest.mark.parametrize("kw,exc,msg", [
    ({"kind": "square"}, ValueError, r"^kind must be one of .*got 'square'"),
    ({"R": []}, ValueError, "empty"),
    ({"R": [1.0, -1.0]}, ValueError, r"R\[1\] must be positive"),
    ({"Theta": [0.0]}, ValueError, "non-zero"),
    ({"R": [1.0, 2.0], "Theta": [1.0, 2.0, 3.0]}, ValueError, "equal lengths"),
    ({"weights": (0.0, 0.0, 0.0)}, ValueError, "not all zero"),
    ({"t_end": -1.0}, ValueError, "t_end"),
    ({"body": None}, TypeError, "Body"),
])
def test_batch_rejects_bad_input(kw, exc, msg):
    args = dict(body=Body(), gains=Gains(), kind="eight", R=[1.0], Theta=[1.0], weights=(1, 1, 1), t_end=1.0)
    args.update(kw)
    with pytest.raises(exc, match=msg):
        weighting.closed_loop_batch(**args)


def test_simulate_allocation_option_is_validated():
    with pytest.raises(ValueError, match="unknown allocation 'torque'"):
        simulate(Body(), Gains(), T.circle(), 1.0, allocation=Allocation("torque"))
    with pytest.raises(ValueError, match="weights"):
        simulate(Body(), Gains(), T.circle(), 1.0, allocation=Allocation("least_squares", (1, 1)))
    with pytest.raises(ValueError, match="supports the position-only allocation only"):
        simulate(Body(), Gains(), T.circle(), 1.0, limits=Limits(angle=1.0), integration=Integration(switching="events"),
                 allocation=Allocation("least_squares", (1, 1, 1)))


def test_map_comparison_classifies_both_laws_by_one_verdict():
    # a slow wide eight settles under both laws; a fast tight one slips under the paper's law
    R, Th = np.array([3.0, 0.25]), np.array([0.3, 1.0])
    cmp = weighting.compare_on_map(Body(), Gains(), R, Th, 0.1)
    assert cmp.paper.w_phi.tolist() == [0.0, 0.0] and cmp.weighted.w_phi.tolist() == [0.1, 0.1]
    assert cmp.paper.regime.tolist() == ["periodic", "slipping"] and cmp.lost.tolist() == [False, True]
    c = cmp.counts
    assert c.loc["heading lost", "paper's law"] == 1 and c["paper's law"].loc[list(weighting.REGIMES)].sum() == 2
    # the cross-table's totals are the counts' "held": one definition behind both
    x = cmp.cross
    assert x.loc["total", "total"] == 2
    assert x.loc["held", "total"] == c.loc["held", "paper's law"] == cmp.paper_held.sum() == 1
    assert x.loc["total", "held"] == c.loc["held", "weighted law"] == cmp.held.sum()
    assert cmp.held[0] and cmp.weighted.pos_rms.iloc[0] < 0.05
    with pytest.raises(ValueError, match="R"):
        weighting.compare_on_map(Body(), Gains(), [-1.0], [0.3], 0.1)
    with pytest.raises(ValueError, match="w_phi must be positive"):
        weighting.compare_on_map(Body(), Gains(), [1.0], [0.3], 0.0)


def test_stability_boundary_reads_the_first_change_of_verdict():
    import pandas as pd

    f = pd.DataFrame({"regime": ["periodic", "periodic", "chaotic", "periodic"], "lost": [False] * 4,
                      "position_lost": [False, False, True, False]})
    f["tracked"] = ~f.position_lost
    b = weighting.stability_boundary([0.0, 0.1, 0.2, 0.4], f)
    assert (b["last_held"], b["first_lost"], b["changes"]) == (0.1, 0.2, 2)
    assert b["verdict"] == "chaotic, position not tracked" and b["ratio"] == pytest.approx(2.0, abs=1e-15)  # exact: a ratio of two grid values; measured 0
    with pytest.raises(ValueError, match="increasing"):
        weighting.stability_boundary([0.1, 0.0, 0.2, 0.3], f)


@pytest.mark.parametrize("law", ["least_squares", "limited"])
@pytest.mark.parametrize("angle", [None, np.pi / 3])
def test_batch_with_limits_agrees_with_adaptive_simulation(law, angle):
    # Fig. 4's cap (4 N), with and without a 60-degree angle limit, by projection and exactly:
    # the fixed-step RK4 steps across the switches of beta; at dt = 5 ms it stays within
    # 5e-5 m, rad of the adaptive run (measured: 3e-6 without, 7e-6 with the angle limit)
    body, gains, lim, w = Body(), Gains(), Limits(4.0, angle), (1.0, 1.0, 0.3)
    b = weighting.closed_loop_batch(body, gains, "eight", 2.0, np.pi / 4, w, t_end=6.0, dt=0.005, record_dt=0.25,
                                     z0=PAPER_Z0, dz0=PAPER_DZ0, allocation=law, limits=lim)
    exact = simulate(body, gains, T.make("eight", 2.0, np.pi / 4), 6.0, t_eval=b.t, allocation=Allocation(law, w),
                     limits=lim, integration=Integration(rtol=1e-9, atol=1e-9))
    assert np.abs(b.z[:, 0] - exact.z).max() < 5e-5  # measured 7.1e-6
    assert np.abs(b.F[:, 0] - exact.F).max() < 2e-4  # measured 1.8e-5
    assert b.F.max() <= 4.0 + 1e-15  # exact: a clip; measured 0 over the cap


def test_batch_allocation_and_limits_are_validated():
    args = dict(body=Body(), gains=Gains(), kind="eight", R=[1.0], Theta=[1.0], weights=(1, 1, 1), t_end=1.0)
    with pytest.raises(ValueError, match="allocation must be 'least_squares'"):
        weighting.closed_loop_batch(**args, allocation="exact")
    with pytest.raises(TypeError, match="limits must be a lib.allocation.Limits"):
        weighting.closed_loop_batch(**args, limits=(4.0, 1.0))


def test_chapter_6_limits_comparison_is_converged_in_the_step_and_its_directions_hold():
    # Chapter 6 runs Fig. 4's setting at dt = 40 ms across the switches of beta; halving the
    # step moves its measures by far less than the exact-minus-projection gaps it reads
    from lib.params import PAPER_DZ0, PAPER_Z0

    sets = {"cap": Limits(4.0), "cap_angle": Limits(4.0, np.pi / 3)}
    runs = [weighting.limits_comparison(Body(), Gains(), "eight", 2.0, np.pi / 4, (1.0, 1.0, 1.0), sets, periods=3,
                                        dt=dt, z0=PAPER_Z0, dz0=PAPER_DZ0).set_index(["limits", "law"])
            for dt in (0.04, 0.02)]
    for col in ("pos_rms", "p_rms"):
        assert (runs[0][col] - runs[1][col]).abs().max() < 0.003  # measured 2.8e-3; reason: a step-convergence bound, below the exact-minus-projection gaps it reads
    for r in runs:
        for s in sets:
            assert r.loc[(s, "exact"), "p_rms"] < r.loc[(s, "projection"), "p_rms"] - 0.003
            assert r.loc[(s, "exact"), "pos_rms"] > r.loc[(s, "projection"), "pos_rms"] + 0.01
    with pytest.raises(ValueError, match="periods must be an integer"):
        weighting.limits_comparison(Body(), Gains(), "eight", 2.0, 1.0, (1, 1, 1), sets, periods=1)


def _verdict_frame(held_flags, why=None):
    """Verdict rows, held where asked; a row that is not held fails for the reason given ("lost",
    "position" or "chaotic")."""
    import pandas as pd
    why = why or ["lost"] * len(held_flags)
    rows = [dict(regime="periodic" if h or w != "chaotic" else "chaotic", lost=not h and w == "lost",
                 tracked=h or w != "position") for h, w in zip(held_flags, why)]
    return pd.DataFrame(rows)


def test_stability_boundary_is_the_first_weight_lost_not_the_last():
    # issue 59's surviving mutant: bad[0] -> bad[-1] went unseen with a single non-held row
    f = _verdict_frame([True, True, False, True, False], ["", "", "lost", "", "position"])
    b = weighting.stability_boundary([0.1, 0.2, 0.4, 0.8, 1.6], f)
    assert (b["last_held"], b["first_lost"], b["changes"]) == (0.2, 0.4, 3)
    assert b["verdict"] == "periodic, heading lost"


def test_refine_boundary_narrows_the_bracket_around_the_true_boundary(monkeypatch):
    # a loop held exactly below w* = 0.3: one round of n new weights, even in log between the last
    # held and the first lost, brackets w* (n + 1) times tighter in log
    from lib.weighting import comparison
    w_star, n = 0.3, 7

    def fake_runs(body, gains, runs, **options):
        w = runs["fine"]["weights"][:, 2]
        return {"fine": _verdict_frame(list(w < w_star))}
    monkeypatch.setattr(comparison, "verdict_runs", fake_runs)
    grid = np.array([0.1, 0.2, 0.4, 0.8])
    b, w_all, frame = comparison.refine_boundary(Body(), Gains(), {"kind": "eight", "R": 2.0, "Theta": 0.5},
                                                 grid, _verdict_frame(list(grid < w_star)), n=n)
    assert b["last_held"] < w_star <= b["first_lost"]
    assert np.log(b["first_lost"] / b["last_held"]) == pytest.approx(np.log(0.4 / 0.2) / (n + 1), rel=1e-12)  # exact: a ratio of geomspace's own grid values, a few roundings
    assert w_all.size == grid.size + n and np.all(np.diff(w_all) > 0) and len(frame) == w_all.size
    with pytest.raises(ValueError, match="no boundary"):
        comparison.refine_boundary(Body(), Gains(), {}, grid, _verdict_frame([True] * 4))
