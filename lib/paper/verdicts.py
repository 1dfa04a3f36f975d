"""The shape of an erratum row and of its check's outcome."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

__all__ = ["Erratum", "Verdict"]


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
    (a document path such as ``chapters/01_model``) that shows it. ``notation``: a slip of
    notation or numbering, or a reading the paper leaves open, that changes no computation of
    the paper's; such a row does not make the report row of its equations "corrected"
    (:func:`lib.paper.outcomes.legend_status`).
    ``equations``: the numbers of the paper's equations whose printed form the row corrects
    (none for a claim, a definition or a theorem without a number).
    """

    key: str
    where: str
    printed: str
    corrected: str
    verified_by: str
    section: str
    check: Callable[[], Verdict]
    notation: bool = False
    equations: tuple[int, ...] = ()
