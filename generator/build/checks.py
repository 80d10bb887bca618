"""Per-permutation compile checks an engine's CI runs: `shadermatrix check` and the pytest plugin share them.

A check is one permutation of a scene in one language: composed, compiled to
SPIR-V, validated (spirv-val) and optimized, through the compile cache. A
failure reads as the brick line that caused it (the compilers' diagnostics are
mapped back through #line). Golden sources: `<golden>/<language>/<hash>.<stage>.<language>`,
the emitted source of each permutation (named by permutation, not by content,
so a drift is a diff of one file).
"""
from __future__ import annotations

import difflib
from dataclasses import dataclass
from pathlib import Path

from ..library.bricks import Library
from ..matrix.scene import Scene
from ..targets import LANGUAGES


@dataclass(frozen=True)
class Check:
    """One permutation × language of a scene."""

    hash: str
    language: str
    objects: tuple[str, ...]

    @property
    def id(self) -> str:
        return f"{self.hash}-{self.language}"


def checks(scene: Scene, languages=LANGUAGES) -> list[Check]:
    return [Check(h, lang, tuple(scene.users.get(h, ()))) for h in sorted(scene.permutations) for lang in languages]


def run_checks(scene: Scene, lib: Library, todo: list[Check], store=None) -> list[tuple[list[str], dict[str, str]]]:
    """Per check, (errors, {golden-relative path: emitted source}); no errors when it compiles and validates.

    Every check's shaders are compiled in one batch (the tool processes run in parallel, identical shaders
    once), as `build` does, then the results are split per check."""
    from ..compose import compose_permutation
    from ..lang import SourceError
    from ..toolchain import compile_many
    from ..toolchain.scenes import source_jobs

    composed: dict[Check, object] = {}
    failed: dict[Check, list[str]] = {}
    jobs = []
    for c in todo:
        try:
            composed[c] = compose_permutation(scene.permutations[c.hash], lib, (c.language,))
        except SourceError as e:
            failed[c] = [str(e)]
            continue
        jobs += source_jobs(c.hash, composed[c].sources)
    results = compile_many(jobs, optimize=True, validate=True, store=store) if jobs else {}
    out = []
    for c in todo:
        if c in failed:
            out.append((failed[c], {}))
            continue
        mine = [results[j.key] for j in source_jobs(c.hash, composed[c].sources)]
        out.append(([line for r in mine if not r.ok for line in r.errors()],
                    {f"{s.language}/{c.hash}.{s.stage}.{s.language}": s.text for s in composed[c].sources}))
    return out


def run_check(scene: Scene, lib: Library, check: Check, store=None) -> tuple[list[str], dict[str, str]]:
    """(errors, sources) of one check (the pytest plugin runs one per test item)."""
    return run_checks(scene, lib, [check], store)[0]


def golden_diff(golden: Path, sources: dict[str, str]) -> list[str]:
    """Unified diffs of emitted sources against `golden` (a missing golden file is a diff from nothing)."""
    out = []
    for rel, text in sorted(sources.items()):
        path = golden / rel
        old = path.read_text(encoding="utf-8") if path.is_file() else ""
        if old != text:
            out += difflib.unified_diff(old.splitlines(keepends=True), text.splitlines(keepends=True),
                                        f"golden/{rel}", f"emitted/{rel}")
    return out


def stale_golden(golden: Path, languages, emitted: set[str]) -> list[str]:
    """Golden files (relative paths) under the checked languages that no check emitted: permutations gone."""
    out = []
    for lang in languages:
        d = golden / lang
        if d.is_dir():
            out += sorted(f"{lang}/{p.name}" for p in d.iterdir() if p.is_file() and f"{lang}/{p.name}" not in emitted)
    return out


def default_store(cache_dir=None):
    from ..io import Store, default_cache_dir
    root = cache_dir or default_cache_dir()
    return Store(root) if root else None
