"""One status word for each verdict: a chapter's "What we found" and the report's row read it from
the same function (:func:`lib.paper.report.status`, through :func:`lib.paper.findings.what_we_found`
for the chapters), the report's tallies count its rows, and the series' a3 is rendered from the
computed coefficient with its kind."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import quad

from lib import trajectories
from lib.paper import report
from lib.paper.findings import WHAT_WE_FOUND, what_we_found
from lib.paper.outcomes import STATUSES, Outcome

ROOT = Path(__file__).resolve().parents[1]
ITEMS = {i.key: i for i in report.items()}
HEAD = re.compile(r"^- \*\*\{glue:text\}`(\w+)`", re.M)


def _what_we_found_box(page: str) -> str:
    text = (ROOT / f"{page}.md").read_text()
    fence = ":::" if ":::{admonition} What we found" in text else "```"
    start = text.index(fence + "{admonition} What we found")
    return text[start:text.index("\n" + fence, start)]


def _fake_statuses(monkeypatch, statuses: dict[str, str]) -> None:
    """Every report row's outcome replaced by one with the status ``statuses`` gives it (the
    row's claimed status otherwise), so that nothing is computed."""
    def outcome(key):
        return Outcome(statuses.get(key, ITEMS[key].expected), 0.0, "fake")
    monkeypatch.setattr(report, "outcome", outcome)


@pytest.mark.parametrize("page", sorted(WHAT_WE_FOUND))
def test_each_report_row_of_a_chapter_heads_one_bullet_of_its_what_we_found(page):
    """The chapter's box glues each bullet's word (no bullet types a word a row decides), and every
    report row shown on the page is in exactly one bullet."""
    box = _what_we_found_box(page)
    assert sorted(HEAD.findall(box)) == sorted(WHAT_WE_FOUND[page])
    typed = re.findall(r"^- \*\*([^{*]+?)\*\*", box, re.M)
    assert not set(w.strip(" .:").lower() for w in typed) & set(STATUSES) - {"extended"}, typed
    keys = [k for ks in WHAT_WE_FOUND[page].values() for k in ks]
    assert sorted(keys) == sorted(k for k, i in ITEMS.items() if i.section == page)
    assert f'what_we_found("{page}")' in (ROOT / f"{page}.md").read_text()


def test_what_we_found_takes_each_word_from_the_report_rows_status(monkeypatch):
    page = "chapters/02_controllability"
    _fake_statuses(monkeypatch, {})
    assert what_we_found(page) == {name: ITEMS[keys[0]].expected.capitalize()
                                   for name, keys in WHAT_WE_FOUND[page].items()}
    # a row decided otherwise changes the chapter's word and the report's row alike
    _fake_statuses(monkeypatch, {"count": "corrected", "thm7": "not reproducible"})
    words = what_we_found(page)
    assert words["found_count"] == "Corrected" and words["found_thm7"] == "Not reproducible"
    assert report.status("count") == "corrected" and report.status("thm7") == "not reproducible"
    # two rows stated in one bullet that stop agreeing stop the page, naming the rows
    _fake_statuses(monkeypatch, {"rank": "reproduced"})
    with pytest.raises(ValueError, match="keys.*eq21.*corrected.*rank.*reproduced"):
        what_we_found(page)
    with pytest.raises(ValueError, match="page must be one of"):
        what_we_found("chapters/99_none")
    with pytest.raises(ValueError, match="keys"):
        report.status()


def test_chapter_2_words_are_its_rows_computed_statuses():
    """The real checks of Chapter 2's rows (symbolic, a few seconds): the words the chapter
    prints are the statuses the rows claim, the legend's for each."""
    words = what_we_found("chapters/02_controllability")
    assert words == {"found_eq21_rank": "Corrected", "found_count": "Reproduced",
                     "found_thm6_stlc": "Refuted", "found_thm7": "Misapplied"}


def test_report_table_status_column_is_report_status(monkeypatch):
    _fake_statuses(monkeypatch, {"thm7": "misapplied", "fourier": "corrected"})
    rep = report.table()
    assert list(rep["status"]) == [report.status(k) for k in rep["key"]]
    assert rep.set_index("key").loc["thm7", "status"] == "misapplied"


# ------------------------------------------------------------------ the executed pages

def status_disagreements(pages: dict[str, dict]) -> list[str]:
    """Where an executed chapter's "What we found" word differs from the executed report's row
    (``status_<key>``), or the report's tally of a status (``n_<status>``) differs from the count
    of its rows with it. ``pages`` as ``tests/test_number_kinds.executed_pages`` gives them."""
    def text(v):
        return v[0].strip("'\"")

    rows = {k[len("status_"):]: text(v) for k, v in pages["report"].items() if k.startswith("status_")}
    bad = [] if rows else ["the report glues no row's status"]
    for page, bullets in WHAT_WE_FOUND.items():
        for name, keys in bullets.items():
            word = text(pages[page][name])
            bad += [f"{page} {name} {word!r}, report row {k} {rows.get(k)!r}" for k in keys
                    if rows.get(k, "").capitalize() != word]
    for status in STATUSES:
        tally = int(text(pages["report"][f"n_{status.replace(' ', '_')}"]))
        n = sum(w == status for w in rows.values())
        bad += [f"tally of {status!r} {tally}, rows {n}"] if tally != n else []
    return bad


@pytest.mark.book
def test_built_chapters_and_report_give_one_word_per_row_and_tallies_count_rows(built_book):
    from test_number_kinds import executed_pages

    assert not status_disagreements(executed_pages())


def test_disagreements_are_found_in_executed_pages():
    rows = {k: i.expected for k, i in ITEMS.items()}
    pages = {"report": {f"status_{k}": (repr(s), None) for k, s in rows.items()}}
    pages["report"] |= {f"n_{s.replace(' ', '_')}": (str(list(rows.values()).count(s)), None) for s in STATUSES}
    pages |= {page: {name: (repr(rows[keys[0]].capitalize()), None) for name, keys in bullets.items()}
              for page, bullets in WHAT_WE_FOUND.items()}
    assert status_disagreements(pages) == []
    ch2 = pages["chapters/02_controllability"]
    ch2["found_count"] = ("'Corrected'", None)                       # Chapter 2's old word
    assert status_disagreements(pages) == ["chapters/02_controllability found_count 'Corrected', "
                                           "report row count 'reproduced'"]
    ch2["found_count"] = ("'Reproduced'", None)
    pages["report"]["n_misapplied"] = ("0", None)                     # a tally that does not count the rows
    assert status_disagreements(pages) == ["tally of 'misapplied' 0, rows 1"]


# ------------------------------------------------------------------ the series' a3

def test_a3_is_rendered_from_the_computed_coefficient_rounded_to_nearest():
    """The report's a3: the computed coefficient (FFT, checked against an adaptive quadrature of
    the tangent angle within 1e-8, quad's estimated error being about 1e-9) written to four
    decimals, exact kind, so rounded to nearest (-0.2348); its two-decimal rounding (-0.23) and
    the paper's printed value (-0.24) come from the computation and PAPER_HEADING_SERIES."""
    heading = trajectories.eight(1.0, 1.0).heading
    a3, _ = quad(lambda s: float(heading(np.array([s]))[0]) * np.cos(3 * s) / np.pi, 0.0, 2 * np.pi,
                 limit=400, epsabs=1e-12)
    out = report.outcome("fourier")
    assert abs(out.merit - a3) < 1e-8  # accuracy: the quadrature of the series coefficient, to about 1e-10
    assert out.merit_kind == "exact" and out.merit_text() == f"{a3:.4f}" == "-0.2348"
    assert out.status == "corrected" and out.erratum == "fourier-a3"
    assert f"a3 = -0.2348 rounds to {a3:.2f}, the paper prints -0.24" in out.note and f"{a3:.2f}" == "-0.23"
    assert out.merit_label.endswith(f"the paper prints {trajectories.PAPER_HEADING_SERIES[3]:.2f}")
    assert out.note.startswith("a1, a5 are the computed ones rounded")


def test_a3_note_follows_the_coefficients_it_is_given(monkeypatch):
    """Nothing in the row is typed: coefficients whose a3 rounds to the printed -0.24 and whose
    a1 does not make the note name a1, not a3."""
    coeffs = np.array([np.pi, -2.2449, 0.0, -0.2361, 0.0, 0.1612])
    monkeypatch.setattr(report, "eight_heading_fourier", lambda n: coeffs[: n + 1])
    out = report._check_item("fourier")          # not the build's cache: the check itself
    assert out.merit_text() == "-0.2361"
    assert out.note.startswith("a3, a5 are the computed ones rounded")
    assert "a1 = -2.2449 rounds to -2.24, the paper prints -2.26" in out.note
