"""Chapter 6: what weighting the heading in the allocation does, over many parameter points.

The position-only law (25)-(26) leaves the heading to itself; the weighted
allocation :func:`lib.allocation.allocate_least_squares` trades position tracking
for heading tracking through the weight w_phi. To map that trade-off over the
(R, Theta) plane of Fig. 5 the closed loop (:class:`lib.closed_loop.ClosedLoop`)
is integrated for all points together by the batch integrator
(:mod:`lib.integrators.batch`, classical RK4 with a fixed step; each point may
have its own R, Theta and weights). The step is chosen small against the
fastest closed-loop time scale; the tests check the result against the
adaptive, tight-tolerance :func:`lib.simulate.simulate`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from .allocation import Allocation, Limits
from .angles import wrap_angle
from .closed_loop import ClosedLoop
from .integrators import batch
from .params import Body, Gains
from .robustness import perturbed
from .rotation_verdicts import eight_rotation_sweep
from .trajectories import KINEMATICS

__all__ = ["BatchResult", "closed_loop_batch", "steady_metrics", "MapComparison", "compare_on_map"]


@dataclass(frozen=True)
class BatchResult:
    """Samples of N closed-loop runs: ``t`` (n,), ``z``/``dz``/``z_d`` (n, N, 3), ``F`` (n, N) in N.

    ``period`` (N,) is the reference period 2 pi / |Theta| of each point (s).
    """

    t: np.ndarray
    z: np.ndarray
    dz: np.ndarray
    z_d: np.ndarray
    F: np.ndarray
    period: np.ndarray

    @property
    def rotation_error(self) -> np.ndarray:
        """p = phi - phi_d (rad), shape (n, N)."""
        return self.z[..., 2] - self.z_d[..., 2]

    @property
    def position_error(self) -> np.ndarray:
        """Distance |(x, y) - (x_d, y_d)| (m), shape (n, N)."""
        return np.hypot(*np.moveaxis(self.z[..., :2] - self.z_d[..., :2], -1, 0))


def _points(R, Theta, weights):
    R = np.atleast_1d(np.asarray(R, dtype=float))
    Theta = np.atleast_1d(np.asarray(Theta, dtype=float))
    w = np.asarray(weights, dtype=float)
    if w.ndim == 1:
        w = np.broadcast_to(w, (max(R.size, Theta.size), 3))
    if R.ndim != 1 or Theta.ndim != 1 or w.ndim != 2 or w.shape[1] != 3:
        raise ValueError("R and Theta must be 1-D arrays and weights (3,) or (N, 3)")
    if R.size == 0 or Theta.size == 0 or w.shape[0] == 0:
        raise ValueError("no parameter points given (empty arrays)")
    n = max(R.size, Theta.size, w.shape[0])
    try:
        R, Theta, w = np.broadcast_to(R, n), np.broadcast_to(Theta, n), np.broadcast_to(w, (n, 3))
    except ValueError:
        raise ValueError(f"R ({R.size}), Theta ({Theta.size}) and weights ({w.shape[0]}) must have equal "
                         "lengths (or length 1)") from None
    if not (np.all(np.isfinite(R)) and np.all(R > 0)):
        raise ValueError("every R must be a positive finite radius (m)")
    if not (np.all(np.isfinite(Theta)) and np.all(Theta != 0)):
        raise ValueError("every Theta must be finite and non-zero (rad/s)")
    return R, Theta, w


def _check_loop(body, gains, kind, allocation, limits) -> Limits:
    if kind not in KINEMATICS:
        raise ValueError(f"unknown trajectory {kind!r}; known: {sorted(KINEMATICS)}")
    if not isinstance(body, Body) or not isinstance(gains, Gains):
        raise TypeError("body must be a lib.params.Body and gains a lib.params.Gains")
    if allocation not in ("least_squares", "limited"):
        raise ValueError(f"allocation must be 'least_squares' (limits by projection) or 'limited' (the exact "
                         f"optimum under the limits), got {allocation!r}")
    limits = Limits() if limits is None else limits
    if not isinstance(limits, Limits):
        raise TypeError(f"limits must be a lib.allocation.Limits, got {type(limits).__name__}")
    return limits


def closed_loop_batch(body: Body, gains: Gains, kind: str, R, Theta, weights=(1.0, 1.0, 0.0), *,
                      t_end: float, dt: float = 0.01, record_dt: float = 0.05,
                      z0=None, dz0=None, allocation: str = "least_squares",
                      limits: Limits | None = None) -> BatchResult:
    """Integrate the closed loop with the weighted allocation for N points at once.

    ``kind`` is ``"circle"`` or ``"eight"``; ``R`` (m), ``Theta`` (rad/s) and
    ``weights`` (w_x, w_y, w_phi) are per point (arrays of length N, or one
    value for all). The runs start on the reference (z = z_d(0), dz = dz_d(0))
    unless ``z0``/``dz0`` (shape (3,) or (N, 3)) are given. Classical RK4 with
    step ``dt`` (s) from 0 to ``t_end`` (s); samples every ``record_dt`` (s).
    A run that becomes non-finite raises ``FloatingPointError`` naming the point.

    ``limits`` (:class:`lib.allocation.Limits`: force cap F <= F_max (N), angle limit
    |beta| <= beta_max (rad) of the paper's Sec. 5) are met either by projection,
    ``allocation="least_squares"`` (:func:`lib.allocation.allocate_least_squares`: the
    unconstrained optimum capped and clipped), or exactly, ``allocation="limited"``
    (:func:`lib.allocation.allocate_limited`: the optimum over the admissible sector).
    With no limits the two are the same law. An angle limit makes the closed-loop field
    discontinuous (beta jumps where the optimum moves from one edge ray to the other, or
    where the demand passes behind the body), and the fixed-step RK4 steps across those
    jumps without locating them: its error is then of first order in ``dt`` near each
    switch, so keep ``dt`` small (0.005 s or less) and check it against the adaptive
    :func:`lib.simulate.simulate`, as the tests do.
    """
    limits = _check_loop(body, gains, kind, allocation, limits)
    for name, v in (("t_end", t_end), ("dt", dt), ("record_dt", record_dt)):
        if not np.isfinite(v) or v <= 0:
            raise ValueError(f"{name} must be a positive finite time (s), got {v!r}")
    R, Theta, w = _points(R, Theta, weights)
    kin = KINEMATICS[kind]
    loop = ClosedLoop.of(body, gains, lambda t: kin(R, Theta, t), Allocation(allocation, w), limits)
    zd0, dzd0, _ = kin(R, Theta, 0.0)
    z0 = zd0 if z0 is None else np.broadcast_to(np.asarray(z0, dtype=float), zd0.shape)
    dz0 = dzd0 if dz0 is None else np.broadcast_to(np.asarray(dz0, dtype=float), dzd0.shape)
    n_steps = int(np.ceil(t_end / dt))
    every = max(1, int(round(record_dt / (t_end / n_steps))))
    try:
        t, S = batch.integrate(lambda t, s: loop.rates(t, s)[0], np.concatenate([z0, dz0], axis=1), 0.0, t_end, dt,
                               batch.RK4, record_every=every)
    except FloatingPointError as err:
        bad = int(str(err).rsplit(" ", 1)[-1])
        raise FloatingPointError(f"{err} (R = {R[bad]:g} m, Theta = {Theta[bad]:g} rad/s, "
                                 f"weights = {w[bad]})") from None
    F = np.array([loop.rates(ti, si)[1] for ti, si in zip(t, S)])
    return BatchResult(t=t, z=S[..., :3], dz=S[..., 3:], z_d=kin(R[None, :], Theta[None, :], t[:, None])[0],
                       F=F, period=2 * np.pi / np.abs(Theta))


def steady_metrics(res: BatchResult, n_periods: float = 2.0) -> pd.DataFrame:
    """Steady-state measures of each run over its last ``n_periods`` reference periods.

    Columns: ``pos_rms`` and ``pos_max`` (m) of the position error; ``p_range``
    (rad) max - min of the rotation error p; ``p_rms`` (rad) its RMS after
    wrapping to (-pi, pi] (how far the heading is from the tangent); ``slip_per_period`` (turns) the
    net change of p over the last period divided by 2 pi; ``heading_held``
    True when that net change is below half a turn (the heading does not keep
    slipping); ``pos_drift`` (m) the mean position error over the last period
    minus that over the period before, and ``position_held`` True when it is
    below 1 mm (the body does not drift away from the path); ``F_max`` and
    ``F_rms`` (N).
    """
    out = []
    p, e, F = res.rotation_error, res.position_error, res.F
    for j, P in enumerate(res.period):
        last = res.t >= res.t[-1] - n_periods * P
        if res.t[-1] < (n_periods + 1) * P:
            raise ValueError(f"run {j} is shorter than {n_periods + 1:g} reference periods; extend t_end")
        one = res.t >= res.t[-1] - P
        before = (res.t >= res.t[-1] - 2 * P) & ~one
        net = p[-1, j] - p[one, j][0]
        drift = float(e[one, j].mean() - e[before, j].mean())
        p_wrapped = wrap_angle(p[last, j])
        out.append(dict(pos_rms=float(np.sqrt(np.mean(e[last, j] ** 2))), pos_max=float(e[last, j].max()),
                        p_range=float(np.ptp(p[last, j])), p_rms=float(np.sqrt(np.mean(p_wrapped ** 2))), slip_per_period=float(net / (2 * np.pi)),
                        heading_held=bool(abs(net) < np.pi), pos_drift=drift,
                        position_held=bool(drift < 1e-3), F_max=float(F[last, j].max()),
                        F_rms=float(np.sqrt(np.mean(F[last, j] ** 2)))))
    return pd.DataFrame(out)


@dataclass(frozen=True)
class MapComparison:
    """The two laws on a set of (R, Theta) points of the eight, from one start.

    ``lost`` (N,) bool: the paper's law reaches no attracting periodic orbit of the
    heading (regime other than ``periodic`` in Chapter 5's verdicts,
    :func:`lib.rotation_verdicts.eight_rotation_sweep`: the broad reading of "lost");
    ``held`` (N,) bool: under the weighted law the heading does not slip over the
    last period and the body stays on the path (:func:`steady_metrics`);
    ``pos_rms`` (N,) the weighted law's steady position error (m RMS).
    """

    lost: np.ndarray
    held: np.ndarray
    pos_rms: np.ndarray

    @property
    def counts(self) -> dict:
        """Points lost under the paper's law, of those held by the weighted law
        ("rescued"), and periodic under the paper's law but not held ("broken")."""
        return {"lost": int(self.lost.sum()), "rescued": int((self.lost & self.held).sum()),
                "broken": int((~self.lost & ~self.held).sum())}


def compare_on_map(body: Body, gains: Gains, R, Theta, w_phi: float, *, t_end: float, dt: float = 0.02,
                   rel: float = 0.0) -> MapComparison:
    """Classify the paper's law and the weighted law (weights (1, 1, ``w_phi``)) on the eight
    at the points (R_i (m), Theta_i (rad/s)), both started on the reference; with ``rel``
    != 0 both starts are moved by :func:`lib.robustness.perturbed` (the heading error of
    the paper's law by ``rel`` rad and ``rel`` rad/s), to show which verdicts ride on
    the last bits of a chaotic motion. The weighted law runs for ``t_end`` (s) with
    RK4 step ``dt`` (s)."""
    R, Theta, _ = _points(R, Theta, (1.0, 1.0, w_phi))
    dp0, dv0 = perturbed(np.zeros(2), rel)
    paper = eight_rotation_sweep(body, R, Theta, p0=dp0, v0=dv0)
    zd0, dzd0, _ = KINEMATICS["eight"](R, Theta, 0.0)
    s0 = perturbed(np.concatenate([zd0, dzd0], axis=1), rel)
    res = closed_loop_batch(body, gains, "eight", R, Theta, (1.0, 1.0, w_phi), t_end=t_end, dt=dt,
                            record_dt=0.05, z0=s0[:, :3], dz0=s0[:, 3:])
    m = steady_metrics(res)
    return MapComparison(lost=paper.regime.to_numpy() != "periodic",
                         held=m.heading_held.to_numpy() & m.position_held.to_numpy(),
                         pos_rms=m.pos_rms.to_numpy())
