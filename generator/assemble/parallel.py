"""Compose, compile and analyse a scene's permutations in worker processes (`build -j N`, N > 1), or on a Dask
cluster (`--executor dask://`, cluster.py): the same tasks either way.

The building process composes, compiles and analyses nothing itself: each task is one chunk of permutations,
composed, compiled (through this build's content-addressed store, `workers=1` tool process per worker),
its SPIR-V analysed and its manifest entries and files made (entries.py: the platform dialects validated, the
uploads packed) in a worker (run_chunk); one more task composes and compiles the ubershader. The building
process writes what comes back, in chunk order, as it comes back. So N processes do the Python work that one
did before, and a build is no longer limited by the building process (benchmarks/results/dask.md measures what
is left there).

The local workers (assemble/workers.py: a pool the build can end at once, on Ctrl-C, SIGTERM or a dead worker)
are started by a forkserver (never a fork of this process, which has threads), with this process's
environment, and receive the build's context and the scene pickled once (pack: BuildContext.for_workers, the
Library in it, and entries.Entries): every worker composes from exactly the bricks this build parsed, not from
files that may have changed since. Results are pure functions of their inputs, so the output is byte-identical
for any N (tested), and the build's counts are the same: a shader is counted distinct, cached or compiled
where it first appears in chunk order.
"""
from __future__ import annotations

import gc
import os
import pickle
import shutil
import tempfile
import threading
from dataclasses import dataclass, field, replace

from ..io import Store
from ..lang.errors import EnvironmentMissing, UserError
from ..link.values import LIGHT_BUFFER
from ..toolchain import CompileStats, compile_many
from .context import BuildContext
from .entries import Entries, compose_ubershader
from .loop import Compiled, compose_chunk
from .workers import Workers

_PRELOAD = ["generator.assemble.parallel", "generator.compose", "generator.analysis", "jinja2"]
_CONTEXT: list[tuple] = []  # in a worker: the build's (context, entries), set once by _start


def chunk_size(permutations: int, workers: int) -> int:
    """Permutations per task: about 8 tasks per worker (an even finish), 4 to 64 each."""
    return max(4, min(64, -(-permutations // (workers * 8))))


def _start(payload: bytes, env: dict, store_root: str | None) -> None:
    os.environ.clear()
    os.environ.update(env)  # the build's (PATH and the settings its tools read), not the forkserver's
    # A worker's progress bars never draw (BuildContext.for_workers), so their lock is a thread's: tqdm's default, a
    # multiprocessing lock, is here (the forkserver's start method) a named semaphore registered with the build's
    # resource tracker, which a worker killed by an interrupt leaves behind, and the tracker then warns of it
    # after the build's one line.
    from tqdm import tqdm
    tqdm.set_lock(threading.RLock())
    _CONTEXT.append(unpack(payload, Store(store_root) if store_root else None))


def pack(ctx: BuildContext, entries: Entries) -> bytes:
    """What every worker of a build is given once: its context and what makes the entries (the scene, the keys)."""
    return pickle.dumps((ctx.for_workers(), entries), protocol=pickle.HIGHEST_PROTOCOL)


def unpack(payload: bytes, store) -> tuple[BuildContext, Entries]:
    """A worker's (context, entries) from pack's bytes, with this process's own store and library caches."""
    ctx, entries = pickle.loads(payload)
    lib = type(ctx.library)(bricks=ctx.library.bricks, errors=ctx.library.errors)
    return replace(ctx, library=lib, store=store), entries


def _task(hashes: list | None, extra: list) -> Chunk:
    return run_chunk(*_CONTEXT[0], hashes, extra)


@dataclass
class Chunk:
    """What a task sends back (every value picklable): its permutations composed (what the tables read of them:
    _bare), their compose errors, the entries made (hash -> entries.Made), the compile results
    (without SPIR-V, which is in the entries' files; extra's whole, which the building process writes), the cache
    key of every job, the cache keys compiled here, the templates composed with and the ubershader's entry."""

    composed: dict
    errors: dict
    made: dict
    results: dict
    keys: dict
    fresh: set
    templates: set = field(default_factory=set)
    ubershader: object = None


def run_chunk(ctx: BuildContext, entries: Entries, hashes: list | None, extra: list, memo: dict | None = None) -> Chunk:
    """One task, wherever it runs (a worker process, a Dask worker): the permutations `hashes` composed, compiled
    (with the CompileJobs `extra`), analysed and their entries made (entries.py); hashes None: the ubershader."""
    if hashes is None:
        return _ubershader(ctx, entries, memo)
    try:
        composed, errors, jobs = compose_chunk(ctx, [(h, entries.scene.permutations[h]) for h in hashes])
        stats = CompileStats()
        results = compile_many(list(extra) + jobs, optimize=True, validate=True, store=ctx.store, stats=stats,
                               workers=1, memo=memo)
        made = entries.make(ctx, list(composed.items()), results, {}) if composed else {}
    except UserError as e:
        raise _portable(e) from None
    mine = {j.key for j in extra}
    templates = {t for c in composed.values() for t in c.templates}
    return Chunk({h: _bare(c) for h, c in composed.items()}, errors, made,
                 {k: r if k in mine else _slim(r) for k, r in results.items()},
                 {k: r.cache_key for k, r in results.items()}, stats.fresh, templates)


def _ubershader(ctx: BuildContext, entries: Entries, memo: dict | None) -> Chunk:
    """The ubershader composed, its shaders compiled (as many tools at once as it has shaders: they are the largest
    of the build) and its entry made."""
    from ..toolchain.jobs import source_jobs
    try:
        unit = compose_ubershader(entries.scene, ctx.library, ctx.languages)
        jobs = source_jobs("ubershader", unit[0].sources) if isinstance(unit, tuple) else []
        stats = CompileStats()
        results = compile_many(jobs, optimize=True, validate=True, store=ctx.store, stats=stats,
                               workers=max(1, min(len(jobs), os.cpu_count() or 1)), memo=memo)
        made = entries.ubershader(ctx, unit, results, {})
    except UserError as e:
        raise _portable(e) from None
    return Chunk({}, {}, {}, {k: _slim(r) for k, r in results.items()}, {k: r.cache_key for k, r in results.items()},
                 stats.fresh, set(unit[0].templates) if isinstance(unit, tuple) else set(), made)


def _bare(c):
    """A Composed as the building process reads it once its entry is made: its material slots, its interface's
    parameters (reflection.scene_tables) and its templates. The rest (the sources, the interface's blocks and
    textures, the light slots: the entry holds them) would be a third of what it unpickles per permutation. A
    permutation of a dynamic light set keeps its interface whole: reflection.dynamic_tables reads its light
    buffers' blocks and their bindings on every platform from it."""
    if any(b.name.startswith(LIGHT_BUFFER) for b in c.interface.blocks):
        return replace(c, sources=[], dialects=[], lights=[])
    iface = replace(c.interface, stage_entries={}, shading_inputs=[], surface=[], blocks=[], textures=[], outputs=[])
    return replace(c, sources=[], dialects=[], lights=[], interface=iface)


def _slim(r):
    return replace(r, spirv=None, spirv_unopt=None, diagnostics=[])


def _portable(e: UserError) -> UserError:
    """A missing tool (exit 3) or another error: its class and message, as they pickle."""
    return (EnvironmentMissing if isinstance(e, EnvironmentMissing) else UserError)(str(e))


@dataclass
class Plan:
    """What compile_in_workers builds: the permutations (sorted (hash, Permutation) pairs), CompileJobs compiled
    with them (the ubershader's, when it was composed in this process), what makes their manifest entries, and
    whether a task composes and compiles the ubershader."""

    items: list
    extra: list
    entries: Entries
    ubershader: bool = False


class _Tally:
    """What the chunks brought back, gathered into `out` and `stats` as they come."""

    def __init__(self, out: Compiled, stats: CompileStats):
        self.out, self.stats = out, stats
        self.seen: set[str] = set()  # the cache keys of every job
        self.fresh: set[str] = set()  # those some worker compiled (the others came from the cache)

    def take(self, value: Chunk) -> tuple:
        out = self.out
        out.add(value.composed, value.errors)
        out.templates.update(value.templates)
        out.results.update(value.results)
        if value.ubershader is not None:
            out.ubershader = value.ubershader
        self.stats.jobs += len(value.keys)
        self.seen.update(value.keys.values())
        self.fresh.update(value.fresh)
        return value.results, value.made

    def finish(self) -> None:
        # counted once per distinct shader, whichever worker got it first: the same counts for any N and any timing
        # (when every shader compiles: in-process, a failing one is compiled, and counted, again per chunk)
        self.stats.distinct += len(self.seen)
        self.stats.compiled += len(self.seen & self.fresh)
        self.stats.cached += len(self.seen - self.fresh)


def compile_in_workers(ctx: BuildContext, plan: Plan, on_done, stats: CompileStats, out: Compiled) -> None:
    """loop.compile_permutations in ctx.jobs worker processes (default: the core count), or on the Dask cluster
    of ctx.executor (cluster.py), into `out`."""
    from tqdm import tqdm

    if not plan.items and not plan.ubershader and not plan.extra:
        return
    tally, local = _Tally(out, stats), ctx.executor is None
    # without a cache (--no-cache), the local workers share a private one for this build alone, so that a shader is
    # compiled once whichever chunks have it (the in-process build's memo); named like the toolchain's temp dirs, a
    # killed build's is removed by the next
    private = None if ctx.store is not None or not local else tempfile.mkdtemp(
        prefix=f"shadermatrix-{os.getpid()}-build-")
    # What comes back is kept to the end of the build (the entries, their texts and files: ~190 KB and some
    # thousand objects a permutation), none of it cyclic garbage, and the cyclic collector would walk all of it
    # again and again as it grows: measured, ~1 ms of this process's CPU per permutation of 1,000. Reference
    # counting frees as always; the collector runs again once the chunks are in.
    collecting = gc.isenabled()
    gc.disable()
    try:
        pool = _pool(ctx, pack(ctx, plan.entries), private)
        with pool, tqdm(total=len(plan.items), disable=not ctx.progress, unit="permutation", leave=False) as bar:
            workers = (ctx.jobs or os.cpu_count() or 1) if local else pool.threads()
            size = chunk_size(len(plan.items), workers)
            chunks = [[h for h, _ in plan.items[k:k + size]] for k in range(0, len(plan.items), size)]
            # the ubershader first (composed there, or its large shaders one task each: they spread over the workers)
            first = [(None, [])] if plan.ubershader else [([], [job]) for job in plan.extra]
            done: dict[int, Chunk] = {}  # chunks back before an earlier one: written when it is
            following = 0  # the next chunk to write
            for k, value in pool.unordered(first + [(chunk, []) for chunk in chunks]):
                if k < len(first):
                    tally.take(value)
                    continue
                done[k - len(first)] = value
                while following in done:  # written in chunk order, each as soon as it and those before are back
                    part, made = tally.take(done.pop(following))
                    chunk = chunks[following]
                    if on_done is not None:
                        on_done([(h, out.composed[h]) for h in chunk if h in out.composed], part, made)
                    bar.update(len(chunk))
                    following += 1
    finally:
        if collecting:
            gc.enable()
        if private is not None:
            shutil.rmtree(private, ignore_errors=True)
    tally.finish()


def _pool(ctx: BuildContext, payload: bytes, private: str | None):
    """The build's workers: ctx.jobs local processes (workers.Workers), or its Dask cluster's (cluster.Cluster)."""
    if ctx.executor is not None:
        from .cluster import Cluster
        return Cluster(ctx.executor, payload, ctx.platforms, cached=ctx.store is not None)
    root = str(ctx.store.root) if ctx.store is not None else private
    return Workers(ctx.jobs or os.cpu_count() or 1, _start, (payload, dict(os.environ), root), _task, _PRELOAD)
