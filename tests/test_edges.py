"""The library at its edges (issue 37): limit_verdicts on the circle (27), whose own heading
turns once a period (an orbit that follows it was counted as a slip), and options checked before
the work."""

import math

import numpy as np
import pytest

from lib import trajectories
from lib.limits.verdicts import limit_verdicts
from lib.params import Body, Gains
from lib.rotation.circle import circle_eigenvalues, circle_equilibria

BODY, GAINS = Body(), Gains()


def test_the_circle_is_periodic_and_held_at_the_closed_form_equilibrium():
    # no angle limit (pi) and one the steady force never reaches (1 rad > beta* = 0.074 rad): the
    # orbit is C on the circle with the heading at (33)'s stable equilibrium p0
    fr, _ = limit_verdicts(BODY, GAINS, trajectories.circle(), [np.pi, 1.0])
    assert list(fr.regime) == ["periodic", "periodic"] and list(fr.turns) == [0, 0]
    assert not fr.lost.any() and (fr.drift == 0).all()
    p0 = circle_equilibria(BODY, 2.0, math.pi / 4)[0]
    for orbit in fr.orbit:
        # accuracy: Newton's tolerance 1e-9 on the switched map, times 100
        assert math.remainder(orbit[2] - math.pi / 2 - p0, 2 * math.pi) == pytest.approx(0.0, abs=1e-7)
    # the largest multiplier is the heading's pair of (35), exp(Re(lambda) T), above the position
    # error's exp(-Kv T / (2 m)) of (24)
    T = trajectories.circle().period
    want = float(np.exp(circle_eigenvalues(BODY, 2.0, math.pi / 4).real.max() * T))
    # accuracy: a forward-difference Jacobian of step 1e-6 on a map integrated to 1e-10, ~1e-5
    assert fr.floquet.to_numpy() == pytest.approx([want, want], abs=1e-4)
    # reason: the heading error is constant on the orbit, its range the integration's noise
    assert (fr.p_range < 1e-6).all()


@pytest.mark.parametrize("kw, name", [({"confirm": ("bogus",)}, "confirm"), ({"lost_factor": 1}, "lost_factor"),
                                      ({"body": "body"}, "body")])
def test_fig5_map_checks_its_options_before_the_sweep(monkeypatch, kw, name):
    # issue 37: a bad option was refused only after the 100 x 100 sweep (115 s)
    from lib.rotation import fig5
    monkeypatch.setattr(fig5, "eight_rotation_sweep", lambda *a, **k: pytest.fail("swept before checking"))
    args = dict(body=BODY, n=100)
    args.update(kw)
    with pytest.raises((TypeError, ValueError), match=name):
        fig5.fig5_map(args.pop("body"), **args)


def test_a_steady_window_longer_than_the_run_is_refused():
    # issue 37: a 100-period window over a 3-period run measured the whole run, start included
    from lib.tracking.runs import run, steady_summary
    res = run(BODY, GAINS, "eight", 2.0, math.pi / 4, 3)
    with pytest.raises(ValueError, match="longer than the run"):
        steady_summary(res, n_periods=100)
    assert steady_summary(res, n_periods=3)["pos_err_max"] > 0.0     # reason: the whole run is allowed


def test_a_bad_force_limit_is_named_with_its_value():
    with pytest.raises(ValueError, match=r"-1"):
        limit_verdicts(BODY, GAINS, trajectories.eight(), [1.0], -1.0)
