"""Finding and running the tools: where an executable is, its version, and the gate every tool process starts
through.

A Gate is one build's switch: the build makes one (assemble.BuildContext.gate) and hands it to everything that
runs a tool for it; its signal handler stops it, which kills the tools running under it at once (whatever
thread waits on them) and refuses to start more, so an interrupted build does not finish the batch its compile
thread had under way. A caller that passes no gate (render, eval, measure, a version query) runs its tool under
a gate of that call alone: nothing another build does can stop it.
"""
from __future__ import annotations

import functools
import os
import re
import shutil
import subprocess
import threading

from ..lang.errors import EnvironmentMissing
from .locate import TOOLS_ENV, tool_dirs


class ToolMissing(EnvironmentMissing):
    """A required external tool is not installed."""

    def __init__(self, name: str):
        super().__init__(f"{name} not found — run `make setup` (scripts/setup.sh) in a clone, or put it on PATH "
                         f"or in a directory named by ${TOOLS_ENV}; `shadermatrix doctor` lists what is missing")
        self.tool = name


class ToolsStopped(RuntimeError):
    """A tool was to start, or was running, when its gate was stopped: the build that ran it is ending."""


def find_tool(name: str) -> str | None:
    """Path of an executable: ``$SHADERMATRIX_TOOLS``, then the running environment's scripts directory
    (a venv's bin/), then ``PATH`` (see toolchain.locate); None when it is in none of them."""
    if os.environ.get("SHADERMATRIX_FORBID_TOOLS"):  # the test tiers: a unit test runs no external tool
        raise RuntimeError(f"external tool '{name}' used where none may run "
                           f"({os.environ['SHADERMATRIX_FORBID_TOOLS']})")
    return shutil.which(name, path=os.pathsep.join(tool_dirs()))


def _find(name: str) -> str | None:
    from .. import toolchain  # read at call time: tests replace find_tool on the package
    return toolchain.find_tool(name)


def need(name: str) -> str:
    """find_tool's path, or ToolMissing."""
    path = _find(name)
    if path is None:
        raise ToolMissing(name)
    return path


class Gate:
    """Whether the tools of one build may run, and the tool processes running under it now."""

    def __init__(self) -> None:
        self._stopped = threading.Event()
        self._running: set[subprocess.Popen] = set()
        # re-entrant: the build's signal handler stops the gate on the thread it interrupts, which may be inside
        # run() holding this lock; with a plain lock the handler would wait for itself and the build would hang
        self._lock = threading.RLock()

    def __reduce__(self):
        # A gate is one process's (its processes, its lock): a build's context pickled for its worker processes
        # arrives with an open gate of the worker's own (the build ends its workers by killing their groups).
        return Gate, ()

    @property
    def stopped(self) -> bool:
        return self._stopped.is_set()

    def stop(self) -> None:
        """Kill every tool running under this gate and start none until resume(): the build ends now, not after
        the batch its compile thread had under way (its queued tools would start)."""
        self._stopped.set()
        with self._lock:
            running = list(self._running)
        for proc in running:
            proc.kill()

    def resume(self) -> None:
        """Let tools start again (a build run again with the same context)."""
        self._stopped.clear()

    def run(self, args: list[str], cwd: str | None = None, env: dict | None = None) -> tuple[int, str]:
        """Run a tool; return (exit status, stdout+stderr decoded with errors=replace). ToolsStopped when the
        gate is stopped before it starts or while it runs (a killed tool's output is no result)."""
        if self._stopped.is_set():
            raise ToolsStopped(f"{args[0]}: not started, the build is ending")
        proc = subprocess.Popen(args, cwd=cwd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                stdin=subprocess.DEVNULL)
        with self._lock:
            self._running.add(proc)
        try:
            if self._stopped.is_set():  # stopped while it started: stop() did not see it
                proc.kill()
            out, _ = proc.communicate()
        except BaseException:  # Ctrl-C on the main thread (a --version): the tool goes too, as subprocess.run does
            proc.kill()
            proc.wait()
            raise
        finally:
            with self._lock:
                self._running.discard(proc)
        if self._stopped.is_set():
            raise ToolsStopped(f"{args[0]}: stopped, the build is ending")
        return proc.returncode, out.decode("utf-8", errors="replace")


def run(args: list[str], cwd: str | None = None, env: dict | None = None, gate: Gate | None = None) -> tuple[int, str]:
    """gate.run(args, cwd, env); without a gate, under one of this call alone (which nothing stops)."""
    return (gate if gate is not None else Gate()).run(args, cwd, env)


def version_of(name: str, parse) -> str:
    """parse(`name --version`), its first line if parse finds nothing, or "missing" / "unusable (why)"."""
    path = _find(name)
    if path is None:
        return "missing"
    try:
        _, out = run([path, "--version"])
    except OSError as exc:
        return f"unusable ({exc.strerror})"
    if not out.strip():
        return "unknown"
    return parse(out) or out.strip().splitlines()[0]


def _glslc_version(out: str) -> str | None:
    parts = dict(line.split(None, 1) for line in out.splitlines() if len(line.split(None, 1)) == 2)
    if "shaderc" not in parts:
        return None
    return f"{parts['shaderc']} (spirv-tools {parts.get('spirv-tools', '?')}, glslang {parts.get('glslang', '?')})"


def _search(pattern: str):
    return lambda out: (m.group(1) if (m := re.search(pattern, out)) else None)


@functools.lru_cache(maxsize=1)
def tool_versions() -> dict[str, str]:
    """Stable version strings of the tools (for cache keys and provenance).

    ``"missing"`` for a tool that is not installed. Computed once per process.
    """
    val = version_of("spirv-val", _search(r"SPIRV-Tools v(\S+)"))
    opt = version_of("spirv-opt", _search(r"SPIRV-Tools v(\S+)"))
    return {
        "glslc": version_of("glslc", _glslc_version),
        "glslang": version_of("glslangValidator", _search(r"Glslang Version: (?:\d+:)?(\S+)")),
        "spirv-tools": val if val == opt else f"spirv-val {val}, spirv-opt {opt}",
        "naga": version_of("naga", _search(r"^(\S+)")),
    }
