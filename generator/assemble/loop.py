"""The build's compile loop, in one place: the permutations to build composed and compiled in chunks, each chunk
handed to the writer (`on_done`) as soon as it is compiled, in chunk order.

One loop, run one of two ways (neither changes a byte of the output, nor the counts):

- in worker processes (parallel.py), from MIN_PERMUTATIONS permutations when more than one job is allowed and
  no executor is given: a worker composes, compiles and analyses a chunk; this process writes;
- here otherwise: chunks of CHUNK permutations are composed on this thread and each is compiled on a thread of
  its own (`jobs` tool processes, or on the executor) while the next is composed, so writing, composing and
  the compilers overlap. Shaders identical across chunks are compiled once (an in-memory record beside the
  store).

Both compose a chunk with compose_chunk. The ubershader's shaders (`extra`) are compiled with the first
chunk's, so that its large shaders start with the others instead of after them.
"""
from __future__ import annotations

import os
from collections import deque
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from ..toolchain import CompileJob, CompileResult, CompileStats, compile_many
from ..toolchain.jobs import source_jobs
from .context import BuildContext

if TYPE_CHECKING:
    from ..compose import Composed

MIN_PERMUTATIONS = 64  # below this, starting worker processes costs more than it saves (measured: ~1.4 s at 36)
WORKERS_FROM_ENV = "SHADERMATRIX_WORKERS_FROM"  # another threshold (a machine whose workers start faster or slower)
CHUNK = 64  # permutations composed per compile batch in this process
_POLL_S = 0.2  # the longest this thread waits on the compile thread without looking at signals


@dataclass
class Compiled:
    """What the loop made: composed units and compose errors by permutation hash, compile results by job key,
    the costs the workers analysed (SPIR-V sha256 -> cost dict) and the templates composed with (by name)."""

    composed: dict[str, Composed] = field(default_factory=dict)
    errors: dict[str, list[str]] = field(default_factory=dict)
    results: dict[str, CompileResult] = field(default_factory=dict)
    costs: dict = field(default_factory=dict)
    templates: set[str] = field(default_factory=set)
    ubershader: object = None  # its entry as a worker made it (entries.Made), when the workers composed it

    def add(self, composed: dict, errors: dict) -> None:
        self.composed.update(composed)
        self.errors.update(errors)
        for c in composed.values():
            self.templates.update(c.templates)


def compose_chunk(ctx: BuildContext, items) -> tuple[dict[str, Composed], dict[str, list[str]], list[CompileJob]]:
    """(Composed by hash, compose errors by hash, compile jobs) of a chunk of (hash, permutation) pairs."""
    from ..compose.batch import compose_permutations  # Jinja and the emitters load only when something is composed
    composed, errors = compose_permutations(items, ctx.library, ctx.languages, ctx.dialects)
    return composed, errors, [j for h, c in composed.items() for j in source_jobs(h, c.sources)]


def in_workers(ctx: BuildContext, permutations: int) -> bool:
    """Whether a build of this many permutations runs its chunks in worker processes or on the cluster."""
    n = ctx.jobs or os.cpu_count() or 1
    return ctx.executor is not None or (n > 1 and permutations >= workers_from())


def workers_from() -> int:
    """The fewest permutations a -j N build (N > 1) runs in worker processes: MIN_PERMUTATIONS, or
    $SHADERMATRIX_WORKERS_FROM when set (a whole number >= 1; anything else is refused, never ignored)."""
    raw = os.environ.get(WORKERS_FROM_ENV)
    if raw is None:
        return MIN_PERMUTATIONS
    if not raw.strip().isdigit() or int(raw) < 1:
        from ..lang.errors import UserError
        raise UserError(f"{WORKERS_FROM_ENV}={raw!r} is not a whole number of permutations >= 1 — "
                        f"set it to a count such as {MIN_PERMUTATIONS}, or unset it")
    return int(raw)


def compile_permutations(ctx: BuildContext, permutations: dict, extra=(), on_done=None,
                         stats: CompileStats | None = None, costs: dict | None = None, entries=None,
                         ubershader: bool = False) -> Compiled:
    """Compose and compile every permutation of `permutations` (hash -> Permutation), and the CompileJobs of
    `extra`. on_done([(hash, Composed)], results by job key, entries made or None) is called on this thread for
    every compiled chunk, in chunk order; stats (a CompileStats) is filled in; costs: the dict Compiled.costs is
    (the writer's). entries (entries.Entries): what makes the chunks' manifest entries, given to the workers when
    they run the chunks (in_workers); ubershader: there, compose and compile the ubershader too (Compiled.ubershader)."""
    stats = stats if stats is not None else CompileStats()
    out = Compiled(costs=costs if costs is not None else {})
    items = sorted(permutations.items())
    if entries is not None and in_workers(ctx, len(items)):
        from .parallel import Plan, compile_in_workers
        compile_in_workers(ctx, Plan(items, list(extra), entries, ubershader), on_done, stats, out)
    else:
        _here(ctx, items, list(extra), on_done, stats, out)
    return out


def _result(future):
    """future.result(), waited for in short steps: a signal the kernel gave another thread (a tool's reader) is
    handled by this one only when it runs Python again, and a wait without a timeout could last the whole batch."""
    while True:
        try:
            return future.result(timeout=_POLL_S)
        except TimeoutError:
            continue


def _here(ctx: BuildContext, items: list, extra: list, on_done, stats: CompileStats, out: Compiled) -> None:
    from concurrent.futures import ThreadPoolExecutor

    size = CHUNK if on_done is not None else max(1, len(items))
    chunks = [items[k:k + size] for k in range(0, len(items), size)] or [[]]
    memo: dict = {}
    waiting: deque = deque()  # (hashes, future) in chunk order: one compile thread, so they finish in order

    def deliver(block: bool) -> None:
        while waiting and (block or waiting[0][1].done()):
            hashes, future = waiting.popleft()
            part = _result(future)  # a compile error is raised here, on the caller's thread
            out.results.update(part)
            if on_done is not None:
                on_done([(h, out.composed[h]) for h in hashes], part)

    pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="compile")
    ctx.gate.resume()  # a context built again: its last build may have stopped it
    try:
        for k, chunk in enumerate(chunks):
            composed, errors, jobs = compose_chunk(ctx, chunk)
            out.add(composed, errors)
            waiting.append((list(composed), pool.submit(
                compile_many, (extra if k == 0 else []) + jobs, optimize=True, validate=True, progress=ctx.progress,
                store=ctx.store, stats=stats, workers=ctx.jobs, executor=ctx.executor, memo=memo, gate=ctx.gate)))
            deliver(block=False)
        deliver(block=True)
    except BaseException as e:
        # Ctrl-C, SIGTERM or a failure: the build ends now, not when the compile thread's batch is done (its
        # running tools are killed and its queued ones never start; an executor's are cancelled when it closes)
        ctx.gate.stop()  # this build's gate: a later build, with a context of its own, compiles as before
        # After a failure wait for the compile thread (its tools are dead: it ends at once), so that none outlives
        # the build; an interrupted process is exiting, so it does not wait for it.
        pool.shutdown(wait=isinstance(e, Exception), cancel_futures=True)
        raise
    pool.shutdown(wait=True)
