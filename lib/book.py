"""Helpers for the book's notebooks."""

from __future__ import annotations

import numbers

import numpy as np

__all__ = ["glue"]


def glue(name: str, value, display: bool = False) -> None:
    """Glue a number (or string) for use with ``{glue:text}`name:fmt``` in the text.

    NumPy scalars are converted to Python numbers first: their repr
    (``np.float64(1.5)``) cannot be formatted by myst-nb's ``fmt`` spec.
    Non-finite numbers are refused: a NaN in the prose is always a bug.
    """
    from myst_nb import glue as _glue

    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, numbers.Real) and not isinstance(value, bool) and not np.isfinite(value):
        raise ValueError(f"refusing to glue non-finite value {value!r} as {name!r}")
    _glue(name, value, display=display)


def markdown_table(frame, index: bool = False):
    """Render a DataFrame as a Markdown table that MyST parses (so ``$...$`` math
    in cells is typeset); returns an :class:`IPython.display.Markdown` object.

    Needs ``nb_render_markdown_format: myst`` (set in ``_config.yml``).
    """
    from IPython.display import Markdown

    if index:
        frame = frame.reset_index()
    cols = [str(c) for c in frame.columns]

    def cell(v) -> str:
        return str(v).replace("|", r"\|").replace("\n", " ")

    lines = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    lines += ["| " + " | ".join(cell(v) for v in row) + " |" for row in frame.itertuples(index=False)]
    return Markdown("\n".join(lines))
