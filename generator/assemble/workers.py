"""A small pool of worker processes that a build can always end at once (what `build -j N` runs its chunks on).

Not concurrent.futures.ProcessPoolExecutor: on Python 3.11.2 (Debian 12's) its shutdown hangs after Ctrl-C or a
killed worker (the build printed its line and never exited), and on later 3.11 releases it takes seconds. Here
every worker has a pipe of its own and at most one task at a time; the building process waits on those pipes
and the workers' sentinels together (multiprocessing.connection.wait), so there are no queue feeder threads and
no management thread to wait for, and a worker that dies is seen the moment it does. Each worker leads a process
group of its own, which holds the tool processes it starts: ending the build kills every group with one signal
each (tools included: nothing keeps writing into a temporary directory after the build has gone) and reaps them
with a timeout. A terminal's Ctrl-C reaches the build alone (the workers are not in its foreground group), and
SIGTERM of the build's group too: the build, not a dying worker, says what happened.

A reply is pickled before it is sent: a result that cannot be pickled, or an exception that cannot make the
trip (one whose class needs other arguments than its message to be made again), is reported as what it is —
the pickling error's type and message, or the exception's — never as a worker that died.

Workers are started by a forkserver (never a fork of the building process, which has threads): modules named
in `preload` are imported once, by the forkserver, and each worker starts as a fork of it.
"""
from __future__ import annotations

import multiprocessing
import os
import pickle
import signal
import threading
import time
import traceback
from collections import deque
from multiprocessing.connection import wait
from multiprocessing.reduction import ForkingPickler

from ..lang.errors import UserError

_POLL_S = 0.2  # the longest the build waits on its workers without looking at signals
_JOIN_S = 5.0  # how long ending the pool waits for a killed worker to be reaped (it takes milliseconds)


class WorkerDied(UserError):
    """A worker process ended while the build still needed it (killed, out of memory)."""

    def __init__(self):
        super().__init__("a worker process of the build died (killed, or out of memory) — build again, or with "
                         "fewer jobs (-j)")


class ReplyNotSent(RuntimeError):
    """A worker's reply that could not make the trip to the build (it did not pickle, or not unpickle)."""


class RemoteTraceback(Exception):
    """Where in a worker an unexpected exception was raised (its traceback, as text: the cause shown)."""

    def __str__(self) -> str:
        return self.args[0]


def _serve(conn, build: int, init, init_args: tuple, run) -> None:
    """A worker: init(*init_args), then run(*task) for every task the pipe brings, until it closes."""
    try:
        os.setpgid(0, 0)  # its own group, which its tools join: the build ends both with one killpg
    except OSError:
        pass
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the build's to handle: it ends the workers
    _watch(build)
    failed = None
    try:
        init(*init_args)
    except BaseException as e:  # noqa: BLE001 — sent to the build, which raises it
        failed = _portable(e)
    while True:
        try:
            task = conn.recv()
        except (EOFError, OSError):  # the build closed the pipe: done
            return
        if failed is not None:
            reply = ("error", failed)
        else:
            try:
                reply = ("ok", run(*task))
            except BaseException as e:  # noqa: BLE001 — as above
                reply = ("error", _portable(e))
        try:
            data = ForkingPickler.dumps(reply)  # as conn.send would, but a failure here is the task's error
        except Exception as e:  # noqa: BLE001 — whatever the result's pickling raises
            what = type(reply[1]).__name__ if reply[0] == "ok" else "error"
            data = ForkingPickler.dumps(("error", _portable(ReplyNotSent(
                f"a worker's result ({what}) cannot be sent to the build: {type(e).__name__}: {e}"))))
        try:
            conn.send_bytes(data)
        except (OSError, ValueError):  # the build is gone: nobody reads it
            return


def _portable(e: BaseException) -> tuple:
    """(the exception, or a stand-in that makes the trip with its type and message, and the worker's traceback as
    text). The round trip is tried here: an exception whose class takes other arguments than the message it was
    given (a SourceError: path, line, col, …) pickles, and fails only when the build unpickles it."""
    text = traceback.format_exc()
    try:
        pickle.loads(ForkingPickler.dumps(e))
    except Exception:  # noqa: BLE001 — any exception may refuse the trip, either way
        e = UserError(str(e)) if isinstance(e, UserError) else RuntimeError(f"{type(e).__name__}: {e}")
    return e, text


def _watch(build: int) -> None:
    """End this worker and its tools as soon as the build that started it is gone (killed with -9: nobody will
    read what the worker computes, and it would print a broken pipe when it tried to send it)."""
    def gone() -> bool:
        try:
            with open(f"/proc/{build}/stat", "rb") as f:  # a zombie (killed, not yet reaped) is gone too
                return f.read().rsplit(b")", 1)[1].split()[0] == b"Z"
        except FileNotFoundError:
            return True
        except OSError:  # no /proc: ask the kernel whether the pid exists
            try:
                os.kill(build, 0)
            except ProcessLookupError:
                return True
            except PermissionError:
                pass
            return False

    def loop() -> None:
        while not gone():
            time.sleep(0.25)
        if os.getpgid(0) == os.getpid():
            os.killpg(os.getpid(), signal.SIGKILL)  # the tools it started go with it
        os._exit(1)
    threading.Thread(target=loop, name="watch-build", daemon=True).start()


class Workers:
    """`n` worker processes, each running init(*init_args) once, then run(*task) per task (both importable
    functions: they are pickled by reference). Use as a context manager: leaving it ends every worker."""

    def __init__(self, n: int, init, init_args: tuple, run, preload=()):
        context = multiprocessing.get_context("forkserver")
        context.set_forkserver_preload(list(preload))
        self._procs, self._conns = [], []
        try:
            for _ in range(n):
                here, there = context.Pipe()
                p = context.Process(target=_serve, args=(there, os.getpid(), init, init_args, run), daemon=True,
                                    name="shadermatrix-worker")
                p.start()
                there.close()  # the worker holds the other end: its exit closes the pipe
                self._procs.append(p)
                self._conns.append(here)
        except BaseException:
            self.close(kill=True)
            raise

    def __enter__(self) -> Workers:
        return self

    def __exit__(self, kind, value, tb) -> None:
        self.close(kill=kind is not None)

    def unordered(self, tasks: list):
        """Yield (index, result) of every task (a tuple of run's arguments) as it is done, any order. A task that
        raised is raised here (UserError as itself, anything else with the worker's traceback as its cause); a
        worker that dies raises WorkerDied."""
        todo = deque(enumerate(tasks))
        busy: dict[int, int] = {}  # worker -> the task it has
        sentinels = {p.sentinel: w for w, p in enumerate(self._procs)}
        conns = {c: w for w, c in enumerate(self._conns)}

        def give(w: int) -> None:
            if todo:
                k, task = todo.popleft()
                try:
                    self._conns[w].send(task)
                except OSError:
                    raise WorkerDied() from None
                busy[w] = k

        for w in range(len(self._procs)):
            give(w)
        while busy:
            # in short steps: a signal the kernel gave another thread is handled here only when Python runs again
            ready = wait([*(self._conns[w] for w in busy), *sentinels], timeout=_POLL_S)
            if not ready:
                continue
            replies = [conns[r] for r in ready if r in conns]
            if not replies:  # only a sentinel: a worker ended with nothing to say
                raise WorkerDied()
            for w in replies:
                try:
                    data = self._conns[w].recv_bytes()
                except (EOFError, OSError):
                    raise WorkerDied() from None
                try:
                    status, value = pickle.loads(data)
                except Exception as e:  # noqa: BLE001 — a result that pickled and does not unpickle here
                    raise ReplyNotSent(f"a worker's result cannot be read by the build: {type(e).__name__}: "
                                       f"{e}") from e
                k = busy.pop(w)
                if status == "error":
                    error, text = value
                    raise error from (None if isinstance(error, UserError) else RemoteTraceback(text))
                give(w)
                yield k, value

    def close(self, kill: bool) -> None:
        """End the workers: idle ones leave when their pipe closes; with `kill` (a failure, an interrupt) every
        worker's group is killed at once, tools and all. Each is reaped within _JOIN_S."""
        for c in self._conns:
            c.close()
        if kill:
            for p in self._procs:
                _kill(p)
        deadline = time.monotonic() + _JOIN_S
        for p in self._procs:
            p.join(max(0.0, deadline - time.monotonic()))
            if p.exitcode is None:  # still there: not waited for again (it would hold the exit up)
                _kill(p)
                p.join(0.5)
        self._procs, self._conns = [], []


def _kill(p) -> None:
    if p.pid is None:
        return
    try:
        os.killpg(p.pid, signal.SIGKILL)  # the worker and the tools it started
    except OSError:  # not yet a group leader (killed while starting), or gone
        try:
            os.kill(p.pid, signal.SIGKILL)
        except OSError:
            pass
