"""The switchings under the difference Jacobian of Chapter 4's Neimark-Sacker multipliers.

:func:`lib.limits.torus.cap_orbit` takes the Floquet multipliers of the switched loop's period-1
orbit from a forward-difference Jacobian: the orbit x and its six companions x + h e_j are each
run over one period. The switched flow is piecewise smooth (the angle limit's clipping, the
force cap, sliding on the angle limit), and a difference quotient is the derivative of the
period map only when every companion meets the same switchings in the same order as the orbit
(no saltation is then crossed differently; the map is smooth across the perturbation).
:func:`switching_census` checks this on the runs themselves: the events the compiled integrator
locates in each run (``locating`` of :class:`lib.limits.runs.SwitchedRuns`), and the mode each run is
in at every step of the period (free, the angle clipped at +beta_max or -beta_max, the force
capped), read from its state through (23) and (25)-(26) without limits.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..allocation import allocate
from ..control import computed_torque
from ..machinery import checks
from ..params import Body, Gains
from ..trajectories import Reference
from .runs import STEPS_PER_PERIOD, switched_runs
from .torus import cap_orbit
from .verdicts import LIMIT_DEFAULTS

__all__ = ["SwitchingCensus", "sample_modes", "switching_census", "crossing_census", "ON_LIMIT"]

#: the band (rad, N) within which a state counts as on a limit (sliding keeps the demand on it)
ON_LIMIT = 1e-6


@dataclass(frozen=True)
class SwitchingCensus:
    """The orbit's run and its six difference companions over one period: ``events`` (7,) the
    switching events each run located, ``differing`` (7,) the steps at which a run's mode
    differs from the orbit's, ``mode_changes`` the orbit's changes of mode between steps,
    ``steps`` the steps a period, and ``spread`` the largest |x_j(t) - x(t)| / h over the
    period and the companions (the difference quotient's size along the way)."""

    events: np.ndarray
    differing: np.ndarray
    mode_changes: int
    steps: int
    spread: float


def sample_modes(body: Body, gains: Gains, ref: Reference, t, states, angle_limit: float, force_limit: float
                 ) -> np.ndarray:
    """The mode of the switched loop at each sample: 0 free, +-1 the angle clipped at +-beta_max,
    plus 3 where the force is capped; the demand of (23) allocated by (25)-(26) without limits,
    a demand within :data:`ON_LIMIT` of a limit counted as on it.

    Parameters
    ----------
    body, gains, ref : Body, Gains, Reference
        The plant, the gains of (23) and the reference.
    t : array_like
        Sample times (s), (n,).
    states : array_like
        (..., n, 6) states at t.
    angle_limit, force_limit : float
        beta_max (rad) and F_max (N).

    Returns
    -------
    numpy.ndarray
        (..., n) int modes.
    """
    states = np.asarray(states, dtype=float)
    tau = computed_torque(body, gains, ref, np.asarray(t, dtype=float), states[..., :3], states[..., 3:])
    F, beta = allocate(tau, states[..., 2])
    angle = np.where(np.abs(beta) >= angle_limit - ON_LIMIT, np.sign(beta), 0).astype(int)
    return angle + 3 * (F >= force_limit - ON_LIMIT).astype(int)


def switching_census(body: Body, gains: Gains, ref: Reference, angle_limit: float, force_limit: float, x, *,
                     fd_step: float = LIMIT_DEFAULTS["fd_step"],
                     steps_per_period: int = STEPS_PER_PERIOD) -> SwitchingCensus:
    """The switchings met over one period by the orbit's state ``x`` and by the companions
    x + ``fd_step`` e_j of the forward-difference Jacobian (the module's docstring).

    Parameters
    ----------
    body, gains, ref : Body, Gains, Reference
        The plant, the gains of (23) and the reference.
    angle_limit, force_limit : float
        beta_max (rad) and F_max (N).
    x : array_like
        The orbit's state at t = 0 (6,).
    fd_step : float
        The difference step h (the state's units), as the Jacobian uses it.
    steps_per_period : int
        Steps of the compiled integrator a period, each one a sample.

    Returns
    -------
    SwitchingCensus
    """
    x = checks.array("x", x, shape=(6,))
    fd_step = checks.number("fd_step", fd_step, positive=True)
    X = np.vstack([x] + [x + fd_step * np.eye(6)[j] for j in range(6)])
    run = switched_runs(body, gains, ref, np.full(7, float(angle_limit)), np.full(7, float(force_limit)), s0=X,
                        n_periods=1, steps_per_period=steps_per_period, samples_per_period=steps_per_period)
    modes = sample_modes(body, gains, ref, run.t, run.states, angle_limit, force_limit)
    spread = float(np.abs(run.states[1:] - run.states[:1]).max() / fd_step)
    return SwitchingCensus(events=run.locating[:, 0].copy(), differing=(modes != modes[:1]).sum(axis=1),
                           mode_changes=int(np.count_nonzero(np.diff(modes[0]))), steps=int(steps_per_period),
                           spread=spread)


def crossing_census(body: Body, gains: Gains, ref: Reference, birth) -> dict:
    """:func:`switching_census` at the two caps one root-finder tolerance either side of a located
    Neimark-Sacker crossing, each at the orbit Newton finds there from the crossing's orbit.

    Parameters
    ----------
    body, gains, ref : Body, Gains, Reference
        The plant, the gains of (23) and the reference.
    birth : lib.limits.torus.TorusBirth
        The located crossing (:func:`lib.limits.torus.torus_birth`).

    Returns
    -------
    dict
        events_min, events_max (events located a period over the 14 runs), differing (steps at
        which a companion's mode differs from its orbit's, summed), mode_changes_min (the orbits'
        fewest changes of mode between steps), steps (a period), spread (the largest
        |x_j - x| / h), residual (the larger Newton residual of the two orbits).
    """
    out = []
    for f in (birth.force_limit - birth.xtol, birth.force_limit + birth.xtol):
        orb = cap_orbit(body, gains, ref, birth.angle_limit, f, birth.orbit)
        out.append((switching_census(body, gains, ref, birth.angle_limit, f, orb.x), orb.residual))
    cs = [c for c, _ in out]
    return dict(events_min=int(min(c.events.min() for c in cs)), events_max=int(max(c.events.max() for c in cs)),
                differing=int(sum(c.differing.sum() for c in cs)), mode_changes_min=min(c.mode_changes for c in cs),
                steps=cs[0].steps, spread=max(c.spread for c in cs), residual=max(r for _, r in out))
