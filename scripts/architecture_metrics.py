"""Measure the architecture's end states (docs/architecture.md quotes this script's output).

    .venv/bin/python scripts/architecture_metrics.py [--ref COMMIT]

Everything is read from the source with :mod:`ast` (nothing of the package is imported);
the import graph is :mod:`tests.test_layers`'s (type-only imports counted as module-level).
``--ref`` measures a commit's tree instead of the working tree (``git archive`` into a
temporary folder).
"""

from __future__ import annotations

import argparse
import ast
import subprocess
import sys
import tarfile
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tests import test_layers as layers  # noqa: E402  (after the path is set)

#: Stages whose imports of the report the issue counts (plus every script): the layer test's
#: (which holds them to rendered documents only, and scripts to none).
REPORT_FREE = layers.REPORT_FREE
#: CaseAnalysis fields that belong to one mode (by prefix, or named).
MODE_PREFIXES = ("exposure_", "crossplay_", "paper_")
MODE_FIELDS = {"indices", "ranking", "pairs", "premise", "crossplay", "outcomes", "references"}


def _within(name: str, prefix: str) -> bool:
    return name == prefix or name.startswith(prefix + ".")


def _all_names(path: Path) -> list[str]:
    for node in ast.parse(path.read_text(encoding="utf-8")).body:
        if isinstance(node, ast.Assign) and any(
            isinstance(t, ast.Name) and t.id == "__all__" for t in node.targets
        ):
            return list(ast.literal_eval(node.value))
    return []


def _class_fields(path: Path, name: str) -> list[tuple[str, str]]:
    """``(field, annotation)`` of a class's annotated attributes."""
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ClassDef) and node.name == name:
            return [
                (s.target.id, ast.unparse(s.annotation))
                for s in node.body
                if isinstance(s, ast.AnnAssign) and isinstance(s.target, ast.Name)
            ]
    return []


def _names_used_from(package: Path, prefix: str) -> set[str]:
    """Distinct names that modules outside ``prefix`` import from it (any of its modules)."""
    found = set()
    for path in package.rglob("*.py"):
        module = ".".join(path.relative_to(package.parent).with_suffix("").parts)
        if _within(module.removesuffix(".__init__"), prefix):
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and _within(node.module or "", prefix):
                found |= {f"{node.module}.{a.name}".rsplit(".", 1)[-1] for a in node.names}
    return found


def measure(root: Path) -> dict[str, object]:
    """The measured end states of the tree at ``root``."""
    package = root / "sumo_ayss"
    layers.ROOT = package
    modules = layers.module_files()
    top, lazy = layers.import_edges(modules)
    lines = {n: len(p.read_text(encoding="utf-8").splitlines()) for n, p in modules.items()}
    run_folder = {n: v for n, v in lines.items() if _within(n, "sumo_ayss.run_folder")}
    report_edges = sorted(
        {
            (a, b)
            for a, b in top | lazy
            if any(_within(a, s) for s in REPORT_FREE) and _within(b, "sumo_ayss.report")
        }
    )
    fields = _class_fields(package / "analysis" / "case.py", "CaseAnalysis")
    mode_fields = [f for f, _ in fields if f.startswith(MODE_PREFIXES) or f in MODE_FIELDS]
    mode_record = _class_fields(package / "modes" / "registry.py", "Mode")
    lambdas = sum(
        isinstance(node, ast.Lambda)
        for path in (package / "modes").glob("*.py")
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8")))
    )
    root_modules = sorted(p.name for p in package.glob("*.py") if p.name != "__init__.py")

    def edges(src: str, dst: str) -> int:
        return sum(
            _within(a, f"sumo_ayss.{src}") and _within(b, f"sumo_ayss.{dst}") for a, b in top | lazy
        )

    return {
        "modules": len(modules),
        "circles, module-level incl. type-only": len(layers.circles(set(modules), top)),
        "circles, incl. function-level": len(layers.circles(set(modules), top | lazy)),
        "edges analysis -> run_folder": edges("analysis", "run_folder"),
        "edges analysis -> modes": edges("analysis", "modes"),
        "edges config -> modes": edges("config", "modes"),
        "edges run_folder -> analysis": edges("run_folder", "analysis"),
        "report imports from pipeline/rank/crossplay/grid (modules)": len(report_edges),
        "report imports from scripts": len(layers.script_report_imports(root / "scripts")),
        "run_folder lines": sum(run_folder.values()),
        "run_folder exported names": len(_all_names(package / "run_folder" / "__init__.py")),
        "run_folder names imported by the rest of the package": len(
            _names_used_from(package, "sumo_ayss.run_folder")
        ),
        "package root modules": " ".join(root_modules),
        "train.py lines": lines.get("sumo_ayss.train", 0),
        "CaseAnalysis fields": len(fields),
        "CaseAnalysis mode-specific fields": len(mode_fields),
        "Mode record callable fields": sum("Callable" in a for _, a in mode_record),
        "lambdas in modes/": lambdas,
        "private names imported across modules": len(layers.private_imports(modules))
        if hasattr(layers, "private_imports")
        else "n/a",
        "modules over 500 lines": sum(v > layers.MAX_MODULE_LINES for v in lines.values()),
    }


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ref", default=None, help="measure this commit instead")
    args = parser.parse_args(argv)
    if args.ref is None:
        result = measure(ROOT)
    else:
        with tempfile.TemporaryDirectory() as tmp:
            archive = subprocess.run(
                ["git", "-C", str(ROOT), "archive", args.ref, "sumo_ayss", "scripts"],
                check=True,
                capture_output=True,
            ).stdout
            tar_path = Path(tmp) / "tree.tar"
            tar_path.write_bytes(archive)
            with tarfile.open(tar_path) as tar:
                tar.extractall(tmp, filter="data")
            result = measure(Path(tmp))
    for key, value in result.items():
        print(f"{key}: {value}")


if __name__ == "__main__":
    main()
