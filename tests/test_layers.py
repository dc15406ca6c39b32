"""Layering of the package, read from the source with :mod:`ast` (nothing is imported).

An import edge ``a -> b`` is an ``import``/``from ... import`` in module ``a`` that names
module ``b`` of ``sumo_ayss`` (``from sumo_ayss.x import y`` counts as ``a -> sumo_ayss.x.y``
when ``y`` is a module, else ``a -> sumo_ayss.x``; importing a submodule also runs its
packages' ``__init__``, counted as edges too, except a module's own ancestor packages: their
``__init__`` is already running when the module is, and Python resolves a sibling import
through ``sys.modules`` without it). *Module-level* edges are the imports run when
``a`` is imported (top level, incl. ``if``/``try`` blocks) and the type-only imports
(``if TYPE_CHECKING:``): a type named across layers is a dependency too, even if Python never
runs it; *function-level* edges are imports inside a function or method body, run when it is
called.

An import circle is a strongly connected component of more than one module. Module-level
circles (type-only imports counted) must not exist; function-level ones (a lazy import that
closes a loop) are reported by ``python tests/test_layers.py``.

Run as a script it prints the circles of both kinds and the largest modules.
"""

from __future__ import annotations

import ast
import sys
from collections.abc import Iterator
from pathlib import Path

PACKAGE = "sumo_ayss"
ROOT = Path(__file__).resolve().parents[1] / PACKAGE
#: The largest module allowed [lines].
MAX_MODULE_LINES = 500
#: What :mod:`sumo_ayss.analysis` may import from the package besides itself: the error
#: tree, range checks, the registry type and the case records. It reads no file (no
#: run_folder, report or config), runs nothing (no sim, envs or agents) and knows no ranking
#: mode: the run records (:func:`sumo_ayss.run_folder.read_run`, typed by analysis's own
#: :class:`~sumo_ayss.analysis.case.RunLike`) and the cross-play table
#: (:func:`sumo_ayss.run_folder.load_crossplay`) are read outside and handed to it, and the
#: modes (:mod:`sumo_ayss.modes`) sit above it.
ANALYSIS_MAY_IMPORT = (
    "sumo_ayss.analysis",
    "sumo_ayss.util.errors",
    "sumo_ayss.util.validation",
    "sumo_ayss.util.registry",
    "sumo_ayss.cases",
)
#: What :mod:`sumo_ayss.modes` may import: what analysis may, and analysis itself; held to
#: the same purity (no file, no loader), so that a mode computes and words from data only.
MODES_MAY_IMPORT = (*ANALYSIS_MAY_IMPORT, "sumo_ayss.modes")
#: Pairs of layers with no import edge of any kind (module, function or type-only level):
#: the configuration is below the ranking modes, the analysis below the modes and the files,
#: and the files are storage: the reader returns what is stored, the analysis scores it.
NO_IMPORTS = (
    ("sumo_ayss.config", "sumo_ayss.modes"),
    ("sumo_ayss.analysis", "sumo_ayss.modes"),
    ("sumo_ayss.analysis", "sumo_ayss.run_folder"),
    ("sumo_ayss.run_folder", "sumo_ayss.analysis"),
)
#: What :mod:`sumo_ayss.records` (the generic CSV and JSON record formats) may import from the
#: package: itself and :mod:`sumo_ayss.util`. It knows no file of a study; the run folder's
#: names and schemas sit above it (:mod:`sumo_ayss.run_folder`).
RECORDS_MAY_IMPORT = ("sumo_ayss.records", "sumo_ayss.util")
#: The stages that import nothing of the report at any level (issue 34: data flows one way,
#: the report is the end of it): the commands that end in documents sit above both
#: (:mod:`sumo_ayss.commands`).
REPORT_FREE = ("sumo_ayss.pipeline", "sumo_ayss.rank", "sumo_ayss.crossplay", "sumo_ayss.grid")
#: Where a stage module's ``if __name__ == "__main__":`` guard may hand over (``python -m
#: sumo_ayss.<stage>``): its own command. Imports under the guard run only when the file is
#: the program (``__main__``), never when the module is imported, so they are no edge of the
#: import graph; :func:`test_main_guards_hand_over_to_their_command` checks them instead.
COMMANDS_PACKAGE = "sumo_ayss.commands"
#: Packages whose ``__init__`` is a docstring: importing one of their modules runs nothing
#: else of them (checked below), so the package edge itself carries no import.
PACKAGES_WITHOUT_CODE = frozenset({"sumo_ayss.util", "sumo_ayss.records"})
#: Calls that read or write files; none appears in :mod:`sumo_ayss.analysis`.
FILE_CALLS = frozenset(
    {
        "open",
        "read_text",
        "read_bytes",
        "write_text",
        "write_bytes",
        "is_file",
        "exists",
        "glob",
        "rglob",
        "iterdir",
        "loadtxt",
        "genfromtxt",
        "load",
        "save",
        "savez",
        "read_csv",
        "savefig",
    }
)


def module_files() -> dict[str, Path]:
    """Dotted module name -> file, for every ``.py`` file of the package."""
    out = {}
    for path in sorted(ROOT.rglob("*.py")):
        parts = list(path.relative_to(ROOT.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        out[".".join(parts)] = path
    return out


def _imports(body: list[ast.stmt], in_function: bool) -> Iterator[tuple[ast.stmt, bool]]:
    """Every import statement under ``body`` with whether it runs inside a function."""
    for node in body:
        if isinstance(node, ast.Import | ast.ImportFrom):
            yield node, in_function
        elif _is_main_guard(node):  # runs only as the program: see COMMANDS_PACKAGE
            continue
        elif isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            yield from _imports(node.body, True)
        else:  # incl. ``if TYPE_CHECKING:``: a type-only import is a dependency too
            for field in ("body", "orelse", "finalbody", "handlers", "cases"):
                children = getattr(node, field, None)
                if isinstance(children, list):
                    stmts = [c for c in children if isinstance(c, ast.stmt)]
                    for child in children:  # except handlers and match cases hold bodies
                        if isinstance(child, ast.ExceptHandler | ast.match_case):
                            stmts.extend(child.body)
                    yield from _imports(stmts, in_function)


def _is_main_guard(node: ast.stmt) -> bool:
    """``if __name__ == "__main__":``."""
    test = getattr(node, "test", None)
    return (
        isinstance(node, ast.If)
        and isinstance(test, ast.Compare)
        and isinstance(test.left, ast.Name)
        and test.left.id == "__name__"
        and len(test.comparators) == 1
        and isinstance(test.comparators[0], ast.Constant)
        and test.comparators[0].value == "__main__"
    )


def main_guard_imports(modules: dict[str, Path]) -> dict[str, list[str]]:
    """Module -> the modules its ``if __name__ == "__main__":`` guard imports."""
    found: dict[str, list[str]] = {}
    for name, path in modules.items():
        for node in ast.parse(path.read_text(encoding="utf-8")).body:
            if _is_main_guard(node):
                found[name] = [
                    (n.module or "") if isinstance(n, ast.ImportFrom) else a.name
                    for n in ast.walk(node)
                    if isinstance(n, ast.Import | ast.ImportFrom)
                    for a in n.names
                ]
    return found


def _with_packages(name: str, modules: dict[str, Path]) -> set[str]:
    """``name`` and the packages above it that are modules of ours (their __init__ runs)."""
    parts = name.split(".")
    return {".".join(parts[:i]) for i in range(1, len(parts) + 1)} & set(modules)


def import_edges(modules: dict[str, Path]) -> tuple[set[tuple[str, str]], set[tuple[str, str]]]:
    """(module-level edges, function-level edges) between modules of the package."""
    top: set[tuple[str, str]] = set()
    lazy: set[tuple[str, str]] = set()
    for name, path in modules.items():
        tree = ast.parse(path.read_text(encoding="utf-8"))
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        for node, in_function in _imports(tree.body, False):
            targets: set[str] = set()
            if isinstance(node, ast.Import):
                for alias in node.names:
                    targets |= _with_packages(alias.name, modules)
            else:
                assert isinstance(node, ast.ImportFrom)
                if node.level:
                    base = package.split(".")
                    base = base[: len(base) - node.level + 1]
                    source = ".".join([*base, node.module] if node.module else base)
                else:
                    source = node.module or ""
                targets |= _with_packages(source, modules)
                for alias in node.names:
                    if f"{source}.{alias.name}" in modules:
                        targets.add(f"{source}.{alias.name}")
            ancestors = _with_packages(name, modules)  # name itself included
            for target in targets - ancestors:
                (lazy if in_function else top).add((name, target))
    return top, lazy


def circles(nodes: set[str], edges: set[tuple[str, str]]) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan), each sorted."""
    graph: dict[str, list[str]] = {n: [] for n in nodes}
    for a, b in edges:
        graph[a].append(b)
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    out: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                out.append(sorted(component))

    sys.setrecursionlimit(max(sys.getrecursionlimit(), 10 * len(graph) + 100))
    for v in sorted(graph):
        if v not in index:
            visit(v)
    return sorted(out)


def module_lines() -> dict[str, int]:
    """Lines of each module of the package."""
    return {
        name: len(path.read_text(encoding="utf-8").splitlines())
        for name, path in module_files().items()
    }


def test_no_module_level_import_circles() -> None:
    """Type-only (``if TYPE_CHECKING:``) imports counted."""
    modules = module_files()
    top, _ = import_edges(modules)
    assert circles(set(modules), top) == []


def _within(name: str, prefixes: tuple[str, ...]) -> bool:
    return any(name == p or name.startswith(p + ".") for p in prefixes)


def test_analysis_imports_no_loader_and_reads_no_file() -> None:
    """analysis/ (and modes/, above it) is pure: it imports nothing from run_folder, report,
    config or the stages, at module, function or type-only level, and calls no file reader or
    writer; analysis imports no mode."""
    modules = module_files()
    assert "sumo_ayss.analysis.case" in modules
    top, lazy = import_edges(modules)
    outside = sorted(
        (a, b)
        for a, b in top | lazy
        if (
            (_within(a, ("sumo_ayss.analysis",)) and not _within(b, ANALYSIS_MAY_IMPORT))
            or (_within(a, ("sumo_ayss.modes",)) and not _within(b, MODES_MAY_IMPORT))
        )
        and b not in PACKAGES_WITHOUT_CODE
    )
    assert outside == []
    calls = []
    for name, path in modules.items():
        if not _within(name, ("sumo_ayss.analysis", "sumo_ayss.modes")):
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Call):
                f = node.func
                called = f.attr if isinstance(f, ast.Attribute) else getattr(f, "id", "")
                if called in FILE_CALLS:
                    calls.append(f"{name}:{node.lineno} {called}")
    assert calls == []


def test_the_record_formats_know_no_file_of_a_study() -> None:
    """records/ (the one CSV and the one JSON reader) imports nothing of the package but
    util/, at any level: a file's name or schema lives in run_folder/, above it."""
    modules = module_files()
    assert "sumo_ayss.records.table" in modules
    top, lazy = import_edges(modules)
    outside = sorted(
        (a, b)
        for a, b in top | lazy
        if _within(a, ("sumo_ayss.records",)) and not _within(b, RECORDS_MAY_IMPORT)
    )
    assert outside == []


def test_layers_that_must_not_import_each_other() -> None:
    modules = module_files()
    top, lazy = import_edges(modules)
    found = sorted(
        (a, b)
        for a, b in top | lazy
        for low, high in NO_IMPORTS
        if _within(a, (low,)) and _within(b, (high,))
    )
    assert found == []


def report_imports(modules: dict[str, Path]) -> list[tuple[str, str]]:
    """The import edges (any level) from :data:`REPORT_FREE` into the report."""
    top, lazy = import_edges(modules)
    return sorted(
        (a, b)
        for a, b in top | lazy
        if _within(a, REPORT_FREE) and _within(b, ("sumo_ayss.report",))
    )


def test_the_stages_import_nothing_of_the_report() -> None:
    """pipeline, rank, crossplay and grid import no report module at any level; the
    commands above them hand the report their data (:mod:`sumo_ayss.commands`)."""
    assert report_imports(module_files()) == []


def test_main_guards_hand_over_to_their_command() -> None:
    """A module's ``__main__`` guard imports nothing, or (a stage whose command lives above
    it) only ``sumo_ayss.commands.<stage>``; at least pipeline's and rank's do."""
    guards = main_guard_imports(module_files())
    handing_over = {}
    for module, imported in guards.items():
        stage = module.rpartition(".")[2]
        assert set(imported) <= {f"{COMMANDS_PACKAGE}.{stage}"}, (module, imported)
        if imported:
            handing_over[module] = imported
    assert {"sumo_ayss.pipeline", "sumo_ayss.rank"} <= set(handing_over)


def script_report_imports(scripts: Path) -> list[str]:
    """``scripts/<name>.py: <module>`` for every import of the report by a script."""
    found = []
    for path in sorted(scripts.glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            names = (
                [node.module or ""]
                if isinstance(node, ast.ImportFrom)
                else [a.name for a in node.names]
                if isinstance(node, ast.Import)
                else []
            )
            found += [
                f"scripts/{path.name}: {n}" for n in names if _within(n, ("sumo_ayss.report",))
            ]
    return found


def test_no_script_imports_the_report(tmp_path: Path) -> None:
    """A script that needs a report's figure or document runs a report entry point
    (``python -m sumo_ayss.report...``)."""
    assert script_report_imports(ROOT.parent / "scripts") == []
    (tmp_path / "draw.py").write_text("from sumo_ayss.report.figures import reward_shapes_figure\n")
    assert script_report_imports(tmp_path) == ["scripts/draw.py: sumo_ayss.report.figures"]


def test_packages_counted_as_without_code_hold_only_a_docstring() -> None:
    for package in PACKAGES_WITHOUT_CODE:
        path = ROOT.parent / package.replace(".", "/") / "__init__.py"
        body = ast.parse(path.read_text(encoding="utf-8")).body
        assert len(body) == 1 and isinstance(body[0], ast.Expr), package


def test_the_analysis_rule_catches_a_loader_import() -> None:
    """The rule above, on an edge it must refuse (the one analysis/ had before)."""
    assert not _within("sumo_ayss.run_folder", ANALYSIS_MAY_IMPORT)
    assert not _within("sumo_ayss.report.load", ANALYSIS_MAY_IMPORT)
    assert _within("sumo_ayss.cases.cut_in", ANALYSIS_MAY_IMPORT)
    assert not _within("sumo_ayss.modes.crossplay", ANALYSIS_MAY_IMPORT)
    assert _within("sumo_ayss.analysis.case", MODES_MAY_IMPORT)


def private_imports(modules: dict[str, Path]) -> list[str]:
    """``module: from other import _name`` for every private name imported from another
    module of the package (a helper two modules share belongs in a module of its own)."""
    found = []
    for name, path in modules.items():
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith(PACKAGE):
                for alias in node.names:
                    if alias.name.startswith("_") and not alias.name.startswith("__"):
                        found.append(f"{name}: from {node.module} import {alias.name}")
    return found


def test_no_module_imports_a_private_name_of_another() -> None:
    assert private_imports(module_files()) == []


def test_the_private_import_rule_sees_one(tmp_path: Path) -> None:
    path = tmp_path / "x.py"
    path.write_text(f"from {PACKAGE}.replay.record import _row, Kind\n")
    assert private_imports({"x": path}) == [f"x: from {PACKAGE}.replay.record import _row"]


def modules_over_limit() -> dict[str, int]:
    """Modules over :data:`MAX_MODULE_LINES` lines -> their lines, largest first."""
    lines = sorted(module_lines().items(), key=lambda kv: (-kv[1], kv[0]))
    return {name: n for name, n in lines if n > MAX_MODULE_LINES}


def _over_limit_text() -> str:
    over = modules_over_limit()
    return ", ".join(f"{name} ({n})" for name, n in over.items()) or "none"


def test_no_module_over_500_lines() -> None:
    too_long = modules_over_limit()
    for name, n in too_long.items():  # shown with -s, or in the failure once strict
        print(f"over {MAX_MODULE_LINES} lines: {n:5d} {name}")
    assert too_long == {}, f"modules over {MAX_MODULE_LINES} lines: {too_long}"


def test_the_walker_sees_circles_and_tells_lazy_imports(tmp_path: Path) -> None:
    """The walker itself, on a hand-made package: a module-level circle, a lazy one, a
    type-only import (counted as module-level), and a sibling import through the package's
    ``__init__`` (not a circle)."""
    pkg = tmp_path / "p"
    pkg.mkdir()
    files = {
        "__init__.py": "from p.a import A\n",
        "a.py": "from p import b\nA = 1\n",
        "b.py": "import p.a\n",
        "c.py": "def f():\n    from p.d import D\n",
        "d.py": "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    import p.a\n"
        "try:\n    from p.c import f\nexcept ImportError:\n    pass\nD = 1\n",
    }
    for name, text in files.items():
        (pkg / name).write_text(text)
    modules = {"p": pkg / "__init__.py"} | {f"p.{n[:-3]}": pkg / n for n in files if n[0] != "_"}
    top, lazy = import_edges(modules)
    assert top == {("p", "p.a"), ("p.a", "p.b"), ("p.b", "p.a"), ("p.d", "p.c"), ("p.d", "p.a")}
    assert lazy == {("p.c", "p.d")}
    assert circles(set(modules), top) == [["p.a", "p.b"]]
    assert circles(set(modules), top | lazy) == [["p.a", "p.b"], ["p.c", "p.d"]]


def main() -> None:
    """Print the import circles (module-level and with function-level imports) and sizes."""
    modules = module_files()
    top, lazy = import_edges(modules)
    print(f"{len(modules)} modules, {len(top)} module-level and {len(lazy)} function-level edges")
    for title, edges in (("module-level", top), ("module- and function-level", top | lazy)):
        found = circles(set(modules), edges)
        print(f"import circles, {title} imports: {len(found)}")
        for component in found:
            print("   ", " <-> ".join(component))
    print(f"modules over {MAX_MODULE_LINES} lines:")
    for name, n in modules_over_limit().items():
        print(f"    {n:5d} {name}")


if __name__ == "__main__":
    main()
