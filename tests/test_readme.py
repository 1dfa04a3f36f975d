"""README.md's instructions stay true: its library example runs, and the commands it
gives for running a chapter as a notebook and the fast tests are the ones installed."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text()


def _section(title: str) -> str:
    match = re.search(rf"^## {re.escape(title)}\n(.*?)(?=^## |\Z)", README, re.S | re.M)
    assert match, f"README.md has no section '## {title}'"
    return match.group(1)


def test_readme_library_example_runs():
    """The python block of "Where to start in the library", run as a script: a small
    Fig. 5 map with the columns it prints, and the capped circle held at its cap."""
    (code,) = re.findall(r"```python\n(.*?)```", _section("Where to start in the library"), re.S)
    proc = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    header, *rows, last = proc.stdout.strip().splitlines()
    assert header.split() == ["R", "Theta", "regime", "range", "lost", "turns_round"]
    assert len(rows) == 9 and {r.split()[3] for r in rows} <= {"periodic", "slipping", "chaotic",
                                                                "quasiperiodic", "undecided"}
    assert float(last.split()[0]) <= 4.0 + 1e-15          # exact: a clip; measured 0 over the cap; F never above the cap


def test_readme_notebook_route_uses_installed_tools():
    """The commands of "Working on a chapter" (what tests/test_notebook_route.py runs)
    name tools the venv has: jupytext, and nbclient's ``jupyter execute``."""
    text = _section("Working on a chapter")
    assert ".venv/bin/jupytext --to ipynb chapters/01_model.md" in text
    assert ".venv/bin/jupyter execute --inplace chapters/01_model.ipynb" in text
    bin_dir = Path(sys.executable).parent
    assert (bin_dir / "jupytext").is_file() and (bin_dir / "jupyter-execute").is_file()


def test_readme_fast_tests_command_deselects_the_slow_markers():
    """The fast-tests command names markers that pyproject.toml registers."""
    assert '.venv/bin/python -m pytest -m "not book and not browser"' in README
    pyproject = (ROOT / "pyproject.toml").read_text()
    assert '"book:' in pyproject and '"browser:' in pyproject


def test_ci_runs_the_portable_tests_after_make_test_with_the_emulation_the_readme_states():
    """`.ci/run` runs `make test`, then `make test-portable`; the target sets every variable
    of the emulation the README's section names (issue 28)."""
    ci = (ROOT / ".ci" / "run").read_text().split()
    assert ci.index("test-portable") > ci.index("test")
    make = (ROOT / "Makefile").read_text()
    text = _section("Another machine's arithmetic")
    for var in ("NUMBA_CPU_NAME=generic", "NUMBA_CACHE_DIR=", "OPENBLAS_CORETYPE=Prescott",
                "NPY_DISABLE_CPU_FEATURES=", "OPENBLAS_NUM_THREADS=1", "NUMBA_NUM_THREADS=1"):
        assert var in make, var
    for var in ("NUMBA_CPU_NAME=generic", "NUMBA_CACHE_DIR", "OPENBLAS_CORETYPE=Prescott", "NPY_DISABLE_CPU_FEATURES"):
        assert var in text, var
    # the numpy feature names the Makefile disables are ones this numpy dispatches on
    import numpy as np
    from numpy._core._multiarray_umath import __cpu_dispatch__, __cpu_baseline__

    names = re.search(r'NPY_DISABLE_CPU_FEATURES="([^"]*)"', make).group(1).split()
    assert names and set(names) <= set(__cpu_dispatch__) - set(__cpu_baseline__), (names, __cpu_dispatch__)
    assert np.__version__
