"""The law for P with a wrong model of the body, as Chapter 3 tests the paper's law.

The paper's law (23), (25)-(26) uses only the model's m and c for the position
(:mod:`lib.tracking.mismatch`). The law for P uses every parameter: s_P = -I_C/(m a) places the
point it tracks, eps = s_P (c/m - c_phi/I_C) divides its demanded angular acceleration, and
u2 = (I_C omega' + c_phi omega)/a realises it. With a wrong model the point the law tracks is not
the plant's centre of percussion, so the lateral force enters that point's acceleration and the
cascade of the nominal loop (P's error linear, the heading driven by it) is broken. Here the
plant keeps the Table's values and the law's model has one parameter scaled by (1 + delta); each
run is decided by :func:`lib.percussion.full_loop.full_loop_verdicts` from the paper's start.
"""

from __future__ import annotations

from dataclasses import replace

import pandas as pd

from ..machinery import checks
from ..params import Body, Gains
from .full_loop import full_loop_verdicts

__all__ = ["MODEL_PARAMETERS", "MODEL_SYMBOLS", "wrong_model_study", "delta_label", "error_table"]

#: the body's parameters the law for P uses, in the order of the study
MODEL_PARAMETERS = ("m", "I", "a", "c", "c_phi")
#: how the book writes each parameter
MODEL_SYMBOLS = {"m": "m", "I": "I_C", "a": "a", "c": "c", "c_phi": "c_phi"}


def wrong_model_study(body: Body, gains: Gains, R: float, Theta: float, deltas=(-0.1, -0.05, 0.05, 0.1),
                      parameters=MODEL_PARAMETERS, **options) -> pd.DataFrame:
    """The law for P on the eight (28) of size R (m) at Theta (rad/s) with its model's
    ``parameter`` scaled by (1 + delta), one run each, and the nominal run (delta = 0).

    Parameters
    ----------
    body, gains : Body, Gains
        The plant and the gains.
    R, Theta : float
        The eight's size (m) and rate (rad/s).
    deltas : sequence of float
        Relative errors of the model, each > -1.
    parameters : sequence of str
        Names of :data:`MODEL_PARAMETERS`.
    **options
        Keys of :data:`lib.percussion.full_loop.FULL_LOOP_OPTIONS`.

    Returns
    -------
    pandas.DataFrame
        One row a run: parameter ("none" for the nominal run), delta, regime, held, P_error (the
        largest distance of the model's P from the path on the orbit, m), orbit_p (rad), F_orbit
        (N), reason.
    """
    checks.instance("body", body, Body)
    for p in parameters:
        checks.one_of("parameter", p, MODEL_PARAMETERS)
    deltas = [checks.number("delta", d) for d in deltas]
    if any(d <= -1 for d in deltas):
        raise ValueError(f"every delta must exceed -1, got {deltas}")
    runs = [("none", 0.0, body)] + [(p, d, replace(body, **{p: getattr(body, p) * (1 + d)}))
                                    for p in parameters for d in deltas]
    rows = []
    for p, d, model in runs:
        fr = full_loop_verdicts(body, gains, [R], [Theta], model=model, **options).iloc[0]
        rows.append(dict(parameter=p, delta=d, regime=fr.regime, held=bool(fr.held), P_error=fr.P_error,
                         orbit_p=fr.orbit_p, F_orbit=fr.F_orbit, reason=fr.reason))
    return pd.DataFrame(rows)


def delta_label(delta: float) -> str:
    """A relative error as the book writes it, with its sign: 0.05 -> "+5 %".

    Parameters
    ----------
    delta : float
        The relative error.

    Returns
    -------
    str
    """
    return f"{delta:+.0%}".replace("%", " %")


def error_table(study: pd.DataFrame) -> pd.DataFrame:
    """The study as a table: one row a parameter, one column a relative error, each cell the
    tracked point's largest distance from the path on the orbit (m, 3 decimals) or the regime
    where the heading is not held.

    Parameters
    ----------
    study : pandas.DataFrame
        :func:`wrong_model_study`.

    Returns
    -------
    pandas.DataFrame
        Columns "model's parameter" (I written I_C) and one per delta (as "+5 %").
    """
    off = study[study.parameter != "none"]
    cell = [f"{r.P_error:.3f}" if r.held else ("diverged" if r.reason == "diverged" else r.regime)
            for r in off.itertuples()]
    table = off.assign(cell=cell, column=[delta_label(d) for d in off.delta])
    wide = table.pivot(index="parameter", columns="column", values="cell")
    order = [delta_label(d) for d in sorted(set(off.delta))]
    wide = wide.reindex(index=[p for p in MODEL_PARAMETERS if p in set(off.parameter)], columns=order)
    wide.index, wide.columns.name = [MODEL_SYMBOLS[p] for p in wide.index], None
    return wide.rename_axis("model's parameter").reset_index()
