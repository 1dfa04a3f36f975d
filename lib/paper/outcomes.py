"""The vocabulary of the reproduction report (:mod:`lib.paper.report`): the statuses a row can
take, a check's :class:`Outcome` and a row, :class:`Item`. Kept apart so that the report's rows
on the paper (:mod:`lib.paper.report`) and on the book's extensions
(:mod:`lib.paper.extensions`) share it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

__all__ = ["STATUSES", "Outcome", "Item", "decide"]

STATUSES = ("reproduced", "corrected", "refuted", "not reproducible", "extended")


@dataclass(frozen=True)
class Outcome:
    """Result of a report check: the status, a figure of merit with its label, a note."""
    status: str
    merit: float
    merit_label: str
    note: str = ""
    erratum: str | None = None

    def __post_init__(self) -> None:
        if self.status not in STATUSES:
            raise ValueError(f"unknown status {self.status!r}; known: {STATUSES}")
        if not np.isfinite(self.merit):
            raise ValueError(f"figure of merit must be finite, got {self.merit!r}")


@dataclass(frozen=True)
class Item:
    """A row of the report: the paper's item, where the book shows it, the expected status and its check."""
    key: str
    paper: str
    section: str
    expected: str
    check: Callable[[], Outcome]


def decide(ok: bool, good: str, bad: str = "not reproducible") -> str:
    """The status a check decides: the row's claimed status ``good`` when ``ok``, else ``bad``."""
    return good if ok else bad
