"""The "Library reference" page (reference.md): every module of the library is on it, the
public API has numpydoc Parameters and Returns sections, and the page's docstring filter
(_ext/docstring_text.py) leaves code alone. The page builds with -W -n as part of the book
(tests/test_book.py)."""

import importlib
import inspect
import pkgutil
import re
import sys
from pathlib import Path

import pytest

import lib

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "_ext"))
import docstring_text  # noqa: E402

#: the API other code calls (issue 21, "Keep stable") and the sweeps
DOCUMENTED = [
    "params.Body", "params.Gains", "trajectories.circle", "trajectories.eight", "trajectories.make",
    "allocation.Limits", "allocation.allocate", "allocation.allocate_least_squares", "allocation.allocate_limited",
    "control.computed_torque", "control.demand", "simulate.simulate", "symbolic.lie_bracket",
    "closed_loop.ClosedLoop.of", "rotation.verdicts.rotation_verdicts", "rotation.verdicts.eight_rotation_sweep",
    "rotation.fig5.fig5_map", "limits.verdicts.limit_verdicts", "limits.sections.sweep_angle_limit",
    "weighting.verdicts.closed_loop_verdicts", "weighting.comparison.verdict_runs", "tracking.runs.run",
    "tracking.runs.eight_sensitivity", "tracking.runs.force_cap_sweep", "machinery.parallel.map_chunks",
    "machinery.parallel.map_in_processes", "machinery.parallel.show_progress", "machinery.checks.number",
    "machinery.checks.integer", "machinery.checks.array", "machinery.checks.one_of", "machinery.checks.flag",
    "machinery.checks.instance",
]


def _object(path: str):
    parts = path.split(".")
    for i in range(len(parts), 0, -1):               # the longest importable module prefix
        try:
            obj = importlib.import_module("lib." + ".".join(parts[:i]))
        except ImportError:
            continue
        for a in parts[i:]:
            obj = getattr(obj, a)
        return obj
    raise ImportError(path)


@pytest.mark.parametrize("path", DOCUMENTED)
def test_public_api_has_numpydoc_parameters_and_returns(path):
    doc = inspect.getdoc(_object(path))
    assert re.search(r"^Parameters\n-{10}$", doc, re.M), f"{path}: no Parameters section"
    if not inspect.isclass(_object(path)):
        assert re.search(r"^Returns\n-{7}$", doc, re.M), f"{path}: no Returns section"


def test_every_public_function_has_numpydoc_sections():
    # the book's rule for lib functions: numpydoc Parameters / Returns (lib.paper, the
    # verdicts on the paper, is not part of the library's API)
    missing = []
    for m in pkgutil.walk_packages(lib.__path__, "lib."):
        if m.name.startswith("lib.paper"):
            continue
        mod = importlib.import_module(m.name)
        for name, obj in vars(mod).items():
            if name.startswith("_") or not inspect.isfunction(obj) or obj.__module__ != mod.__name__:
                continue
            doc = inspect.getdoc(obj) or ""
            if not re.search(r"^(Parameters\n-{10}|Returns\n-{7})$", doc, re.M):
                missing.append(f"{m.name}.{name}")
    assert missing == []


def test_every_module_is_on_the_reference_page():
    page = "".join(p.read_text() for p in [ROOT / "reference.md", *sorted((ROOT / "reference").glob("*.md"))])
    on_page = re.findall(r"^\.\. automodule:: (\S+)$", page, re.M)
    assert len(on_page) == len(set(on_page)), "a module is on two reference pages"
    on_page = set(on_page)
    modules = {m.name for m in pkgutil.walk_packages(lib.__path__, "lib.") if not m.name.startswith("lib.paper")}
    assert modules - on_page == set(), "add these modules to reference.md"
    assert on_page - modules == set()


def test_bars_are_escaped_outside_code_and_roles():
    esc = docstring_text.escape_bars
    assert esc("|beta| <= beta_max") == r"\|beta\| <= beta_max"
    assert esc(r"already \|x\|") == r"already \|x\|"
    assert esc("``|x|`` and :func:`a|b` and `y|z`") == "``|x|`` and :func:`a|b` and `y|z`"
    assert esc("ln|mu_1| / (k T), ``a``, |p|") == r"ln\|mu_1\| / (k T), ``a``, \|p\|"


def test_a_reexported_name_resolves_where_it_is_defined():
    canon = docstring_text._canonical
    assert canon("lib.weighting", "closed_loop_verdicts") == "lib.weighting.verdicts.closed_loop_verdicts"
    assert canon(None, "lib.limits.switched_runs") == "lib.limits.runs.switched_runs"
    assert canon("lib.weighting.verdicts", "closed_loop_verdicts") is None      # defined there: nothing to do
    assert canon("lib.limits", "no_such_name") is None
