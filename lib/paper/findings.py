"""What the book found, for its front page (``intro.md``): each finding a report row
(:mod:`lib.paper.report`), its status and its figure of merit, read through
:func:`lib.paper.report.outcome`, so the front page quotes the computation the report and the
chapters show, computed once per book build."""

from __future__ import annotations

from .report import outcome

__all__ = ["FINDINGS", "findings"]

#: the report rows the front page states, each with the status it states
FINDINGS = {
    "eq6": "corrected", "thm6": "refuted", "stlc": "refuted", "gas": "refuted", "window": "extended",
    "fig3": "reproduced", "limit-mirror": "extended", "chaos": "reproduced", "fig5": "extended",
    "weight-limit": "extended", "percussion-map": "extended", "cap-bound": "extended",
}


def findings() -> dict[str, float]:
    """The figure of merit of each row of :data:`FINDINGS`, by key.

    Returns
    -------
    dict
        key -> the row's figure of merit (its unit in the row's label).

    Raises
    ------
    AssertionError
        If a row's check decided another status than the one the front page states.
    """
    out = {}
    for key, status in FINDINGS.items():
        o = outcome(key)
        assert o.status == status, (key, o.status, status)
        out[key] = o.merit
    return out
