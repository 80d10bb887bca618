"""Compose and compile every permutation of a scene, in batches (what `build` and `costs` share)."""
from __future__ import annotations

from typing import TYPE_CHECKING

from ..io import show_progress
from ..lang import SourceError
from ..library.bricks import Library
from ..matrix.scene import Scene
from ..targets import LANGUAGES
from . import CompileJob, CompileResult, compile_many

if TYPE_CHECKING:
    from ..compose import Composed


def job_key(h: str, stage: str, lang: str) -> str:
    return f"{h}.{stage}.{lang}"


def compile_scene(scene: Scene, lib: Library, languages=LANGUAGES, store=None, stats=None, extra=(), workers=None,
                  executor=None
                  ) -> tuple[dict[str, Composed], dict[str, list[str]], dict[str, CompileResult]]:
    """Compose and compile every permutation: (composed by hash, compose errors by hash, results by job key).

    store, stats: as compile_many takes them (the content-addressed cache; what the compile did).
    extra: more CompileJobs for the same batch (the ubershader: its large shaders start with the others
    instead of after them)."""
    from ..compose import compose_permutation  # Jinja and the emitters load only when something is composed
    composed: dict[str, Composed] = {}
    errors: dict[str, list[str]] = {}
    jobs: list[CompileJob] = list(extra)
    for h, perm in sorted(scene.permutations.items()):
        try:
            c = compose_permutation(perm, lib, languages)
        except SourceError as e:
            errors[h] = [str(e)]
            continue
        composed[h] = c
        for src in c.sources:
            jobs.append(CompileJob(job_key(h, src.stage, src.language), src.language, src.stage, src.text,
                                   line_map=tuple(src.line_map)))
    results = compile_many(jobs, optimize=True, validate=True, progress=show_progress(), store=store, stats=stats,
                           workers=workers, executor=executor)
    return composed, errors, results
