"""The book's glued values as one build executed them, written to a JSON file, and two such files
compared: the check that a change of the library's layout left every number of the book as it was.

    .venv/bin/python tools/glued.py dump before.json           # after `make book`
    ... move the code, `make book` again ...
    .venv/bin/python tools/glued.py dump after.json
    .venv/bin/python tools/glued.py compare before.json after.json

``dump`` reads the execution cache that ``make book`` fills (``_build/.jupyter_cache``): for each
page, each glued name's text as the page writes it (``text/plain``, the kind's rendering for a
number with a kind). ``compare`` prints every name whose text differs, or is on one side only, and
exits 1 if there is any.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def executed_glue(root: Path = ROOT) -> dict[str, dict[str, tuple[str, dict | None]]]:
    """page -> {glued name: (its text/plain, the record of its kind or None)}, from the execution
    cache of the book at ``root`` (a number with a kind carries its value and kind beside its text,
    :data:`lib.machinery.kinds.MIME`). ``tests/test_number_kinds.py`` reads the pages through it."""
    from jupyter_cache import get_cache
    from myst_nb.ext.glue import GLUE_PREFIX

    from lib.machinery.kinds import MIME

    out: dict[str, dict[str, tuple[str, dict | None]]] = {}
    cache = get_cache(root / "_build" / ".jupyter_cache")
    for rec in cache.list_cache_records():
        nb = cache.get_cache_bundle(rec.pk).nb
        page = Path(rec.uri).resolve().relative_to(root.resolve()).with_suffix("").as_posix()
        values = out.setdefault(page, {})
        for cell in nb.cells:
            for output in cell.get("outputs", []):
                name = output.get("metadata", {}).get("scrapbook", {}).get("name")
                data = output.get("data", {})
                plain = data.get(GLUE_PREFIX + "text/plain", data.get("text/plain"))
                if name and plain is not None:
                    values[name] = (plain, data.get(GLUE_PREFIX + MIME, data.get(MIME)))
    return out


def glued_values(root: Path = ROOT) -> dict[str, dict[str, str]]:
    """page -> {glued name: its text/plain}, from the execution cache of the book at ``root``."""
    return {page: {name: plain for name, (plain, _) in glued.items()}
            for page, glued in executed_glue(root).items()}


def differences(before: dict, after: dict) -> list[str]:
    """Every page and name whose text differs between two dumps, or is on one side only."""
    lines = []
    for page in sorted(set(before) | set(after)):
        a, b = before.get(page, {}), after.get(page, {})
        for name in sorted(set(a) | set(b)):
            if a.get(name) != b.get(name):
                lines.append(f"{page}: {name}: {a.get(name, '(absent)')} -> {b.get(name, '(absent)')}")
    return lines


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="command", required=True)
    d = sub.add_parser("dump", help="write the current build's glued values to a JSON file")
    d.add_argument("path", type=Path)
    c = sub.add_parser("compare", help="compare two dumps; exit 1 if any value differs")
    c.add_argument("before", type=Path)
    c.add_argument("after", type=Path)
    args = ap.parse_args(argv)
    if args.command == "dump":
        values = glued_values()
        args.path.write_text(json.dumps(values, indent=1, sort_keys=True))
        print(f"{sum(map(len, values.values()))} glued values on {len(values)} pages -> {args.path}")
        return 0
    lines = differences(json.loads(args.before.read_text()), json.loads(args.after.read_text()))
    print("\n".join(lines) if lines else "the same glued values on every page")
    return 1 if lines else 0


if __name__ == "__main__":
    sys.exit(main())
