"""The law for P beside the paper's law, in steady state on the circle (27) and the eight (28).

Both steady motions are exact without a full closed-loop run: under the paper's law C is on the
path and the heading runs on the attracting orbit of the reduced rotation (32)
(:func:`lib.rotation.reduced.rotation_orbit`), the force is tau = m z_d'' + c z_d' (25)-(26); under the
law for P, P is on the path and the heading runs on the attracting orbit of the zero dynamics
(:mod:`lib.percussion.engine`), the force from the body-frame split of P's equation
(:mod:`lib.percussion.zero_dynamics`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..machinery import checks
from ..angles import wrap_angle
from ..params import Body
from ..rotation.engine import check_domain
from ..rotation.reduced import reduced_rotation, rotation_orbit
from ..trajectories import make
from .engine import HeadingEngine, coefficients
from .point import _eps, _s_p
from .sweep import heading_sweep
from .zero_dynamics import _heading_rate, path_drive

__all__ = ["SteadyMotion", "paper_steady", "percussion_steady", "steady_table", "path_distance"]


@dataclass(frozen=True)
class SteadyMotion:
    """One period of a steady motion: t (s), heading error p = phi - phi_d (rad), F (N),
    beta (rad), C (n, 2) (m)."""

    t: np.ndarray
    p: np.ndarray
    F: np.ndarray
    beta: np.ndarray
    C: np.ndarray


def _check(body, kind, R, Theta):
    checks.instance("body", body, Body)
    checks.one_of("kind", kind, ("eight", "circle"))
    return checks.number("R", R, positive=True, unit="m"), checks.number("Theta", Theta, positive=True, unit="rad/s")


def paper_steady(body: Body, kind: str, R: float, Theta: float, *, transient: int = 12, steps: int = 128,
                 record_steps: int = 512) -> SteadyMotion:
    """The paper's law (23), (25)-(26) with C on the path: one period of its attracting orbit
    (the start on the reference, ``transient`` periods, then Newton, on the map of ``steps``
    steps per period), recorded at ``record_steps`` steps.

    Parameters
    ----------
    body : Body
        The body.
    kind : str
        ``"eight"`` (28) or ``"circle"`` (27).
    R : float
        Size of the path (m), > 0.
    Theta : float
        Rate of the reference (rad/s), > 0.
    transient : int
        Periods run from the start on the reference before Newton.
    steps : int
        Steps per period of the period map the orbit is found on.
    record_steps : int
        Steps of the recorded period.

    Returns
    -------
    SteadyMotion
        ``record_steps + 1`` samples from t = 0 to the period 2 pi / Theta (s); C on the path.

    Raises
    ------
    ValueError
        If no orbit of period 1 of the reduced rotation is found.
    """
    R, Theta = _check(body, kind, R, Theta)
    transient = checks.integer("transient", transient, minimum=1)
    steps, record_steps = (checks.integer(n, v, minimum=8)
                           for n, v in (("steps", steps), ("record_steps", record_steps)))
    check_domain(body, kind, np.array([R]), np.array([Theta]))      # the verdicts' domain, before any run
    ref = make(kind, R, Theta)
    orb = rotation_orbit(body, kind, [R], [Theta], transient=transient, steps=steps)
    if not bool(np.all(orb.converged)):
        raise ValueError(f"no orbit of period 1 of the reduced rotation at R = {R}, Theta = {Theta}")
    x = orb.x[0]
    _, dz0, _ = ref.kinematics(0.0)
    p0, v0 = x[0] - ref.z(0.0)[2], (x[1] * Theta - dz0[2])
    t, p = reduced_rotation(body, kind, R, Theta, 1, p0=float(wrap_angle(p0)), v0=float(v0), steps=record_steps)
    z, dz, ddz = ref.kinematics(t)
    tau = body.m * ddz[:, :2] + body.c * dz[:, :2]
    phi = p + z[:, 2]
    return SteadyMotion(t=t, p=p, F=np.hypot(tau[:, 0], tau[:, 1]),
                        beta=wrap_angle(np.arctan2(tau[:, 1], tau[:, 0]) - phi), C=z[:, :2])


def percussion_steady(body: Body, kind: str, R: float, Theta: float, *, steps: int = 512) -> SteadyMotion:
    """The law for P with P on the path: one period of the zero dynamics' attracting orbit
    (decided by :func:`lib.percussion.heading_sweep`), the force and C along it.

    Parameters
    ----------
    body : Body
        The body.
    kind : str
        ``"eight"`` (28) or ``"circle"`` (27), the path of P.
    R : float
        Size of the path (m), > 0.
    Theta : float
        Rate of the reference (rad/s), > 0.
    steps : int
        Magnus steps per period, of the verdict and of the record.

    Returns
    -------
    SteadyMotion
        ``steps`` samples at the step ends, t from (2 pi / Theta) / ``steps`` to 2 pi / Theta (s);
        P on the path, C = P - s_P e1 off it.

    Raises
    ------
    ValueError
        If the heading is not held on an orbit of period 1.
    """
    R, Theta = _check(body, kind, R, Theta)
    v = heading_sweep(body, [R], [Theta], kind=kind, steps=steps)
    if v.regime[0] != "periodic" or v.period[0] != 1:
        raise ValueError(f"the heading is not held on a period-1 orbit at R = {R}, Theta = {Theta}")
    eng = HeadingEngine(kind, steps)
    cA, cV = coefficients(body, [R], [Theta])
    o = eng.flow(np.array([eng.H0 + v.orbit_p[0]]), cA, cV, 1, record=True)
    ref = make(kind, R, Theta)
    t = np.arange(1, steps + 1) * eng.h / Theta
    z = ref.z(t)
    p = wrap_angle(o["p"][0])
    phi = p + z[:, 2]
    w, dw = path_drive(body, ref, t)
    dphi = _heading_rate(_eps(body), phi, w)
    e1 = np.stack([np.cos(phi), np.sin(phi)], -1)
    e2 = np.stack([-e1[:, 1], e1[:, 0]], -1)
    wa, dwl = (w * e1).sum(-1), (dw * e2).sum(-1)
    ddphi = (dwl - wa * dphi) / _eps(body)
    s = _s_p(body)
    u1 = body.m * (wa + s * dphi**2)
    u2 = (body.I * ddphi + body.c_phi * dphi) / body.a
    return SteadyMotion(t=t, p=p, F=np.hypot(u1, u2), beta=np.arctan2(u2, u1), C=z[:, :2] - s * e1)


def path_distance(kind: str, R: float, points, n: int = 20000) -> np.ndarray:
    """Distance (m) of ``points`` (M, 2) from the path ``kind`` of size R, to the nearest of n
    samples of the path refined by a parabola (error far below 1e-6 m for n = 20000).

    Parameters
    ----------
    kind : str
        ``"eight"`` (28) or ``"circle"`` (27).
    R : float
        Size of the path (m).
    points : array_like
        Points (M, 2) (m).
    n : int
        Samples of the path over one period.

    Returns
    -------
    numpy.ndarray
        (M,): the distances (m).
    """
    s = np.linspace(0, 2 * np.pi, n, endpoint=False)
    curve = make(kind, R, 1.0).z(s)[:, :2]
    pts = np.asarray(points, float)
    out = np.empty(len(pts))
    for i, q in enumerate(pts):
        d2 = ((curve - q) ** 2).sum(-1)
        j = int(np.argmin(d2))
        a, b, c = d2[j - 1], d2[j], d2[(j + 1) % n]
        den = a - 2 * b + c
        out[i] = np.sqrt(max(b - (a - c) ** 2 / (8 * den) if den > 0 else b, 0.0))
    return out


def steady_table(body: Body, cases) -> pd.DataFrame:
    """Side by side, for each (kind, R, Theta) of ``cases``: the range of p (rad), peak and mean
    F (N), peak |beta| (rad) and C's largest distance from the path (m), for each law.

    Parameters
    ----------
    body : Body
        The body.
    cases : iterable of tuple
        (kind, R (m), Theta (rad/s)) triples; kind ``"eight"`` or ``"circle"``.

    Returns
    -------
    pandas.DataFrame
        Two rows per case (law ``"C (paper)"`` by :func:`paper_steady`, then ``"P (percussion)"`` by
        :func:`percussion_steady`), columns path, R (m), Theta (rad/s), law, p_range (rad),
        F_peak (N), F_mean (N), beta_peak (rad), C_distance (m; 0 for the paper's law, C being on
        the path, else over every 8th sample).
    """
    rows = []
    for kind, R, Theta in cases:
        for law, fn in (("C (paper)", paper_steady), ("P (percussion)", percussion_steady)):
            sm = fn(body, kind, R, Theta)
            dist = 0.0 if law.startswith("C") else float(path_distance(kind, R, sm.C[::8]).max())
            rows.append(dict(path=kind, R=R, Theta=Theta, law=law, p_range=float(np.ptp(sm.p)),
                             F_peak=float(sm.F.max()), F_mean=float(sm.F.mean()),
                             beta_peak=float(np.abs(sm.beta).max()), C_distance=dist))
    return pd.DataFrame(rows)
