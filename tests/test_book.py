"""The book builds from scratch, executing every notebook, with Sphinx warnings as errors."""

import re

import pytest

pytestmark = pytest.mark.book


def test_book_builds_with_no_warnings(built_book):
    log = built_book.stdout + built_book.stderr
    warnings = [line for line in log.splitlines() if re.search(r"\bWARNING\b|\bERROR\b", line)]
    assert built_book.returncode == 0, "jupyter-book build failed:\n" + log[-6000:]
    assert not warnings, "build printed warnings:\n" + "\n".join(warnings[:40])
