"""Shared fixtures. The book is built once per test session, in the repository's
own ``_build`` (the same output as ``make book``)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="session")
def built_book() -> subprocess.CompletedProcess:
    """Run ``jupyter-book build --all -W -n --keep-going .`` and return the completed process."""
    exe = Path(sys.executable).with_name("jupyter-book")
    env = dict(os.environ, PYTHONWARNINGS="default")
    proc = subprocess.run([str(exe), "build", "--all", "-W", "-n", "--keep-going", "."],
                          cwd=ROOT, env=env, capture_output=True, text=True)
    (ROOT / "_build").mkdir(exist_ok=True)
    (ROOT / "_build" / "build.log").write_text(proc.stdout + "\n" + proc.stderr)
    return proc
