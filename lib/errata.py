"""Errata of the paper: one list of rows, each with the computation that proves it.

A row is an :class:`Erratum`. Its ``check`` runs the computation and returns a
:class:`Verdict`: whether the printed form holds (it must not) and whether the
corrected form holds (it must). The errata page renders :func:`rows` with a
live verdict and the test suite iterates the same list, so a row cannot exist
without its check.

Rows are owned by the module whose computation proves them: each module listed
in :data:`SOURCES` defines a list ``ERRATA``. A module added to SOURCES must
exist; a missing one is an import error, not a silently shorter table.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from typing import Callable

__all__ = ["Erratum", "Verdict", "rows", "table", "SOURCES"]

#: modules that contribute rows, in the order of the paper's sections
SOURCES: tuple[str, ...] = ("lib.symbolic", "lib.tracking", "lib.stability")


@dataclass(frozen=True)
class Verdict:
    """Outcome of an erratum's check.

    ``printed_holds`` must be False and ``corrected_holds`` True for the row to
    stand; ``detail`` is a short human-readable account (a residual, a count).
    """

    printed_holds: bool
    corrected_holds: bool
    detail: str

    @property
    def confirmed(self) -> bool:
        return (not self.printed_holds) and self.corrected_holds


@dataclass(frozen=True)
class Erratum:
    """One row: where in the paper, what is printed, the correction, how it is verified.

    ``printed`` and ``corrected`` are MyST/LaTeX snippets (inline math in $...$);
    ``verified_by`` names the test or the computation; ``section`` the book page
    (a document path such as ``chapters/01_model``) that shows it.
    """

    key: str
    where: str
    printed: str
    corrected: str
    verified_by: str
    section: str
    check: Callable[[], Verdict]


def rows() -> list[Erratum]:
    """All errata rows, collected from :data:`SOURCES` in order."""
    out: list[Erratum] = []
    for name in SOURCES:
        out.extend(importlib.import_module(name).ERRATA)
    keys = [r.key for r in out]
    dup = {k for k in keys if keys.count(k) > 1}
    if dup:
        raise RuntimeError(f"duplicate errata keys: {sorted(dup)}")
    return out


def table(run_checks: bool = True):
    """The errata as a pandas DataFrame; with ``run_checks`` each row's verdict is computed."""
    import pandas as pd

    records = []
    for r in rows():
        rec = {"key": r.key, "where": r.where, "printed": r.printed, "corrected": r.corrected,
               "verified by": r.verified_by, "section": r.section}
        if run_checks:
            v = r.check()
            rec["confirmed"] = v.confirmed
            rec["detail"] = v.detail
        records.append(rec)
    return pd.DataFrame.from_records(records)
