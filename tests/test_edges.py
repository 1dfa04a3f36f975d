"""The library at its edges (issue 37): options checked before the work, windows and limits
refused with their values. (limit_verdicts on the circle: tests/test_circle_verdicts.py.)"""

import math

import pytest

from lib import trajectories
from lib.limits.verdicts import limit_verdicts
from lib.params import Body, Gains

BODY, GAINS = Body(), Gains()


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


def test_a_scalar_limit_is_named_without_an_empty_index():
    # issue 37: "angle_limits[] must be finite"
    with pytest.raises(ValueError, match=r"^angle_limits must be finite, got nan$"):
        limit_verdicts(BODY, GAINS, trajectories.eight(), float("nan"))
    with pytest.raises(ValueError, match=r"^angle_limits\[1\] must be in \(0, pi\] rad, got -1\.0$"):
        limit_verdicts(BODY, GAINS, trajectories.eight(), [0.5, -1.0])


def test_limit_verdicts_returns_a_named_pair_that_still_unpacks():
    from lib.limits.verdicts import LimitVerdicts
    out = limit_verdicts(BODY, GAINS, trajectories.circle(), [1.0], transient=4, periods=24)
    assert isinstance(out, LimitVerdicts)
    frame, runs = out                                   # the old unpacking
    assert frame is out.frame and runs is out.runs and len(frame) == 1


def test_percussion_steady_checks_its_body_at_the_public_faces_only(monkeypatch):
    # issue 37: following percussion_steady's body, it entered lib.machinery.checks 13 times (every
    # layer, and twice in each of five eps); now at percussion_steady and at the sweep it runs
    from lib.machinery import checks
    from lib.percussion import compare
    seen = []
    real = checks.instance
    monkeypatch.setattr(checks, "instance", lambda name, value, cls, what=None: (
        seen.append(name) if isinstance(value, Body) else None) or real(name, value, cls, what))
    compare.percussion_steady(BODY, "eight", 2.0, 0.5)
    assert len(seen) == 2


def test_the_law_for_p_checks_its_body_once_a_run_not_every_step(monkeypatch):
    # issue 37: the law's inner loop went through the public helpers, each checking the body again
    # at every evaluation of the rates (thousands a run); now simulate checks it, the kernels do not
    from lib.machinery import checks
    from lib.percussion import run as prun
    seen = []
    real = checks.instance
    monkeypatch.setattr(checks, "instance", lambda name, value, cls, what=None: (
        seen.append(name) if isinstance(value, Body) else None) or real(name, value, cls, what))
    res = prun.simulate(BODY, GAINS, trajectories.eight(), 2.0, thrust0=0.5)
    assert res.t.size > 10 and len(seen) <= 4, len(seen)   # simulate and error_polynomial; measured 2
