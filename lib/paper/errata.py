"""Errata of the paper: one list of rows, each with the computation that proves it.

A row is an :class:`Erratum`. Its ``check`` runs the computation and returns a
:class:`Verdict`: whether the printed form holds (it must not) and whether the
corrected form holds (it must). The errata page renders :func:`rows` with a
live verdict and the test suite iterates the same list, so a row cannot exist
without its check.

Rows are grouped by the paper's sections in :mod:`.model_errata` (Secs. 2-3),
:mod:`.tracking_errata` (Secs. 4-5), :mod:`.rotation_errata` (Sec. 6) and
:mod:`.reading_errata` (slips of notation, readings and definitions found by a
line-by-line audit: the branch of Arg in (28) and the rows in which (24) holds change no
computation of the paper's and are flagged ``notation``), each
importing the domain modules whose computations prove its rows; no domain
module imports this subpackage.
"""

from __future__ import annotations

import pandas as pd

from ..machinery.cache import cached
from . import model_errata, reading_errata, rotation_errata, tracking_errata
from .verdicts import Erratum, Verdict

__all__ = ["Erratum", "Verdict", "rows", "verdict", "table", "SOURCES"]

#: the modules that contribute rows, in the order of the paper's sections
SOURCES = (model_errata, tracking_errata, rotation_errata, reading_errata)


def rows() -> list[Erratum]:
    """All errata rows, collected from :data:`SOURCES` in order."""
    out: list[Erratum] = []
    for module in SOURCES:
        out.extend(module.ROWS)
    keys = [r.key for r in out]
    dup = {k for k in keys if keys.count(k) > 1}
    if dup:
        raise RuntimeError(f"duplicate errata keys: {sorted(dup)}")
    return out


def verdict(key: str) -> Verdict:
    """The verdict of the row ``key``'s check. In a book build it is computed once per state
    of the library (:func:`lib.machinery.cache.cached`) and shared by the errata page, the
    report, Chapter 5 and the tests run beside the build; elsewhere it is simply computed."""
    return cached(_check_row, key)


def _check_row(key: str) -> Verdict:
    for r in rows():
        if r.key == key:
            return r.check()
    raise KeyError(f"no errata row {key!r}")


def table(run_checks: bool = True):
    """The errata as a pandas DataFrame; with ``run_checks`` each row's verdict is computed.

    Parameters
    ----------
    run_checks : bool
        Run each row's check (columns ``confirmed`` and ``detail``).

    Returns
    -------
    pandas.DataFrame
        One row an erratum; ``kind`` says whether it changes a result or is a slip of notation
        or a reading that changes no computation (``Erratum.notation``).
    """
    records = []
    for r in rows():
        rec = {"key": r.key, "where": r.where, "printed": r.printed, "corrected": r.corrected,
               "verified by": r.verified_by, "section": r.section,
               "kind": "notation or reading" if r.notation else "changes a result"}
        if run_checks:
            v = verdict(r.key)
            rec["confirmed"] = v.confirmed
            rec["detail"] = v.detail
        records.append(rec)
    return pd.DataFrame.from_records(records)
