"""README's route from a chapter to a running notebook: jupytext converts the chapter's
MyST Markdown to an .ipynb, and nbclient (``jupyter execute``) runs it. The notebook must
find this checkout's ``lib`` whether its kernel runs in the repository root or in
``chapters/`` (where ``jupyter execute chapters/01_model.ipynb`` and the book build run it)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import nbformat
import pytest
from nbclient import NotebookClient

ROOT = Path(__file__).resolve().parents[1]
CHAPTER = ROOT / "chapters" / "01_model.md"      # the shortest chapter: about 4 s to execute

_WHERE = "import json, os, lib; print(json.dumps({'cwd': os.getcwd(), 'lib': lib.__file__}))"


@pytest.fixture(scope="module")
def notebook(tmp_path_factory) -> Path:
    """The chapter converted by README's command, written to a temporary directory."""
    out = tmp_path_factory.mktemp("notebook") / "01_model.ipynb"
    jupytext = Path(sys.executable).with_name("jupytext")
    proc = subprocess.run([str(jupytext), "--to", "ipynb", "--output", str(out), str(CHAPTER)],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    return out


@pytest.mark.parametrize("cwd", [".", "chapters"], ids=["repository-root", "chapters"])
def test_converted_chapter_executes_and_finds_this_checkouts_lib(notebook, cwd):
    nb = nbformat.read(notebook, as_version=4)
    n_code = sum(c.cell_type == "code" for c in nb.cells)
    assert n_code > 3, "jupytext did not turn the chapter's code-cells into code cells"
    nb.cells.append(nbformat.v4.new_code_cell(_WHERE))
    NotebookClient(nb, timeout=120, kernel_name="python3",
                   resources={"metadata": {"path": str(ROOT / cwd)}}).execute()
    errors = [o for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", [])
              if o.output_type == "error"]
    assert not errors
    where = json.loads(nb.cells[-1].outputs[0]["text"])
    assert Path(where["cwd"]).resolve() == (ROOT / cwd).resolve()
    assert Path(where["lib"]).resolve().is_relative_to(ROOT), where
