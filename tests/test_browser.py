"""Open every page of the built book in headless Chromium, offline, and check that
it reads correctly: math typeset by the bundled MathJax, every image loaded, no
request leaving the loopback address, and every glued number present in the text.

Needs Debian's ``chromium`` (``.ci/run`` installs it); without it the test is
skipped with a message saying so.
"""

from __future__ import annotations

import functools
import http.server
import json
import re
import shutil
import threading
from pathlib import Path
from urllib.parse import urlparse

import pytest
import yaml

pytestmark = pytest.mark.browser

ROOT = Path(__file__).resolve().parents[1]
HTML = ROOT / "_build" / "html"
CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"
GLUE_ROLE = re.compile(r"\{glue(?::text)?\}`([^`]+)`")


def toc_documents() -> list[str]:
    toc = yaml.safe_load((ROOT / "_toc.yml").read_text())
    docs = [toc["root"]]

    def walk(entries):
        for e in entries or []:
            if "file" in e:
                docs.append(e["file"])
            walk(e.get("sections"))
            for part in e.get("parts", []):
                walk(part.get("chapters"))

    walk(toc.get("chapters"))
    for part in toc.get("parts", []):
        walk(part.get("chapters"))
    return docs


def expected_glue_strings(doc: str) -> list[str]:
    """The text each glue role of ``doc`` renders to, from the executed notebook."""
    from myst_nb.core.variables import format_plain_text

    src = (ROOT / f"{doc}.md").read_text()
    roles = GLUE_ROLE.findall(src)
    if not roles:
        return []
    glued = json.loads((ROOT / "_build" / "jupyter_execute" / f"{doc}.glue.json").read_text())
    values = {key: out["data"]["text/plain"] for key, out in glued.items()}
    expected = []
    for role in roles:
        key, _, fmt = role.partition(":")
        assert key in values, f"{doc}: glue key {key!r} is used in the text but never glued"
        expected.append(format_plain_text(values[key], fmt))
    return expected


class _QuietHandler(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args) -> None:
        pass


@pytest.fixture(scope="module")
def server(built_book):
    if built_book.returncode != 0:
        pytest.fail("the book did not build; see test_book.py")
    handler = functools.partial(_QuietHandler, directory=str(HTML))
    httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=httpd.serve_forever, daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{httpd.server_address[1]}"
    httpd.shutdown()


@pytest.fixture(scope="module")
def browser():
    if not Path(CHROMIUM).exists():
        pytest.skip(f"Debian's chromium is not installed ({CHROMIUM} missing): browser test skipped; "
                    "run .ci/run or `apt-get install chromium` to enable it")
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, headless=True, args=[
            "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
            "--disable-background-networking", "--disable-component-update", "--disable-sync"])
        yield b
        b.close()


TEXT_WITHOUT_CODE = """() => {
  const main = document.querySelector('main') || document.body;
  const copy = main.cloneNode(true);
  copy.querySelectorAll('pre, code, mjx-container, script, style, .cell_input').forEach(e => e.remove());
  return copy.innerText;
}"""


@pytest.mark.parametrize("doc", toc_documents())
def test_page_reads_correctly_offline(doc, server, browser):
    page = browser.new_page()
    requests: list[str] = []
    page.on("request", lambda r: requests.append(r.url))
    failed: list[str] = []
    page.on("requestfailed", lambda r: failed.append(r.url))
    url = f"{server}/{'index' if doc == 'intro' else doc}.html"
    page.goto(url, wait_until="networkidle")
    src = (ROOT / f"{doc}.md").read_text()

    has_mathjax = page.evaluate("() => !!(window.MathJax && MathJax.startup && MathJax.startup.promise)")
    if has_mathjax:
        page.evaluate("() => MathJax.startup.promise")
    n_math = page.locator("mjx-container").count()
    if "$" in src or "{math}" in src:
        assert has_mathjax, f"{doc}: MathJax did not load"
        assert n_math > 0, f"{doc}: no typeset math (mjx-container) found"

    text = page.evaluate(TEXT_WITHOUT_CODE)
    for raw in ("$$", "\\[", "\\begin{"):
        assert raw not in text, f"{doc}: raw LaTeX {raw!r} left in the text"
    leftover = re.findall(r"\\(?:frac|varphi|omega|beta|tau|sqrt|mathbb|dot|ddot)\b", text)
    assert not leftover, f"{doc}: untypeset LaTeX commands in the text: {sorted(set(leftover))}"

    page.wait_for_function("() => Array.from(document.images).every(i => i.complete)")
    broken = page.evaluate("() => Array.from(document.images).filter(i => i.naturalWidth === 0).map(i => i.src)")
    assert not broken, f"{doc}: images that did not load: {broken}"

    outside = [u for u in requests
               if urlparse(u).scheme not in ("data", "blob", "about") and urlparse(u).hostname != "127.0.0.1"]
    assert not outside, f"{doc}: requests left the loopback address: {outside}"
    assert not failed, f"{doc}: requests failed: {failed}"

    full_text = " ".join(page.evaluate("() => document.body.innerText").split())
    for expected in expected_glue_strings(doc):
        assert expected in full_text, f"{doc}: glued value {expected!r} not found in the page text"
    page.close()
