"""A wrong model: the closed loop (2)-(4), (23), (25)-(26) when the controller's model of
the body (the m, I_C, c, c_phi, a that (23) and the allocation use) is not the plant.

The plant keeps the Table's values; the model is the plant with each parameter scaled
by (1 + delta), delta a relative error (e.g. -0.2 to 0.2). :func:`mismatch_sweep`
decides each run with the book's one procedure (:mod:`lib.dynamics.verdicts`, the full
closed loop's period map of :mod:`lib.weighting.verdicts`, batch RK4) and reports the
position error it reaches with the heading's verdict; :func:`linear_position_error`
gives the steady position error of the exact error equation with a mismatch,

    m e'' + (K_v + c - c^) e' + K_p e = (m - m^) z_d'' + (c - c^) z_d'    (x and y rows),

which replaces (24) (hats: the model's values). It holds exactly whenever (25)-(26)
realise (tau_x, tau_y) without a limit; (25)-(26) take no body parameter, so only the
model's m and c enter the position, and I_C, c_phi, a of the model do not enter the loop
at all (tau_phi is computed and ignored).

Units: R in m, Theta in rad/s, errors in m, relative errors dimensionless.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Mapping

import numpy as np
import pandas as pd

from ..machinery import checks
from ..allocation import Limits
from ..closed_loop import _paper_rows_tabled
from ..dynamics import verdicts as dv
from ..weighting.verdicts import _PeriodFlow, _check_steps, _decide, _loop_options, _observe, _start
from ..machinery.parallel import concat_frames, map_chunks
from ..params import PAPER_DZ0, PAPER_Z0, Body, Gains
from ..trajectories import KINEMATICS

__all__ = ["PARAMETERS", "model_of", "error_equation", "linear_position_error", "mismatch_sweep", "influence",
           "mismatch_study"]

#: the model's parameters, as :class:`lib.params.Body` names them (m, I_C, c, c_phi, a)
PARAMETERS = ("m", "I", "c", "c_phi", "a")


def model_of(body: Body, **delta: float) -> Body:
    """The controller's model: ``body`` with each named parameter scaled by (1 + delta).

    Parameters
    ----------
    body : Body
        The plant.
    **delta : float
        Relative errors of the model by parameter name (:data:`PARAMETERS`), each > -1.

    Returns
    -------
    Body
        The model, e.g. ``model_of(Body(), m=0.2)`` has m = 2.4 kg.
    """
    checks.instance("body", body, Body)
    scale = _scales({k: np.atleast_1d(v) for k, v in delta.items()}, 1)[0]
    return replace(body, **{p: getattr(body, p) * float(s) for p, s in zip(PARAMETERS, scale)})


def _scales(mismatch: Mapping, n: int) -> np.ndarray:
    """(N, 5) factors 1 + delta in the order of :data:`PARAMETERS`, N = max(n, lengths)."""
    if not isinstance(mismatch, Mapping):
        raise TypeError(f"mismatch must be a mapping of parameter name to relative error, "
                        f"got {type(mismatch).__name__}")
    unknown = sorted(set(mismatch) - set(PARAMETERS))
    if unknown:
        raise ValueError(f"mismatch names unknown parameter(s) {unknown}; known: {list(PARAMETERS)}")
    cols = {k: checks.array(f"mismatch[{k!r}]", v, ndim=1, nonempty=True)
            for k, v in ((k, np.atleast_1d(np.asarray(v))) for k, v in mismatch.items())}
    for k, v in cols.items():
        if np.any(v <= -1):
            i = int(np.flatnonzero(v <= -1)[0])
            raise ValueError(f"mismatch[{k!r}][{i}] must be > -1 (a positive model parameter), got {v[i]!r}")
    N = max([n] + [v.size for v in cols.values()])
    out = np.ones((N, len(PARAMETERS)))
    for j, p in enumerate(PARAMETERS):
        if p in cols:
            v = cols[p]
            if v.size not in (1, N):
                raise ValueError(f"mismatch[{p!r}] has {v.size} entries for {N} points")
            out[:, j] = 1.0 + v
    return out


def linear_position_error(body: Body, gains: Gains, model: Body, kind: str, R: float, Theta: float,
                          n: int = 512) -> np.ndarray:
    """The steady position error e = z_d - z (m) of the error equation with a mismatch.

    Under (23) computed with ``model`` and (25)-(26) without limits, the plant's x row
    m x'' + c x' = tau_x gives, with e = x_d - x, exactly
    m e'' + (k_v + c - c^) e' + k_p e = (m - m^) x_d'' + (c - c^) x_d' (and the y row
    alike): (24) with the plant's mass, the damping moved by the drag's error, and a
    forcing of first order in the mismatch. Its periodic solution is found harmonic by
    harmonic (the forcing of (27), (28) is a trigonometric polynomial: exact up to
    rounding for ``n`` >= 8 samples).

    Parameters
    ----------
    body, model : Body
        The plant and the controller's model.
    gains : Gains
        The gains of (23) (the x and y entries).
    kind : str
        "circle" (27) or "eight" (28).
    R, Theta : float
        Size (m) and rate (rad/s) of the reference.
    n : int
        Samples over one period T = 2 pi / |Theta|.

    Returns
    -------
    numpy.ndarray
        (n, 2): (e_x, e_y) at t = j T / n, j = 0, ..., n - 1, on the periodic solution.
    """
    checks.instance("body", body, Body)
    checks.instance("model", model, Body)
    checks.instance("gains", gains, Gains)
    checks.one_of("kind", kind, tuple(KINEMATICS))
    R = checks.number("R", R, positive=True, unit="m")
    Theta = checks.number("Theta", Theta, nonzero=True, unit="rad/s")
    n = checks.integer("n", n, minimum=8)
    t = np.arange(n) * (2 * np.pi / abs(Theta)) / n
    _, dz_d, ddz_d = KINEMATICS[kind](R, Theta, t)
    dm, dc = body.m - model.m, body.c - model.c
    force = dm * ddz_d[:, :2] + dc * dz_d[:, :2]                       # (n, 2)
    w = np.fft.fftfreq(n, d=1.0 / n) * Theta                           # rad/s of each harmonic
    h = gains.kp[:2] - body.m * w[:, None] ** 2 + 1j * w[:, None] * (gains.kv[:2] + dc)
    return np.fft.ifft(np.fft.fft(force, axis=0) / h, axis=0).real


def error_equation():
    """The x row of the error equation with a mismatch, derived with sympy.

    From the plant's x row of (22), m x'' + c x' = Q_x, with Q_x = tau_x by (25)-(26) and
    tau_x the x row of (23) computed with the model's m^, c^, the substitution
    x = x_d - e leaves a linear equation in e. (The y row is the same with y.)

    Returns
    -------
    tuple
        (lhs, rhs, symbols): sympy expressions with lhs = rhs the error equation,
        lhs = m e'' + (k_v + c - c^) e' + k_p e and rhs the forcing by x_d; ``symbols``
        maps names (t, m, m_hat, c, c_hat, k_p, k_v, e, x_d) to the sympy objects.
    """
    import sympy as sp                      # only here: keeps ``import lib.tracking`` light

    t = sp.symbols("t", real=True)
    m, m_hat, c, c_hat, kp, kv = sp.symbols(r"m \hat{m} c \hat{c} k_p k_v", positive=True)
    e, x_d = sp.Function("e")(t), sp.Function("x_d")(t)
    x = x_d - e
    tau = m_hat * x_d.diff(t, 2) + c_hat * x.diff(t) + kv * (x_d - x).diff(t) + kp * (x_d - x)   # (23)
    residual = sp.expand(tau - (m * x.diff(t, 2) + c * x.diff(t)))       # (22) with Q_x = tau_x: = 0
    lhs = sp.collect(sp.expand(sum(residual.coeff(d) * d for d in (e.diff(t, 2), e.diff(t), e))),
                     [e.diff(t, 2), e.diff(t), e])
    rhs = sp.collect(sp.expand(lhs - residual), [x_d.diff(t, 2), x_d.diff(t)])
    names = dict(t=t, m=m, m_hat=m_hat, c=c, c_hat=c_hat, k_p=kp, k_v=kv, e=e, x_d=x_d)
    return lhs, rhs, names


class _MismatchFlow(_PeriodFlow):
    """The full closed loop's period map (:class:`lib.weighting.verdicts._PeriodFlow`, whose
    tables, sections and error map it keeps) with (23) computed from a model of its own
    for every point (``scale``: (N, 5) factors of the plant's parameters) and the paper's
    allocation (25)-(26); the plant ``body`` in (2)-(4)."""

    def __init__(self, body, gains, kinds, R, Theta, scale, n):
        w = np.broadcast_to(np.array([1.0, 1.0, 0.0]), (R.size, 3))
        super().__init__(body, gains, kinds, R, Theta, w, "least_squares", Limits(), n, lean=False)
        self.scale = scale

    def rates(self, idx):
        """dy/dtau of the rows ``idx``: (23) with each point's model, (25)-(26), (2)-(4), compiled
        (``lib.closed_loop._paper_rows_tabled``; ``tests/test_mismatch.py`` checks the field against
        :class:`lib.closed_loop.ClosedLoop` with each point's model)."""
        b, g = self.body, self.gains
        T = np.ascontiguousarray(self.T[idx])
        table = np.ascontiguousarray(self.table[:, :, idx])                     # (2n, 9, M)
        s = self.scale[idx]
        model = np.stack([b.m * s[:, 0], b.c * s[:, 2]])                        # the model's m and c (2, M)
        k = np.array([g.kp[0], g.kp[1], g.kv[0], g.kv[1]], dtype=float)
        plant = np.array([b.m, b.I, b.c, b.c_phi, b.a])

        def f(tau, y):
            out = np.empty((T.size, 6))
            _paper_rows_tabled(table[self._phase(tau)[1]], np.ascontiguousarray(y, dtype=float), T, model, k, plant, out)
            return out
        return f


def mismatch_sweep(body: Body, gains: Gains, kind, R, Theta, mismatch: Mapping, *, z0=PAPER_Z0,
                   dz0=PAPER_DZ0, executor=None, chunk_size: int | None = None, **options) -> pd.DataFrame:
    """Track the circle (27) or the eight (28) with the plant ``body`` and a controller whose
    model is off: the position error reached and the heading's verdict, point by point.

    Each point runs the full closed loop (2)-(4), (23), (25)-(26) from the Table's start
    (``z0``, ``dz0``), (23) with the model ``body`` scaled by 1 + delta, by the batch RK4 of
    :func:`lib.weighting.verdicts.closed_loop_verdicts` and decided by the same procedure
    (:mod:`lib.dynamics.verdicts`; the words of ``def-regimes``, the Methods page), with the same
    ``options`` (:data:`lib.weighting.verdicts.LOOP_VERDICT_DEFAULTS`). With every delta = 0 it is
    that function's run of the paper's law.

    Parameters
    ----------
    body : Body
        The plant (the Table's values by default in the book).
    gains : Gains
        The gains of (23).
    kind : str or array of str
        "circle" or "eight", one or one per point.
    R, Theta : float or 1-D array
        Size (m) and rate (rad/s) per point (broadcast with the mismatch).
    mismatch : mapping
        Parameter name (:data:`PARAMETERS`) to the model's relative error delta (> -1),
        a number or a 1-D array (one per point); a parameter not named is exact.
    z0, dz0 : array_like
        The start, (3,) (default: the Table's ``PAPER_Z0``, ``PAPER_DZ0``).
    executor, chunk_size
        Scale-out as in :func:`lib.machinery.parallel.map_chunks`: every point is decided on its
        own, so the frame is the one of the serial call.

    Returns
    -------
    pandas.DataFrame
        One row per point: kind, R, Theta, d_m, d_I, d_c, d_c_phi, d_a (the deltas), the
        verdict columns of :func:`lib.weighting.verdicts.closed_loop_verdicts` (regime, lost,
        turns_round, position_lost, tracked, pos_max and pos_rms (m, last block), pos_drift
        (m per period), p_range and p_rms (rad, range and RMS of the heading error p), ...), ``held`` (:func:`lib.dynamics.verdicts.held`)
        and ``pos_linear`` (m), the largest |(e_x, e_y)| of :func:`linear_position_error` at
        the same samples as pos_max (the ``steps`` step ends of a period).
    """
    checks.instance("body", body, Body)
    checks.instance("gains", gains, Gains)
    kinds = np.atleast_1d(np.asarray(kind, dtype=object))
    for k in kinds:
        checks.one_of("kind", k, tuple(KINEMATICS))
    R = checks.array("R", np.atleast_1d(R), ndim=1, positive=True, nonempty=True)
    Theta = checks.array("Theta", np.atleast_1d(Theta), ndim=1, nonempty=True)
    if np.any(Theta == 0):
        raise ValueError(f"Theta[{int(np.flatnonzero(Theta == 0)[0])}] must be non-zero (rad/s)")
    scale = _scales(mismatch, max(kinds.size, R.size, Theta.size))
    N = scale.shape[0]
    try:
        kinds, R, Theta = (np.broadcast_to(v, N) for v in (kinds, R, Theta))
    except ValueError:
        raise ValueError(f"kind ({kinds.size}), R ({R.size}), Theta ({Theta.size}) and the mismatch "
                         f"({N}) must have equal lengths (or length 1)") from None
    z0 = checks.array("z0", z0, shape=(3,))
    dz0 = checks.array("dz0", dz0, shape=(3,))
    o = _loop_options(options)
    for k in set(kinds.tolist()):                 # the domain before any run (issue 37)
        checks.loop_domain(body, gains, KINEMATICS[k], R[kinds == k], Theta[kinds == k], heading_gains=False)
    _check_steps(body, gains, R, Theta, o["steps"])     # the RK4 steps follow the error dynamics, or refused
    parts = map_chunks(_sweep_chunk, N, (kinds, R, Theta, scale),
                       dict(body=body, gains=gains, z0=z0, dz0=dz0, o=o), executor, chunk_size)
    return concat_frames(parts)


def _sweep_chunk(kinds, R, Theta, scale, *, body, gains, z0, dz0, o) -> pd.DataFrame:
    """The rows of :func:`mismatch_sweep` for validated points (one chunk of them)."""
    flow = _MismatchFlow(body, gains, kinds, R, Theta, scale, o["steps"])
    obs = _observe(flow, _start(flow, z0, dz0), o)
    out = _decide(flow, obs, np.ones(R.size, bool), o)
    acc, cnt = obs["acc"], obs["acc"]["cnt"][-1]
    # the linear solution at the flow's own samples (the step ends, t = j T / steps)
    linear = [np.hypot(*linear_position_error(body, gains, _scaled(body, s), k, r, th, o["steps"]).T).max()
              for k, r, th, s in zip(kinds, R, Theta, scale)]
    return pd.DataFrame({"kind": kinds, "R": R, "Theta": Theta,
                         **{f"d_{p}": scale[:, j] - 1.0 for j, p in enumerate(PARAMETERS)}, **out,
                         "held": dv.held(out["regime"], out["lost"], out["tracked"]),
                         "p_range": acc["lmax"] - acc["lmin"], "p_rms": np.sqrt(acc["p2"] / cnt), "pos_rms": np.sqrt(acc["pos2"] / cnt),
                         "pos_max": acc["posmax"], "pos_linear": linear, "periods": int(obs["t_end"]),
                         "steps": o["steps"]})


def _scaled(body: Body, scale) -> Body:
    return replace(body, **{p: getattr(body, p) * float(s) for p, s in zip(PARAMETERS, scale)})


def influence(frame: pd.DataFrame) -> pd.DataFrame:
    """How much each parameter's error moves the runs of a one-at-a-time sweep.

    Parameters
    ----------
    frame : pandas.DataFrame
        A :func:`mismatch_sweep` frame holding, per kind, the exact model (every delta 0)
        and rows with one delta non-zero.

    Returns
    -------
    pandas.DataFrame
        One row per parameter, most influential first: ``pos_change`` (m), the largest
        change of the steady position error pos_max against the exact model's run of the
        same kind; ``p_range_change`` (rad), the same for the heading's range; ``verdicts``,
        how many of its runs have another regime or ``lost`` than the exact model's.
    """
    d = frame[[f"d_{p}" for p in PARAMETERS]].to_numpy()
    exact = np.all(d == 0, axis=1)
    rows = []
    for j, p in enumerate(PARAMETERS):
        pos = dp = 0.0
        changed = 0
        for kind in pd.unique(frame.kind):
            ref = frame[exact & (frame.kind == kind).to_numpy()]
            if len(ref) != 1:
                raise ValueError(f"frame needs one exact-model row of kind {kind!r}, has {len(ref)}")
            ref = ref.iloc[0]
            one = frame[(frame.kind == kind).to_numpy() & (d[:, j] != 0)
                        & np.all(np.delete(d, j, axis=1) == 0, axis=1)]
            pos = max(pos, float(np.abs(one.pos_max.to_numpy() - ref.pos_max).max(initial=0.0)))
            dp = max(dp, float(np.abs(one.p_range.to_numpy() - ref.p_range).max(initial=0.0)))
            changed += int(((one.regime != ref.regime) | (one.lost != ref.lost)).sum())
        rows.append({"parameter": p, "pos_change": pos, "p_range_change": dp, "verdicts": changed})
    return pd.DataFrame(rows).sort_values(["pos_change", "p_range_change"], ascending=False,
                                          kind="stable").reset_index(drop=True)


def mismatch_study(body: Body, gains: Gains, R: float, Theta: float, *, levels=(-0.2, -0.1, 0.1, 0.2),
                   map_levels=tuple(np.linspace(-0.2, 0.2, 13)), kinds=("circle", "eight"), executor=None,
                   chunk_size: int | None = None, **options) -> dict:
    """Chapter 3's study of a wrong model: each parameter off alone, the ranking, and a map
    over the two that matter most.

    Parameters
    ----------
    body, gains : Body, Gains
        The plant and the gains of (23).
    R, Theta : float
        Size (m) and rate (rad/s) of both references.
    levels : sequence of float
        The relative errors of the one-at-a-time runs (the exact model is added).
    map_levels : sequence of float
        The relative errors of each axis of the map.
    kinds : sequence of str
        The references ("circle", "eight").
    executor, chunk_size, **options
        As for :func:`mismatch_sweep`.

    Returns
    -------
    dict
        ``single`` (the one-at-a-time frame, the exact model first for each kind),
        ``influence`` (:func:`influence` of it), ``pair`` (the two most influential
        parameters) and ``map`` (the frame over ``pair``: for each kind, the first
        parameter's level slowest).
    """
    levels = checks.array("levels", levels, ndim=1, nonempty=True)
    map_levels = checks.array("map_levels", map_levels, ndim=1, nonempty=True)
    cols = {p: [] for p in PARAMETERS}
    kind_col = []
    for kind in kinds:
        for p in (None,) + PARAMETERS:
            for v in ([0.0] if p is None else levels):
                kind_col.append(kind)
                for q in PARAMETERS:
                    cols[q].append(v if q == p else 0.0)
    run = dict(executor=executor, chunk_size=chunk_size, **options)
    single = mismatch_sweep(body, gains, np.array(kind_col, dtype=object), R, Theta, cols, **run)
    rank = influence(single)
    pair = tuple(rank.parameter[:2])
    a, b = np.meshgrid(map_levels, map_levels, indexing="ij")
    n = a.size
    grid = mismatch_sweep(body, gains, np.repeat(np.array(kinds, dtype=object), n), R, Theta,
                          {pair[0]: np.tile(a.ravel(), len(kinds)), pair[1]: np.tile(b.ravel(), len(kinds))}, **run)
    return {"single": single, "influence": rank, "pair": pair, "map": grid}
