"""Every verdict function on the circle (27), not only on the eight (issue 37): on the circle the
heading error obeys the autonomous (33), whose stable equilibrium p_s and eigenvalues (35) are
closed forms (:func:`lib.rotation.circle.circle_equilibria`, :func:`circle_eigenvalues`), so an
orbit's point, multipliers and exponent are known without a run; below the critical radius (36)
there is no equilibrium and the heading is lost.

The circle's other verdict functions are tested where their law is: the loop of Chapter 8
(:func:`lib.optimal.loop.loop_verdict`, tests/test_optimal_loop.py), the wrong model's sweep
(:func:`lib.tracking.mismatch.mismatch_sweep`, tests/test_mismatch.py) and the weighted law's
closed forms (:mod:`lib.weighting.circle`, tests/test_weighted_circle.py).
"""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from lib import trajectories
from lib.limits.sections import section_sweep
from lib.limits.verdicts import limit_verdicts
from lib.params import Body, Gains
from lib.percussion import sweep as percussion, zero_dynamics
from lib.rotation import attractor, reduced, verdicts
from lib.rotation.circle import circle_critical_radius, circle_eigenvalues, circle_equilibria, circle_rotation_rhs
from lib.rotation.fig5 import confirm_attractors, confirm_lost
from lib.tracking.runs import force_cap_sweep
from lib.weighting.verdicts import closed_loop_verdicts

BODY, GAINS = Body(), Gains()
TH = math.pi / 4                       # the paper's circle: R = 2 m, Theta = pi / 4 rad/s, T = 8 s
T = 2 * math.pi / TH
HELD = (2.0, 0.3)                      # above the critical radius (36), 0.149 m at this rate
LOST = 0.1                             # below it


def _closed_form(R):
    """p_s (rad), the heading's multiplier modulus exp(Re lambda T) and its exponent Re lambda (1/s)."""
    lam = circle_eigenvalues(BODY, R, TH).real.max()
    return circle_equilibria(BODY, R, TH)[0], math.exp(lam * T), lam


def test_the_critical_radius_separates_the_two_cases():
    assert LOST < circle_critical_radius(BODY, TH) < min(HELD)    # reason: the cases are on either side


def test_rotation_verdicts_hold_the_heading_at_the_closed_form_equilibrium():
    df = verdicts.rotation_verdicts(BODY, "circle", list(HELD), [TH, TH])
    assert list(df.regime) == ["periodic", "periodic"] and list(df.period) == [1, 1]
    assert not df.lost.any() and (df.slip == 0).all()
    for R, row in zip(HELD, df.itertuples()):
        p_s, mu, lam = _closed_form(R)
        # accuracy: Newton's tolerance newton_tol 1e-10 rad on the fine map, times 100 (measured 1.8e-14)
        assert row.orbit_p == pytest.approx(p_s, abs=1e-8)
        # accuracy: the fine map's 8th-order steps, its Jacobian exact: 1e-9 relative (measured 1.5e-14)
        assert row.floquet == pytest.approx(mu, rel=1e-9) and row.lyapunov == pytest.approx(lam, rel=1e-9)
        assert row.range < 1e-9             # accuracy: p is constant on the orbit; 100 x newton_tol (measured 4.4e-14)


def _drift_of_33(R, periods=400):
    """Turns of p per period of (33) from rest on the reference, by solve_ivp: its late mean rate."""
    sol = solve_ivp(lambda t, x: [x[1], circle_rotation_rhs(BODY, R, TH, x[0], x[1])], (0, periods * T),
                    [0.0, 0.0], rtol=1e-10, atol=1e-12, t_eval=[periods * T / 2, periods * T])
    return (sol.y[0, 1] - sol.y[0, 0]) / (2 * math.pi) / (periods / 2)


def test_below_the_critical_radius_the_heading_is_lost_at_the_drift_of_33():
    row = verdicts.rotation_verdicts(BODY, "circle", [LOST], [TH]).iloc[0]
    assert row.lost and row.regime not in ("periodic", "slipping")
    # the heading runs round at (33)'s own rate, not locked to the circle's period: the drift
    # measured over the Lyapunov run (batch means) is (33)'s, solved by another integrator
    # accuracy: 3 standard errors of the batch means, and the finite run's start (1e-3 turns); measured 2.1e-4
    assert row.slip == pytest.approx(_drift_of_33(LOST), abs=3 * row.slip_stderr + 1e-3)
    wait = reduced.rotation_sweep(BODY, "circle", [LOST], [TH]).iloc[0]   # the first edition's classifier
    assert wait.regime != "periodic"


def test_the_attractor_is_the_equilibrium_with_the_multipliers_of_35():
    for R in HELD:
        p_s, _, _ = _closed_form(R)
        orb = attractor.rotation_attractor(BODY, "circle", R, TH)
        # accuracy: Newton's orbit, 100 x newton_tol 1e-10 (measured 3.7e-14)
        np.testing.assert_allclose(orb.states[0], [p_s, 0.0], rtol=0, atol=1e-8)
        # the period map's multipliers are exp(lambda T), lambda the pair of (35)
        want = np.sort_complex(np.exp(circle_eigenvalues(BODY, R, TH) * T))
        # accuracy: the fine map's 8th-order steps, its Jacobian exact (measured 3.5e-16 on |mu| = 0.018)
        np.testing.assert_allclose(np.sort_complex(orb.multipliers), want, rtol=0, atol=1e-10)


def test_the_first_editions_classifier_and_the_confirmations_leave_the_circle_periodic():
    wait = reduced.rotation_sweep(BODY, "circle", list(HELD), [TH, TH])
    assert list(wait.regime) == ["periodic", "periodic"] and (wait.slip == 0).all()
    df = verdicts.rotation_verdicts(BODY, "circle", list(HELD), [TH, TH])
    # the equilibrium is reached within the transient: nothing to decide again
    assert list(confirm_attractors(BODY, "circle", df).regime) == ["periodic", "periodic"]
    assert not confirm_lost(BODY, "circle", df).lost.any()


def test_the_full_closed_loop_holds_c_on_the_circle_and_the_heading_at_the_equilibrium():
    df = closed_loop_verdicts(BODY, GAINS, "circle", list(HELD) + [LOST], [TH] * 3)
    assert list(df.regime[:2]) == ["periodic", "periodic"] and df.tracked[:2].all() and not df.lost[:2].any()
    for R, row in zip(HELD, df.iloc[:2].itertuples()):
        p_s, _, lam = _closed_form(R)
        # measured 3.1e-6: RK4 at 128 steps a period; p is constant, so its RMS is |p_s|
        assert row.p_rms == pytest.approx(abs(p_s), abs=3e-5)
        # measured 5.4e-5 relative: Newton's forward-difference Jacobian; the heading's pair is the slowest mode
        assert row.lyapunov == pytest.approx(lam, rel=5e-4)
    assert df.lost[2] and df.regime[2] not in ("periodic", "slipping")        # below the critical radius


def test_the_law_for_p_holds_the_circle_at_its_closed_form_steady_motion():
    df = percussion.heading_sweep(BODY, list(HELD), [TH, TH], kind="circle", steps=512)
    assert list(df.regime) == ["periodic", "periodic"] and not df.lost.any()
    for R, row in zip(HELD, df.itertuples()):
        m = zero_dynamics.circle_steady_motion(BODY, R, TH)
        assert row.orbit_p == pytest.approx(m.p, abs=3e-6)   # measured 2.2e-7: 512 steps a period, fourth order
        assert row.lyapunov == pytest.approx(m.rate, rel=3e-7)  # measured 2.3e-8, as above


def test_a_force_cap_below_the_circles_steady_force_cannot_hold_c_on_it():
    # C on the circle needs |F| = R Theta sqrt(m^2 Theta^2 + c^2) (centripetal and drag), constant
    R = 2.0
    need = R * TH * math.hypot(BODY.m * TH, BODY.c)
    df = force_cap_sweep(BODY, GAINS, trajectories.circle(R, TH), [0.9 * need, 4.0, 10.0])
    assert df.sat_fraction[0] == 1.0 and df.pos_err_max[0] > 0.1     # reason: the cap always binds, C falls behind
    assert (df.sat_fraction[1:] == 0).all()
    assert (df.pos_err_max[1:] < 1e-9).all()                          # measured 4.4e-13: the error decays as (24)


def test_the_section_of_an_angle_limit_that_never_binds_is_the_equilibrium():
    # the steady beta on the paper's circle is 0.074 rad: a 1 rad limit never binds after the transient
    sec = section_sweep(BODY, GAINS, trajectories.circle(2.0, TH), [1.0], n_transient=10, n_points=3)[0]
    want = np.array([0.0, 0.0, 0.0, 0.0, _closed_form(2.0)[0], 0.0])
    np.testing.assert_allclose(sec, np.broadcast_to(want, sec.shape), rtol=0, atol=1e-7)  # accuracy: rtol 1e-8 times 10 (measured 5.6e-10)


def test_limit_verdicts_hold_the_circle_at_the_closed_form_equilibrium():
    # no angle limit (pi) and one the steady force never reaches (1 rad > beta* = 0.074 rad): the
    # orbit is C on the circle with the heading at (33)'s stable equilibrium p0 (issue 37: the
    # circle's own turn was counted as a slip)
    fr, _ = limit_verdicts(BODY, GAINS, trajectories.circle(), [np.pi, 1.0])
    assert list(fr.regime) == ["periodic", "periodic"] and list(fr.turns) == [0, 0]
    assert not fr.lost.any() and (fr.drift == 0).all()
    p0 = circle_equilibria(BODY, 2.0, TH)[0]
    for orbit in fr.orbit:
        # accuracy: Newton's tolerance 1e-9 on the switched map, times 100
        assert math.remainder(orbit[2] - math.pi / 2 - p0, 2 * math.pi) == pytest.approx(0.0, abs=1e-7)
    # the largest multiplier is the heading's pair of (35), exp(Re(lambda) T), above the position
    # error's exp(-Kv T / (2 m)) of (24)
    want = float(np.exp(circle_eigenvalues(BODY, 2.0, TH).real.max() * T))
    # accuracy: a forward-difference Jacobian of step 1e-6 on a map integrated to 1e-10, ~1e-5
    assert fr.floquet.to_numpy() == pytest.approx([want, want], abs=1e-4)
    # reason: the heading error is constant on the orbit, its range the integration's noise
    assert (fr.p_range < 1e-6).all()
