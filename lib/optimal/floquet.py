"""The largest Floquet multiplier of a loop's orbit as the book reads and writes it (Chapter 8).

A multiplier taken by differences on an RK4 period map is a numerical estimate, not a certified
value: :mod:`lib.optimal.verdict` states its error (the spread over differencing steps and over
the h and h / 2 maps) and :func:`floquet_estimate` writes it ``value ± error``, the same text in
the chapter's tables and prose and in the report. Two values agree relatively
(:func:`multipliers_agree`), so that a factor 2 is told apart.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from ..machinery import checks
from ..machinery.kinds import Number, numerical

__all__ = ["floquet_estimate", "floquet_text", "largest_floquet", "multiplier_tolerance", "multipliers_agree",
           "MULTIPLIER_TOL", "MULTIPLIER_RTOL", "MULTIPLIER_ATOL"]

#: the most two values of |mu_1| may differ and agree (:func:`multiplier_tolerance`): MULTIPLIER_RTOL of
#: the larger (a factor 2 differs by half the larger: told apart), never more than MULTIPLIER_TOL (as the
#: verdict reads |mu_1| < 1, and the reach test |mu_1| ** (periods / 2) against a factor 3), and never
#: less than MULTIPLIER_ATOL: at |mu_1| <= 0.005 the reach test's term 3 d |mu_1| ** 4 (over the chapter's
#: 8 periods) is below 2e-9 d, three orders under its floor for any start within a metre, so two
#: multipliers that small are alike to both readings (a factor 2 above it is told apart)
MULTIPLIER_TOL, MULTIPLIER_RTOL, MULTIPLIER_ATOL = 0.05, 0.25, 5e-3


def floquet_estimate(value: float, error: float) -> Number:
    """A largest |Floquet multiplier| from differences as the book writes it, everywhere: a
    numerical estimate ``value ± error`` (:func:`lib.machinery.kinds.numerical`) to the decimal
    of the error's second significant digit, at least 3 decimals and at most the value's third
    significant digit: ``0.030 ± 0.023``, ``0.0028 ± 0.0013``, ``0.000934 ± 0.000001``.

    Parameters
    ----------
    value, error : float
        |mu_1| and its stated error (:class:`lib.optimal.verdict.MotionVerdict`), finite, >= 0.

    Returns
    -------
    Number
    """
    value, error = checks.number("value", value, nonnegative=True), checks.number("error", error, nonnegative=True)

    def decimals(x, digits):
        return digits - 1 - math.floor(math.log10(x)) if x > 0 else 3
    return numerical(value, error, f".{max(3, min(decimals(error, 2), decimals(value, 3)))}f")


def floquet_text(value: float, error: float) -> str:
    """:func:`floquet_estimate`'s text, or "-" where the row has no multiplier or no error (no orbit).

    Parameters
    ----------
    value, error : float
        |mu_1| and its stated error; NaN where there is none.

    Returns
    -------
    str
        The text a table prints.
    """
    ok = math.isfinite(value) and math.isfinite(error)
    return floquet_estimate(value, error).text() if ok else "-"


def largest_floquet(frame: pd.DataFrame) -> Number:
    """The largest |mu_1| of a table's rows (columns ``floquet`` and ``floquet_error``, as
    :func:`lib.optimal.studies.compare.side_by_side` and :func:`lib.optimal.studies.margins.tracked_case` give
    them) with that row's error, as :func:`floquet_estimate` writes it: the page's prose, its
    tables and the report print the same text.

    Parameters
    ----------
    frame : pandas.DataFrame
        Rows with finite ``floquet``.

    Returns
    -------
    Number
    """
    checks.instance("frame", frame, pd.DataFrame)
    if not {"floquet", "floquet_error"} <= set(frame.columns) or not np.isfinite(frame.floquet).any():
        raise ValueError("frame must have the columns floquet and floquet_error, with a finite floquet")
    row = frame.loc[frame.floquet.idxmax()]
    return floquet_estimate(float(row.floquet), float(row.floquet_error))


def multiplier_tolerance(a: float, b: float) -> float:
    """How far two values of |mu_1| may lie apart and agree: :data:`MULTIPLIER_RTOL` of the larger
    modulus, at most :data:`MULTIPLIER_TOL` and at least :data:`MULTIPLIER_ATOL`.

    Parameters
    ----------
    a, b : float
        The two moduli (dimensionless).

    Returns
    -------
    float
        The tolerance.
    """
    big = max(abs(a), abs(b))
    return max(MULTIPLIER_ATOL, min(MULTIPLIER_TOL, MULTIPLIER_RTOL * big))


def multipliers_agree(a: float, b: float) -> bool:
    """Whether two values of |mu_1| agree, relatively (:func:`multiplier_tolerance`): 0.008 and
    0.03 do not, nor does any pair a factor 2 apart above :data:`MULTIPLIER_ATOL`; NaN never does.

    Parameters
    ----------
    a, b : float
        The two moduli (dimensionless).

    Returns
    -------
    bool
    """
    a, b = float(a), float(b)
    return bool(math.isfinite(a) and math.isfinite(b) and abs(a - b) <= multiplier_tolerance(a, b))
