"""The distribution ``korczak2014-lib``: its wheel holds every module of ``lib`` and
they import from the installed copy alone; the name ``lib`` is not taken by anything
else in the environment; and the ``lib`` the tests and the notebooks import is this
checkout's, not another checkout's that shares the venv (the editable install maps
``lib`` to an absolute path)."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest
import yaml

ROOT = Path(__file__).resolve().parents[1]
LIB = ROOT / "lib"

pytestmark = pytest.mark.packaging

#: a fresh interpreter of this venv: no user site (-s), no script or working
#: directory prepended to sys.path (-P); PYTHONPATH as given
_FRESH = [sys.executable, "-s", "-P"]


def _env(**extra: str) -> dict:
    env = {k: v for k, v in os.environ.items() if not k.startswith("PYTHON")}
    env.update(extra)
    return env


def _run(args, cwd: Path, **env: str) -> subprocess.CompletedProcess:
    proc = subprocess.run(args, cwd=cwd, env=_env(**env), capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, f"{' '.join(map(str, args))} failed:\n{proc.stdout}\n{proc.stderr}"
    return proc


def _repo_modules() -> set[str]:
    names = set()
    for path in LIB.rglob("*.py"):
        parts = path.relative_to(ROOT).with_suffix("").parts
        names.add(".".join(parts[:-1] if parts[-1] == "__init__" else parts))
    return names


# Imports every module of the installed ``lib`` with the editable install's finder
# removed, so that a module missing from the wheel cannot be found in the checkout.
_IMPORT_ALL = r"""
import importlib, json, pkgutil, sys
sys.meta_path[:] = [f for f in sys.meta_path if not getattr(f, "__module__", "").startswith("__editable__")]
import lib
names = ["lib"] + [m.name for m in pkgutil.walk_packages(lib.__path__, "lib.")]
print(json.dumps({n: importlib.import_module(n).__file__ for n in names}))
"""


def test_wheel_installs_every_module_of_lib_and_they_import_from_it(tmp_path):
    # build from a copy, so that setuptools' build/ and egg-info never land in the shared tree
    src = tmp_path / "src"
    src.mkdir()
    for name in ("pyproject.toml", "README.md", "LICENSE"):
        shutil.copy2(ROOT / name, src / name)
    shutil.copytree(LIB, src / "lib", ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    pip = [sys.executable, "-m", "pip", "--disable-pip-version-check", "--no-input"]
    _run(pip + ["wheel", "--no-deps", "--no-build-isolation", "--no-index", "-q", "-w", str(tmp_path / "dist"),
                str(src)], cwd=tmp_path)
    (wheel,) = (tmp_path / "dist").glob("korczak2014_lib-*.whl")
    site = tmp_path / "site"
    _run(pip + ["install", "--no-deps", "--no-index", "-q", "--target", str(site), str(wheel)], cwd=tmp_path)

    out = _run(_FRESH + ["-c", _IMPORT_ALL], cwd=tmp_path, PYTHONPATH=str(site)).stdout
    files = json.loads(out.strip().splitlines()[-1])
    assert Path(files["lib"]).resolve() == (site / "lib" / "__init__.py").resolve(), files["lib"]
    outside = {n: f for n, f in files.items() if not Path(f).resolve().is_relative_to(site.resolve())}
    assert not outside, f"imported from outside the installed wheel: {outside}"
    assert set(files) == _repo_modules(), (
        f"missing from the wheel: {sorted(_repo_modules() - set(files))}; "
        f"not in the repository: {sorted(set(files) - _repo_modules())}")
    # the typing marker and the module map ship with the package; the licence and its name with the metadata
    assert (site / "lib" / "py.typed").is_file() and (site / "lib" / "README.md").is_file()
    (info,) = site.glob("korczak2014_lib-*.dist-info")
    assert "License-Expression: MIT" in (info / "METADATA").read_text()          # PEP 639
    assert (info / "LICENSE").is_file() or any(info.glob("licenses/LICENSE"))


_WHO_PROVIDES_LIB = r"""
import importlib.machinery, json, sys
from importlib.metadata import packages_distributions
print(json.dumps({
    "distributions": sorted(set(packages_distributions().get("lib", []))),
    "path_entries": [p for p in sys.path if importlib.machinery.PathFinder.find_spec("lib", [p]) is not None],
    "stdlib": "lib" in sys.stdlib_module_names,
}))
"""


def test_no_other_distribution_provides_a_top_level_lib(tmp_path):
    """``lib`` is a generic name: in this venv, only ``korczak2014-lib`` may provide it,
    and no directory on a fresh interpreter's sys.path may hold another ``lib``."""
    found = json.loads(_run(_FRESH + ["-c", _WHO_PROVIDES_LIB], cwd=tmp_path).stdout)
    assert found["distributions"] == ["korczak2014-lib"], found
    assert not found["stdlib"]
    assert found["path_entries"] == [], f"another top-level lib on sys.path: {found['path_entries']}"


def test_lib_is_this_checkouts(tmp_path):
    """The ``lib`` of this session and the one a fresh interpreter of the venv finds from
    outside the repository (as a notebook kernel does) are both this checkout's."""
    import lib

    here = Path(lib.__file__).resolve()
    assert here.is_relative_to(ROOT), f"this session imports lib from {here}, not from the checkout {ROOT}"
    spec = _run(_FRESH + ["-c", "import importlib.util; print(importlib.util.find_spec('lib').origin)"],
                cwd=tmp_path).stdout.strip()
    assert Path(spec).resolve().is_relative_to(ROOT), (
        f"the venv {sys.prefix} maps lib to {spec}, not to this checkout {ROOT}: another checkout "
        f"shares the venv; run `{sys.executable} -m pip install -e {ROOT}` or give this checkout its own .venv")


def test_import_lib_is_light(tmp_path):
    """``import lib`` runs only its docstring and one default of the environment (below): no
    numpy, no submodule (the entry points it names are imported by who uses them)."""
    code = "import sys, lib; print(sorted(m for m in sys.modules if m.split('.')[0] in ('lib', 'numpy')))"
    assert _run(_FRESH + ["-c", code], cwd=ROOT).stdout.strip() == "['lib']"


def test_import_lib_makes_numbas_waiting_threads_sleep_unless_the_user_chose(tmp_path):
    """``import lib`` sets OpenMP's wait policy to PASSIVE only where the environment does not
    choose one, before numba loads its OpenMP threading layer (which reads it once): the
    spinning threads of the default took 74 s of CPU for Fig. 5's sweep beside one other busy
    process, against 31 s (lib/__init__.py). A child process shows what the kernels see."""
    code = "import os, lib; print(os.environ.get('OMP_WAIT_POLICY'))"
    env = {k: v for k, v in _env().items() if k != "OMP_WAIT_POLICY"}
    out = subprocess.run(_FRESH + ["-c", code], cwd=ROOT, env=env, capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "PASSIVE"
    assert _run(_FRESH + ["-c", code], cwd=ROOT, OMP_WAIT_POLICY="ACTIVE").stdout.strip() == "ACTIVE"


def test_citation_cff_cites_the_book_and_the_paper():
    cff = yaml.safe_load((ROOT / "CITATION.cff").read_text())
    assert cff["cff-version"] == "1.2.0"
    assert {"cff-version", "message", "title", "authors"} <= set(cff)
    assert cff["authors"] == [{"name": "The replication project"}]
    assert cff["preferred-citation"]["year"] == 2026
    (paper,) = cff["references"]
    assert paper["title"] == "Tracking control of an underactuated rigid body with a coupling input force"
    assert paper["journal"] == "Archives of Control Sciences"
    assert (paper["volume"], str(paper["issue"]), paper["year"]) == (24, "3", 2014)
    assert paper["authors"][0]["family-names"] == "Korczak"


def test_code_is_mit_and_text_cc_by_4():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert project["license"] == "MIT" and project["license-files"] == ["LICENSE"]      # PEP 639, not a table
    licence = (ROOT / "LICENSE").read_text()
    assert "MIT licence" in licence and "Permission is hereby granted, free of charge" in licence
    assert "Creative Commons Attribution 4.0 International" in licence
    assert "https://creativecommons.org/licenses/by/4.0/legalcode" in licence
    for path in ("chapters/", "lib/", "tests/", "benchmarks/"):
        assert f"`{path}`" in licence, f"LICENSE does not say which licence covers {path}"
