"""Compose, compile and analyse a scene's permutations in worker processes (`build -j N`, N > 1).

The building process composes, compiles and analyses nothing itself: each task is one chunk of
permutations, composed, compiled (through this build's content-addressed store, `workers=1` tool process
per worker) and its SPIR-V analysed in a worker process; the building process writes the results, in
chunk order, as they come back. So N processes do the Python work that one did before, and a build is
no longer limited by the building process (benchmarks/results/build.md).

The workers (assemble/workers.py: a pool the build can end at once, on Ctrl-C, SIGTERM or a dead worker) are
started by a forkserver (never a fork of this process, which has threads), with this process's environment,
and receive the build's context pickled (BuildContext.for_workers, the Library in it): every worker composes
from exactly the bricks this build parsed, not from files that may have changed since. Results are pure functions of their
inputs, so the output is byte-identical for any N (tested), and the build's counts are the same: a
shader is counted distinct, cached or compiled where it first appears in chunk order.
"""
from __future__ import annotations

import os
import pickle
import shutil
import tempfile
import threading
from dataclasses import replace

from ..io import Store, sha256
from ..lang.errors import EnvironmentMissing, UserError
from ..toolchain import CompileStats, cache_key, compile_many
from .context import BuildContext
from .loop import Compiled, compose_chunk
from .workers import Workers

_PRELOAD = ["generator.assemble.parallel", "generator.compose", "generator.analysis", "jinja2"]
_CONTEXT: list[BuildContext] = []  # in a worker: the build's context (set once, by _start)


def chunk_size(permutations: int, workers: int) -> int:
    """Permutations per task: about 8 tasks per worker (an even finish), 4 to 64 each."""
    return max(4, min(64, -(-permutations // (workers * 8))))


def _start(ctx_bytes: bytes, env: dict, store_root: str | None) -> None:
    os.environ.clear()
    os.environ.update(env)  # the build's (PATH and the settings its tools read), not the forkserver's
    # A worker's progress bars never draw (BuildContext.for_workers), so their lock is a thread's: tqdm's default, a
    # multiprocessing lock, is here (the forkserver's start method) a named semaphore registered with the build's
    # resource tracker, which a worker killed by an interrupt leaves behind, and the tracker then warns of it
    # after the build's one line.
    from tqdm import tqdm
    tqdm.set_lock(threading.RLock())
    ctx = pickle.loads(ctx_bytes)
    lib = type(ctx.library)(bricks=ctx.library.bricks, errors=ctx.library.errors)  # this process's own caches
    _CONTEXT.append(replace(ctx, library=lib, store=Store(store_root) if store_root else None))


def _task(items: list, extra: list) -> tuple:
    """One chunk, in a worker: (composed, compose errors, results, costs by SPIR-V sha256, cache key by job
    key, cache keys compiled here) — every value picklable."""
    from ..analysis import cost_dict

    ctx = _CONTEXT[0]
    try:
        composed, errors, jobs = compose_chunk(ctx, items)
        jobs = list(extra) + jobs
        stats = CompileStats()
        results = compile_many(jobs, optimize=True, validate=True, store=ctx.store, stats=stats, workers=1)
        costs = {}
        for r in results.values():
            if r.ok and r.spirv:
                digest = sha256(r.spirv)
                if digest not in costs:
                    costs[digest] = cost_dict(r.spirv, ctx.store)
    except UserError as e:  # a missing tool (exit 3) or another error: its class and message, as they pickle
        raise (EnvironmentMissing if isinstance(e, EnvironmentMissing) else UserError)(str(e)) from None
    keys = {j.key: cache_key(j, True, True) for j in jobs}
    return composed, errors, results, costs, keys, stats.fresh


def compile_in_workers(ctx: BuildContext, items: list, extra: list, on_done, stats: CompileStats, workers: int,
                       out: Compiled) -> None:
    """loop.compile_permutations in `workers` processes (items: sorted (hash, Permutation) pairs), into `out`."""
    from tqdm import tqdm

    size = chunk_size(len(items), workers)
    chunks = [items[k:k + size] for k in range(0, len(items), size)]
    seen: set[str] = set()  # the cache keys of every job
    fresh: set[str] = set()  # those some worker compiled (the others came from the cache)

    def take(value) -> dict:
        composed, errors, part, costs, keys, compiled = value
        out.add(composed, errors)
        out.results.update(part)
        out.costs.update(costs)
        stats.jobs += len(keys)
        seen.update(keys.values())
        fresh.update(compiled)
        return part

    # without a cache (--no-cache), the workers share a private one for this build alone, so that a shader is
    # compiled once whichever chunks have it (the in-process build's memo); named like the toolchain's temp dirs, a
    # killed build's is removed by the next
    private = None if ctx.store is not None else tempfile.mkdtemp(prefix=f"shadermatrix-{os.getpid()}-build-")
    init = (pickle.dumps(ctx.for_workers()), dict(os.environ), str(ctx.store.root) if ctx.store else private)
    # the ubershader's large shaders first, one task each: they spread over the workers
    tasks = [([], [job]) for job in extra] + [(chunk, []) for chunk in chunks]
    done: dict[int, tuple] = {}  # chunks back before an earlier one: written when it is
    following = 0  # the next chunk to write
    try:
        with Workers(workers, _start, init, _task, _PRELOAD) as pool, \
                tqdm(total=len(items), disable=not ctx.progress, unit="permutation", leave=False) as bar:
            for k, value in pool.unordered(tasks):
                if k < len(extra):
                    take(value)
                    continue
                done[k - len(extra)] = value
                while following in done:  # written in chunk order, each as soon as it and those before are back
                    part = take(done.pop(following))
                    chunk = chunks[following]
                    if on_done is not None:
                        on_done([(h, out.composed[h]) for h, _ in chunk if h in out.composed], part)
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
