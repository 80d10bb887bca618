"""Compilers and validators: HLSL / GLSL / WGSL source -> validated SPIR-V.

One call, :func:`compile_many`, takes any number of :class:`CompileJob` and
returns one :class:`CompileResult` per job key. Every failing job carries at
least one error :class:`Diagnostic`; no job fails silently.

Pipeline per job (all SPIR-V is version 1.3, validated for ``vulkan1.1``):

1. front end
   - GLSL and HLSL: ``glslc --target-env=vulkan1.1 -c`` over a *batch* of
     files in one process (``-x``/``-fshader-stage``/``-fentry-point`` apply
     to the files after them, so GLSL and HLSL of all stages share a batch).
     glslc carries on past a failing file and still writes the other outputs,
     but its diagnostics name the ``#line`` path, not the input file. So when
     a batch prints anything, it is rerun with a tiny *sentinel* file after
     each input that always fails with ``#error SHADERMATRIX_SENTINEL``; the
     sentinel's message closes the previous job's diagnostics. A job that has
     no output and no parsed error (a crash, an unknown message format) is
     recompiled alone.
   - WGSL: ``naga --spirv-version 1.3 --keep-coordinate-space in.wgsl out.spv`` (no y flip:
    the same matrices place vertices alike in every language), one process per file
     (naga converts one input per run); about 2 ms each.
2. with ``optimize``: ``spirv-opt --target-env=vulkan1.1 -O`` (which validates its input itself:
   an invalid module is refused with the validator's message) and ``spirv-val`` on the result;
   without: ``spirv-val --target-env vulkan1.1`` on the front end's output.

Batches and per-file steps run on a thread pool of ``os.cpu_count()``
workers; GLSL/HLSL jobs are dealt into one glslc batch per worker (at least
8 and at most 256 jobs per batch). Sentinels are in the job's language, so
glslang does not switch front ends; a GLSL sentinel costs ~1 ms.

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

Error mapping: GLSL/HLSL sources carry ``#line N "bricks/x.py"`` (GLSL with
``#extension GL_GOOGLE_cpp_style_line_directive : require``); glslc then
reports ``bricks/x.py:N: error: ...`` (no column: col 0). Lines outside any
``#line`` are reported against the job key. naga reports
``┌─ file.wgsl:LINE:COL``; those lines go through ``CompileJob.line_map``.
"""
from __future__ import annotations

import base64
import bisect
import functools
import hashlib
import json
import os
import re
import shutil
import subprocess
import tempfile
import threading
from concurrent.futures import ThreadPoolExecutor, as_completed
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Iterable

from ..io import content_key
from ..lang.errors import EnvironmentMissing
from ..backends import LANGUAGES
from .locate import TOOLS_ENV, pinned_versions, tool_dirs

__all__ = ["Diagnostic", "CompileJob", "CompileResult", "CompileStats", "ToolMissing",
           "compile_many", "cache_key", "tool_versions", "find_tool", "tool_dirs", "pinned_versions", "TOOLS_ENV",
           "TARGET_ENV", "SPIRV_VERSION", "SPIRV_MAGIC"]

TARGET_ENV = "vulkan1.1"      # every tool gets this target environment
SPIRV_VERSION = "1.3"         # what glslc emits for vulkan1.1; naga is told the same
SPIRV_MAGIC = 0x07230203
STAGES = ("vert", "frag", "comp")
_SENTINEL = "SHADERMATRIX_SENTINEL"
_MAX_BATCH = 256  # jobs per glslc process
_SENTINEL_SRC = {"glsl": f"#version 450\n#error {_SENTINEL}\n", "hlsl": f"#error {_SENTINEL}\n"}


@dataclass(frozen=True)
class Diagnostic:
    path: str
    line: int
    col: int
    severity: str  # "error" | "warning"
    message: str
    tool: str

    def __str__(self) -> str:
        return f"{self.path}:{self.line}:{self.col}: {self.severity}: {self.message} [{self.tool}]"


@dataclass(frozen=True)
class CompileJob:
    key: str            # unique, filesystem-safe (e.g. "3fa9c2d1.frag.glsl")
    language: str       # "glsl" | "hlsl" | "wgsl"
    stage: str          # "vert" | "frag" | "comp"
    source: str
    entry: str = "main"
    # (generated_line, path, line) sorted by generated_line, with #line
    # semantics: generated line g >= generated_line maps to
    # (path, line + g - generated_line) for the last such entry; lines before
    # the first entry map to the job key itself.
    line_map: tuple = ()
    # WGSL pipeline-overridable constants, ((name or @id, int value), ...): naga resolves them when it
    # translates (as WebGPU does when a pipeline is created); GLSL/HLSL keep SpecIds instead.
    overrides: tuple = ()


@dataclass
class CompileResult:
    key: str
    ok: bool
    spirv: bytes | None        # validated SPIR-V (optimized when optimize=True); None unless ok
    spirv_unopt: bytes | None  # front-end output, kept whenever the front end produced one
    diagnostics: list[Diagnostic]

    def errors(self) -> list[str]:
        """The error diagnostics as text; never empty for a failed job."""
        lines = [str(d) for d in self.diagnostics if d.severity == "error"]
        return lines or ([] if self.ok else [f"{self.key}: compile failed"])


class ToolMissing(EnvironmentMissing):
    """A required external tool is not installed."""

    def __init__(self, name: str):
        super().__init__(f"{name} not found — run `make setup` (scripts/setup.sh) in a clone, or put it on PATH "
                         f"or in a directory named by ${TOOLS_ENV}; `shadermatrix doctor` lists what is missing")
        self.tool = name


def find_tool(name: str) -> str | None:
    """Path of an executable: ``$SHADERMATRIX_TOOLS``, then the running environment's scripts directory
    (a venv's bin/), then ``PATH`` (see toolchain.locate); None when it is in none of them."""
    if os.environ.get("SHADERMATRIX_FORBID_TOOLS"):  # the test tiers: a unit test runs no external tool
        raise RuntimeError(f"external tool '{name}' used where none may run ({os.environ['SHADERMATRIX_FORBID_TOOLS']})")
    return shutil.which(name, path=os.pathsep.join(tool_dirs()))


def _need(name: str) -> str:
    path = find_tool(name)
    if path is None:
        raise ToolMissing(name)
    return path


class ToolsStopped(RuntimeError):
    """A tool was to start after stop_tools(): the build that ran it is ending."""


_RUNNING: set = set()  # the tool processes running now (any thread)
_RUNNING_LOCK = threading.RLock()  # re-entrant: the build's signal handler calls stop_tools() on the thread it interrupts, which may hold it
_STOPPED = threading.Event()


def stop_tools() -> None:
    """Kill every tool process this process is running, and start none until resume_tools(): an interrupted
    build ends now, not after the batch its compile thread had under way (its queued tools would start)."""
    _STOPPED.set()
    with _RUNNING_LOCK:
        running = list(_RUNNING)
    for proc in running:
        proc.kill()


def resume_tools() -> None:
    _STOPPED.clear()


def _run(args: list[str], cwd: str | None = None, env: dict | None = None) -> tuple[int, str]:
    """Run a tool; return (exit status, stdout+stderr decoded with errors=replace)."""
    if _STOPPED.is_set():
        raise ToolsStopped(f"{args[0]}: not started, the build is ending")
    proc = subprocess.Popen(args, cwd=cwd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            stdin=subprocess.DEVNULL)
    with _RUNNING_LOCK:
        _RUNNING.add(proc)
    try:
        if _STOPPED.is_set():  # stopped while it started: stop_tools did not see it
            proc.kill()
        out, _ = proc.communicate()
    except BaseException:  # Ctrl-C on the main thread (a --version): the tool goes too, as subprocess.run does
        proc.kill()
        proc.wait()
        raise
    finally:
        with _RUNNING_LOCK:
            _RUNNING.discard(proc)
    return proc.returncode, out.decode("utf-8", errors="replace")


def _version_of(name: str, parse) -> str:
    path = find_tool(name)
    if path is None:
        return "missing"
    try:
        _, out = _run([path, "--version"])
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
    val = _version_of("spirv-val", _search(r"SPIRV-Tools v(\S+)"))
    opt = _version_of("spirv-opt", _search(r"SPIRV-Tools v(\S+)"))
    return {
        "glslc": _version_of("glslc", _glslc_version),
        "glslang": _version_of("glslangValidator", _search(r"Glslang Version: (?:\d+:)?(\S+)")),
        "spirv-tools": val if val == opt else f"spirv-val {val}, spirv-opt {opt}",
        "naga": _version_of("naga", _search(r"^(\S+)")),
    }


# ---------------------------------------------------------------- diagnostics

def _map_line(job: CompileJob, line: int) -> tuple[str, int]:
    """Generated line of ``job`` -> (path, line) through ``job.line_map``."""
    if not job.line_map:
        return job.key, line
    idx = bisect.bisect_right([e[0] for e in job.line_map], line) - 1
    if idx < 0:
        return job.key, line
    gen, path, src = job.line_map[idx]
    return str(path), int(src) + line - int(gen)


_GLSLC_DIAG = re.compile(r"^(?P<path>.+?):(?:(?P<line>\d+):)? (?P<sev>(?:fatal )?error|warning): (?P<msg>.*)$")
_GLSLC_SUMMARY = re.compile(r"^\d+ (?:errors?|warnings?)( and \d+ warnings?)? generated\.$")


def _parse_glslc(text: str, job: CompileJob, src_name: str) -> list[Diagnostic]:
    diags: list[dict] = []
    for raw in text.splitlines():
        line = raw.rstrip()
        if not line or _GLSLC_SUMMARY.match(line):
            continue
        m = _GLSLC_DIAG.match(line)
        if not m:
            if diags:
                diags[-1]["message"] += " | " + line.strip()
            continue
        path, lineno = m["path"], int(m["line"] or 0)
        if path in (src_name, "glslc") or path.endswith("/" + src_name):
            path, lineno = _map_line(job, lineno)
        sev = "warning" if m["sev"] == "warning" else "error"
        msg = re.sub(r"^'' :\s+", "", m["msg"].strip())  # glslang's empty-token prefix
        diags.append(dict(path=path, line=lineno, col=0, severity=sev, message=msg, tool="glslc"))
    return [Diagnostic(**d) for d in diags]


_ANSI = re.compile(r"\x1b\[[0-9;]*[A-Za-z]")
_NAGA_HEAD = re.compile(r"^(?P<sev>error|warning)(?:\[[^\]]*\])?: (?P<msg>.*)$")
_NAGA_LOC = re.compile(r"^\s*┌─\s*(?P<path>.+?):(?P<line>\d+):(?P<col>\d+)")
_NAGA_NOTE = re.compile(r"^\s*= (?P<note>.*)$")
_NAGA_SOURCE = re.compile(r"^\s*(?P<line>\d+)\s+│")  # a numbered source line of the snippet
_NAGA_EXPR_LABEL = re.compile(r"\^+\s+naga::ir::Expression")


def _parse_naga(text: str, job: CompileJob) -> list[Diagnostic]:
    """naga's diagnostics. A validation error's header points at the whole function; the
    snippet underlines the offending expression below its source line, so that line wins."""
    diags: list[dict] = []
    source_line = 0
    for raw in _ANSI.sub("", text).splitlines():
        if m := _NAGA_HEAD.match(raw):
            diags.append(dict(path=job.key, line=0, col=0, severity=m["sev"], message=m["msg"].strip(), tool="naga"))
            source_line = 0
        elif diags and (m := _NAGA_LOC.match(raw)) and diags[-1]["line"] == 0:
            path, line = _map_line(job, int(m["line"]))
            diags[-1].update(path=path, line=line, col=int(m["col"]))
        elif diags and (m := _NAGA_SOURCE.match(raw)):
            source_line = int(m["line"])
        elif diags and source_line and _NAGA_EXPR_LABEL.search(raw):
            path, line = _map_line(job, source_line)
            diags[-1].update(path=path, line=line, col=0)  # the line map has no columns
        elif diags and (m := _NAGA_NOTE.match(raw)):
            diags[-1]["message"] += ": " + m["note"].strip()
    return [Diagnostic(**d) for d in diags]


def _parse_spirv_tool(text: str, job: CompileJob, tool: str) -> list[Diagnostic]:
    diags = []
    for line in text.splitlines():
        if m := re.match(r"^(error|warning): (.*)$", line.strip()):
            diags.append(Diagnostic(job.key, 0, 0, m[1], m[2].strip(), tool))
        elif diags and line.strip():
            d = diags[-1]
            diags[-1] = Diagnostic(d.path, d.line, d.col, d.severity, f"{d.message} | {line.strip()}", tool)
    return diags


def _failure(job: CompileJob, tool: str, rc: int, text: str) -> Diagnostic:
    tail = " | ".join(_ANSI.sub("", text).strip().splitlines()[-5:]) or "no output"
    return Diagnostic(job.key, 0, 0, "error", f"{tool} failed (exit status {rc}): {tail}", tool)


def _has_error(diags: list[Diagnostic]) -> bool:
    return any(d.severity == "error" for d in diags)


# ---------------------------------------------------------------- front ends

_Front = tuple[CompileJob, "bytes | None", list[Diagnostic]]


def _glslc_batch(glslc: str, tmp: str, items: list[tuple[int, CompileJob]],
                 sentinels: bool = False) -> list[_Front]:
    """Compile GLSL/HLSL jobs with one glslc process.

    Optimistic: without sentinels first. Only when glslc printed diagnostics
    for a batch of several jobs is the batch run again with a sentinel after
    every job, so that each message can be given to its job.
    """
    # -fhlsl-16bit-types: HLSL `half` is a real 16-bit float (DXC's -enable-16bit-types), what the fp16
    # HLSL target emits (backends/hlsl/emit.py HlslHalfTarget); fp32 HLSL never spells half, so its SPIR-V is unchanged
    args = [glslc, f"--target-env={TARGET_ENV}", "-fhlsl-16bit-types", "-c"]
    names: list[tuple[str, str, str]] = []
    for idx, job in items:
        src, out = f"j{idx:06d}.{job.language}", f"j{idx:06d}.spv"  # glslc: x.glsl -> x.spv
        sentinel = f"s{idx:06d}.{job.language}"  # same language: no front-end switch
        Path(tmp, src).write_text(job.source, encoding="utf-8")
        args += ["-x", job.language, f"-fshader-stage={job.stage}", f"-fentry-point={job.entry}", src]
        if sentinels:
            Path(tmp, sentinel).write_text(_SENTINEL_SRC[job.language])
            args.append(sentinel)
        names.append((src, out, sentinel))
    rc, text = _run(args, cwd=tmp)
    lines = text.splitlines()
    if not sentinels and len(items) > 1 and any(_GLSLC_DIAG.match(x) for x in lines):
        return _glslc_batch(glslc, tmp, items, sentinels=True)

    # Give each job its lines: job i's messages precede sentinel i's.
    chunks: list[list[str]] = [[] for _ in items]
    if sentinels:
        pos = 0
        for line in lines:
            if pos < len(items) and line.startswith(names[pos][2] + ":") and _SENTINEL in line:
                pos += 1
            elif pos < len(items):
                chunks[pos].append(line)
    elif len(items) == 1:
        chunks[0] = lines

    results: list[_Front] = []
    for (idx, job), (src, out, _), job_lines in zip(items, names, chunks):
        out_path = Path(tmp, out)
        spv = out_path.read_bytes() if out_path.is_file() else None
        diags = _parse_glslc("\n".join(job_lines), job, src)
        if spv is None and not _has_error(diags):
            if len(items) > 1:  # failed inside a batch with nothing said about it: retry alone
                results.extend(_glslc_batch(glslc, tmp, [(idx, job)]))
                continue
            diags.append(_failure(job, "glslc", rc, text))
        results.append((job, spv, diags))
    return results


def _naga_one(naga: str, tmp: str, idx: int, job: CompileJob) -> _Front:
    src, out = f"j{idx:06d}.wgsl", f"j{idx:06d}.spv"
    Path(tmp, src).write_text(job.source, encoding="utf-8")
    env = dict(os.environ, NO_COLOR="1", RUST_LOG="off")
    over = ["--override", ",".join(f"{n}={int(v)}" for n, v in job.overrides)] if job.overrides else []
    rc, text = _run([naga, "--spirv-version", SPIRV_VERSION, "--keep-coordinate-space", "--entry-point", job.entry,
                     *over, src, out],
                    cwd=tmp, env=env)
    out_path = Path(tmp, out)
    spv = out_path.read_bytes() if rc == 0 and out_path.is_file() else None
    diags = _parse_naga(text, job)
    if spv is None and not _has_error(diags):
        diags.append(_failure(job, "naga", rc, text))
    return job, spv, diags


# ---------------------------------------------------------------- SPIR-V steps

def _spirv_steps(tools: dict, tmp: str, idx: int, job: CompileJob, spv: bytes,
                 diags: list[Diagnostic], optimize: bool, validate: bool) -> CompileResult:
    diags = list(diags)
    unopt = Path(tmp, f"j{idx:06d}.spv")
    unopt.write_bytes(spv)

    def val(path: Path) -> bool:
        if not validate:
            return True
        rc, text = _run([tools["spirv-val"], "--target-env", TARGET_ENV, str(path)])
        if rc == 0:
            return True
        found = _parse_spirv_tool(text, job, "spirv-val")
        diags.extend(found if _has_error(found) else [_failure(job, "spirv-val", rc, text)])
        return False

    if not optimize:
        if not val(unopt):
            return CompileResult(job.key, False, None, spv, diags)
        return CompileResult(job.key, True, spv, spv, diags)
    # No spirv-val before spirv-opt: spirv-opt validates its input itself (for the same target environment)
    # and refuses an invalid module with the validator's message; the result is validated below.
    opt = Path(tmp, f"j{idx:06d}.opt.spv")
    rc, text = _run([tools["spirv-opt"], f"--target-env={TARGET_ENV}", "-O", str(unopt), "-o", str(opt)])
    if rc != 0 or not opt.is_file():
        found = _parse_spirv_tool(text, job, "spirv-opt")
        diags.extend(found if _has_error(found) else [_failure(job, "spirv-opt", rc, text)])
        return CompileResult(job.key, False, None, spv, diags)
    if not val(opt):
        return CompileResult(job.key, False, None, spv, diags)
    return CompileResult(job.key, True, opt.read_bytes(), spv, diags)


# ---------------------------------------------------------------- driver

_SELF_HASH = hashlib.sha256(Path(__file__).read_bytes()).hexdigest()  # how the tools are invoked
COMPILE_NAMESPACE = "compile-v1"


def _normalized(source: str) -> str:
    """The source without its whole-line ``//`` comments (the provenance header): comments never reach
    SPIR-V (no debug info is emitted), so shaders that differ only there compile to the same module."""
    return "\n".join(line for line in source.split("\n") if not line.lstrip().startswith("//"))


def cache_key(job: CompileJob, optimize: bool = True, validate: bool = True) -> str:
    """sha256 of everything that determines a job's SPIR-V: source (comments aside), language, stage, entry
    point, overrides, target environment, SPIR-V version, flags, generator version, the tools' exact
    versions and this module (how they are invoked). A tool upgrade changes every key."""
    from .. import __version__
    return content_key(COMPILE_NAMESPACE, _normalized(job.source), job.language, job.stage, job.entry,
                       [list(o) for o in job.overrides], TARGET_ENV, SPIRV_VERSION, optimize, validate,
                       __version__, tool_versions(), _SELF_HASH)


def _encode(r: CompileResult) -> bytes:
    return json.dumps({"spirv": base64.b64encode(r.spirv).decode(),
                       "spirv_unopt": base64.b64encode(r.spirv_unopt or b"").decode(),
                       "diagnostics": [asdict(d) for d in r.diagnostics], "key": r.key}).encode()


def _decode(data: bytes, key: str) -> CompileResult | None:
    try:
        d = json.loads(data)
        diags = [Diagnostic(**x) for x in d["diagnostics"]]
        spirv, unopt = base64.b64decode(d["spirv"]), base64.b64decode(d["spirv_unopt"])
    except (ValueError, KeyError, TypeError):
        return None
    return _renamed(CompileResult(d["key"], True, spirv, unopt or None, diags), key)


def _renamed(r: CompileResult, key: str) -> CompileResult:
    """A result for another job with the same cache key: diagnostics that named the first job name this one."""
    diags = [replace(d, path=key) if d.path == r.key else d for d in r.diagnostics]
    return CompileResult(key, r.ok, r.spirv, r.spirv_unopt, diags)


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
                 workers: int | None = None, executor=None, memo: dict | None = None) -> dict[str, CompileResult]:
    """Compile and validate every job; returns {key: CompileResult} in input order.

    Jobs with the same :func:`cache_key` are compiled once (identical shaders, e.g. vertex shaders whose
    sources differ only in their provenance header). store: an io.Store; a job whose key is there is
    served from it (no tool runs) and every successful compile is put there. Failures are not stored
    (their diagnostics name each job's own lines), and a job whose twin failed is compiled on its own.
    memo: a dict (cache key -> result) shared by several calls of one build: a shader another call
    compiled is not compiled again (and not counted distinct again).
    stats: a CompileStats to fill in. workers: how many tool processes run at once (default: the core
    count). executor: where the compiles run instead of here (toolchain/dask.py: a Dask cluster); the
    store, deduplication and results are the same wherever they ran.

    Raises ToolMissing if a tool the jobs need is absent, ValueError on a
    malformed job (duplicate key, unknown language or stage).
    """
    jobs = list(jobs)
    seen: set[str] = set()
    for job in jobs:
        if job.key in seen:
            raise ValueError(f"duplicate compile job key {job.key!r}")
        if job.language not in LANGUAGES or job.stage not in STAGES:
            raise ValueError(f"{job.key}: unknown language/stage {job.language!r}/{job.stage!r}")
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
                results[job.key] = _renamed(memo[ck], job.key)
            continue
        stats.distinct += 1
        data = store.get(COMPILE_NAMESPACE, ck) if store is not None else None
        hit = _decode(data, members[0].key) if data is not None else None
        if hit is not None:
            stats.cached += 1
            if memo is not None:
                memo[ck] = hit
            for job in members:
                results[job.key] = _renamed(hit, job.key)
        else:
            todo.append(members[0])
    run = executor.compile if executor is not None else _compile_all
    fresh = run(todo, optimize, validate, progress, workers)
    stats.compiled += len(todo)
    stats.fresh.update(keys[job.key] for job in todo)
    again = []
    for first in todo:
        r = fresh[first.key]
        members = groups[keys[first.key]]
        if r.ok:
            if store is not None:
                store.put(COMPILE_NAMESPACE, keys[first.key], _encode(r))
            if memo is not None:
                memo[keys[first.key]] = r
            for job in members:
                results[job.key] = _renamed(r, job.key)
        else:
            results[first.key] = r
            again += members[1:]
    if again:  # a failed shader's twins: each reports its own lines
        stats.compiled += len(again)
        results.update(run(again, optimize, validate, progress, workers))
    return {job.key: results[job.key] for job in jobs}


def _compile_all(jobs: list[CompileJob], optimize: bool, validate: bool, progress: bool,
                 workers: int | None = None) -> dict[str, CompileResult]:
    """Run the tools on every job (no store, no deduplication), `workers` tool processes at a time."""
    if not jobs:
        return {}
    tools: dict[str, str] = {}
    if any(j.language in ("glsl", "hlsl") for j in jobs):
        tools["glslc"] = _need("glslc")
    if any(j.language == "wgsl" for j in jobs):
        tools["naga"] = _need("naga")
    if validate:
        tools["spirv-val"] = _need("spirv-val")
    if optimize:
        tools["spirv-opt"] = _need("spirv-opt")

    from tqdm import tqdm

    workers = max(1, workers or os.cpu_count() or 1)
    index = {job.key: i for i, job in enumerate(jobs)}
    results: dict[str, CompileResult] = {}
    batchable = [(i, j) for i, j in enumerate(jobs) if j.language != "wgsl"]
    n_chunks = max(min(workers, len(batchable) // 8), -(-len(batchable) // _MAX_BATCH), 1 if batchable else 0)
    with tempfile.TemporaryDirectory(prefix=f"shadermatrix-{os.getpid()}-") as tmp, \
            ThreadPoolExecutor(max_workers=workers) as pool, \
            tqdm(total=len(jobs), disable=not progress, unit="shader", leave=False) as bar:
        front = [pool.submit(_glslc_batch, tools["glslc"], tmp, batchable[k::n_chunks])
                 for k in range(n_chunks)]
        front += [pool.submit(lambda i, j: [_naga_one(tools["naga"], tmp, i, j)], i, j)
                  for i, j in enumerate(jobs) if j.language == "wgsl"]
        back = []
        for fut in as_completed(front):
            for job, spv, diags in fut.result():
                if spv is None:
                    results[job.key] = CompileResult(job.key, False, None, None, diags)
                    bar.update()
                else:
                    back.append(pool.submit(_spirv_steps, tools, tmp, index[job.key], job, spv,
                                            diags, optimize, validate))
        for fut in as_completed(back):
            res = fut.result()
            results[res.key] = res
            bar.update()
    return {job.key: results[job.key] for job in jobs}
