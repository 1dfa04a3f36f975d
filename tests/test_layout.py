"""The layout of ``lib``: its import graph flows one way, the book's verdicts on the paper
(``lib.paper``) sit on top, and modules import each other at module level."""

import ast
from graphlib import CycleError, TopologicalSorter
from pathlib import Path

import pytest

LIB = Path(__file__).resolve().parents[1] / "lib"

#: function-local imports of lib modules, each with what justifies it: lib.integrators.compiled imports
#: lib.rotation.field, and lib/rotation/__init__.py imports these two modules, so at their top level the
#: import would close a cycle through the package (test_every_module_imports_first_without_a_cycle_through_a_package)
LOCAL_IMPORTS_ALLOWED = {("lib.rotation.reduced", "lib.integrators.compiled"),
                         ("lib.rotation.slow_eight", "lib.integrators.compiled")}


def _module_name(path: Path) -> str:
    parts = path.relative_to(LIB.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path: Path):
    """(imported lib module, whether the import is inside a function) for each import of lib."""
    name = _module_name(path)
    package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
    tree = ast.parse(path.read_text())
    local = {id(n) for f in ast.walk(tree) if isinstance(f, (ast.FunctionDef, ast.AsyncFunctionDef))
             for n in ast.walk(f)}
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - node.level + 1]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            targets = [mod] if node.module else [f"{mod}.{a.name}" for a in node.names]
            if node.module:  # "from .pkg import module" imports the module
                targets += [f"{mod}.{a.name}" for a in node.names]
        elif isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        else:
            continue
        for t in targets:
            if t == "lib" or t.startswith("lib."):
                yield t, id(node) in local


def _graph():
    """{module: set of lib modules it imports}, and the set of function-local (module, import) pairs."""
    modules = {_module_name(p): p for p in LIB.rglob("*.py")}
    g = {name: set() for name in modules}
    local = set()
    for name, path in modules.items():
        for target, is_local in _imports(path):
            if target in modules and target != name:
                g[name].add(target)
                if is_local:
                    local.add((name, target))
    return g, local


def _descendants(g, node):
    seen, todo = set(), [node]
    while todo:
        for nxt in g[todo.pop()] - seen:
            seen.add(nxt)
            todo.append(nxt)
    return seen


def test_import_graph_of_lib_is_acyclic():
    g, _ = _graph()
    try:
        order = list(TopologicalSorter(g).static_order())
    except CycleError as err:
        pytest.fail(f"import cycle in lib: {err.args[1]}")
    assert len(order) == len(g) > 30


def test_a_chapters_studies_are_imported_by_no_library_module():
    # lib/optimal/studies holds Chapter 8's studies, which call the library of lib/optimal; the
    # library never reaches up into them (issue 58: the library apart from the chapter's studies)
    g, _ = _graph()
    studies = "lib.optimal.studies"
    assert any(m.startswith(studies + ".") for m in g)
    up = sorted((m, t) for m, ts in g.items() if m.startswith("lib.optimal") and not m.startswith(studies)
                for t in ts if t == studies or t.startswith(studies + "."))
    assert not up, up


def test_every_module_imports_first_without_a_cycle_through_a_package():
    # importing lib.pkg.mod from outside lib.pkg runs lib/pkg/__init__.py first, and a public
    # face's __init__ imports its folder's modules: a module that reaches back to the importer
    # at module level would meet it half initialised (an ImportError, seen only when that
    # module is the first one imported, as autodoc imports it)
    g, local = _graph()
    packages = {m for m in g if (LIB.parent / m.replace(".", "/") / "__init__.py").exists()}
    h = {m: {t for t in ts if (m, t) not in local} for m, ts in g.items()}
    for m, ts in g.items():
        for t in list(h[m]):
            pkg = t.rsplit(".", 1)[0]
            if pkg in packages and pkg != "lib" and not (m == pkg or m.startswith(pkg + ".")):
                h[m].add(pkg)
    try:
        list(TopologicalSorter(h).static_order())
    except CycleError as err:
        pytest.fail(f"import cycle through a package's __init__: {err.args[1]}")


def test_domain_modules_never_import_the_verdicts_on_the_paper():
    g, _ = _graph()
    offenders = [(a, b) for a in g for b in g[a] if b.startswith("lib.paper") and not a.startswith("lib.paper")]
    assert not offenders, offenders


def test_lib_imports_its_own_modules_at_module_level_and_never_through_importlib():
    _, local = _graph()
    assert local <= LOCAL_IMPORTS_ALLOWED, sorted(local - LOCAL_IMPORTS_ALLOWED)
    for path in LIB.rglob("*.py"):
        assert "importlib" not in path.read_text(), path


@pytest.mark.parametrize("core", ["lib.params", "lib.angles", "lib.model", "lib.trajectories", "lib.control",
                                  "lib.allocation", "lib.closed_loop"])
def test_the_model_core_depends_on_nothing_above_it(core):
    # the core (params, model, trajectories, control, allocation, closed loop) never reaches up
    # into the integrators, the analyses, the figures or the verdicts
    g, _ = _graph()
    below = {"lib", "lib.machinery", "lib.machinery.checks", "lib.machinery.domain", "lib.params", "lib.angles",
             "lib.model", "lib.trajectories", "lib.allocation", "lib.control", "lib.closed_loop"}
    assert _descendants(g, core) <= below, sorted(_descendants(g, core) - below)


def test_the_parser_sees_relative_and_local_imports():
    # the checks above are only as good as the parser: it must see a known edge of each kind
    g, local = _graph()
    assert "lib.integrators.switched" in g["lib.simulate"]        # from .integrators.switched import
    assert "lib.trajectories" in g["lib.integrators.switched"]     # from ..trajectories import
    assert "lib.paper.model_errata" in g["lib.paper.errata"]       # from . import model_errata
    assert "lib.machinery.checks" in g["lib.params"]               # from .machinery import checks
    assert ("lib.rotation.reduced", "lib.integrators.compiled") in local


def test_modules_and_functions_stay_a_size_a_reader_can_hold():
    # no module over 500 lines; no function over 100 lines of code (its docstring aside:
    # the numpydoc Parameters and Returns are reading, not logic)
    long_modules, long_functions = [], []
    for path in sorted(LIB.rglob("*.py")):
        text = path.read_text()
        if text.count("\n") > 500:
            long_modules.append((path.name, text.count("\n")))
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                body = node.body
                doc = isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant) and len(body) > 1
                first = body[1].lineno if doc else body[0].lineno
                if node.end_lineno - first + 1 > 100:
                    long_functions.append((path.name, node.name, node.end_lineno - first + 1))
    assert not long_modules, long_modules
    assert not long_functions, long_functions


#: the most modules a folder (the top of lib included) holds, its __init__ aside: a reader takes
#: in a folder at a glance. The top holds the model core every chapter uses, and two public faces
#: kept where readers' scripts import them (lib.symbolic, lib.controllability, lib.stability).
MAX_MODULES_PER_FOLDER = 11


def test_each_folder_holds_few_modules_and_says_which_part_of_the_book_it_serves():
    folders = [LIB] + sorted(p for p in LIB.iterdir() if p.is_dir() and (p / "__init__.py").exists())
    assert len(folders) > 8
    for folder in folders:
        modules = [p for p in folder.glob("*.py") if p.name != "__init__.py"]
        assert 0 < len(modules) <= MAX_MODULES_PER_FOLDER, (folder.name, len(modules))
        doc = ast.get_docstring(ast.parse((folder / "__init__.py").read_text()))
        assert doc and len(doc) > 80, f"{folder.name}/__init__.py needs a docstring saying what it holds"


def test_module_names_inside_a_folder_drop_the_folder_s_prefix():
    for folder in (p for p in LIB.iterdir() if p.is_dir() and (p / "__init__.py").exists()):
        stem = folder.name.rstrip("s")
        offenders = [p.name for p in folder.glob("*.py") if p.stem.startswith(stem + "_")]
        assert not offenders, (folder.name, offenders)


def test_a_face_package_re_exports_and_every_other_init_only_documents():
    # the public faces re-export the names readers import (issue 21's stable names among them);
    # every other folder's __init__ holds a docstring and, at most, imports of its own modules
    faces = {"tracking", "limits", "rotation", "weighting", "percussion", "dynamics", "integrators", "paper", "optimal"}
    for folder in (p for p in LIB.iterdir() if p.is_dir() and (p / "__init__.py").exists()):
        tree = ast.parse((folder / "__init__.py").read_text())
        defs = [n for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))]
        assert not defs, f"{folder.name}/__init__.py defines code; it belongs in a module"
        if folder.name not in faces:
            assert not [n for n in tree.body if isinstance(n, (ast.Import, ast.ImportFrom))], folder.name
