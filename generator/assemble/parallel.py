"""Compose, compile and analyse a scene's permutations in worker processes (`build -j N`, N > 1).

The building process composes, compiles and analyses nothing itself: each task is one chunk of
permutations, composed, compiled (through this build's content-addressed store, `workers=1` tool process
per worker) and its SPIR-V analysed in a worker process; the building process writes the results, in
chunk order, as they come back. So N processes do the Python work that one did before, and a build is
no longer limited by the building process (benchmarks/results/build.md).

The workers (assemble/workers.py: a pool the build can end at once, on Ctrl-C, SIGTERM or a dead worker) are
started by a forkserver (never a fork of this process, which has threads), with this process's environment,
and receive the Library pickled: every worker composes from exactly the bricks
this build parsed, not from files that may have changed since. Results are pure functions of their
inputs, so the output is byte-identical for any N (tested), and the build's counts are the same: a
shader is counted distinct, cached or compiled where it first appears in chunk order.
"""
from __future__ import annotations

import os
import pickle
import shutil
import sys
import tempfile

from ..io import Store, sha256, show_progress
from ..lang import SourceError
from ..lang.errors import EnvironmentMissing, UserError
from ..library import bricks as _bricks
from ..toolchain import CompileStats, cache_key, compile_many
from ..toolchain.scenes import source_jobs
from .workers import Workers

MIN_PERMUTATIONS = 64  # below this, starting worker processes costs more than it saves (measured: ~1.4 s at 36)
# multiprocessing's resource tracker warns of "leaked semaphore objects" when a build is interrupted (the progress
# bar's lock), which it then removes itself. Noise to whoever pressed Ctrl-C: its process starts with this filter.
_QUIET_TRACKER = "ignore::UserWarning:multiprocessing.resource_tracker"
_PRELOAD = ["generator.assemble.parallel", "generator.compose", "generator.analysis", "jinja2"]
_WORKER: dict = {}  # this worker's library, store and languages (set by _start)


def chunk_size(permutations: int, workers: int) -> int:
    """Permutations per task: about 8 tasks per worker (an even finish), 4 to 64 each."""
    return max(4, min(64, -(-permutations // (workers * 8))))


def _start(lib_bytes: bytes, env: dict, store_root: str | None, languages: tuple, dialects: tuple = ()) -> None:
    os.environ.clear()
    os.environ.update(env)
    lib = pickle.loads(lib_bytes)
    lib.memo, lib.serial = {}, next(_bricks._SERIALS)  # this process's own caches
    _WORKER.update(lib=lib, store=Store(store_root) if store_root else None, languages=languages,
                   dialects=dialects)


def _task(items: list, extra: list) -> tuple:
    """One chunk, in a worker: (composed, compose errors, results, costs by SPIR-V sha256, cache key by job
    key, cache keys compiled here, templates read) — every value picklable."""
    from ..analysis import cost_dict
    from ..compose import compose_permutation, loaded_templates

    lib, store, languages = _WORKER["lib"], _WORKER["store"], _WORKER["languages"]
    composed, errors, jobs = {}, {}, list(extra)
    try:
        for h, perm in items:
            try:
                c = composed[h] = compose_permutation(perm, lib, languages, _WORKER["dialects"])
            except SourceError as e:
                errors[h] = [str(e)]
                continue
            jobs += source_jobs(h, c.sources)
        stats = CompileStats()
        results = compile_many(jobs, optimize=True, validate=True, store=store, stats=stats, workers=1)
        costs = {}
        for r in results.values():
            if r.ok and r.spirv:
                digest = sha256(r.spirv)
                if digest not in costs:
                    costs[digest] = cost_dict(r.spirv, store)
    except UserError as e:  # a missing tool (exit 3) or another error: its class and message, as they pickle
        raise (EnvironmentMissing if isinstance(e, EnvironmentMissing) else UserError)(str(e)) from None
    keys = {j.key: cache_key(j, True, True) for j in jobs}
    return composed, errors, results, costs, keys, stats.fresh, loaded_templates()


def compile_scene_parallel(scene, lib, languages, store=None, stats=None, extra=(), workers: int = 2,
                           on_done=None, costs: dict | None = None, templates: set | None = None, dialects=()):
    """toolchain.scenes.compile_scene's contract, in `workers` processes; also fills `costs` (SPIR-V sha256 ->
    cost dict, for the writer) and `templates` (the template files the workers read)."""
    from tqdm import tqdm

    stats = stats if stats is not None else CompileStats()
    costs = costs if costs is not None else {}
    templates = templates if templates is not None else set()
    items = sorted(scene.permutations.items())
    size = chunk_size(len(items), workers)
    chunks = [items[k:k + size] for k in range(0, len(items), size)]
    composed, errors, results = {}, {}, {}
    seen: set[str] = set()  # the cache keys of every job
    fresh: set[str] = set()  # those some worker compiled (the others came from the cache)

    def take(value) -> dict:
        c, errs, part, cost, keys, compiled, read = value
        composed.update(c)
        errors.update(errs)
        results.update(part)
        costs.update(cost)
        templates.update(read)
        stats.jobs += len(keys)
        seen.update(keys.values())
        fresh.update(compiled)
        return part

    # without a cache (--no-cache), the workers share a private one for this build alone, so that a shader is
    # compiled once whichever chunks have it (the in-process build's memo); named like the toolchain's temp dirs, a
    # killed build's is removed by the next
    private = None if store is not None else tempfile.mkdtemp(prefix=f"shadermatrix-{os.getpid()}-build-")
    lib_bytes = pickle.dumps(type(lib)(bricks=lib.bricks, errors=lib.errors))  # no memo: workers link their own
    if _QUIET_TRACKER not in sys.warnoptions:  # read when multiprocessing starts its resource tracker
        sys.warnoptions.append(_QUIET_TRACKER)
    init = (lib_bytes, dict(os.environ), str(store.root) if store else private, tuple(languages), tuple(dialects))
    # the ubershader's large shaders first, one task each: they spread over the workers
    tasks = [([], [job]) for job in extra] + [(chunk, []) for chunk in chunks]
    done: dict[int, tuple] = {}  # chunks back before an earlier one: written when it is
    following = 0  # the next chunk to write
    try:
        with Workers(workers, _start, init, _task, _PRELOAD) as pool, \
                tqdm(total=len(items), disable=not show_progress(), unit="permutation", leave=False) as bar:
            for k, value in pool.unordered(tasks):
                if k < len(extra):
                    take(value)
                    continue
                done[k - len(extra)] = value
                while following in done:  # written in chunk order, each as soon as it and those before are back
                    part = take(done.pop(following))
                    chunk = chunks[following]
                    if on_done is not None:
                        on_done([(h, composed[h]) for h, _ in chunk if h in composed], part)
                    bar.update(len(chunk))
                    following += 1
    finally:
        if private is not None:
            shutil.rmtree(private, ignore_errors=True)
    # counted once per distinct shader, whichever worker got it first: the same counts for any N and any timing
    # (when every shader compiles: in-process, a failing one is compiled, and counted, again per chunk)
    stats.distinct += len(seen)
    stats.compiled += len(seen & fresh)
    stats.cached += len(seen - fresh)
    return composed, errors, results
