"""The gate a build stops its tools with: stopping kills what runs under it and starts nothing more, and it is
one build's, never the process's: a stopped build stops no other build, earlier, later or at the same time."""
from __future__ import annotations

import pickle
import sys
import threading
import time
from pathlib import Path

import pytest

from generator.toolchain import CompileJob, Gate, ToolsStopped, compile_many

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "scenes" / "example.toml"
SLEEPER = [sys.executable, "-c", "import time; time.sleep(60)"]  # a tool that runs until it is killed
GLSL_FRAG = "#version 450\nlayout(location = 0) out vec4 o;\nvoid main() { o = vec4(0.5); }\n"


def _when(condition, timeout: float = 30.0) -> bool:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(0.001)
    return False


def _running(gate: Gate) -> bool:
    with gate._lock:
        return bool(gate._running)


def _in_thread(fn, *args):
    """Run fn(*args) on a thread; returns (thread, box) where box gets "result" or "error"."""
    box: dict = {}

    def target():
        try:
            box["result"] = fn(*args)
        except BaseException as e:  # noqa: BLE001 — handed to the test
            box["error"] = e
    thread = threading.Thread(target=target, daemon=True)
    thread.start()
    return thread, box


def test_stop_kills_the_running_tool_and_starts_no_other_until_resumed():
    gate = Gate()
    thread, box = _in_thread(gate.run, SLEEPER)
    assert _when(lambda: _running(gate)), "the tool did not start"
    started = time.monotonic()
    gate.stop()
    thread.join(5)
    assert not thread.is_alive() and time.monotonic() - started < 5, "the stopped tool ran on"
    assert isinstance(box.get("error"), ToolsStopped), box  # a killed tool's output is no result
    assert not _running(gate)
    with pytest.raises(ToolsStopped, match="not started"):
        gate.run([sys.executable, "-c", "raise SystemExit('must not run')"])
    gate.resume()
    assert gate.run([sys.executable, "-c", "print('again')"]) == (0, "again\n")


def test_stop_returns_on_the_thread_that_holds_the_gate():
    """The build's signal handler runs on the thread it interrupts, which may be inside run() holding the gate's
    lock: stop() must not wait for that lock's release (it would wait for itself, and the build would hang)."""
    gate = Gate()

    def handler_inside_run():
        with gate._lock:  # where run() is when it registers or forgets a process
            gate.stop()
    thread, box = _in_thread(handler_inside_run)
    thread.join(5)
    assert not thread.is_alive(), "stop() waited for a lock its own thread held"
    assert "error" not in box and gate.stopped


def test_a_stopped_gate_stops_no_other_and_no_call_without_one():
    stopped = Gate()
    stopped.stop()
    assert Gate().run([sys.executable, "-c", "print(1)"]) == (0, "1\n")
    from generator.toolchain.run import run
    assert run([sys.executable, "-c", "print(2)"]) == (0, "2\n")  # no gate: one of this call alone


def test_a_gate_crosses_to_a_worker_process_open():
    """A build's context is pickled for its worker processes: its gate arrives as the worker's own, open, not
    as this one's lock and processes (which do not pickle), whatever this one's state."""
    from generator.assemble import BuildContext
    from generator.library.bricks import Library

    ctx = BuildContext(Library(bricks={}, errors=[]))
    ctx.gate.stop()
    arrived = pickle.loads(pickle.dumps(ctx.for_workers()))
    assert isinstance(arrived.gate, Gate) and not arrived.gate.stopped and arrived.gate is not ctx.gate
    assert BuildContext(ctx.library).gate is not ctx.gate  # each context (each build) has a gate of its own


@pytest.mark.toolchain
def test_compile_many_under_a_stopped_gate_raises_and_others_compile(require_tool):
    for tool in ("glslc", "spirv-val", "spirv-opt"):
        require_tool(tool)
    jobs = [CompileJob("a.frag.glsl", "glsl", "frag", GLSL_FRAG)]
    stopped = Gate()
    stopped.stop()
    with pytest.raises(ToolsStopped):
        compile_many(jobs, gate=stopped)
    assert compile_many(jobs)["a.frag.glsl"].ok  # the default: a gate of the call's own
    assert compile_many(jobs, gate=Gate())["a.frag.glsl"].ok


@pytest.fixture(scope="module")
def lib_scene():
    from generator.library.bricks import load_library
    from generator.scene.load import load_scene
    lib = load_library()
    return lib, load_scene(EXAMPLE, lib)


@pytest.mark.toolchain
def test_a_stopped_build_stops_neither_the_build_beside_it_nor_a_later_one(lib_scene, tmp_path, require_tool):
    """Two builds in one process; the first is stopped while its tools run. With one switch for the process
    (as the tool stop was) the second build's tools died with the first's; with a gate per build it finishes,
    and so does a build started after, while the stopped build's gate is still stopped."""
    for tool in ("glslc", "naga", "spirv-val", "spirv-opt", "glslangValidator"):
        require_tool(tool)
    from generator.assemble import BuildContext, build

    lib, scene = lib_scene
    stopped, beside = BuildContext(lib), BuildContext(lib)
    first, first_box = _in_thread(build, scene, tmp_path / "stopped", stopped)
    second, second_box = _in_thread(build, scene, tmp_path / "beside", beside)
    assert _when(lambda: _running(stopped.gate) or not first.is_alive()), "no tool of the first build ran"
    assert first.is_alive(), "the first build ended before it could be stopped"
    stopped.gate.stop()
    first.join(30)
    assert not first.is_alive() and isinstance(first_box.get("error"), ToolsStopped), first_box
    second.join(120)
    assert not second.is_alive() and "error" not in second_box, second_box
    assert second_box["result"].ok, second_box["result"].failures
    assert stopped.gate.stopped
    later = build(scene, tmp_path / "later", BuildContext(lib))
    assert later.ok, later.failures
