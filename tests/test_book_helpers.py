"""lib.machinery.glue's helpers for the notebooks: the Markdown tables they emit parse back to
the frame's columns and cells (read by markdown-it, the parser MyST uses)."""

from __future__ import annotations

import pandas as pd
import pytest

from lib.machinery.glue import markdown_table

markdown_it = pytest.importorskip("markdown_it")
dollarmath = pytest.importorskip("mdit_py_plugins.dollarmath")


def parse_table(text: str) -> tuple[list[str], list[list[str]]]:
    """Header cells and body rows of the one table in ``text``, as MyST parses them
    (inline math kept as its TeX source)."""
    md = markdown_it.MarkdownIt("commonmark").enable("table").use(dollarmath.dollarmath_plugin)
    header, rows, row, where = [], [], None, None
    for tok in md.parse(text):
        if tok.type in ("thead_open", "tbody_open"):
            where = tok.type[:5]
        elif tok.type == "tr_open":
            row = []
        elif tok.type == "tr_close":
            (header.extend(row) if where == "thead" else rows.append(row))
        elif tok.type == "inline" and row is not None:
            row.append("".join(f"${c.content}$" if c.type == "math_inline" else c.content
                               for c in tok.children))
    return header, rows


def test_markdown_table_escapes_the_pipe_in_a_column_name():
    frame = pd.DataFrame({"angle": [30, 45], r"$|\mu_1|$": ["0.5", "0.9"]})
    text = markdown_table(frame).data
    assert r"$\|\mu_1\|$" in text.splitlines()[0], "the header's pipes must be escaped"
    header, rows = parse_table(text)
    assert header == ["angle", r"$|\mu_1|$"]
    assert rows == [["30", "0.5"], ["45", "0.9"]]


def test_markdown_table_keeps_its_columns_with_pipes_and_newlines_in_cells():
    frame = pd.DataFrame({"a | b": ["x | y", "two\nlines"], "c": [r"$|p|$", "None"]})
    header, rows = parse_table(markdown_table(frame).data)
    assert header == ["a | b", "c"]
    assert rows == [["x | y", r"$|p|$"], ["two lines", "None"]]


def test_markdown_table_with_index_adds_the_index_as_first_column():
    frame = pd.DataFrame({"v": [1.5]}, index=pd.Index(["k|1"], name="key"))
    header, rows = parse_table(markdown_table(frame, index=True).data)
    assert header == ["key", "v"]
    assert rows == [["k|1", "1.5"]]


def test_with_alt_gives_every_image_without_one_the_alt_text():
    from lib.machinery.glue import with_alt

    snippet = '<div><img id="a" src="x.png"><img alt="kept" src="y.png"><IMG\nsrc="z"></div>'
    out = with_alt(snippet, 'The body "tracking" a circle.')
    assert out.count('alt="The body &quot;tracking&quot; a circle."') == 2
    assert 'alt="kept"' in out and out.count("alt=") == 3
    with pytest.raises(ValueError):
        with_alt(snippet, "  ")
