"""Where Chapter 4's quasi-periodic regime is born: a Neimark-Sacker bifurcation of the
switched closed loop's period-1 orbit along the force cap, at a fixed angle limit.

Newton on the period map (the one Newton, :func:`lib.dynamics.orbits.newton`, with the
Jacobian by forward differences, as :func:`lib.limits.verdicts.limit_verdicts` uses it) finds
the period-1 orbit at one cap; the orbit is continued along the cap, each Newton starting
from the orbit at the last cap, and the cap where the largest Floquet multiplier crosses
the unit circle is located by ``scipy.optimize.brentq`` on |mu| - 1. Where the crossing
multipliers are a complex pair mu = |mu| e^(+-2 pi i rho), the orbit's loss of stability
is a Neimark-Sacker bifurcation: an invariant closed curve of the section (the trace of a
torus of the flow) grows from the orbit on the unstable side, turning by rho turns a
period at its birth. :func:`invariant_circle` measures that rotation on the curve itself,
from a run started on the orbit's unstable plane, and the curve's size, which grows as
the square root of the distance from the crossing when the bifurcation is supercritical.

Units: caps in N, angle limits in rad, states [x, y, phi, xdot, ydot, phidot] (m, rad,
m/s, rad/s), rotation numbers in turns per period of the reference.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.optimize import brentq

from ..dynamics.orbits import floquet_multipliers, newton
from ..params import Body, Gains
from ..trajectories import Reference
from .runs import STEPS_PER_PERIOD, switched_runs
from .verdicts import LIMIT_DEFAULTS, _SwitchedMap

__all__ = ["STEPS_PER_PERIOD", "NS_ANGLE_DEG", "NS_START_CAP", "CapOrbit", "InvariantCircle", "TorusBirth", "cap_orbit",
           "section_centre", "invariant_circle", "torus_birth"]

#: the angle limit (deg) and the cap (N) where Chapter 4 finds the quasi-periodic regime
NS_ANGLE_DEG, NS_START_CAP = 37.0, 6.0

#: Newton on the period map along the cap: more steps than the verdicts allow, each cut to 0.1
_NEWTON = dict(max_iter=30, max_step=0.1)


@dataclass(frozen=True)
class CapOrbit:
    """The period-1 orbit at one cap: its state at t = 0 ``x`` (6,), Newton's ``residual``
    (max-norm) and the Floquet ``multipliers`` (6,), complex, by decreasing modulus."""

    force_limit: float
    x: np.ndarray
    residual: float
    multipliers: np.ndarray

    @property
    def modulus(self) -> float:
        """The largest |multiplier|."""
        return float(abs(self.multipliers[0]))


@dataclass(frozen=True)
class InvariantCircle:
    """The closed curve of the section at ``force_limit`` (N): ``rotation`` (turns a period)
    and its bound ``rotation_error`` (2 / ``periods``, see :func:`invariant_circle`),
    ``amplitude`` (rad, the heading's largest distance from the orbit's on the curve) over
    the last ``periods`` periods of the run."""

    force_limit: float
    rotation: float
    rotation_error: float
    amplitude: float
    periods: int


@dataclass(frozen=True)
class TorusBirth:
    """The located Neimark-Sacker cap ``force_limit`` (N) at ``angle_limit`` (rad), to
    ``xtol`` (N): the orbit there, its crossing ``multiplier`` (Im > 0), ``rotation`` =
    arg(mu) / 2 pi (turns a period), |mu| at the cap -/+ ``xtol`` (``modulus_below``,
    ``modulus_above``), the continuation ``path`` (columns force_limit, modulus, rotation,
    residual) and the invariant ``circles`` measured just past the crossing."""

    angle_limit: float
    force_limit: float
    xtol: float
    orbit: np.ndarray
    multiplier: complex
    rotation: float
    modulus_below: float
    modulus_above: float
    path: pd.DataFrame
    circles: tuple

    @property
    def circle_rotation(self) -> float:
        """The circles' rotation extrapolated linearly to the crossing (turns a period)."""
        (d1, r1), (d2, r2) = [(abs(c.force_limit - self.force_limit), c.rotation) for c in self.circles[:2]]
        return float(r1 + (r1 - r2) * d1 / (d2 - d1))

    @property
    def amplitude_exponent(self) -> float:
        """The exponent of amplitude ~ (distance to the crossing)^e from the first two circles
        (1/2 for a supercritical bifurcation)."""
        (d1, a1), (d2, a2) = [(abs(c.force_limit - self.force_limit), c.amplitude) for c in self.circles[:2]]
        return float(np.log(a2 / a1) / np.log(d2 / d1))


def cap_orbit(body: Body, gains: Gains, ref: Reference, angle_limit: float, force_limit: float, x0, *,
              fd_step: float = LIMIT_DEFAULTS["fd_step"], newton_tol: float = LIMIT_DEFAULTS["newton_tol"],
              steps_per_period: int = STEPS_PER_PERIOD) -> CapOrbit:
    """The period-1 orbit of the switched loop at (``angle_limit`` (rad), ``force_limit`` (N))
    by Newton from ``x0`` (6,), the Jacobian by forward differences of step ``fd_step``.

    Parameters
    ----------
    body, gains, ref : Body, Gains, Reference
        The plant, the gains of (23) and the reference.
    angle_limit, force_limit : float
        beta_max (rad) and F_max (N).
    x0 : array_like
        The start (6,).
    fd_step, newton_tol : float
        Difference step and residual tolerance (the state's units).
    steps_per_period : int
        Fixed steps of the compiled integrator per period.

    Returns
    -------
    CapOrbit
        The orbit, its residual and multipliers.
    """
    pm = _SwitchedMap(body, gains, ref, np.array([float(angle_limit)]), np.array([float(force_limit)]),
                      steps_per_period)
    r = newton(lambda i, x, k: pm.step(i, x, k, fd_step), np.array([0]), np.asarray(x0, dtype=float)[None], 1,
               turn_axis=2, tol=newton_tol, **_NEWTON)
    return CapOrbit(float(force_limit), r.x[0].copy(), float(r.residual[0]), floquet_multipliers(r.jacobian)[0])


def section_centre(body: Body, gains: Gains, ref: Reference, angle_limit: float, force_limit: float, *,
                   transient: int = LIMIT_DEFAULTS["transient"], periods: int = LIMIT_DEFAULTS["periods"],
                   steps_per_period: int = STEPS_PER_PERIOD) -> np.ndarray:
    """The centre of the section of a run from the paper's start (mean state over ``periods``
    periods after ``transient``, the heading by its circular mean): Newton's start inside a
    closed curve, as :func:`lib.dynamics.orbit_search.enclosed_orbit` takes it.

    Parameters
    ----------
    body, gains, ref : Body, Gains, Reference
        The plant, the gains and the reference.
    angle_limit, force_limit : float
        beta_max (rad) and F_max (N).
    transient, periods : int
        Periods dropped and periods averaged.
    steps_per_period : int
        Fixed steps per period.

    Returns
    -------
    numpy.ndarray
        The centre (6,).
    """
    run = switched_runs(body, gains, ref, [angle_limit], [force_limit], n_periods=transient + periods,
                        steps_per_period=steps_per_period)
    sec = run.states[0, transient:]
    x0 = sec.mean(axis=0)
    x0[2] = np.angle(np.exp(1j * sec[:, 2]).mean())
    return x0


def _complex_pair(mu: np.ndarray) -> complex:
    """The multiplier of largest modulus, with Im >= 0."""
    m = complex(mu[0])
    return m.conjugate() if m.imag < 0 else m


def invariant_circle(body: Body, gains: Gains, ref: Reference, angle_limit: float, orbit: CapOrbit, *,
                     periods: int = 1500, settle: int = 1500, kick: float = 1e-3,
                     steps_per_period: int = STEPS_PER_PERIOD) -> InvariantCircle:
    """The closed curve of the section around an orbit that repels through a complex pair:
    a run from the orbit moved by ``kick`` along its unstable plane, ``settle`` periods to
    reach the curve, then ``periods`` periods measured. Each point's complex coordinate on
    that plane, z = w^T (x - x*) (w the left eigenvector of the pair's mu, Im mu > 0), turns
    by arg(z_(k+1) / z_k) in [0, 2 pi) a period; the rotation number is its mean over 2 pi.
    The curve winds once round the orbit, so the turning of a circle map's lift over N
    periods is N rho to within one turn, and the angle read on the plane differs from the
    curve's own by less than half a turn at each end: ``rotation_error`` = 2 / N.

    Parameters
    ----------
    body, gains, ref : Body, Gains, Reference
        The plant, the gains and the reference.
    angle_limit : float
        beta_max (rad).
    orbit : CapOrbit
        The repelling orbit (:func:`cap_orbit`), its cap the run's.
    periods, settle : int
        Periods measured, and before them periods let settle.
    kick : float
        The start's distance from the orbit (max-norm, the state's units).
    steps_per_period : int
        Fixed steps per period.

    Returns
    -------
    InvariantCircle
        The rotation number, its bound, the amplitude.
    """
    mu = _complex_pair(orbit.multipliers)
    if abs(mu.imag) < 1e-9:
        raise ValueError(f"the largest multiplier {mu} is real: no invariant circle is born")
    pm = _SwitchedMap(body, gains, ref, np.array([float(angle_limit)]), np.array([orbit.force_limit]),
                      steps_per_period)
    J = pm.step(np.array([0]), orbit.x[None], np.array([1]), LIMIT_DEFAULTS["fd_step"])[1][0]
    lam, W = np.linalg.eig(J.T)                      # left eigenvectors: w^T J = lambda w^T
    w = W[:, int(np.argmin(np.abs(lam - mu)))]
    lam_r, V = np.linalg.eig(J)
    v = np.real(V[:, int(np.argmin(np.abs(lam_r - mu)))])
    s0 = orbit.x + kick * v / np.abs(v).max()
    run = switched_runs(body, gains, ref, [angle_limit], [orbit.force_limit], s0=s0, n_periods=settle + periods,
                        steps_per_period=steps_per_period)
    d = run.states[0, settle:] - orbit.x
    d[:, 2] = np.angle(np.exp(1j * d[:, 2]))
    z = d @ w
    turn = np.mod(np.angle(z[1:] / z[:-1]), 2 * np.pi)
    return InvariantCircle(orbit.force_limit, float(turn.mean() / (2 * np.pi)), 2.0 / periods,
                           float(np.abs(d[:, 2]).max()), int(periods))


def torus_birth(body: Body, gains: Gains, ref: Reference, angle_limit: float, start_cap: float, *,
                cap_step: float = -0.1, max_steps: int = 40, xtol: float = 1e-4, past=(0.01, 0.03),
                steps_per_period: int = STEPS_PER_PERIOD) -> TorusBirth:
    """Locate the cap where the period-1 orbit at ``angle_limit`` (rad) loses stability, and
    measure the invariant circle born there. Newton from the section's centre at
    ``start_cap`` (N); the orbit continued in steps ``cap_step`` (N) until |mu| - 1 changes
    sign (at most ``max_steps``); ``brentq`` on |mu| - 1 within that step to ``xtol`` (N),
    each evaluation's Newton starting from the last orbit; |mu| then at the cap -/+ ``xtol``;
    and :func:`invariant_circle` at the caps ``past`` (N) beyond the crossing on the side
    where the orbit repels. ``xtol`` must exceed the error of the located cap: |mu| carries
    the difference Jacobian's error (about 1e-5, from comparing difference steps and step
    counts), and |mu| changes by about 1 per N here, so the cap is known to about 1e-5 N.

    Parameters
    ----------
    body, gains, ref : Body, Gains, Reference
        The plant, the gains and the reference.
    angle_limit : float
        beta_max (rad), fixed.
    start_cap : float
        The cap (N) where the continuation starts (a torus there: its section's centre).
    cap_step : float
        The continuation's step (N), signed.
    max_steps : int
        Steps allowed before the crossing.
    xtol : float
        The root finder's tolerance on the cap (N).
    past : tuple of float
        Distances (N) beyond the crossing where the circle is measured.
    steps_per_period : int
        Fixed steps per period.

    Returns
    -------
    TorusBirth
        The crossing, its multiplier and rotation number, the path and the circles.
    """
    kw = dict(steps_per_period=steps_per_period)
    last = cap_orbit(body, gains, ref, angle_limit, start_cap,
                     section_centre(body, gains, ref, angle_limit, start_cap, **kw), **kw)
    path = [last]
    for _ in range(max_steps):
        nxt = cap_orbit(body, gains, ref, angle_limit, last.force_limit + cap_step, last.x, **kw)
        if not nxt.residual <= LIMIT_DEFAULTS["newton_tol"]:
            raise RuntimeError(f"Newton lost the orbit at {nxt.force_limit:g} N (residual {nxt.residual:.1e})")
        path.append(nxt)
        if (nxt.modulus - 1.0) * (last.modulus - 1.0) <= 0.0:
            break
        last = nxt
    else:
        raise RuntimeError(f"|mu| did not cross 1 within {max_steps} steps of {cap_step:g} N from {start_cap:g} N")
    state = {"x": last.x}

    def excess(f):
        o = cap_orbit(body, gains, ref, angle_limit, f, state["x"], **kw)
        if not o.residual <= LIMIT_DEFAULTS["newton_tol"]:
            raise RuntimeError(f"Newton lost the orbit at {f:g} N (residual {o.residual:.1e})")
        state["x"] = o.x
        return o.modulus - 1.0

    lo, hi = sorted((last.force_limit, nxt.force_limit))
    fc = brentq(excess, lo, hi, xtol=xtol)
    at = cap_orbit(body, gains, ref, angle_limit, fc, state["x"], **kw)
    below, above = (cap_orbit(body, gains, ref, angle_limit, fc + s * xtol, at.x, **kw).modulus for s in (-1, 1))
    mu = _complex_pair(at.multipliers)
    out = 1.0 if above > 1.0 else -1.0
    circles = tuple(invariant_circle(body, gains, ref, angle_limit,
                                     cap_orbit(body, gains, ref, angle_limit, fc + out * d, at.x, **kw), **kw)
                    for d in past)
    frame = pd.DataFrame(dict(force_limit=[o.force_limit for o in path], modulus=[o.modulus for o in path],
                              rotation=[abs(np.angle(o.multipliers[0])) / (2 * np.pi) for o in path],
                              residual=[o.residual for o in path]))
    return TorusBirth(float(angle_limit), float(fc), float(xtol), at.x, mu, float(np.angle(mu) / (2 * np.pi)),
                      float(below), float(above), frame, circles)
