"""Compose and compile every permutation of a scene, in batches (what `build` and `costs` share)."""
from __future__ import annotations

from typing import TYPE_CHECKING

from ..io import show_progress
from ..lang import SourceError
from ..library.bricks import Library
from ..scene.load import Scene
from ..backends import LANGUAGES
from . import CompileJob, CompileResult, compile_many

if TYPE_CHECKING:
    from ..compose import Composed


def job_key(h: str, stage: str, lang: str) -> str:
    return f"{h}.{stage}.{lang}"


def source_jobs(name: str, sources) -> list[CompileJob]:
    """One compile job per composed source of unit `name` (a permutation hash, "ubershader")."""
    return [CompileJob(job_key(name, s.stage, s.language), s.language, s.stage, s.text, line_map=tuple(s.line_map))
            for s in sources]


CHUNK = 64  # permutations composed per compile batch when pipelining


def compile_scene(scene: Scene, lib: Library, languages=LANGUAGES, store=None, stats=None, extra=(), workers=None,
                  executor=None, on_done=None, dialects=()
                  ) -> tuple[dict[str, Composed], dict[str, list[str]], dict[str, CompileResult]]:
    """Compose and compile every permutation: (composed by hash, compose errors by hash, results by job key).

    store, stats: as compile_many takes them (the content-addressed cache; what the compile did).
    extra: more CompileJobs for the same batch (the ubershader: its large shaders start with the others
    instead of after them).
    on_done([(hash, Composed)], results): pipelined. Permutations are composed CHUNK at a time and each chunk is
    compiled on a thread of its own as soon as it is composed, while this thread composes the next one;
    on_done is called here, in chunk order, for every compiled chunk (as soon as it is, between composing
    later ones), so that writing and analysing overlap the compilers too. Shaders identical across chunks
    are compiled once (an in-memory record beside the store).
    dialects: platform dialects composed beside the languages (Composed.dialects; not compiled here).
    """
    from collections import deque
    from concurrent.futures import ThreadPoolExecutor

    from ..compose import compose_permutation  # Jinja and the emitters load only when something is composed
    composed: dict[str, Composed] = {}
    errors: dict[str, list[str]] = {}
    results: dict[str, CompileResult] = {}
    items = sorted(scene.permutations.items())
    size = CHUNK if on_done is not None else max(1, len(items))
    chunks = [items[k:k + size] for k in range(0, len(items), size)] or [[]]
    memo: dict = {}
    waiting: deque = deque()  # (hashes, future) in chunk order: one compile thread, so they finish in order

    def deliver(block: bool) -> None:
        while waiting and (block or waiting[0][1].done()):
            hashes, future = waiting.popleft()
            part = future.result()  # a compile error is raised here, on the caller's thread
            results.update(part)
            if on_done is not None:
                on_done([(h, composed[h]) for h in hashes], part)

    with ThreadPoolExecutor(max_workers=1, thread_name_prefix="compile") as pool:
        for k, chunk in enumerate(chunks):
            jobs: list[CompileJob] = list(extra) if k == 0 else []
            hashes = []
            for h, perm in chunk:
                try:
                    c = compose_permutation(perm, lib, languages, dialects)
                except SourceError as e:
                    errors[h] = [str(e)]
                    continue
                composed[h] = c
                hashes.append(h)
                jobs += source_jobs(h, c.sources)
            waiting.append((hashes, pool.submit(compile_many, jobs, optimize=True, validate=True,
                                                progress=show_progress(), store=store, stats=stats, workers=workers,
                                                executor=executor, memo=memo)))
            deliver(block=False)
        deliver(block=True)
    return composed, errors, results
