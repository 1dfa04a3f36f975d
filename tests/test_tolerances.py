"""Every numerical tolerance in the tests says where it comes from.

The convention. A numerical comparison is

- a call of ``assert_allclose``, ``isclose``, ``allclose`` or ``approx`` (each has a
  tolerance, given as ``rtol=``, ``atol=``, ``rel=``, ``abs=`` or left at the function's
  default), or
- an ``assert`` comparing with ``<``, ``<=``, ``>`` or ``>=`` against a number written in
  scientific notation (``err < 1e-9``).

Its statement carries a comment, on one of its lines or in the comment lines directly
above it, that either

- contains ``measured``, with the error measured on a run of the comparison: the
  tolerance is then at most about 10 times that value (a floor near 1e-15 relative where
  the error is rounding; about 10 times, and no tighter, where the error depends on the
  libm or the CPU, as in long integrations), e.g. ``atol=1e-9)  # measured 1.2e-10``; or
- contains ``reason:``, saying why the tolerance is not an error bound: a physical or a
  statistical margin, or an inequality that is a property (``lambda > 3 SE``).

No file is exempt (``EXEMPT`` is kept for a file that must be, with the reason beside it).
"""

from __future__ import annotations

import ast
import io
import re
import tokenize
from pathlib import Path

import pytest

TESTS = Path(__file__).resolve().parent
#: test files whose authors work on them elsewhere; they come under this check later
EXEMPT: frozenset[str] = frozenset()
COMPARISONS = frozenset({"assert_allclose", "isclose", "allclose", "approx"})
SCIENTIFIC = re.compile(r"\d(\.\d*)?e-?\d+", re.IGNORECASE)
STATED = re.compile(r"measured|reason:", re.IGNORECASE)


def _comments(source: str) -> dict[int, str]:
    """Line number -> the text of the comment on that line."""
    return {tok.start[0]: tok.string for tok in tokenize.generate_tokens(io.StringIO(source).readline)
            if tok.type == tokenize.COMMENT}


def _header_span(stmt: ast.stmt) -> tuple[int, int]:
    """The lines of a statement, or of a compound statement's header only."""
    body = getattr(stmt, "body", None)
    if isinstance(body, list) and body and isinstance(body[0], ast.stmt):
        return stmt.lineno, body[0].lineno - 1
    return stmt.lineno, stmt.end_lineno


def _is_threshold(node: ast.Compare, source: str) -> bool:
    if not any(isinstance(op, (ast.Lt, ast.LtE, ast.Gt, ast.GtE)) for op in node.ops):
        return False
    return any(_scientific_outside_calls(side, source) for side in [node.left, *node.comparators])


def _scientific_outside_calls(node: ast.AST, source: str) -> bool:
    """A number in scientific notation in ``node``, not inside a call's arguments (where
    it is an input such as a step, not the threshold)."""
    if isinstance(node, ast.Constant):
        return isinstance(node.value, float) and bool(
            SCIENTIFIC.fullmatch(ast.get_source_segment(source, node) or ""))
    if isinstance(node, ast.Call):
        return False
    return any(_scientific_outside_calls(child, source) for child in ast.iter_child_nodes(node))


def unstated_tolerances(source: str) -> list[tuple[int, str]]:
    """The numerical comparisons in ``source`` (a test module's text) whose statement has
    no comment saying ``measured`` or ``reason:``.

    Returns
    -------
    list of (line number, the statement's first line)
    """
    tree = ast.parse(source)
    comments = _comments(source)
    lines = source.splitlines()
    parent = {child: node for node in ast.walk(tree) for child in ast.iter_child_nodes(node)}
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Call):
            name = getattr(node.func, "attr", None) or getattr(node.func, "id", None)
            hit = name in COMPARISONS
        else:
            hit = isinstance(node, ast.Compare) and _is_threshold(node, source)
        if not hit:
            continue
        stmt = node
        while not isinstance(stmt, ast.stmt):
            stmt = parent[stmt]
        if isinstance(node, ast.Compare) and not isinstance(stmt, ast.Assert):
            continue
        first, last = _header_span(stmt)
        above = first - 1
        while above >= 1 and lines[above - 1].strip().startswith("#"):
            above -= 1
        if not any(STATED.search(comments.get(k, "")) for k in range(above + 1, last + 1)):
            found.add((first, lines[first - 1].strip()))
    return sorted(found)


def _test_files() -> list[Path]:
    return sorted(f for f in TESTS.glob("*.py") if f.name not in EXEMPT)


@pytest.mark.parametrize("path", _test_files(), ids=lambda p: p.name)
def test_every_tolerance_states_its_measured_error_or_its_reason(path):
    missing = unstated_tolerances(path.read_text())
    assert not missing, "\n".join(f"{path.name}:{n}: {text}" for n, text in missing)


def test_the_check_finds_an_unstated_tolerance_and_accepts_a_stated_one():
    bare = ("def test_a():\n"
            "    np.testing.assert_allclose(x, y, atol=1e-9)\n"
            "    assert pytest.approx(1.0) == z\n"
            "    assert err < 1e-6\n"
            "    if np.isclose(a, b):\n"
            "        pass\n")
    assert [n for n, _ in unstated_tolerances(bare)] == [2, 3, 4, 5]
    stated = ("def test_a():\n"
              "    np.testing.assert_allclose(x, y,\n"
              "                               atol=1e-9)  # measured 1.2e-10\n"
              "    # reason: a statistical margin of 3 standard errors\n"
              "    assert pytest.approx(1.0, rel=0.1) == z\n"
              "    assert err < 1e-6, err  # measured 2e-7\n"
              "    assert n > 3 and x < 0.5 and margin(x, 1e-4) > 1\n")
    assert unstated_tolerances(stated) == []

