"""The compiled switched integrator's two event locators (lib.integrators.switched_events):
the dense one (on a smooth step's 7th-order dense output, then one real step) against the
bracket one (real steps only). Both place every event within T_TOL = 1e-11 s before the
landing; what a located orbit gives must not move beyond its accuracy, and a chaotic run's
statistics may move only within their standard errors."""

import math

import numpy as np
import pytest

from lib import trajectories as T
from lib.integrators import switched_events as E
from lib.integrators.batch import dop853
from lib.integrators.switched_compiled import dop853_dense
from lib.limits import verdicts as L
from lib.params import PAPER_DZ0, PAPER_Z0, Body, Gains

EIGHT = T.eight()
S0 = np.concatenate([PAPER_Z0, PAPER_DZ0])


def _packed(body=Body(), gains=Gains(), ref=EIGHT):
    g = gains
    return np.array([body.m, body.I, body.a, body.c, body.c_phi, g.kp[0], g.kp[1], g.kv[0], g.kv[1], ref.R,
                     ref.theta, 5.0, 1.0])


def _smooth_step(dt):
    """One DOP853 step of the field under mode +1 with no angle limit (pi) or cap: smooth."""
    P, tab = _packed(), dop853()
    lim = (math.pi, -1.0, 0.0, math.inf)
    K, ys, y1, g = np.zeros((16, 6)), np.empty(6), np.empty(6), np.empty(4)
    E._field(P, lim, 1, 0.3, S0, K[0], g)
    E._step(P, lim, 1, 0.3, S0, dt, tab.A, tab.b, tab.c, K, ys, y1, g)
    K[12] = ys
    return P, lim, tab, K, y1


@pytest.mark.parametrize("u", [0.25, 0.5, 0.9, 1.0, 1.002, 1.05])
def test_the_dense_output_and_its_continuation_agree_with_a_real_step(u):
    # the locator reads the event's time on a smooth step's dense output, continued a little
    # past its end; a real step of length u dt from the same start is the reference
    dt = EIGHT.period / 200
    P, lim, tab, K, y1 = _smooth_step(dt)
    F, yh, gh, out = np.empty((7, 6)), np.empty(6), np.empty(4), np.empty(6)
    AX, CX, D = dop853_dense()
    E._dense_coefficients(P, lim, 1, 0.3, S0, dt, y1, K, AX, CX, D, F, yh, gh)
    E._dense_state(F, S0, u, out)
    K2, ys, y2, g = K.copy(), np.empty(6), np.empty(6), np.empty(4)
    E._step(P, lim, 1, 0.3, S0, u * dt, tab.A, tab.b, tab.c, K2, ys, y2, g)
    # accuracy: the interpolant is of order 7 in dt = 0.04 s (local error ~ dt^8 x the 8th
    # derivative, O(1e-11) here), measured at most 6.7e-13 on [0, 1.05]; at u = 1 it is the step
    # itself up to rounding. A wrong coefficient of D moves it by dt x a rate, ~1e-2
    assert np.abs(out - y2).max() < 1e-10, np.abs(out - y2).max()


ROWS = dict(deg=[12, 20, 30, 45, 60, 90, 30, 45, 90], cap=[np.inf] * 6 + [4.0] * 3)


@pytest.fixture(scope="module")
def both():
    b, f = np.radians(ROWS["deg"]), np.array(ROWS["cap"])
    return {loc: L.limit_verdicts(Body(), Gains(), EIGHT, b, f, locator=loc)[0] for loc in ("bracket", "dense")}


def test_periodic_verdicts_their_orbits_and_multipliers_do_not_move(both):
    br, de = both["bracket"], both["dense"]
    per = br.regime.isin(["periodic", "slipping"]).to_numpy()
    assert per.sum() >= 5 and (de.regime[per] == br.regime[per]).all() and (de.period[per] == br.period[per]).all()
    for i in np.flatnonzero(per):
        # accuracy: Newton stops at 1e-9 and every event is placed within 1e-11 s (x a jump of
        # the rates < 10) by either locator; 1e-7 on the orbit's point (measured 4.4e-11)
        assert np.abs(de.orbit[i] - br.orbit[i]).max() < 1e-7
        # accuracy: multipliers from a difference Jacobian with steps of 1e-6: good to ~1e-6
        # (measured 1.9e-7); a wrong orbit moves them by its distance x the map's curvature
        assert abs(de.floquet[i] - br.floquet[i]) < 1e-5
        # accuracy: ranges read from the orbit sampled 40 times a period and refined: the orbit
        # moves by < 1e-7, so does the range (measured 9.5e-12)
        assert abs(de.p_range[i] - br.p_range[i]) < 1e-6 and abs(de.pos_err[i] - br.pos_err[i]) < 1e-6


def test_chaotic_statistics_move_only_within_their_standard_errors(both):
    br, de = both["bracket"], both["dense"]
    cha = (br.regime == "chaotic").to_numpy()
    assert cha.sum() >= 3 and (de.regime[cha] == "chaotic").all()
    for i in np.flatnonzero(cha):
        # reason: no integrator follows a chaotic run point by point: a 1e-11 s move of one
        # event grows by e^(0.3 t); the exponent and the drift are batch means over 120 periods
        # with their batch-means errors, and the two estimates are independent; 4 combined
        # standard errors (measured at most 1.15 for the exponent, 1.08 for the drift)
        se = math.hypot(de.lyapunov_stderr[i], br.lyapunov_stderr[i])
        assert abs(de.lyapunov[i] - br.lyapunov[i]) < 4 * se, (ROWS["deg"][i], de.lyapunov[i], br.lyapunov[i], se)
        se = math.hypot(de.drift_stderr[i], br.drift_stderr[i])
        assert abs(de.drift[i] - br.drift[i]) < 4 * se
        assert de.turns_round[i] == br.turns_round[i]


def test_the_dense_locator_lands_within_the_tolerance_of_the_bracket_one():
    # over one period of periodic runs, the two locators' states differ by the events' placement
    # only: each within 1e-11 s before its landing, the run moved by 1e-11 s x a jump of the
    # rates (< 10) per event, about 25 events a period; a landing one step late moves it by
    # dt x a rate, ~1e-2
    r = {loc: L.switched_runs(Body(), Gains(), EIGHT, np.radians([60.0, 90.0, 45.0]), [np.inf, np.inf, 4.0],
                              n_periods=1, locator=loc).states[:, -1] for loc in ("bracket", "dense")}
    # accuracy: 25 events x 1e-11 s x 10 = 2.5e-9 (measured 3.5e-13)
    assert np.abs(r["dense"] - r["bracket"]).max() < 2.5e-9


def test_an_unknown_locator_is_refused():
    with pytest.raises(ValueError, match="locator"):
        L.switched_runs(Body(), Gains(), EIGHT, 0.5, n_periods=1, locator="hermite")
    with pytest.raises(ValueError, match="locator"):
        L.limit_verdicts(Body(), Gains(), EIGHT, [0.5], locator=None)


def test_the_dense_locator_places_nearly_every_event_itself_in_a_few_real_steps():
    # the dense locator's landing stands when a Newton step from it (the event function's real value
    # over its slope on the continuation) puts the root within T_TOL before it; an event it cannot
    # place goes to the bracket locator (about ten real steps). On the book's limits the share handed
    # on was measured at 1.4 % (16 runs' periods, 358 events) and the real steps at 2.2 an event; a
    # landing test that fails (a wrong Newton step) hands on every event, at 3.8 steps an event
    runs = L.switched_runs(Body(), Gains(), EIGHT, np.radians([60.0, 90.0, 45.0, 30.0]), [np.inf, np.inf, 4.0, np.inf],
                           n_periods=4, locator="dense")
    events, steps, handed_on = runs.locating.sum(axis=0)
    assert events > 300                                      # reason: the share is taken over many events
    assert handed_on / events < 0.1                          # measured 0.014; the docstring's "about 3 %"
    assert steps / events < 3.0                              # measured 2.2; the bracket locator's alone ~10
