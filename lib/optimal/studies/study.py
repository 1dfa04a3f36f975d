"""Chapter 8's computations, each one call that the chapter and the report share (through
:func:`lib.machinery.cache.cached`, with the same arguments): the bound under a force cap over
caps and meshes (:func:`cap_sweep`, :func:`cap_convergence`), the best periodic motions found under
the angle limits by continuation from the cap's own optimum (:func:`limit_motions`), their
refinement and extrapolation (:func:`mesh_study`, :func:`richardson`)
and a multi-start study of one setting (:func:`multistart`).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from ...machinery import checks
from ...machinery.kinds import round_directed
from ...params import Body
from ..bound import cap_bound, exact_peak_force
from ..collocation import ACCEPTED
from ..motion import START_TIE, PeriodicMotion, periodic_motion, reintegrated

__all__ = ["PAPER_CAP", "CHAPTER_ANGLES_DEG", "SETTINGS", "CAP_REFINED", "MULTISTART_SEED", "MULTISTART_FINE_RANDOM",
           "setting_label", "cap_sweep", "cap_convergence", "limit_motions", "mesh_study", "richardson",
           "multistart", "convergence_table", "motions_table", "multistart_summary", "multistart_optima",
           "cap_alone_chain"]

#: the paper's force cap (N), Fig. 4
PAPER_CAP = 4.0
#: Chapter 4's chosen angle limits (deg), in the order of the continuation (the largest first)
CHAPTER_ANGLES_DEG = (90, 60, 45, 30)
#: the limit settings of Chapter 8's comparison; (angle limit (deg) or None, cap (N) or None)
SETTINGS = ((None, PAPER_CAP),) + tuple((a, None) for a in CHAPTER_ANGLES_DEG[::-1]) \
    + tuple((a, PAPER_CAP) for a in CHAPTER_ANGLES_DEG[::-1])
#: the meshes (intervals a period) every motion is refined through after the default one. Its inputs
#: are held in the body's frame while the heading swings within an interval, so under a cap its RMS
#: error falls as h^2 (the cap alone's towards the convex optimum, in the bound's bracket at 320)
CAP_REFINED = (160, 320)
#: the seed of :func:`multistart`'s random headings
MULTISTART_SEED = 20141
#: random headings of Chapter 8's multi-start on its finest mesh (each about 1.4 s of CPU there;
#: tests/test_optimal_motion.py runs the full 16 of :func:`multistart`'s default)
MULTISTART_FINE_RANDOM = 4


def setting_label(angle_deg, cap) -> str:
    """'4 N', '30 deg', '30 deg + 4 N': the words of a limit setting.

    Parameters
    ----------
    angle_deg : float or None
        The angle limit (deg), None for none.
    cap : float or None
        The force cap (N), None for none.

    Returns
    -------
    str
        The label ('none' without limits).
    """
    parts = ([] if angle_deg is None else [f"{angle_deg:g} deg"]) + ([] if cap is None else [f"{cap:g} N"])
    return " + ".join(parts) or "none"


def _up(value, fmt: str) -> str:
    """A motion's distance as the page writes a best found value: rounded up (:mod:`lib.machinery.kinds`)."""
    return round_directed(float(value), fmt, "up")


def _check(body, R, Theta, kind):
    checks.instance("body", body, Body)
    checks.one_of("kind", kind, ("eight", "circle"))
    return checks.number("R", R, positive=True, unit="m"), checks.number("Theta", Theta, positive=True, unit="rad/s")


def cap_sweep(body: Body, R: float, Theta: float, caps, *, kind: str = "eight", nodes: int = 256) -> pd.DataFrame:
    """:func:`lib.optimal.bound.cap_bound` at each cap (N): one row per cap with the certified lower
    bounds and the achieved values of the largest and the RMS distance (m), and the gap (m).

    Parameters
    ----------
    body : Body
        The body.
    R, Theta : float
        The path's size (m) and rate (rad/s), > 0.
    caps : array_like
        Force caps F_max (N), > 0, 1-D.
    kind : str
        ``"eight"`` or ``"circle"``.
    nodes : int
        Nodes per period.

    Returns
    -------
    pandas.DataFrame
        Columns cap, max_error, max_error_achieved, rms_error, rms_error_achieved, gap, demand
        (the exact-tracking peak force, N).
    """
    R, Theta = _check(body, R, Theta, kind)
    caps = np.atleast_1d(checks.array("caps", caps, positive=True, ndim=1, nonempty=True))
    checks.integer("nodes", nodes, minimum=16)
    demand = float(exact_peak_force(body, R, Theta, kind=kind))
    rows = []
    for cap in caps:
        b = cap_bound(body, R, Theta, float(cap), kind=kind, nodes=nodes)
        rows.append(dict(cap=float(cap), max_error=b.max_error, max_error_achieved=b.max_error_achieved,
                         rms_error=b.rms_error, rms_error_achieved=b.rms_error_achieved, gap=b.gap, demand=demand))
    return pd.DataFrame(rows)


def cap_convergence(body: Body, R: float, Theta: float, F_max: float, nodes=(64, 128, 256, 512), *,
                    kind: str = "eight") -> pd.DataFrame:
    """The bound against the mesh: :func:`lib.optimal.bound.cap_bound` at each number of nodes,
    with the bracket (achieved - lower bound, m) of each objective.

    Returns
    -------
    pandas.DataFrame
        Columns nodes, max_error, max_error_achieved, max_bracket, rms_error, rms_error_achieved,
        rms_bracket, gap (all m).
    """
    R, Theta = _check(body, R, Theta, kind)
    F_max = checks.number("F_max", F_max, positive=True, unit="N")
    nodes = [checks.integer("nodes", n, minimum=16) for n in np.atleast_1d(nodes)]
    rows = []
    for n in nodes:
        b = cap_bound(body, R, Theta, F_max, kind=kind, nodes=n)
        rows.append(dict(nodes=n, max_error=b.max_error, max_error_achieved=b.max_error_achieved,
                         max_bracket=b.max_error_achieved - b.max_error, rms_error=b.rms_error,
                         rms_error_achieved=b.rms_error_achieved, rms_bracket=b.rms_error_achieved - b.rms_error,
                         gap=b.gap))
    return pd.DataFrame(rows)


def cap_alone_chain(body: Body, R: float, Theta: float, F_max: float, *, kind: str = "eight", nodes: int = 80,
                    refine=CAP_REFINED) -> tuple:
    """The best motion found under the cap alone (:func:`lib.optimal.motion.periodic_motion`): at
    ``nodes`` intervals from every start (the convex one included), then through the meshes
    ``refine``, each from the one before alone (as :func:`mesh_study`).

    Returns
    -------
    tuple of PeriodicMotion
        One a mesh, the coarsest first.
    """
    R, Theta = _check(body, R, Theta, kind)
    F_max = checks.number("F_max", F_max, positive=True, unit="N")
    nodes = checks.integer("nodes", nodes, minimum=8)
    refine = [checks.integer("refine", n, minimum=nodes + 1) for n in refine]
    return _refined(body, periodic_motion(body, R, Theta, kind=kind, F_max=F_max, nodes=nodes), refine)


def _refined(body: Body, m: PeriodicMotion, refine) -> tuple:
    """``m`` and its optimum refined through the meshes ``refine``, each from the one before alone."""
    chain = [m]
    for n in refine:
        chain.append(periodic_motion(body, m.R, m.Theta, kind=m.kind, F_max=m.F_max, beta_max=m.beta_max, nodes=n,
                                     starts=(), guess={f"from {chain[-1].nodes} intervals": chain[-1]}))
    return tuple(chain)


def limit_motions(body: Body, R: float, Theta: float, *, kind: str = "eight", angles_deg=CHAPTER_ANGLES_DEG,
                  caps=(None, PAPER_CAP), nodes: int = 80, refine=CAP_REFINED, chains=None) -> dict:
    """The best periodic motions found (:func:`lib.optimal.motion.periodic_motion`) at every
    setting: for each cap (N, or None) the angle limits in the given order, each started from its
    own starts and from the best found at the limit before (continuation: the largest limit first,
    so that each smaller one starts from a motion just outside its set); with a cap, the first
    angle limit also from the cap alone's optimum at ``nodes`` (:func:`cap_alone_chain`, or
    ``chains[cap]`` if given), whose finest mesh of ``refine`` is kept under the key (None, cap). Each motion's
    ``best_start`` names the start that won (``"from 4 N"``, ``"from 90 deg + 4 N"`` for the
    continuation).

    Returns
    -------
    dict
        (angle limit in deg or None, cap in N or None) -> PeriodicMotion.
    """
    R, Theta = _check(body, R, Theta, kind)
    angles = [checks.number("angles_deg", a, positive=True, maximum=180.0) for a in angles_deg]
    caps = [None if c is None else checks.number("caps", c, positive=True, unit="N") for c in caps]
    nodes = checks.integer("nodes", nodes, minimum=8)
    out: dict = {}
    for cap in caps:
        guess = None
        if cap is not None:
            chain = (chains or {}).get(cap) or cap_alone_chain(body, R, Theta, cap, kind=kind, nodes=nodes,
                                                                refine=refine)
            guess, out[(None, cap)] = {f"from {setting_label(None, cap)}": chain[0]}, chain[-1]
        for a in angles:
            m = periodic_motion(body, R, Theta, kind=kind, F_max=cap, beta_max=math.radians(a), nodes=nodes,
                                guess=guess)
            key = (int(a) if float(a).is_integer() else a, cap)
            out[key] = m
            guess = {f"from {setting_label(*key)}": m}
    return out


def multistart(body: Body, R: float, Theta: float, beta_max: float, F_max: float | None, *, n_random: int = 16,
               seed: int = MULTISTART_SEED, nodes: int = 80, kind: str = "eight") -> pd.DataFrame:
    """The local optima that the collocation (:func:`lib.optimal.motion.periodic_motion`) reaches
    from many starts at one setting: the named starts (``"paper"``, ``"force"``,
    ``"shifted+-"``, and ``"convex"`` under a cap) and ``n_random`` headings turned by angles
    drawn uniformly in [-pi, pi) by ``numpy.random.default_rng(seed)``.

    Parameters
    ----------
    body : Body
        The body.
    R, Theta : float
        The path (m, rad/s).
    beta_max, F_max : float
        Angle limit (rad), force cap (N; None for none).
    n_random, seed : int
        Random headings (>= 1), the generator's seed.
    nodes : int
        Intervals a period.
    kind : str
        ``"eight"`` or ``"circle"``.

    Returns
    -------
    pandas.DataFrame
        One row a start: start (its name), rms_error (m; NaN if IPOPT did not converge), converged.
    """
    R, Theta = _check(body, R, Theta, kind)
    n_random = checks.integer("n_random", n_random, minimum=1)
    seed = checks.integer("seed", seed, minimum=0)
    shifts = np.random.default_rng(seed).uniform(-math.pi, math.pi, n_random)
    named = ("paper", "force", "shifted") + (() if F_max is None else ("convex",))
    m = periodic_motion(body, R, Theta, kind=kind, F_max=F_max, beta_max=beta_max, nodes=nodes, starts=named,
                        shifts=shifts)
    return pd.DataFrame([dict(start=name, rms_error=rms, converged=status in ACCEPTED)
                         for name, rms, status in m.starts])


def multistart_optima(frame: pd.DataFrame, tol: float = START_TIE) -> pd.DataFrame:
    """The distinct optima of :func:`multistart` (RMS errors within ``tol`` (m) of one another are
    one), best first, as the page shows them: RMS distance (m, six decimals, rounded up), starts
    ending there, and a last row of the starts that did not converge.

    Returns
    -------
    pandas.DataFrame
        One row an optimum.
    """
    ok = np.sort(frame.rms_error[frame.converged.astype(bool)].to_numpy())
    group = np.concatenate([[0], np.cumsum(np.diff(ok) > tol)]) if ok.size else np.zeros(0, int)
    rows = [{"RMS distance (m)": _up(ok[group == g][0], ".6f"), "starts ending there": int((group == g).sum())}
            for g in np.unique(group)]
    return pd.DataFrame(rows + [{"RMS distance (m)": "not converged",
                                 "starts ending there": int((~frame.converged.astype(bool)).sum())}])


def multistart_summary(frame: pd.DataFrame, tol: float = 1e-4) -> dict:
    """:func:`multistart`'s spread: starts, converged, best and worst RMS (m) over the converged
    ones, and how many lie within ``tol`` (m) of the best.

    Returns
    -------
    dict
        starts, converged, best, worst, near_best.
    """
    ok = frame.rms_error[frame.converged.astype(bool)]
    best = float(ok.min())
    return dict(starts=len(frame), converged=len(ok), best=best, worst=float(ok.max()),
                near_best=int((ok <= best + tol).sum()))


def mesh_study(body: Body, motions: dict, refine=CAP_REFINED) -> dict:
    """Each motion of :func:`limit_motions` with an angle limit refined through the meshes ``refine``
    (intervals a period, increasing, each above the motion's), each solved from the one before
    alone, interpolated (as :func:`cap_alone_chain`: the same optimum refined, not chosen anew), and
    each re-integrated from its inputs by the book's integrator (:func:`lib.optimal.motion.reintegrated`).

    Parameters
    ----------
    body : Body
        The body the motions were solved for.
    motions : dict
        (angle limit in deg or None, cap in N or None) -> PeriodicMotion.
    refine : sequence of int
        The finer meshes.

    Returns
    -------
    dict
        ``chains``: (angle limit, cap) -> tuple of PeriodicMotion, one a mesh, the given first;
        ``frame``: one row a (setting, mesh): setting, angle_deg, cap, nodes, rms_error (the
        collocation's), rms_integrated (the integrated motion's), max_error (m), F_peak (N),
        return_position (m), return_heading (rad), return_velocity (m/s), return_rate (rad/s),
        best_start, starts_at (starts within START_TIE of the optimum) and starts.
    """
    checks.instance("body", body, Body)
    if not isinstance(motions, dict) or not all(isinstance(m, PeriodicMotion) for m in motions.values()):
        raise TypeError("motions must be a dict (angle limit, cap) -> PeriodicMotion (limit_motions' result)")
    limited = {key: m for key, m in motions.items() if key[0] is not None}
    refine = [checks.integer("refine", n, minimum=max(m.nodes for m in limited.values()) + 1) for n in refine]
    if any(b <= a for a, b in zip(refine, refine[1:])):
        raise ValueError(f"refine must increase (each mesh refines the one before), got {refine}")
    chains, rows = {key: _refined(body, m, refine) for key, m in limited.items()}, []
    for (a, c), chain in chains.items():
        for m in chain:
            r = reintegrated(body, m)
            rows.append(dict(setting=setting_label(a, c), angle_deg=a, cap=c, nodes=m.nodes, rms_error=m.rms_error,
                             rms_integrated=r.pop("rms"), max_error=m.max_error, F_peak=float(m.F.max()),
                             **{f"return_{q}": e for q, e in r.items()}, best_start=m.best_start,
                             starts_at=sum(x <= m.rms_error + START_TIE for _, x, _ in m.starts), starts=len(m.starts)))
    return dict(chains=chains, frame=pd.DataFrame(rows))


def richardson(frame: pd.DataFrame, order: float = 2.0) -> pd.DataFrame:
    """Richardson's extrapolation of each capped motion's integrated RMS (m) over :func:`mesh_study`'s
    meshes (three or more, each twice the one before): e_h - (e_2h - e_h) / (2^p - 1) from the finest
    pair; its error, the larger of that correction and its change from the pair before. Without a
    cap the optimum's force grows with the mesh: no limit is estimated (NaN).

    Parameters
    ----------
    frame : pandas.DataFrame
        :func:`mesh_study`'s frame.
    order : float
        p, the order of the RMS error in h.

    Returns
    -------
    pandas.DataFrame
        One row a setting: setting, nodes (the finest), best (its integrated RMS, m), estimate and
        error (m), ratio (the finest three meshes' differences' ratio, 2^p where the order holds).
    """
    rows, q = [], 2.0 ** checks.number("order", order, positive=True) - 1
    for s, f in frame.groupby("setting", sort=False):
        e, n = f.rms_integrated.to_numpy(), f.nodes.to_numpy()
        if len(e) < 3 or np.any(n[1:] != 2 * n[:-1]):
            raise ValueError(f"frame: setting {s!r} needs three or more meshes, each twice the one before, got {n}")
        est, prev = e[-1] - (e[-2] - e[-1]) / q, e[-2] - (e[-3] - e[-2]) / q
        capped = not pd.isna(f.cap.iloc[0])
        rows.append(dict(setting=s, nodes=int(n[-1]), best=e[-1], estimate=est if capped else math.nan,
                         error=max(abs(e[-1] - est), abs(est - prev)) if capped else math.nan,
                         ratio=(e[-3] - e[-2]) / (e[-2] - e[-1])))
    return pd.DataFrame(rows)


def convergence_table(conv: pd.DataFrame) -> pd.DataFrame:
    """:func:`cap_convergence`'s frame as the page shows it: nodes, the largest distance's bound
    and achieved value, the RMS distance's, and the duality gap (m).

    Parameters
    ----------
    conv : pandas.DataFrame
        The frame of :func:`cap_convergence`.

    Returns
    -------
    pandas.DataFrame
        Six columns, formatted.
    """
    return pd.DataFrame({"nodes": conv.nodes, "largest, bound (m)": conv.max_error.map("{:.5f}".format),
                         "largest, achieved (m)": conv.max_error_achieved.map("{:.5f}".format),
                         "RMS, bound (m)": conv.rms_error.map("{:.5f}".format),
                         "RMS, achieved (m)": conv.rms_error_achieved.map("{:.5f}".format),
                         "duality gap (m)": conv.gap.map("{:.0e}".format)})


def motions_table(frame: pd.DataFrame, rich: pd.DataFrame) -> pd.DataFrame:
    """The best motions found under the angle limits against the mesh (:func:`mesh_study`) as the page
    shows them: RMS distance at each mesh (m, rounded up: motions found), its Richardson estimate
    (:func:`richardson`, "± its error"; "none" without a cap), the largest distance at the
    finest mesh (m, up), the peak force at each mesh (N), the start that won at the coarsest and
    how many starts end within :data:`lib.optimal.motion.START_TIE` of it.

    Parameters
    ----------
    frame, rich : pandas.DataFrame
        :func:`mesh_study`'s and :func:`richardson`'s frames.

    Returns
    -------
    pandas.DataFrame
        One row a setting, formatted.
    """
    nodes, est, rows = " / ".join(str(n) for n in frame.nodes[frame.setting == frame.setting.iloc[0]]), \
        rich.set_index("setting"), []
    for s, f in frame.groupby("setting", sort=False):
        r, first = est.loc[s], f.iloc[0]
        rows.append({"setting": s, f"RMS at {nodes} intervals (m)": " / ".join(_up(v, ".4f") for v in f.rms_integrated),
                     "RMS, Richardson estimate (m)": "none (no cap)" if pd.isna(r.estimate) else
                     f"{round_directed(r.estimate, '.4f', 'nearest')} ± {_up(r.error, '.4f')}",
                     f"largest at {f.nodes.iloc[-1]} (m)": _up(f.max_error.iloc[-1], ".4f"),
                     f"peak F at {nodes} (N)": " / ".join(f"{v:.2f}" for v in f.F_peak),
                     f"best start at {first.nodes}": f"{first.best_start} ({first.starts_at} of {first.starts})"})
    return pd.DataFrame(rows)
