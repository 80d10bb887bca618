"""A Dask distributed cluster (`build --executor dask://HOST:PORT`): the connection, and compile jobs run there.

A build sends its workers whole chunks — compose, compile, analyse, the manifest entries made — through
assemble/cluster.py, which holds this module's DaskExecutor for the connection (the scheduler's address, its
workers) and refuses a worker whose generator or tools differ from the build's (WorkerMismatch).

compile_many(executor=DaskExecutor(...)) runs only the compiles there: a compile job is a pure function of
its inputs (source, language, stage, flags, tool versions: the cache key), so any worker can run it. The
jobs are cut into chunks (four per worker), each compiled on a worker by the same code as a local build
(toolchain.compile_all), and the results come back to this process, which deduplicates, serves and fills the
content-addressed store as it does for a local build. Each chunk first checks the worker's tool versions
against this process's; a worker without a tool, or with another version, fails with one line naming the
worker and the tool — a result from another compiler is never taken.
"""
from __future__ import annotations

from . import ToolMissing, compile_all, tool_versions
from ..lang.errors import UserError

SCHEME = "dask://"


class WorkerMismatch(UserError):
    """A Dask worker cannot compile for this build (missing or other tool versions)."""


def _on_worker(jobs, optimize: bool, validate: bool, versions: dict):
    import socket
    here = tool_versions()
    wrong = {k: (v, here.get(k)) for k, v in versions.items() if here.get(k) != v}
    if wrong:
        what = ", ".join(f"{k} {have or 'missing'} (this build: {want})" for k, (want, have) in sorted(wrong.items()))
        raise WorkerMismatch(f"dask worker {socket.gethostname()}: {what} — install the pinned tools there "
                             "(`make setup`)")
    try:
        return compile_all(list(jobs), optimize, validate, False)
    except ToolMissing as e:
        raise WorkerMismatch(f"dask worker {socket.gethostname()}: {e}") from None


def _reachable(address: str) -> None:
    """Refuse at once a tcp:// address nothing listens on (distributed's Client retries a refused connection until
    its timeout: 10 s before saying what one connection says)."""
    import socket
    host, _, port = address.removeprefix("tcp://").rpartition(":")
    if not address.startswith("tcp://") or not port.isdigit():
        return  # another transport, or a form the Client reports on itself
    try:
        socket.create_connection((host.strip("[]"), int(port)), timeout=10).close()
    except OSError as e:
        raise UserError(f"no Dask scheduler at {address}: {e.strerror or e} — start one (`dask scheduler`) or check "
                        "the address") from None


class DaskExecutor:
    """Runs compile_many's tool work on the cluster at `address` (tcp://host:port or host:port)."""

    def __init__(self, address: str):
        from distributed import Client
        address = address[len(SCHEME):] if address.startswith(SCHEME) else address
        if "://" not in address:
            address = f"tcp://{address}"
        _reachable(address)
        try:
            self.client = Client(address, timeout="10s", set_as_default=False)
        except OSError as e:
            raise UserError(f"no Dask scheduler at {address}: {e} — start one (`dask scheduler`) or check the "
                            "address") from None
        self.address = address
        try:
            self.client.wait_for_workers(1, timeout=30)
        except Exception:  # noqa: BLE001 — distributed's TimeoutError or a closed scheduler
            self.client.close()
            raise UserError(f"the Dask scheduler at {address} has no workers (waited 30 s) — start one "
                            f"(`dask worker {address}`)") from None

    def workers(self) -> int:
        return max(1, len(self.client.scheduler_info().get("workers", {})))

    def compile(self, jobs, optimize: bool, validate: bool, progress: bool = False, workers=None) -> dict:
        if not jobs:
            return {}
        n = 4 * self.workers()
        chunks = [jobs[k::n] for k in range(min(n, len(jobs)))]
        versions = tool_versions()
        futures = self.client.map(_on_worker, chunks, optimize=optimize, validate=validate, versions=versions,
                                  pure=False)
        out = {}
        try:
            parts = self.client.gather(futures)
        except UserError:
            raise
        except Exception as e:  # noqa: BLE001 — a worker died (KilledWorker), the connection closed …
            raise UserError(f"the Dask cluster at {self.address} failed the compile: {type(e).__name__}: {e} — "
                            "check its workers, or build without --executor") from None
        for part in parts:
            out.update(part)
        return out

    def close(self) -> None:
        self.client.close()
