"""The methods' budget: the one domain check of every public entry that takes R, Theta, gains or a
reference (issue 37), re-exported by :mod:`lib.machinery.checks`.

A run is refused before any computation when it would exceed a stated budget, naming the argument
that costs most: an explicit adaptive run (:func:`lib.simulate.simulate`) more than
:data:`MAX_RUN_STEPS` steps (its fastest mode from :func:`loop_modes`, the steps from
:func:`run_steps`); a sweep's point more than :data:`MAX_STEPS` fixed steps a reference period
(:func:`steps_domain`, :func:`loop_domain`); any heading verdict a damping time I_C / c_phi longer
than :data:`MAX_DAMPING_PERIODS` reference periods (:func:`heading_damping`). Every check ends in
:func:`within_budget`. The functions take the body and gains duck-typed, so this module imports
nothing of ``lib``.
"""

from __future__ import annotations

import numpy as np

__all__ = ["loop_modes", "run_steps", "within_budget", "scale_culprit", "by_scale", "heading_damping", "steps_domain",
           "loop_domain", "path_budget", "path_extremes", "MAX_RUN_STEPS", "MAX_ODE_STEPS", "STEPS_PER_RADIAN",
           "MAX_STEPS", "MAX_DAMPING_PERIODS", "RK4_REACH", "slow_rate", "grid_budget", "MAX_GRID_POINTS", "H_DAMP",
           "MAX_SAMPLES", "rate_culprit"]

#: the most steps an explicit adaptive run (:func:`lib.simulate.simulate`) may be expected to take,
#: at about 1.3 ms a step of DOP853 on the closed loop in Python, about a minute of CPU
MAX_RUN_STEPS = 4e4
#: DOP853's steps per radian of an oscillating mode at the default rtol 1e-10 (measured 4 to 13
#: on the closed loop with stiff gains or a large path); a decaying mode costs its rate times the
#: span over 4 (the method's stability reaches about 4 along the negative real axis)
STEPS_PER_RADIAN = 10.0
#: the most steps an adaptive run of two states ((33), the zero dynamics) may be expected to take,
#: at about 50 us a step of ``solve_ivp`` on them, about a minute of CPU
MAX_ODE_STEPS = 1e6
#: the most fixed steps a reference period may need in a sweep over (R, Theta) (beyond, a point
#: costs minutes, R far beyond the body's scale, or Theta far below its rates)
MAX_STEPS = 2 ** 14
#: the most points a map over an n x n grid may hold (Fig. 5's 100 x 100 takes about 20 s of CPU, 2 ms a
#: point: 250 000 points, n = 500, take about 10 minutes on one core)
MAX_GRID_POINTS = 250_000
#: the most samples of a run's default output grid (each sample holds 18 numbers, about 300 MB)
MAX_SAMPLES = 2_000_000
#: the most reference periods the heading's damping time I_C / c_phi may last in a verdict
#: (their transients run 16 to 48 periods, so a start is forgotten before the orbit search begins)
MAX_DAMPING_PERIODS = 8.0


def loop_modes(body, gains=None, *, speed=0.0, accel=0.0, heading_gains: bool = True) -> dict:
    """The closed loop's fastest modes (1/s, complex), each under the arguments that set it: the
    error dynamics M e'' + (Kv + N) e' + Kp e = 0 of (23)-(24) on each axis (``"body and gains"``;
    the heading's axis only when the allocation uses it), and the heading driven by the path,
    (32)'s stiffness omega^2 = a (c v + m a_ref) / I_C at the path's largest speed v and
    acceleration a_ref (``"ref"``, R and Theta). Cheap: a few scalar roots.

    Parameters
    ----------
    body : Body
        The body (duck-typed: m, I, a, c, mass_matrix, drag).
    gains : Gains, optional
        The gains of (23); None for the heading alone.
    speed, accel : float or array_like
        The path's largest speed (m/s) and acceleration (m/s^2), one or one per point.
    heading_gains : bool
        Whether the heading's gains act (an allocation that weights the heading).

    Returns
    -------
    dict
        Argument name -> the fastest mode's eigenvalue (complex, 1/s), a scalar or one per point.
    """
    modes = {}
    if gains is not None:
        M, N = body.mass_matrix.diagonal(), body.drag
        axes = range(3) if heading_gains else range(2)
        lam = [np.roots([M[i], gains.kv[i] + N[i], gains.kp[i]]).astype(complex) for i in axes]
        modes["body and gains"] = max((r for pair in lam for r in pair), key=abs)
    w2 = body.a * (body.c * np.asarray(speed, float) + body.m * np.asarray(accel, float)) / body.I
    modes["ref"] = 1j * np.sqrt(np.maximum(w2, 0.0)) - body.c_phi / body.I
    return modes


def run_steps(mode, span) -> np.ndarray:
    """The steps an explicit adaptive run needs for a mode ``mode`` (1/s, complex) over ``span`` (s):
    :data:`STEPS_PER_RADIAN` a radian it turns and its decay rate over 4 (the stability bound).

    Parameters
    ----------
    mode : complex or array_like
        The eigenvalue (1/s).
    span : float or array_like
        The time span (s).

    Returns
    -------
    numpy.ndarray
        Estimated steps.
    """
    mode = np.asarray(mode, complex)
    return (STEPS_PER_RADIAN * np.abs(mode.imag) + np.abs(mode.real) / 4) * np.abs(np.asarray(span, float))


def within_budget(need, limit: float, *, what: str, unit: str = "", fix: str = "", values=None) -> None:
    """The one domain check of every entry that takes R, Theta, gains or a reference: ``need``
    maps each argument (a name, ``"gains"``, ``"R"``, ``"Theta"``, ``"ref"``, with an index
    where one is given per point) to what it makes the run cost (steps, or periods), a scalar
    or one per point; the first point over ``limit`` is refused, naming the argument that
    costs most there, before any computation.

    Parameters
    ----------
    need : Mapping
        Argument name -> cost (scalar or (N,)).
    limit : float
        The budget, in the cost's unit.
    what : str
        The cost, for the message, read before the number (``"a period would need"``).
    unit : str
        The cost's unit, read after the number (``"steps"``).
    fix : str
        What to do instead, for the message.
    values : Mapping, optional
        Argument name -> its values (scalar or (N,)) with their unit, ``(array, "m")``, quoted
        in the message.

    Raises
    ------
    ValueError
        Naming the argument (and index), its cost and the budget.
    """
    names = list(need)
    cost = np.broadcast_arrays(*(np.atleast_1d(np.asarray(need[k], float)) for k in names))
    worst = np.max(cost, axis=0)
    over = np.flatnonzero(~(worst <= limit))
    if over.size == 0:
        return
    i = int(over[0])
    k = int(np.argmax([c[i] for c in cost]))
    where = names[k] + (f"[{i}]" if worst.size > 1 else "")
    if values and names[k] in values:
        v, v_unit = values[names[k]]
        where += f" = {np.broadcast_to(np.asarray(v, float), worst.shape)[i]:g} {v_unit}".rstrip()
    raise ValueError(f"{where}: {what} about {worst[i]:.3g} {unit}, beyond the budget of {limit:g}".replace("  ", " ")
                     + (f"; {fix}" if fix else ""))


def scale_culprit(body, R, Theta) -> np.ndarray:
    """Which of R and Theta lies farther from the body's own scales (its length a, its rate
    c_phi / I_C) on a log scale, point by point: the argument a cost set by their product is
    laid on. Returns (N,) str, ``"R"`` or ``"Theta"``.

    Parameters
    ----------
    body : Body
        The body (duck-typed: a, c_phi, I).
    R, Theta : array_like
        Radii (m) and rates (rad/s), > 0.

    Returns
    -------
    numpy.ndarray
        ``"R"`` or ``"Theta"`` per point.
    """
    r = np.abs(np.log(np.asarray(R, float) / abs(body.a)))
    t = np.abs(np.log(np.abs(np.asarray(Theta, float)) * body.I / body.c_phi))
    return np.where(r >= t, "R", "Theta")


def by_scale(body, R, Theta, need, names=("R", "Theta")) -> dict:
    """``need`` (a cost set by R and Theta together, one per point) laid on the argument that
    lies farther from the body's scales (:func:`scale_culprit`), for :func:`within_budget`.

    Parameters
    ----------
    body : Body
        The body.
    R, Theta : array_like
        The points.
    need : array_like
        The cost per point.
    names : tuple of str
        How the caller names R and Theta.

    Returns
    -------
    dict
        {names[0]: the cost where R is the culprit, else 0; names[1]: the rest}.
    """
    by_r = scale_culprit(body, R, Theta) == "R"
    need = np.asarray(need, float) * np.ones(by_r.shape)
    return {names[0]: np.where(by_r, need, 0), names[1]: np.where(by_r, 0, need)}


def rate_culprit(body, Theta, mode) -> np.ndarray:
    """Whether a cost set by a rate Theta (rad/s) and a mode ``mode`` (1/s, complex) together, as
    the steps a period T = 2 pi / |Theta| of a mode, lies on Theta: where Theta lies farther from
    the body's rate c_phi / I_C than the mode does, on a log scale (a slow path, not stiff gains).

    Parameters
    ----------
    body : Body
        The body (duck-typed: c_phi, I).
    Theta : array_like
        Rates (rad/s), non-zero.
    mode : complex or array_like
        The mode's eigenvalue (1/s).

    Returns
    -------
    numpy.ndarray
        True where Theta is the culprit, one per point.
    """
    rate = body.c_phi / body.I
    t = np.abs(np.log(np.abs(np.asarray(Theta, float)) / rate))
    m = np.abs(np.log(np.maximum(np.abs(np.asarray(mode, complex)), 1e-300) / rate))
    return t > m


#: the bound on h c_phi / (I_C Theta), the heading's damping over one step of the phase s = Theta t, of the
#: rotation's verdict map (:func:`lib.rotation.engine.check_domain`, ``h_lambda``)
H_DAMP = 0.125


def slow_rate(body, Theta, name: str = "Theta") -> None:
    """Refuse a rate Theta (rad/s) so far below the body's rate c_phi / I_C that the heading's damping
    alone asks more than :data:`MAX_STEPS` fixed steps a reference period of the rotation's verdict
    map (h A <= :data:`H_DAMP`, A = c_phi / (I_C Theta)): the floor of Fig. 5's verdicts
    (:func:`lib.rotation.verdicts.eight_rotation_sweep` refuses the same rates), for a verdict on
    the heading that does not step (the law for P's exact map).

    Parameters
    ----------
    body : Body
        The body (duck-typed: I, c_phi).
    Theta : float or array_like
        Rates (rad/s).
    name : str
        The argument's name in the message.

    Raises
    ------
    ValueError
        Naming the first rate outside, and the domain.
    """
    Theta = np.atleast_1d(np.asarray(Theta, float))
    need = 2 * np.pi * body.c_phi / (body.I * np.abs(Theta) * H_DAMP)
    floor = 2 * np.pi * body.c_phi / (body.I * H_DAMP * MAX_STEPS)
    floor = float(np.ceil(floor / 10 ** np.floor(np.log10(floor) - 2)) * 10 ** np.floor(np.log10(floor) - 2))
    within_budget({name: need}, MAX_STEPS, what="a period would need", unit="fixed steps (the heading's damping "
                  f"alone, at h c_phi / (I_C Theta) <= {H_DAMP:g})", values={name: (Theta, "rad/s")},
                  fix=f"outside the verdicts' domain (Theta far below the body's rates: the heading's verdicts need "
                  f"|{name}| >= {floor:g} rad/s)")


def grid_budget(n: int, name: str = "n") -> None:
    """Refuse an n x n map (an int n, checked) holding more than :data:`MAX_GRID_POINTS` points,
    before any array of it is built, naming ``name``.

    Parameters
    ----------
    n : int
        Points per side.
    name : str
        The argument's name in the message.

    Raises
    ------
    ValueError
        Naming n, the points and the largest n.
    """
    side = int(np.floor(np.sqrt(MAX_GRID_POINTS)))
    if n > side:
        raise ValueError(f"{name} = {n}: an {name} x {name} grid would hold {float(n) ** 2:.3g} points, beyond the "
                         f"budget of {MAX_GRID_POINTS} (at about 2 ms a point, 10 minutes of CPU); use {name} <= "
                         f"{side}, or sweep the points you need")


#: the largest h |lambda| of a fixed-step sweep's RK4 step (its stability reaches about 2.8)
RK4_REACH = 2.5


def heading_damping(body, Theta, name: str = "Theta") -> None:
    """Refuse a rate Theta (rad/s) at which the heading's damping time I_C / c_phi lasts more than
    :data:`MAX_DAMPING_PERIODS` reference periods 2 pi / |Theta|: there no run of a few dozen
    periods forgets its start (every verdict's transient is 16 to 48 periods).

    Parameters
    ----------
    body : Body
        The body (duck-typed: I, c_phi).
    Theta : float or array_like
        Rates (rad/s).
    name : str
        The argument's name in the message.

    Raises
    ------
    ValueError
        Naming the first rate outside, and the domain.
    """
    Theta = np.atleast_1d(np.asarray(Theta, float))
    within_budget({name: body.I / body.c_phi * np.abs(Theta) / (2 * np.pi)}, MAX_DAMPING_PERIODS,
                  values={name: (Theta, "rad/s")}, what="the heading's damping time I_C / c_phi would last",
                  unit="reference periods",
                  fix=f"the domain is |{name}| <= {2 * np.pi * MAX_DAMPING_PERIODS * body.c_phi / body.I:.4g} "
                  "rad/s, where a start is forgotten within the transient")


def steps_domain(steps, damping_steps, R, Theta) -> None:
    """Refuse the first point (R_i (m), Theta_i (rad/s)) whose fixed ``steps`` a period exceed
    :data:`MAX_STEPS`, naming Theta where the damping alone asks for a quarter of them or more
    (``damping_steps``: a rate far below the body's; the steps are rounded up to a power of 2, up to
    twice the exact need, so this is the damping at about half the need or more) and R elsewhere (a
    path far beyond the body's scale).

    Parameters
    ----------
    steps, damping_steps : array_like
        Steps a period each point needs, in all and for its damping alone.
    R, Theta : array_like
        The points.

    Raises
    ------
    ValueError
        Naming R or Theta and the index.
    """
    steps = np.asarray(steps, float)
    by_theta = np.asarray(damping_steps, float) >= steps / 4
    within_budget({"R": np.where(by_theta, 0, steps), "Theta": np.where(by_theta, steps, 0)}, MAX_STEPS,
                  what="a period would need", unit="fixed steps", values={"R": (R, "m"), "Theta": (Theta, "rad/s")},
                  fix="outside the verdicts' domain (R far beyond the body's scale, or Theta far below its rates)")


def loop_domain(body, gains, kin, R, Theta, *, heading_gains: bool = True, names=("R", "Theta"),
                steps: int | None = None, option: str = "steps") -> None:
    """The domain of a sweep of the full closed loop over points (R_i (m), Theta_i (rad/s)) on the
    path ``kin`` (``kin(R, Theta, t)`` -> (z_d, dz_d, ddz_d), :data:`lib.trajectories.KINEMATICS`):
    the heading's damping time at most :data:`MAX_DAMPING_PERIODS` periods (``Theta``), and the
    fixed steps a period that its fastest mode (:func:`loop_modes`: the gains', or the heading's
    driven by the path, laid on R or Theta by :func:`scale_culprit`) needs for RK4, h |lambda| <=
    :data:`RK4_REACH`, at most :data:`MAX_STEPS`. The gains' cost is laid on Theta where Theta lies
    farther from the body's rate than the gains' mode does (:func:`rate_culprit`: a long period, not
    stiff gains). Refuses the first point outside, naming it.

    Parameters
    ----------
    body : Body
        The body.
    gains : Gains or None
        The gains of (23); None for a loop without them (the paper's inputs given, as the optimal
        motions').
    kin : callable
        The path's kinematics, vectorised.
    R, Theta : numpy.ndarray
        The points (N,), checked.
    heading_gains : bool
        Whether the allocation uses the heading's gains (w_phi > 0 somewhere).
    names : tuple of str
        How the caller names R and Theta (``("ref.R", "ref.theta")`` for a reference).
    steps : int, optional
        The fixed steps a period the caller will take: when given, the point must also fit them (a
        run with fewer steps than its fastest mode needs diverges), and the message advises the
        steps it needs.
    option : str
        How the caller names ``steps``, for that advice.

    Raises
    ------
    ValueError
        Naming the argument and index.
    """
    R, Theta = np.atleast_1d(np.asarray(R, float)), np.atleast_1d(np.asarray(Theta, float))
    T = 2 * np.pi / np.abs(Theta)
    heading_damping(body, Theta, names[1])
    _, dz, ddz = kin(R[:, None], Theta[:, None], np.linspace(0.0, 1.0, 65)[None, :] * T[:, None])
    modes = loop_modes(body, gains, speed=np.hypot(dz[..., 0], dz[..., 1]).max(axis=1),
                       accel=np.hypot(ddz[..., 0], ddz[..., 1]).max(axis=1), heading_gains=heading_gains)
    need = by_scale(body, R, Theta, T * np.abs(modes["ref"]) / RK4_REACH, names)
    if gains is not None:
        on_theta = rate_culprit(body, Theta, modes["body and gains"])
        g = T * abs(modes["body and gains"]) / RK4_REACH
        need[names[1]] = np.maximum(need[names[1]], np.where(on_theta, g, 0))
        need["gains"] = np.where(on_theta, 0, g)
    within_budget(need, MAX_STEPS, what="a period would need", unit="fixed steps",
                  values={names[0]: (R, "m"), names[1]: (Theta, "rad/s")},
                  fix="outside the sweep's domain (stiff gains, R far beyond the body's scale or Theta far "
                  "from its rates)")
    if steps is not None:
        most = int(np.ceil(max(np.max(v) for v in need.values())))
        within_budget(need, steps, what="a period would need", unit=f"fixed steps (h |lambda| <= {RK4_REACH:g})",
                      values={names[0]: (R, "m"), names[1]: (Theta, "rad/s")},
                      fix=f"raise {option} to {most} ({option}={steps} given)")


def path_budget(body, R, Theta, span, *, speed: float = 1.0, accel: float = 1.0, names=("R", "Theta"),
                limit: float = MAX_RUN_STEPS, damping: bool = True) -> None:
    """The domain of an adaptive run of the heading driven by a path of size R (m) at rate
    Theta (rad/s) over ``span`` (s, scalar or per point): the heading's damping time
    (:func:`heading_damping`), then :data:`MAX_RUN_STEPS` steps of its fastest mode
    (:func:`loop_modes` at the path's largest speed ``speed`` R Theta and acceleration
    ``accel`` R Theta^2, ``speed`` and ``accel`` those of the unit path: 1 and 1 on the circle),
    laid on R or Theta by :func:`scale_culprit`. Refuses the first point outside, naming it.

    Parameters
    ----------
    body : Body
        The body.
    R, Theta : float or array_like
        The points.
    span : float or array_like
        The run's length (s).
    speed, accel : float
        The unit path's largest speed and acceleration.
    names : tuple of str
        How the caller names R and Theta.
    limit : float
        The budget of steps: :data:`MAX_RUN_STEPS` (the closed loop), or :data:`MAX_ODE_STEPS` (a
        run of two states).
    damping : bool
        Whether to check the heading's damping time too (a verdict after a transient); False for
        the circle's autonomous (33), analysed in its phase plane.

    Raises
    ------
    ValueError
        Naming the argument and index.
    """
    R, Theta = np.broadcast_arrays(np.atleast_1d(np.asarray(R, float)), np.atleast_1d(np.asarray(Theta, float)))
    if damping:
        heading_damping(body, Theta, names[1])
    mode = loop_modes(body, speed=speed * R * np.abs(Theta), accel=accel * R * Theta ** 2)["ref"]
    within_budget(by_scale(body, R, Theta, run_steps(mode, span), names), limit,
                  what="the run would need", unit="steps", values={names[0]: (R, "m"), names[1]: (Theta, "rad/s")},
                  fix="outside the methods' domain (R far beyond the body's scale, or Theta far from its rates)")


def path_extremes(ref) -> tuple[float, float]:
    """The largest speed (m/s) and acceleration (m/s^2) of a path of the book (a reference with
    ``R``, ``theta``, ``period``, ``dz`` and ``ddz``: :class:`lib.trajectories.Circle` or
    :class:`lib.trajectories.Eight`) over one period, sampled at 257 times; (0, 0) for a reference
    of the caller's own making, whose run is then watched for blow-ups as it goes.

    Parameters
    ----------
    ref : Reference
        The reference.

    Returns
    -------
    tuple of float
        Speed (m/s) and acceleration (m/s^2).
    """
    if not all(hasattr(ref, k) for k in ("R", "theta", "period", "dz", "ddz")):
        return 0.0, 0.0
    t = np.linspace(0.0, ref.period, 257)
    dz, ddz = np.asarray(ref.dz(t), float), np.asarray(ref.ddz(t), float)
    return float(np.hypot(dz[:, 0], dz[:, 1]).max()), float(np.hypot(ddz[:, 0], ddz[:, 1]).max())
