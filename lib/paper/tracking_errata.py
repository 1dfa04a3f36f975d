"""Errata of the paper's Secs. 4-5: the number of the parameter table."""

from __future__ import annotations

import re

from .verdicts import Erratum, Verdict

__all__ = ["ROWS", "PAPER_TABLE_LINES"]


#: The lines of the paper that name its parameter table, transcribed from the
#: published text (Korczak 2014, Sec. 5): every table caption, and every sentence
#: that refers to a table. Kept here as data so that the check below reads
#: nothing outside the repository.
PAPER_TABLE_LINES = (
    "Tab. 1 presents system and control parameters, Fig. 2 shows the results for circular trajectory.",
    "Table 5. System and control parameters",
)


def _check_table_number(lines=PAPER_TABLE_LINES, printed=5, corrected=1):
    """The paper's only table is captioned "Table 5"; the text refers to it as "Tab. 1".
    ``printed`` and ``corrected`` are the table's number: a caption "Table k" is right
    only if the paper has at least k tables; the corrected number must also be the
    count of tables (one here) and the number every text reference cites."""
    captions = [m.group(0) for line in lines if (m := re.match(r"Table\s+\d+", line))]
    refs = [r for line in lines for r in re.findall(r"Tab\.\s*\d+", line)]
    n_tables = len(captions)
    cited = [int(re.search(r"\d+$", r).group(0)) for r in refs]
    return Verdict(printed_holds=n_tables >= printed,
                   corrected_holds=n_tables == corrected and all(k == corrected for k in cited),
                   detail=f"table captions {captions}, text references {refs}: {n_tables} table(s)")


def _errata():
    return [
        Erratum(
            key="table-number",
            where="Sec. 5, caption of the parameter table",
            printed="Table 5",
            corrected="Table 1 (the paper's only table; the text cites it as Tab. 1)",
            verified_by="count of table captions and of table references in the paper's text "
                        "(`lib.paper.tracking_errata._check_table_number`); a text check can show the numbering is "
                        "inconsistent, not what the typesetter intended",
            section="chapters/03_tracking",
            check=_check_table_number,
            notation=True,
        ),
    ]


ROWS = _errata()
