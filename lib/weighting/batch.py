"""Batch runs of the closed loop under any allocation (Chapter 6): the six-state closed loop
(:class:`lib.closed_loop.ClosedLoop`) integrated for many (R, Theta, weights) points together
by the batch integrator (:mod:`lib.integrators.batch`, classical RK4 with a fixed step; each
point may have its own R, Theta and weights), and the steady tracking metrics of a run. The
step is chosen small against the fastest closed-loop time scale; the tests check the result
against the adaptive, tight-tolerance :func:`lib.simulate.simulate`. :mod:`lib.weighting`
re-exports these names.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..machinery import checks
from ..allocation import Allocation, Limits
from ..angles import wrap_angle
from ..closed_loop import ClosedLoop
from ..integrators import batch
from .verdicts import _check_loop, _points
from ..params import Body, Gains
from ..trajectories import KINEMATICS

__all__ = ["BatchResult", "closed_loop_batch", "steady_metrics"]


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
    switch. Check a result by halving ``dt``; the tests compare runs at dt = 5 ms with the
    adaptive :func:`lib.simulate.simulate` (within 1e-5) and Chapter 6's 40 ms runs with 20 ms.

    Parameters
    ----------
    body : Body
        The body.
    gains : Gains
        The gains of (23).
    kind : str
        ``"circle"`` or ``"eight"``.
    R, Theta : float or array_like
        Radii (m), > 0, and rates (rad/s), non-zero.
    weights : array_like
        (w_x, w_y, w_phi) >= 0, not all zero, (3,) or (N, 3).
    t_end, dt, record_dt : float
        End time, step and sampling interval (s), > 0.
    z0, dz0 : array_like, optional
        Start (m, m, rad; m/s, m/s, rad/s), (3,) or (N, 3).
    allocation : str
        ``"least_squares"`` or ``"limited"``.
    limits : Limits, optional
        Force and angle limits.

    Returns
    -------
    BatchResult
        The runs, sampled every ``record_dt``.
    """
    limits = _check_loop(body, gains, kind, allocation, limits)
    t_end, dt, record_dt = (checks.number(n, v, positive=True, unit="s")
                            for n, v in (("t_end", t_end), ("dt", dt), ("record_dt", record_dt)))
    R, Theta, w = _points(R, Theta, weights)
    kin = KINEMATICS[kind]
    checks.loop_domain(body, gains, kin, R, Theta, heading_gains=bool(np.any(w[:, 2] > 0)))
    loop = ClosedLoop.of(body, gains, lambda t: kin(R, Theta, t), Allocation(allocation, w), limits)
    zd0, dzd0, _ = kin(R, Theta, 0.0)
    z0 = zd0 if z0 is None else np.broadcast_to(checks.array("z0", z0), zd0.shape)
    dz0 = dzd0 if dz0 is None else np.broadcast_to(checks.array("dz0", dz0), dzd0.shape)
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

    Parameters
    ----------
    res : BatchResult
        Runs of :func:`closed_loop_batch`.
    n_periods : float
        Reference periods at the end.

    Returns
    -------
    pandas.DataFrame
        One row per run, the columns above.
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
