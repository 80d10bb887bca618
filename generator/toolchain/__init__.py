"""Compilers and validators: a shading language's source -> validated SPIR-V.

One call, :func:`compile_many`, takes any number of :class:`CompileJob` and
returns one :class:`CompileResult` per job key. Every failing job carries at
least one error :class:`Diagnostic`; no job fails silently.

Pipeline per job (all SPIR-V is version 1.3, validated for ``vulkan1.1``):

1. front end: the one the job's back end declares (generator.backends.FrontEnd on its Language), run by its
   driver (frontends.py) — the toolchain has no branch on a language's name:
   - ``glslc`` (GLSL, HLSL): ``glslc --target-env=vulkan1.1 -c`` over a *batch* of files in one process,
     with a sentinel file after each job when the batch printed anything, so that each message goes to its
     job; a GLSL sentinel costs ~1 ms.
   - ``naga`` (WGSL): ``naga --spirv-version 1.3 --keep-coordinate-space in.wgsl out.spv`` (no y flip:
     the same matrices place vertices alike in every language), one process per file; about 2 ms each.
2. with ``optimize``: ``spirv-opt -O`` and ``spirv-val`` on the result; without: ``spirv-val`` on the front
   end's output (spirv.py).

Batches and per-file steps run on a thread pool of ``os.cpu_count()``
workers; glslc jobs are dealt into one batch per worker (at least
8 and at most 256 jobs per batch).

Measured on the 2-core development machine (Debian glslc 2023.2, 50 small
Blinn-Phong fragment shaders, best of 3, wall clock)::

    step                                        GLSL      HLSL      WGSL
    one glslc process per shader (sequential)   5.4 s     1.3 s      -
      = per shader (process start-up dominates) ~110 ms   ~27 ms     -
    one glslc process for all 50                0.16 s    0.12 s     -
      the same with a sentinel after each job   0.20 s    0.14 s     -
    compile_many, front end only                0.14 s    0.11 s    0.08 s (naga x50)
    compile_many, + spirv-val, spirv-opt -O,    0.38 s    0.30 s    0.31 s
      spirv-val (3 processes per shader)

Batching makes the GLSL front end ~35x and the HLSL one ~10x faster; after
it, the three per-shader SPIR-V steps (~2-3 ms each) dominate.

The modules: model.py (jobs, results, diagnostics), run.py (finding and running tools, the Gate a build stops),
diagnostics.py (the tools' messages, located), frontends.py, spirv.py, cache.py (cache keys, stored results);
jobs.py names a composed unit's jobs, platforms.py runs the platforms' own tools, dask.py a cluster's workers.
"""
from __future__ import annotations

import os
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor, as_completed
from dataclasses import dataclass, field
from typing import Iterable

from .cache import COMPILE_NAMESPACE, apportion, cache_key, decode, encode, renamed
from .frontends import DRIVERS, check, front_end
from .locate import TOOLS_ENV, pinned_versions, tool_dirs
from .model import SPIRV_MAGIC, SPIRV_VERSION, STAGES, TARGET_ENV, CompileJob, CompileResult, Diagnostic
from .run import Gate, ToolMissing, ToolsStopped, find_tool, need, tool_versions, version_of
from .spirv import spirv_steps

__all__ = ["Diagnostic", "CompileJob", "CompileResult", "CompileStats", "ToolMissing", "ToolsStopped", "Gate",
           "compile_many", "cache_key", "tool_versions", "version_of", "find_tool", "tool_dirs", "pinned_versions",
           "TOOLS_ENV", "TARGET_ENV", "SPIRV_VERSION", "SPIRV_MAGIC", "COMPILE_NAMESPACE"]


@dataclass
class CompileStats:
    """What a compile_many call did: jobs, distinct shaders, served by the store, compiled."""

    jobs: int = 0
    distinct: int = 0
    cached: int = 0
    compiled: int = 0
    fresh: set = field(default_factory=set)  # the cache keys compiled (not served by the store or the memo)


def compile_many(jobs: Iterable[CompileJob], *, optimize: bool = True, validate: bool = True,
                 progress: bool = False, store=None, stats: CompileStats | None = None,
                 workers: int | None = None, executor=None, memo: dict | None = None,
                 gate: Gate | None = None) -> dict[str, CompileResult]:
    """Compile and validate every job; returns {key: CompileResult} in input order.

    Jobs with the same :func:`cache_key` are compiled once (identical shaders, e.g. vertex shaders whose
    sources differ only in their provenance header). store: an io.Store; a job whose key is there is
    served from it (no tool runs) and every successful compile is put there, with its compile time (cache.py:
    a batch's time apportioned over its shaders; CompileResult.seconds, the stored time when served from
    there). Failures are not stored (their diagnostics name each job's own lines), and a job whose twin failed
    is compiled on its own.
    memo: a dict (cache key -> result) shared by several calls of one build: a shader another call
    compiled is not compiled again (and not counted distinct again).
    stats: a CompileStats to fill in. workers: how many tool processes run at once (default: the core
    count). executor: where the compiles run instead of here (toolchain/dask.py: a Dask cluster); the
    store, deduplication and results are the same wherever they ran. gate: the build's (run.Gate): its
    stop() kills this call's tools and makes it raise ToolsStopped; None: a gate of this call alone.

    Raises ToolMissing if a tool the jobs need is absent, ValueError on a
    malformed job (duplicate key, unknown language or stage).
    """
    jobs = list(jobs)
    seen: set[str] = set()
    for job in jobs:
        if job.key in seen:
            raise ValueError(f"duplicate compile job key {job.key!r}")
        if job.stage not in STAGES:
            raise ValueError(f"{job.key}: unknown language/stage {job.language!r}/{job.stage!r}")
        check(job)
        seen.add(job.key)
    stats = stats if stats is not None else CompileStats()
    stats.jobs += len(jobs)
    if not jobs:
        return {}
    keys = {job.key: cache_key(job, optimize, validate) for job in jobs}
    groups: dict[str, list[CompileJob]] = {}
    for job in jobs:
        groups.setdefault(keys[job.key], []).append(job)
    results: dict[str, CompileResult] = {}
    todo = []
    for ck, members in groups.items():
        if memo is not None and ck in memo:  # compiled by an earlier call of this build
            for job in members:
                results[job.key] = renamed(memo[ck], job.key)
            continue
        stats.distinct += 1
        data = store.get(COMPILE_NAMESPACE, ck) if store is not None else None
        hit = decode(data, members[0].key) if data is not None else None
        if hit is not None:
            stats.cached += 1
            if memo is not None:
                memo[ck] = hit
            for job in members:
                results[job.key] = renamed(hit, job.key)
        else:
            todo.append(members[0])
    gate = gate if gate is not None else Gate()

    def run(batch: list[CompileJob]) -> dict[str, CompileResult]:
        if executor is not None:
            return executor.compile(batch, optimize, validate, progress, workers)
        return compile_all(batch, optimize, validate, progress, workers, gate=gate)

    fresh = run(todo)
    stats.compiled += len(todo)
    stats.fresh.update(keys[job.key] for job in todo)
    again = []
    for first in todo:
        r = fresh[first.key]
        members = groups[keys[first.key]]
        if r.ok:
            if store is not None:
                store.put(COMPILE_NAMESPACE, keys[first.key], encode(r))
            if memo is not None:
                memo[keys[first.key]] = r
            for job in members:
                results[job.key] = renamed(r, job.key)
        else:
            results[first.key] = r
            again += members[1:]
    if again:  # a failed shader's twins: each reports its own lines
        stats.compiled += len(again)
        results.update(run(again))
    for job in jobs:
        results[job.key].cache_key = keys[job.key]
    return {job.key: results[job.key] for job in jobs}


def _timed(step, *args, front_s: float | None = None):
    """(wall seconds, step(*args)); with front_s (a shader's share of its front end), the result is a
    CompileResult and its seconds are set to that share plus this step's own time."""
    started = time.perf_counter()
    value = step(*args)
    seconds = time.perf_counter() - started
    if front_s is not None:
        value.seconds = front_s + seconds
    return seconds, value


def compile_all(jobs: list[CompileJob], optimize: bool, validate: bool, progress: bool,
                workers: int | None = None, gate: Gate | None = None) -> dict[str, CompileResult]:
    """Run the tools on every job (no store, no deduplication), `workers` tool processes at a time, each
    front end's jobs in the batches its driver takes."""
    if not jobs:
        return {}
    gate = gate if gate is not None else Gate()
    by_driver: dict[str, list[tuple[int, CompileJob]]] = {}
    for i, job in enumerate(jobs):
        by_driver.setdefault(front_end(job).tool, []).append((i, job))
    used = [name for name in DRIVERS if name in by_driver]  # a missing tool is reported in the drivers' order
    tools = {name: need(DRIVERS[name].tool) for name in used}
    if validate:
        tools["spirv-val"] = need("spirv-val")
    if optimize:
        tools["spirv-opt"] = need("spirv-opt")

    from tqdm import tqdm

    workers = max(1, workers or os.cpu_count() or 1)
    index = {job.key: i for i, job in enumerate(jobs)}
    results: dict[str, CompileResult] = {}
    with tempfile.TemporaryDirectory(prefix=f"shadermatrix-{os.getpid()}-") as tmp, \
            ThreadPoolExecutor(max_workers=workers) as pool, \
            tqdm(total=len(jobs), disable=not progress, unit="shader", leave=False) as bar:
        front = [pool.submit(_timed, DRIVERS[name].batch, tools[name], tmp, part, gate)
                 for name in used for part in DRIVERS[name].parts(by_driver[name], workers)]
        back = []
        for fut in as_completed(front):
            seconds, done = fut.result()
            share = apportion(seconds, [job for job, _, _ in done])  # the batch's time, over its shaders
            for job, spv, diags in done:
                if spv is None:
                    results[job.key] = CompileResult(job.key, False, None, None, diags, share[job.key])
                    bar.update()
                else:
                    back.append(pool.submit(_timed, spirv_steps, tools, tmp, index[job.key], job, spv,
                                            diags, optimize, validate, gate, front_s=share[job.key]))
        for fut in as_completed(back):
            seconds, res = fut.result()
            results[res.key] = res
            bar.update()
    return {job.key: results[job.key] for job in jobs}
