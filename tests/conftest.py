"""Shared fixtures. The book is built once per test session, in the repository's
own ``_build`` (the same output as ``make book``)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from lib.robustness import ROBUST_REL, perturbed

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


# ------------------------------------------------------------------ robustness mode
#
# Every test that decides a verdict on a chaotic or switched motion takes the
# ``perturb`` fixture and applies it to its initial state. The fixture runs the
# test twice: once from the nominal start, once from the start moved by a relative
# 1e-12 (the size of a few ulps' worth of difference between two CPUs or libms
# after a few operations). A verdict that flips is one that rode on the last bits.

@pytest.fixture(params=[0.0, ROBUST_REL], ids=["nominal", "perturbed-1e-12"])
def perturb(request):
    """The robustness mode: a function x -> x (nominal run) or x perturbed by a relative 1e-12."""
    rel = request.param
    return (lambda x: np.asarray(x, dtype=float)) if rel == 0 else (lambda x: perturbed(x, rel))


def pytest_collection_modifyitems(config, items):
    """Mark every test that uses the robustness mode, so that ``pytest -m robustness`` runs them alone."""
    for item in items:
        if "perturb" in getattr(item, "fixturenames", ()):
            item.add_marker(pytest.mark.robustness)


# ------------------------------------------------------------------ checkout guard

def pytest_sessionstart(session):
    """Stop at once unless ``lib`` is this checkout's, both in this process and in a fresh
    interpreter whose working directory holds no ``lib`` (as the book's notebook kernels,
    which run in ``chapters/``): the editable install maps ``lib`` to an absolute path, so
    a second checkout sharing the venv would otherwise test and build the first one's code
    (``tests/test_packaging.py::test_lib_is_this_checkouts`` says the same as a test)."""
    import tempfile

    import lib

    probe = subprocess.run([sys.executable, "-s", "-P", "-c",
                            "import importlib.util; print(importlib.util.find_spec('lib').origin)"],
                           cwd=tempfile.gettempdir(), capture_output=True, text=True)
    for who, origin in (("this session", lib.__file__), ("a fresh interpreter", probe.stdout.strip() or None)):
        if origin is None or not Path(origin).resolve().is_relative_to(ROOT):
            pytest.exit(f"{who} imports lib from {origin}, not from this checkout {ROOT}: another checkout "
                        f"shares the venv {sys.prefix}. Run `{sys.executable} -m pip install -e {ROOT}` "
                        f"or give this checkout its own .venv.", returncode=pytest.ExitCode.USAGE_ERROR)
