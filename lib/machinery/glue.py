"""Helpers for the book's notebooks."""

from __future__ import annotations

import html
import numbers
import re
from collections.abc import Mapping
from dataclasses import fields, is_dataclass

import numpy as np

__all__ = ["glue", "glue_all", "markdown_table", "with_alt"]


def glue(name: str, value, display: bool = False) -> None:
    """Glue a number (or string) for use with ``{glue:text}`name:fmt``` in the text.

    NumPy scalars are converted to Python numbers first: their repr
    (``np.float64(1.5)``) cannot be formatted by myst-nb's ``fmt`` spec.
    Non-finite numbers are refused: a NaN in the prose is always a bug.
    A :class:`lib.machinery.kinds.Number` (a bound, a motion found, an estimate with its
    error) is glued as the text its kind renders, with its value and kind beside it; the
    page writes it with no format spec (``{glue:text}`name```), since a spec would round
    it again, to nearest (``tests/test_number_kinds.py`` checks every one in the built book).

    Parameters
    ----------
    name : str
        The glue key.
    value : Any
        A finite number, a :class:`~lib.machinery.kinds.Number` or a string.
    display : bool
        Show the value in the cell's output.

    Returns
    -------
    None
    """
    from myst_nb import glue as _glue

    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, numbers.Real) and not isinstance(value, bool) and not np.isfinite(value):
        raise ValueError(f"refusing to glue non-finite value {value!r} as {name!r}")
    _glue(name, value, display=display)


def glue_all(values, prefix: str = "") -> None:
    """Glue every entry of ``values`` as ``prefix + key``: a mapping, or an object with
    fields (a dataclass, a :class:`typing.NamedTuple`). Lets a chapter glue the result
    object of a claim in one call, e.g. ``glue_all(summary, "cap_")``.

    Parameters
    ----------
    values : mapping or dataclass or NamedTuple
        The values.
    prefix : str
        Prefix of every key.

    Returns
    -------
    None
    """
    if is_dataclass(values) and not isinstance(values, type):
        values = {f.name: getattr(values, f.name) for f in fields(values)}
    elif hasattr(values, "_asdict"):
        values = values._asdict()
    if not isinstance(values, Mapping):
        raise TypeError(f"glue_all needs a mapping or a dataclass, got {type(values).__name__}")
    for key, value in values.items():
        glue(f"{prefix}{key}", value)


def markdown_table(frame, index: bool = False):
    """Render a DataFrame as a Markdown table that MyST parses (so ``$...$`` math
    in cells is typeset); returns an :class:`IPython.display.Markdown` object.
    Every cell and every column name is escaped: a ``|`` (as in ``$|\\mu_1|$``)
    becomes ``\\|`` and a newline a space, so the table keeps its columns.

    Needs ``nb_render_markdown_format: myst`` (set in ``_config.yml``).

    Parameters
    ----------
    frame : pandas.DataFrame
        The table.
    index : bool
        Include the index.

    Returns
    -------
    IPython.display.Markdown
        The table.
    """
    from IPython.display import Markdown

    if index:
        frame = frame.reset_index()

    def cell(v) -> str:
        return str(v).replace("|", r"\|").replace("\n", " ")

    cols = [cell(c) for c in frame.columns]
    lines = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    lines += ["| " + " | ".join(cell(v) for v in row) + " |" for row in frame.itertuples(index=False)]
    return Markdown("\n".join(lines))


def with_alt(snippet: str, alt: str) -> str:
    """``snippet`` (HTML, e.g. an animation from :func:`lib.figures.animation.animate`) with ``alt``
    as the alt text of every ``<img>`` that has none, so that a figure shown as HTML says
    what it shows, as ``mystnb: image: alt:`` does for an image output.

    Parameters
    ----------
    snippet : str
        HTML.
    alt : str
        Alt text, a sentence.

    Returns
    -------
    str
        The HTML.
    """
    if not alt.strip():
        raise ValueError("an alt text must say what the image shows")
    attr = f' alt="{html.escape(alt.strip(), quote=True)}"'
    return re.sub(r"<img\b(?![^>]*\balt=)", lambda m: m.group(0) + attr, snippet, flags=re.IGNORECASE)
