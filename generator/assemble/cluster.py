"""Whole chunks on a Dask cluster (`build --executor dask://HOST:PORT`): what `-j N` does in local worker processes.

Each task is one chunk of permutations, run on a Dask worker by the same function a local worker runs
(parallel.run_chunk): composed, compiled, analysed and its manifest entries and files made (entries.py). The
building process plans (the keys, what is up to date) and writes what comes back, in chunk order: no composing,
compiling or analysing there, so the cluster's size, not the building process, bounds the build
(benchmarks/dask_build.py measures the building process's CPU per permutation).

What a chunk needs besides its hashes — the build's context (the bricks as this build parsed them) and the
scene with every permutation's input key — is pickled once and scattered to every worker (parallel.pack); each
worker process unpickles it once per build. Results are pure functions of those inputs, so the output is
byte-identical to a local build (tested).

A worker must run this build's generator (its version and the sha256 of its own sources) with the same tools
(every tool's version, those of the platforms built included): they are part of every key. Before anything is
sent, every worker reports its own, and a chunk checks again on the worker that runs it (a worker may join
later); a worker that differs is refused with one line naming it and what differs. Each worker compiles
through its own cache ($SHADERMATRIX_CACHE_DIR there, else its default; none with --no-cache, where each worker
process remembers what it compiled for this build): the cache keys are the same everywhere.

A worker that dies while it runs a chunk: Dask runs the chunk again on another worker (up to the scheduler's
allowed failures, then the build fails in one line). A cluster that loses every worker loses the build's data
with them, and the build fails in one line at once; one left without workers for NO_WORKERS_S fails it too,
instead of waiting (tested: never a hang). Run workers with one thread each (`dask worker --nworkers N --nthreads 1`): composing
is Python, which the threads of one process do not run in parallel.
"""
from __future__ import annotations

import functools
import hashlib
import threading
import time
import uuid
from collections import OrderedDict

from ..lang.errors import UserError
from ..toolchain import tool_versions
from ..toolchain.dask import WorkerMismatch

NO_WORKERS_S = 30.0  # how long a build waits for a worker when the cluster has none left
_POLL_S = 0.05  # the longest the build sleeps between looks at its chunks
_WATCH_S = 1.0  # how often the build asks the scheduler how many workers it has
_KEEP = 2  # builds a worker process keeps unpickled (the last ones; a build's end forgets its own)


@functools.lru_cache(maxsize=8)
def fingerprint(platforms: tuple[str, ...]) -> dict[str, str]:
    """What a worker must share with the build: the generator (its version and its own sources' sha256) and the
    version of every tool the build's keys hold (the platforms' own tools, dxc where d3d12 is built, included)."""
    from .. import __version__
    from .keys import own_sources
    from .platforms import all_tools
    out = {"shadermatrix": f"{__version__} (sources {own_sources()[:16]})", **tool_versions()}
    for tools in all_tools(platforms).values():
        for tool, version in tools.items():
            out.setdefault(tool, version)
    return out


def _differences(expected: dict, here: dict) -> str:
    return ", ".join(f"{k} {here.get(k, 'missing')} (this build: {v})" for k, v in expected.items()
                     if here.get(k) != v)


def _refusal(address: str, what: str) -> WorkerMismatch:
    return WorkerMismatch(f"dask worker {address}: {what} — give it this build's shadermatrix and pinned tools "
                          "(`make setup`), or build without --executor")


def _report(platforms: tuple[str, ...], dask_worker=None) -> dict:
    """On a worker (Client.run): its fingerprint."""
    return fingerprint(tuple(platforms))


_BUILDS: OrderedDict = OrderedDict()  # in a worker process: digest -> (context, entries, memo) of recent builds
_LOCK = threading.Lock()


def _state(payload: bytes, digest: str, cached: bool) -> tuple:
    with _LOCK:
        if digest not in _BUILDS:
            from ..io import Store, default_cache_dir
            from .parallel import unpack
            root = default_cache_dir() if cached else None
            _BUILDS[digest] = (*unpack(payload, Store(root) if root is not None else None), {})
            while len(_BUILDS) > _KEEP:
                _BUILDS.popitem(last=False)
        _BUILDS.move_to_end(digest)
        return _BUILDS[digest]


def _chunk(payload: bytes, digest: str, expected: dict, platforms: tuple, cached: bool, hashes: list, extra: list):
    """On a worker: one chunk (parallel.run_chunk), after checking that this worker may build for the build."""
    from distributed import get_worker

    from .parallel import run_chunk
    wrong = _differences(expected, fingerprint(tuple(platforms)))
    if wrong:
        raise _refusal(get_worker().address, wrong)
    ctx, entries, memo = _state(payload, digest, cached)
    return run_chunk(ctx, entries, hashes, extra, memo)


def _forget(digest: str, dask_worker=None) -> None:
    with _LOCK:
        _BUILDS.pop(digest, None)


class Cluster:
    """The chunk pool of one build on the Dask cluster of `executor` (toolchain/dask.DaskExecutor), used as
    workers.Workers is: a context manager whose unordered(tasks) yields (index, result) as chunks finish."""

    def __init__(self, executor, payload: bytes, platforms, cached: bool):
        self.client, self.address = executor.client, executor.address
        self.platforms, self.cached = tuple(platforms), cached
        self.expected = fingerprint(self.platforms)
        self._refuse_mismatched()
        self.digest = hashlib.sha256(payload).hexdigest()
        self.futures: list = []
        try:
            self.data = self.client.scatter(payload, broadcast=True, hash=False)
        except Exception as e:  # noqa: BLE001 — the connection closed, no worker to take it
            raise self._failed("could not send the build to its workers", e) from None

    def _failed(self, what: str, e: BaseException) -> UserError:
        return UserError(f"the Dask cluster at {self.address} {what}: {type(e).__name__}: {e} — check its workers, "
                         "or build without --executor")

    def _refuse_mismatched(self) -> None:
        try:
            reports = self.client.run(_report, self.platforms, on_error="return")
        except Exception as e:  # noqa: BLE001 — the scheduler went away
            raise self._failed("stopped answering", e) from None
        for address, here in sorted(reports.items()):
            if isinstance(here, OSError):  # it died as it was asked (CommClosedError): the scheduler drops it
                continue
            if isinstance(here, BaseException):  # one without this shadermatrix cannot even unpickle the call
                raise _refusal(address, f"cannot run this build's shadermatrix ({type(here).__name__}: {here})")
            wrong = _differences(self.expected, here)
            if wrong:
                raise _refusal(address, wrong)

    def __enter__(self) -> Cluster:
        return self

    def __exit__(self, kind, value, tb) -> None:
        try:
            left = [f for f in self.futures if not f.done()]
            if left:
                self.client.cancel(left)
            self.client.cancel([self.data])
            self.client.run(_forget, self.digest)
        except Exception:  # noqa: BLE001 — a cluster gone already: nothing there to end
            pass

    def threads(self) -> int:
        return max(1, sum(self.client.nthreads().values()))

    def unordered(self, tasks: list):
        """Yield (index, result) of every task (a (hashes, extra jobs) pair) as it is done, any order; a chunk that
        failed is raised here (a UserError as itself: a refused worker, a missing tool)."""
        from distributed import as_completed

        build = uuid.uuid4().hex[:8]
        self.futures = [self.client.submit(_chunk, self.data, self.digest, self.expected, self.platforms, self.cached,
                                           hashes, extra, key=f"shadermatrix-chunk-{build}-{k:06d}",
                                           priority=len(tasks) - k, pure=False)
                        for k, (hashes, extra) in enumerate(tasks)]
        index = {f.key: k for k, f in enumerate(self.futures)}
        finished = as_completed(self.futures, loop=self.client.loop)
        left, watched, alone = len(self.futures), time.monotonic(), None
        while left:
            done = finished.next_batch(block=False)
            for f in sorted(done, key=lambda f: index[f.key]):
                left -= 1
                yield index[f.key], self._result(f)
            now = time.monotonic()
            if left and now - watched >= _WATCH_S:  # a cluster without workers never finishes a chunk
                watched = now
                try:
                    alone = None if self.client.nthreads() else (alone or now)
                except Exception as e:  # noqa: BLE001 — the scheduler went away
                    raise self._failed("stopped answering", e) from None
                if alone is not None and now - alone >= NO_WORKERS_S:
                    raise UserError(f"the Dask cluster at {self.address} has had no workers for {NO_WORKERS_S:.0f} s "
                                    f"with {left} chunks left — start workers (`dask worker {self.address}`), or "
                                    "build without --executor")
            if not done:
                time.sleep(_POLL_S)  # short: a signal is handled, and a chunk back is written, within it

    def _result(self, f):
        if f.status == "error":
            e = f.exception()
            if isinstance(e, UserError):
                raise e
            if type(e).__name__ == "KilledWorker":  # every worker that ran it died (distributed's allowed-failures)
                raise self._failed("lost a chunk: each worker that ran it died", e)
            raise e.with_traceback(f.traceback())
        try:
            return f.result()
        except Exception as e:  # noqa: BLE001 — cancelled: what it needed went with the workers that held it
            raise self._failed("lost a chunk (its workers died, and the build's data with them)", e) from None
