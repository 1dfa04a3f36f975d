"""Sphinx extension of the book: the library's docstrings are plain text with math written
out (|beta| <= beta_max, |multiplier| < 1), read in a terminal by ``help()`` as well as on
the "Library reference" page. reST would take ``|beta|`` for a substitution reference, so
every ``|`` outside inline literals and roles is escaped before autodoc renders the
docstring (after napoleon has turned its numpydoc sections into fields).

A name a module re-exports (``lib.weighting.verdicts.closed_loop_verdicts``) is documented once,
where it is defined; a cross-reference to it by the name in use resolves there."""

from __future__ import annotations

import re

# inline literals (``x``), roles (:func:`x`) and plain interpreted text (`x`): left alone
_CODE = re.compile(r"(:[\w:.-]+:`[^`]*`|``[^`]*``|`[^`]*`_?)")


def escape_bars(line: str) -> str:
    """``line`` with every ``|`` outside code and roles escaped (``\\|``)."""
    parts = _CODE.split(line)
    return "".join(p if i % 2 else re.sub(r"(?<!\\)\|", r"\\|", p) for i, p in enumerate(parts))


def _process(app, what, name, obj, options, lines: list[str]) -> None:
    lines[:] = [escape_bars(line) for line in lines]


def setup(app):
    app.setup_extension("sphinx.ext.autodoc")
    app.connect("autodoc-process-docstring", _process, priority=600)   # after napoleon (500)
    app.connect("missing-reference", _resolve_reexport)
    return {"parallel_read_safe": True, "parallel_write_safe": True}


def _canonical(modname: str | None, target: str) -> str | None:
    """Where the object a docstring names (``target``, seen from module ``modname``) is
    defined: a re-exported function or class, named where it is used, is documented where
    it is defined (``lib.limits.switched_runs`` is :func:`lib.limits.runs.switched_runs`)."""
    import importlib

    parts = target.split(".")
    for i in range(len(parts) - 1, -1, -1):        # the longest importable module prefix
        mod = ".".join(parts[:i]) if i else modname
        if not mod:
            continue
        try:
            obj = importlib.import_module(mod)
        except ImportError:
            continue
        try:
            for attr in parts[i:]:
                obj = getattr(obj, attr)
        except AttributeError:
            return None
        owner, qual = getattr(obj, "__module__", None), getattr(obj, "__qualname__", None)
        if owner and qual and f"{owner}.{qual}" not in (target, f"{modname}.{target}"):
            return f"{owner}.{qual}"
        return None
    return None


def _resolve_reexport(app, env, node, contnode):
    if node.get("refdomain") != "py":
        return None
    canonical = _canonical(node.get("py:module"), node["reftarget"])
    if canonical is None:
        return None
    return env.get_domain("py").resolve_xref(env, node["refdoc"], app.builder, node["reftype"], canonical,
                                             node, contnode)
