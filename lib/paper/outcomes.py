"""The vocabulary of the reproduction report (:mod:`lib.paper.report`): the statuses a row can
take, a check's :class:`Outcome` and a row, :class:`Item`. Kept apart so that the report's rows
on the paper (:mod:`lib.paper.report`) and on the book's extensions
(:mod:`lib.paper.extensions`) share it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..machinery.kinds import Kind, Number

__all__ = ["STATUSES", "Outcome", "Item", "legend_status"]

STATUSES = ("reproduced", "reproduced under an added condition", "corrected", "misapplied", "refuted",
            "not reproducible as stated", "not reproducible", "extended")


@dataclass(frozen=True)
class Outcome:
    """Result of a report check: the status, a figure of merit with its label, a note, the
    errata row it links, and what the check established beside its evidence (the flags of
    :func:`legend_status`): a counterexample to the claim as the paper uses it, a theorem used
    outside its hypotheses, a condition the paper does not state that the confirmation needs,
    or a figure whose grid and criterion the paper does not state and that depends on them.

    The figure of merit has a kind (:class:`lib.machinery.kinds.Kind`: exact unless the check says
    it is a certified bound, a motion found or an estimate, which carries ``merit_stderr``, its standard
    or stated error), and :meth:`merit_text` writes it as its kind says: a lower bound rounded down, a
    motion found up, to the digits ``merit_fmt`` gives (a coefficient the paper prints to two decimals
    is shown to four, so that the digit it gets wrong is visible; a multiplier in the format its
    chapter prints it with)."""
    status: str
    merit: float
    merit_label: str
    note: str = ""
    erratum: str | None = None
    counterexample: bool = False
    misapplied: bool = False
    added_condition: bool = False
    unstated: bool = False
    merit_kind: str = Kind.EXACT.value
    merit_stderr: float | None = None
    merit_fmt: str = ".3g"

    def __post_init__(self) -> None:
        if self.status not in STATUSES:
            raise ValueError(f"unknown status {self.status!r}; known: {STATUSES}")
        if not np.isfinite(self.merit):
            raise ValueError(f"figure of merit must be finite, got {self.merit!r}")
        self.number()                                  # the kind and its error are consistent

    def number(self, fmt: str | None = None) -> Number:
        """The figure of merit as a :class:`~lib.machinery.kinds.Number` of its kind (format
        ``fmt``, default ``merit_fmt``)."""
        return Number(float(self.merit), Kind(self.merit_kind), fmt or self.merit_fmt, stderr=self.merit_stderr)

    def merit_text(self, fmt: str | None = None) -> str:
        """The figure of merit as the report writes it (its kind decides the rounding)."""
        return self.number(fmt).text()


@dataclass(frozen=True)
class Item:
    """A row of the report: the paper's item, where the book shows it, the expected status and its check."""
    key: str
    paper: str
    section: str
    expected: str
    check: Callable[[], Outcome]


def legend_status(evidence: bool, *, printed_fails: bool = False, counterexample: bool = False,
                  extension: bool = False, misapplied: bool = False, added_condition: bool = False,
                  unstated: bool = False) -> str:
    """The report's legend as one rule: the status of a row from what its check established.

    In this order:

    - ``evidence`` False (the computation does not confirm the row): **not reproducible**;
    - ``extension`` (the book goes beyond the paper): **extended**;
    - ``unstated`` (the paper leaves out what a reproduction needs, a grid or a criterion, and
      the check shows that the result depends on it): **not reproducible as stated**; the
      book's own answer is an extension row;
    - ``misapplied`` (a true theorem cited for a system outside its hypotheses, the check
      showing a hypothesis fails): **misapplied**, not "refuted": the theorem stands;
    - ``counterexample`` (a case where the paper's claim, as printed and as it is used, is
      false: a bistable window against "globally", a two-state system against Theorem 6):
      **refuted**, however much of it survives;
    - ``printed_fails`` (an errata row on the row's equations, not a slip of notation only,
      confirms that the printed form fails and the corrected one holds): **corrected**;
    - ``added_condition`` (confirmed only with something the paper does not state, such as a
      force cap beside the angle limit): **reproduced under an added condition**;
    - else: **reproduced**, the paper's statement holds as printed.

    Parameters
    ----------
    evidence : bool
        The check confirmed its evidence.
    printed_fails : bool
        A confirmed errata row (not ``notation``) on the row's equations or claim.
    counterexample : bool
        The check exhibits a counterexample to the claim.
    extension : bool
        The row is one of the book's extensions.
    misapplied : bool
        The claim cites a theorem whose hypotheses the paper's system does not meet.
    added_condition : bool
        The confirmation needs a condition the paper does not state.
    unstated : bool
        The paper does not state what a reproduction needs, and the result depends on it.

    Returns
    -------
    str
        One of :data:`STATUSES`.
    """
    if not evidence:
        return "not reproducible"
    if extension:
        return "extended"
    if unstated:
        return "not reproducible as stated"
    if misapplied:
        return "misapplied"
    if counterexample:
        return "refuted"
    if printed_fails:
        return "corrected"
    return "reproduced under an added condition" if added_condition else "reproduced"
