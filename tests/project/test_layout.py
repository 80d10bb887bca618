"""The layout shows the pipeline: one package per stage, and no import runs backwards against it."""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

GENERATOR = Path(__file__).resolve().parents[2] / "generator"

# The stages in data-flow order (docs/design/ describes them). reference/ and runtime/ come before eval/,
# which evaluates on them, and before measure/, whose cost tables also read RADV's compiler statistics
# (runtime/gpu_stats.py); io.py is the utility layer right after the language.
ORDER = ["lang", "io", "library", "spec", "scene", "link", "backends", "compose", "toolchain", "analysis",
         "reference", "runtime", "measure", "eval", "assemble", "cli"]


def _stage(module: str) -> str | None:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 and parts[0] == "generator" else None


def _imports(path: Path) -> list[tuple[int, str]]:
    """(line, absolute generator module) of every import in a file, lazy ones included."""
    pkg = list(path.relative_to(GENERATOR.parent).parts[:-1])  # the package a relative import starts from
    out = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = pkg[: len(pkg) - node.level + 1]
                mod = ".".join(base + ([node.module] if node.module else []))
                names = [mod + "." + a.name for a in node.names] if not node.module else [mod]
            else:
                names = [node.module]
            out += [(node.lineno, n) for n in names]
        elif isinstance(node, ast.Import):
            out += [(node.lineno, a.name) for a in node.names]
    return [(line, m) for line, m in out if m.startswith("generator")]


def test_every_stage_is_a_package_in_generator():
    found = {p.name for p in GENERATOR.iterdir() if p.is_dir() and (p / "__init__.py").exists()}
    found |= {p.stem for p in GENERATOR.glob("*.py") if p.stem != "__init__"}
    assert found == set(ORDER), f"generator/ holds {sorted(found)}; the pipeline is {ORDER}"


@pytest.mark.parametrize("path", sorted(GENERATOR.rglob("*.py")), ids=lambda p: str(p.relative_to(GENERATOR)))
def test_no_import_runs_backwards(path):
    parts = path.relative_to(GENERATOR.parent).with_suffix("").parts
    here = _stage(".".join(p for p in parts if p != "__init__"))
    if here is None:  # generator/__init__.py: the package facade
        return
    for line, mod in _imports(path):
        there = _stage(mod)
        if there is None or there not in ORDER:
            continue  # the package root (version, target names) is below every stage
        assert ORDER.index(there) <= ORDER.index(here), (
            f"{path.relative_to(GENERATOR.parent)}:{line}: {here}/ imports {mod}, a later stage — "
            f"move the shared code to the earlier stage")
