"""Every number the front page's findings and each chapter's findings box state is labelled:
written beside its unit (m, rad, 1/s, points, angle limits, ...) and, in the same bullet, the
reading it counts or measures ("lost", "not held", "turns round", "paper's law", ...), as
:data:`lib.paper.findings.LABELS` records them. A count without its reading, or a norm that
adds metres to radians, fails here (issue 36)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from lib.paper.findings import LABELS

ROOT = Path(__file__).resolve().parents[1]
GLUE = re.compile(r"\{glue:text\}`([A-Za-z0-9_]+)(?::[^`]*)?`")


def _box(page: str) -> str:
    """The findings of ``page``: the front page's numbered list, or a chapter's Findings admonition."""
    text = (ROOT / f"{page}.md").read_text()
    if page == "intro":
        return text[text.index("## What this book found"):text.index("Each finding is a row")]
    m = re.search(r"(:::|```)\{admonition\} Findings\n(.*?)\n\1\n", text, re.S)
    assert m, f"{page}: no Findings admonition"
    return m.group(2)


def _bullets(box: str) -> list[str]:
    """The box's items (``- `` or ``1. ``), each as one line of text."""
    items = re.split(r"\n(?=\s*(?:-|\d+\.) )", "\n" + box)
    return [" ".join(i.split()) for i in items if GLUE.search(i)]


def _unit_near(unit: str, bullet: str, start: int, end: int) -> bool:
    """``unit`` (a plural also singular) within 25 characters before the number or 60 after it,
    the other numbers written as '#'."""
    if not unit:
        return True
    word = re.escape(unit[:-1]) + "s?" if re.fullmatch(r"[A-Za-z ]+s", unit) else re.escape(unit)
    window = GLUE.sub("#", bullet[max(0, start - 40):start]) + " # " + GLUE.sub("#", bullet[end:end + 90])
    before, after = window.split(" # ", 1)
    near = before[-25:] + " # " + after[:60]
    return re.search(rf"(?<![A-Za-z]){word}(?![A-Za-z])", near) is not None


@pytest.mark.parametrize("page", sorted(LABELS))
def test_each_glued_number_of_the_findings_names_its_unit_and_its_reading(page):
    labels = LABELS[page]
    seen = set()
    for bullet in _bullets(_box(page)):
        for m in GLUE.finditer(bullet):
            name = m.group(1)
            assert name in labels, f"{page}: {name} has no unit and reading in lib.paper.findings.LABELS"
            unit, reading = labels[name]
            seen.add(name)
            assert _unit_near(unit, bullet, m.start(), m.end()), f"{page}: {name} is not written beside {unit!r}"
            assert reading.lower() in bullet.lower(), f"{page}: {name}'s bullet does not name {reading!r}"
    assert seen == set(labels), f"{page}: labels for numbers the box no longer states: {set(labels) - seen}"


def test_every_findings_box_is_labelled():
    pages = {"intro"} | {p.with_suffix("").relative_to(ROOT).as_posix() for p in (ROOT / "chapters").glob("*.md")
                         if "{admonition} Findings" in p.read_text()}
    assert pages == set(LABELS)


def test_unit_check_catches_a_count_without_its_unit():
    bullet = "the heading is lost at {glue:text}`n` of the grid"
    m = GLUE.search(bullet)
    assert not _unit_near("points", bullet, m.start(), m.end())
    bullet = "the heading is lost at {glue:text}`n` points"
    m = GLUE.search(bullet)
    assert _unit_near("points", bullet, m.start(), m.end())
    bullet = "a {glue:text}`n`-point grid"
    m = GLUE.search(bullet)
    assert _unit_near("points", bullet, m.start(), m.end()) and not _unit_near("m", bullet, m.start(), m.end())
