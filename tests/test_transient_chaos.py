"""Transient chaos (issue 29): a verdict whose attractor the last bits decide is called so
(``transient`` in lib.dynamics.verdicts), and a heading lost by a drift test is tested again
over a longer horizon (lib.rotation.fig5)."""

import numpy as np
import pandas as pd
import pytest

from lib.dynamics import verdicts as dv
from lib.machinery.robustness import ROBUST_REL, perturbed
from lib.params import Body
from lib.rotation.fig5 import LOST_FACTOR, confirm_attractors, confirm_lost
from lib.rotation.verdicts import VERDICT_DEFAULTS, eight_rotation_sweep

BODY = Body()


# ---------------------------------------------------------------- the trigger and the rule

def test_the_trigger_is_a_chaotic_verdict_or_an_orbit_reached_after_the_transient():
    T = VERDICT_DEFAULTS["transient"]
    regime = ["chaotic", "periodic", "periodic", "slipping", "slipping", "undecided", "quasiperiodic"]
    periods = [120, T, T + 12, 16, 132, 348, 348]
    assert dv.needs_confirmation(regime, periods, T).tolist() == [True, False, True, False, True, False, False]


def _two_attractor_map(scale):
    """A synthetic period map with a chaotic repeller and two attractors: on [-1, 1] the
    Chebyshev map x -> scale (4 x^3 - 3 x) (onto [-1, 1] at scale 1, chaotic; a run leaves
    it after a chaotic transient when scale > 1), outside it a contraction onto +2 or -2."""
    def P(x):
        inside = np.abs(x) <= 1
        return np.where(inside, scale * (4 * x ** 3 - 3 * x), np.sign(x) * (2 + 0.5 * (np.abs(x) - 2)))
    return P


def _decide(P, x, periods=400):
    """The attractor a run of the synthetic map reaches: ("periodic", 1, orbit point) or ("chaotic", 0, nan)."""
    for _ in range(periods):
        x = P(x)
    settled = np.abs(np.abs(x) - 2) < 1e-9
    return (np.where(settled, "periodic", "chaotic").astype(object), np.where(settled, 1, 0),
            np.where(settled, x, np.nan))


def test_two_resolutions_that_reach_different_attractors_leave_the_attractor_undetermined():
    # two "resolutions" of one map (its scale moved in the 13th digit) from the same starts:
    # after the chaotic transient on [-1, 1] the runs settle on +2 or -2, and which one is
    # decided by the last bits, at a good share of the starts (those that stay long near the repeller)
    x0 = np.linspace(-0.9, 0.9, 201)
    a, b = (_decide(_two_attractor_map(1.002 * (1 + e)), x0, 1000) for e in (0.0, 1e-13))
    assert (a[0] == "periodic").all() and (b[0] == "periodic").all()     # every run escapes
    same_orbit = np.abs(a[2] - b[2]) < 1e-9
    det = dv.attractor_determined([a[0], b[0]], [a[1], b[1]], [same_orbit])
    assert det.tolist() == same_orbit.tolist()
    assert 0.1 < 1 - det.mean() < 0.9                                    # not a rare event


def test_the_attractor_is_determined_when_every_decision_reaches_the_same_one():
    # one attractor only: the map contracts everything onto +2
    P = lambda x: 2 + 0.5 * (x - 2)                                     # noqa: E731
    x0 = np.linspace(-0.9, 0.9, 11)
    a, b = _decide(P, x0), _decide(P, perturbed(x0))
    assert dv.attractor_determined([a[0], b[0]], [a[1], b[1]], [np.abs(a[2] - b[2]) < 1e-9]).all()  # reason: two orbits of a contraction by 0.5, equal within 1e-9


def test_the_rule_tells_regime_period_and_orbit_apart():
    first = ["chaotic", "periodic", "periodic", "periodic", "slipping"]
    other = ["chaotic", "chaotic", "periodic", "periodic", "slipping"]
    det = dv.attractor_determined([first, other], [[0, 1, 1, 1, 2], [0, 0, 2, 1, 2]],
                                  [[False, False, True, False, True]])
    assert det.tolist() == [True, False, False, False, True]
    assert "transient" in dv.REGIMES and dv.TRANSIENT == "transient"


# ---------------------------------------------------------------- a real Fig. 5 point

#: a chaotic-region point of the Fig. 5 grid (its row 6179, R index 79, Theta index 61): from starts
#: 1e-12 apart the run is chaotic over its budget, or reaches period 1 after a chaotic transient
FLIP = (np.linspace(0.25, 4.0, 100)[79], np.linspace(0.05, 1.5, 100)[61])


def test_a_fig5_point_whose_attractor_the_last_bits_decide_is_transient_chaos(perturb):
    # decisions from the reference start and from x0 + m delta, m = 0..7 (delta the 1e-12 of the
    # robustness mode): they do not all reach one attractor; the map's confirmation (from each
    # start moved by 1e-12) calls a point transient exactly where a triggered decision and its
    # confirmation differ (an orbit reached within the transient is not decided again)
    delta = perturbed(np.zeros(2), ROBUST_REL)
    starts = np.vstack([np.zeros(2), perturb(np.zeros(2)) + np.arange(8)[:, None] * delta])
    moved = np.array([perturbed(x, ROBUST_REL) for x in starts])
    n = len(starts)
    f, g = (eight_rotation_sweep(BODY, np.full(n, FLIP[0]), np.full(n, FLIP[1]), p0=x[:, 0], v0=x[:, 1])
            for x in (starts, moved))

    def seen(fr):   # an orbit of period 1 is told by its point at s = 0 (its mirror twin has another)
        return [(r, k, round(p, 3) if k == 1 else None) for r, k, p in zip(fr.regime, fr.period, fr.orbit_p)]

    assert len(set(seen(f)) | set(seen(g))) >= 2, seen(f)
    c = confirm_attractors(BODY, "eight", f, x0=starts)
    trig = dv.needs_confirmation(f.regime, f.periods, VERDICT_DEFAULTS["transient"])
    differs = [a != b for a, b in zip(seen(f), seen(g))]
    assert (c.regime == "transient").tolist() == [d and t for d, t in zip(differs, trig)]
    assert c.reason[c.regime == "transient"].str.startswith("transient chaos: attractor not determined").all()


# ---------------------------------------------------------------- lost over a longer horizon

@pytest.mark.parametrize("R, Theta, lost", [
    (0.3257575757575758, 0.9287878787878788, True),    # drifts by hundreds of standard errors
    (2.5984848484848486, 1.2070707070707072, False),   # no drift, over 300 periods or 1200
])
def test_a_heading_lost_without_an_orbit_is_tested_over_four_times_the_horizon(R, Theta, lost, perturb):
    x0 = perturb(np.zeros(2))
    f = eight_rotation_sweep(BODY, [R], [Theta], p0=x0[0], v0=x0[1])
    c = confirm_lost(BODY, "eight", f, x0=x0)
    h = int(f.drift_periods.iloc[0])       # the drift's run: on to 300 periods where the heading slipped
    assert f.regime.iloc[0] == "chaotic" and h == VERDICT_DEFAULTS["drift_periods"]
    assert bool(c.lost.iloc[0]) is lost
    if f.lost.iloc[0]:                     # decided again, every block of the longer run observed
        assert c.lost_horizon.iloc[0] == LOST_FACTOR * h
        z = abs(c.slip.iloc[0]) / c.slip_stderr.iloc[0]
        assert (z > 10 * dv.SIGMAS) if lost else (z < dv.SIGMAS)
    else:
        assert c.lost_horizon.iloc[0] == h


def test_a_slipping_orbit_is_lost_on_its_orbit_and_not_decided_again():
    frame = pd.DataFrame(dict(R=[1.0], Theta=[1.0], regime=["slipping"], period=[1], periods=[8], drift_periods=[0], lost=[True],
                              slip=[1.0], slip_stderr=[0.0], steps=[64], verdict_steps=[32], reason=[""]))
    c = confirm_lost(BODY, "eight", frame)
    assert bool(c.lost.iloc[0]) and c.lost_horizon.iloc[0] == 0


def test_a_slipping_orbit_of_period_two_reached_late_is_the_same_orbit_when_decided_again(perturb):
    # a point whose heading reaches, after the transient, an orbit of period 2 that slips two turns
    # (one a period): decided again from the moved start it reaches the same orbit with the same
    # turns, n = slip x period = 2 (the slip column counts turns a period), so the attractor is
    # determined and the verdict stays slipping
    p0 = float(perturb([0.0])[0])
    frame = eight_rotation_sweep(BODY, [0.477273], [0.562626], p0=p0)
    row = frame.iloc[0]
    assert row.regime == "slipping" and row.period == 2 and row.slip * row.period == 2
    assert row.periods > VERDICT_DEFAULTS["transient"]    # reached late: it is decided again
    c = confirm_attractors(BODY, "eight", frame, x0=(p0, 0.0))
    assert c.confirmed.iloc[0] == 1
    assert c.regime.iloc[0] == "slipping" and c.period.iloc[0] == 2, c.reason.iloc[0]


def test_a_chaotic_row_whose_longer_drift_run_ended_undecided_is_confirmed_without_a_warning():
    # confirm_lost leaves slip NaN where the longer run decided nothing; confirm_attractors then
    # decides the row again (a chaotic first decision) without casting that NaN to turns
    import warnings

    f = eight_rotation_sweep(BODY, [FLIP[0]], [FLIP[1]])
    assert f.regime.iloc[0] in ("chaotic", "periodic", "slipping")
    f.loc[:, ["regime", "period", "slip", "slip_stderr"]] = ["chaotic", 0, np.nan, np.nan]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        c = confirm_attractors(BODY, "eight", f)
    assert c.confirmed.iloc[0] == 1 and c.regime.iloc[0] in ("chaotic", "transient")
