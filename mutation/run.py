"""Mutation testing of the library's core modules with mutmut 3 (run by hand, not in CI).

    .venv/bin/python mutation/run.py                 # every module of TESTS (see below for the time)
    .venv/bin/python mutation/run.py angles params   # some of them

mutmut mutates the modules one small change at a time (an operator, a constant, a
comparison...) and runs the tests that reach the mutated function; a mutant that no
test fails on "survives" and marks a property nobody checks. The run works on a copy
of ``lib/`` and ``tests/`` in a temporary directory (mutmut writes its mutants into
``mutants/`` under the directory it runs in, and this keeps them out of the working
tree), with mutmut's configuration written there as ``setup.cfg``, and writes the
score and every surviving mutant, with its diff, to ``mutation/REPORT.md``. Each
module is checked with the fast tests that cover it (:data:`TESTS`), not the whole
suite. On 2 idle cores the six modules other than ``allocation`` take about 6 minutes,
``allocation`` about 11 and the verdict procedure about 1; the run is niced. ``weighting.circle``
(887 mutants) and the ten modules of ``lib/paper`` (about 4870 mutants) are slower: on 2 nearly
idle cores the circle takes 17 minutes (its mutants of the solver and the Jacobian run every
test of the file), the paper 16, then about 10 to write its survivors' diffs; run them on their
own (``MODULES=weighting.circle make mutation``).

The survivors are then triaged by hand in REPORT.md: killed by a new test
(``tests/test_core_mutants.py``, ``tests/test_paper_mutants.py``) or listed as equivalent, with
the reason.
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
VENV_BIN = Path(sys.executable).parent

#: the errata rows' checks, on the row's own forms and on falsifying ones
PAPER_ERRATA = ["tests/test_errata.py", "tests/test_errata_falsifiable.py"]
#: the report's rules that need no row's real evidence (tests/test_report.py without its
#: parametrized test, which runs every row's check on the book's computations)
REPORT_RULES = [f"tests/test_report.py::{t}" for t in (
    "test_outcome_rejects_unknown_status_and_non_finite_merit",
    "test_the_front_page_states_report_rows_with_the_status_each_row_claims",
    "test_legend_status_is_the_reports_legend",
    "test_equation_numbers_are_read_from_the_rows_head",
    "test_rows_with_a_failing_printed_equation_are_not_reproduced")]
#: the report rows whose real check takes a second or two (measured on the loaded machine), each
#: run as in the book; the others recompute a flow map, a sweep or a symbolic determinant (4 s to
#: minutes each), and every mutant of the rows' shared code (items, outcome) would run them all
REPORT_ROWS = [f"tests/test_report.py::test_report_row_status_is_decided_by_its_check[{k}]" for k in (
    "eq2-4", "eq5-10", "eq6", "eq21", "count", "thm6", "thm7", "stlc", "eq25-26", "eq27-28", "eq29-30",
    "eq31", "table", "fig2", "eq32", "eq33", "p0", "eq34-35", "eq36", "eq37", "fourier")]

#: the core modules and the fast test files (or test ids) that cover each
TESTS = {
    "params": ["tests/test_params.py", "tests/test_model.py", "tests/test_control.py"],
    "angles": ["tests/test_derivatives.py", "tests/test_control.py"],
    "model": ["tests/test_model.py", "tests/test_control.py"],
    "trajectories": ["tests/test_trajectories.py", "tests/test_derivatives.py"],
    "allocation": ["tests/test_allocation.py", "tests/test_control.py"],
    "control": ["tests/test_control.py", "tests/test_allocation.py"],
    "closed_loop": ["tests/test_limits.py::test_compiled_field_is_the_closed_loop_with_its_limits",
                    "tests/test_limits.py::test_switched_loop_scalar_fast_path_is_eqs_23_and_2_4"],
    # the one decision procedure behind every verdict (issue 22): its unit tests, which feed it
    # statistics and small maps with known answers (the flows' own tests run minutes per mutant)
    "dynamics.verdicts": ["tests/test_verdict_procedure.py"],
    "dynamics.orbit_search": ["tests/test_verdict_procedure.py"],
    "dynamics.statistics": ["tests/test_verdict_procedure.py"],
    # the paper's errata and report (issue 28): each errata row's check run on its own forms and on
    # falsifying ones, every report row (on the paper and the extensions) fed synthetic evidence
    # that passes or breaks each clause in turn, the report's own rules, and the report rows whose
    # real check is cheap (REPORT_ROWS); the other rows' real checks recompute the book's flow maps
    # and sweeps, minutes per mutant, and run only on their synthetic evidence here
    "paper.errata": PAPER_ERRATA + REPORT_RULES,
    "paper.verdicts": PAPER_ERRATA,
    "paper.model_errata": PAPER_ERRATA + ["tests/test_symbolic.py"],
    "paper.tracking_errata": PAPER_ERRATA,
    "paper.rotation_errata": PAPER_ERRATA,
    "paper.reading_errata": PAPER_ERRATA,
    "paper.outcomes": REPORT_RULES + ["tests/test_report_falsifiable.py", "tests/test_report_paper_falsifiable.py"],
    "paper.extensions": ["tests/test_report_falsifiable.py"],
    "paper.report": REPORT_RULES + REPORT_ROWS + ["tests/test_report_paper_falsifiable.py"],
    "paper.findings": REPORT_RULES,
    # the circle's steady motion under the weighted allocation (Chapter 6)
    "weighting.circle": ["tests/test_weighted_circle.py"],
}
#: tests written to kill survivors: always run
ALWAYS = ["tests/test_core_mutants.py", "tests/test_paper_mutants.py"]
#: helpers the test files import
SUPPORT = ["tests/conftest.py", "tests/flows.py"]

#: appended to the copied tests/conftest.py: a test that runs slowly on a loaded machine must not
#: fail hypothesis's 200 ms deadline (in the clean run that stops mutmut, in a mutant's run it
#: would count as a kill)
NO_DEADLINES = """

# added by mutation/run.py
from hypothesis import settings as _mutation_settings  # noqa: E402

_mutation_settings.register_profile("mutation", deadline=None)
_mutation_settings.load_profile("mutation")
"""

PYTEST_INI = """[tool:pytest]
markers =
    book: builds the Jupyter Book (slow)
    browser: drives headless Chromium against the built book
    robustness: a verdict rerun from a start perturbed by a relative 1e-12
"""


def _path(module: str) -> str:
    """The file of a module named as in :data:`TESTS` (``dynamics.verdicts``: lib/dynamics/verdicts.py)."""
    return f"lib/{module.replace('.', '/')}.py"


def _config(modules: list[str], tests: list[str], debug: bool = False) -> str:
    lines = ["[mutmut]", "source_paths = lib", f"debug = {str(debug).lower()}", "only_mutate ="]
    lines += [f"    {_path(m)}" for m in modules]
    lines += ["pytest_add_cli_args_test_selection ="] + [f"    {t}" for t in tests]
    # a fixed hypothesis seed: a mutant is killed by the same examples the clean run passed
    lines += ["pytest_add_cli_args =", "    -p", "    no:cacheprovider", "    --hypothesis-seed=0",
              "use_git_change_detection = false", ""]
    return "\n".join(lines) + "\n" + PYTEST_INI


def _stage(work: Path, modules: list[str], debug: bool = False) -> list[str]:
    shutil.copytree(ROOT / "lib", work / "lib", ignore=shutil.ignore_patterns("__pycache__"))
    tests = sorted({t for m in modules for t in TESTS[m]} | {t for t in ALWAYS if (ROOT / t).exists()})
    (work / "tests").mkdir()
    for t in {t.split("::")[0] for t in tests} | set(SUPPORT):
        shutil.copy2(ROOT / t, work / t)
    with open(work / "tests" / "conftest.py", "a") as f:
        f.write(NO_DEADLINES)
    (work / "setup.cfg").write_text(_config(modules, tests, debug))
    return tests


def _results(work: Path) -> list[tuple[str, str]]:
    out = subprocess.run([str(VENV_BIN / "mutmut"), "results", "--all", "true"], cwd=work,
                         capture_output=True, text=True, check=True).stdout
    return [(m.group(1), m.group(2)) for m in re.finditer(r"^\s+(\S+): (.+)$", out, re.M)]


def _diff(work: Path, name: str) -> str:
    out = subprocess.run([str(VENV_BIN / "mutmut"), "show", name], cwd=work, capture_output=True,
                         text=True).stdout
    return "\n".join(line for line in out.splitlines() if not line.startswith("# ")).strip()


def _report(modules, tests, results, diffs, seconds) -> str:
    by_status: dict[str, int] = {}
    for _, status in results:
        by_status[status] = by_status.get(status, 0) + 1
    killed = by_status.get("killed", 0) + by_status.get("timeout", 0)
    tested = len(results) - by_status.get("skipped", 0) - by_status.get("not checked", 0)
    score = 100.0 * killed / tested if tested else float("nan")
    lines = [f"## Run of {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}: "
             f"{', '.join(f'`{_path(m)}`' for m in modules)}", "",
             f"- tests: {', '.join(f'`{t}`' for t in tests)}",
             f"- {len(results)} mutants: " + ", ".join(f"{n} {s}" for s, n in sorted(by_status.items())),
             f"- **score {score:.1f} %** (killed and timed out over all mutants tested)",
             f"- wall time {seconds / 60:.1f} min (mutmut 3, 2 workers, nice 19)", ""]
    survivors = [(n, s) for n, s in results if s not in ("killed", "timeout")]
    if survivors:
        lines += ["### Mutants not killed", ""]
        for name, status in survivors:
            lines += [f"#### `{name}` ({status})", "", "```diff", diffs.get(name, ""), "```", ""]
    return "\n".join(lines) + "\n"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("modules", nargs="*", default=list(TESTS), help=f"core modules, of {list(TESTS)}")
    ap.add_argument("--keep", action="store_true", help="keep the work directory (it is printed)")
    ap.add_argument("--debug", action="store_true", help="mutmut's debug output (every pytest command)")
    ap.add_argument("--report", default=str(ROOT / "mutation" / "REPORT.md"),
                    help="file to append the run's section to")
    args = ap.parse_args()
    bad = [m for m in args.modules if m not in TESTS]
    if bad:
        ap.error(f"unknown modules {bad}; the core modules are {list(TESTS)}")
    work = Path(tempfile.mkdtemp(prefix="mutation-"))
    try:
        tests = _stage(work, args.modules, args.debug)
        t0 = time.time()
        # a fresh interpreter must import the mutated lib too (tests/conftest.py checks which lib
        # a subprocess sees): mutmut runs the tests in mutants/ under the work directory
        # (made now: a directory missing when the interpreter starts is never searched later)
        (work / "mutants").mkdir()
        # mutmut forks a child per mutant after running the tests in the parent: numba's OpenMP
        # threading layer aborts a forked child (the mutant then reads "suspicious"), its
        # workqueue layer does not
        env = dict(os.environ, PYTHONPATH=str(work / "mutants"), PYTHONHASHSEED="0",
                   NUMBA_THREADING_LAYER="workqueue")
        code = subprocess.run(["nice", "-n", "19", str(VENV_BIN / "mutmut"), "run", "--max-children", "2"],
                              cwd=work, env=env).returncode
        seconds = time.time() - t0
        if code != 0:
            print(f"mutmut run failed with exit code {code} (work directory {work})", file=sys.stderr)
            args.keep = True
            return code
        results = _results(work)
        diffs = {n: _diff(work, n) for n, s in results if s not in ("killed", "timeout")}
        section = _report(args.modules, tests, results, diffs, seconds)
        report = Path(args.report)
        head = report.read_text() if report.exists() else "# Mutation testing of the core modules\n\n"
        report.write_text(head.rstrip("\n") + "\n\n" + section)
        print(section)
        return 0
    finally:
        if args.keep:
            print(f"work directory kept: {work}")
        else:
            shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
