"""``make lab``'s server, driven as a Jupyter user's browser drives it (issue 59): JupyterLab's
server on 127.0.0.1 opens a chapter, a MyST text notebook, as a notebook through jupytext, starts
the project's kernel for it, and runs its cells over the kernel's websocket; a value the chapter
glues comes back and equals the one computed here directly."""

from __future__ import annotations

import asyncio
import json
import socket
import subprocess
import sys
import time
import urllib.request
import uuid
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
TOKEN = uuid.uuid4().hex
CHAPTER = "chapters/01_model.md"


def _lab_options() -> list[str]:
    """The options of ``make lab``'s command line, read from the Makefile, so that the test starts
    the server the target starts."""
    import re
    make = (ROOT / "Makefile").read_text().replace("\\\n", " ")        # continuation lines joined
    line = next(ln for ln in make.splitlines() if "jupyter lab" in ln)
    return [o for o in re.findall(r"--[\w.]+=\S+", line) if "root_dir" not in o]


LAB_OPTIONS = _lab_options()


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _api(port: int, path: str, body: dict | None = None) -> dict:
    req = urllib.request.Request(f"http://127.0.0.1:{port}/api/{path}", method="POST" if body else "GET",
                                 data=json.dumps(body).encode() if body else None,
                                 headers={"Authorization": f"token {TOKEN}", "Content-Type": "application/json"})
    with urllib.request.urlopen(req, timeout=30) as r:
        return json.loads(r.read())


@pytest.fixture(scope="module")
def lab():
    """JupyterLab as ``make lab`` starts it (the book's folder, 127.0.0.1), without a browser."""
    port = _free_port()
    proc = subprocess.Popen([sys.executable, "-m", "jupyterlab", "--no-browser", *LAB_OPTIONS,
                             f"--ServerApp.port={port}", f"--IdentityProvider.token={TOKEN}",
                             f"--ServerApp.root_dir={ROOT}"], cwd=ROOT, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True)
    try:
        for _ in range(120):
            try:
                _api(port, "status")
                break
            except OSError:
                if proc.poll() is not None:
                    pytest.fail(f"the lab server exited: {proc.stderr.read()[-2000:]}")
                time.sleep(0.5)
        else:
            pytest.fail("the lab server did not answer within 60 s")
        yield port
    finally:
        proc.terminate()
        proc.wait(timeout=30)


async def _run_cells(port: int, kernel: str, sources: list[str]) -> dict:
    """Each source executed in turn on the kernel's channels; the glued values by name (their
    text/plain), failing on the first error."""
    from tornado.websocket import websocket_connect
    ws = await websocket_connect(f"ws://127.0.0.1:{port}/api/kernels/{kernel}/channels?token={TOKEN}")
    session, glued = uuid.uuid4().hex, {}
    for src in sources:
        msg_id = uuid.uuid4().hex
        ws.write_message(json.dumps({
            "header": {"msg_id": msg_id, "username": "test", "session": session, "msg_type": "execute_request",
                       "version": "5.3", "date": ""},
            "parent_header": {}, "metadata": {}, "channel": "shell", "buffers": [],
            "content": {"code": src, "silent": False, "store_history": False, "user_expressions": {},
                        "allow_stdin": False, "stop_on_error": True}}))
        while True:
            m = json.loads(await asyncio.wait_for(ws.read_message(), timeout=300))
            if m.get("parent_header", {}).get("msg_id") != msg_id:
                continue
            kind, content = m["msg_type"], m["content"]
            if kind == "error":
                pytest.fail(f"{CHAPTER}: {content['ename']}: {content['evalue']}")
            if kind == "display_data" and "scrapbook" in content.get("metadata", {}):
                name = content["metadata"]["scrapbook"]["name"]
                glued[name] = next(v for k, v in content["data"].items() if k.endswith("text/plain"))
            if kind == "execute_reply":
                assert content["status"] == "ok", content
                break
    ws.close()
    return glued


def test_a_chapter_opens_as_a_notebook_and_runs_in_the_lab_kernel(lab):
    nb = _api(lab, f"contents/{CHAPTER}?type=notebook&content=1")
    assert nb["type"] == "notebook" and nb["format"] == "json"              # jupytext opened the .md
    cells = [c for c in nb["content"]["cells"] if c["cell_type"] == "code"]
    assert len(cells) >= 5
    assert nb["content"]["metadata"]["kernelspec"]["name"] == "python3"
    session = _api(lab, "sessions", {"path": CHAPTER, "type": "notebook", "name": "",
                                     "kernel": {"name": "python3"}})
    glued = asyncio.run(_run_cells(lab, session["kernel"]["id"], [c["source"] for c in cells]))
    # the glued count of wrong rows of (6), against the same comparison made here
    import sympy as sp
    from lib import symbolic
    sm = symbolic.derive_body_frame()
    printed = symbolic.printed_drift(sm)
    wrong = sum(sp.simplify(sm.f[i] - printed[i]) != 0 for i in range(6))
    assert wrong == 1 and int(glued["n_wrong_rows"]) == wrong and "ol_t_end" in glued
