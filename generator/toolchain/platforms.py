"""The platforms' own tools: glslangValidator for OpenGL GLSL and GLSL ES, dxc for DXIL when present.

- **OpenGL / ES** (`validate_dialects`): glslangValidator *without* `-V`/`-G` validates GLSL for OpenGL
  (GLSL 4.50 core, `#version 450 core`) and GLSL ES (`#version 310 es`: ES rules, precision
  qualifiers) with the OpenGL front end's rules — the Vulkan-only features (separate samplers,
  descriptor sets, `constant_id`) are errors there. One process validates a batch of files (each a
  compilation unit of its own; the file extension gives the stage); it prints each file's name and
  then that file's messages (`ERROR: 0:LINE: what`), which are mapped back to the brick line through
  the source's line map (GL sources carry no `#line`: backends/gl/emit.py). Measured here: ~0.1 s for a
  batch of 20 shaders, most of it the process start.
  A valid source is remembered in the content-addressed store (namespace ``gl-validate-v1``, keyed by
  the text without its comments, the dialect, the stage, glslang's exact version and this module), so
  a rebuild validates only what changed; failures are never stored.
- **D3D12** (`compile_dxil`): DXC (https://github.com/microsoft/DirectXShaderCompiler/releases: the
  `dxc` of a release archive, or the Vulkan SDK's) compiles the HLSL to DXIL when it is on PATH; Shader
  Model 6.0 (`vs_6_0`/`ps_6_0`), 6.2 with `-enable-16bit-types` for fp16 keys (16-bit arithmetic
  needs SM 6.2). Without it the d3d12 platform ships HLSL only and says so in the manifest.
"""
from __future__ import annotations

import functools
import hashlib
import os
import re
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from ..io import content_key
from .. import toolchain as _tc  # find_tool read at call time (tests replace it on the package)
from .cache import normalized
from .diagnostics import map_line
from .model import CompileJob, Diagnostic
from .run import Gate, ToolMissing, run, tool_versions

NAMESPACE = "gl-validate-v1"
_SELF_HASH = hashlib.sha256(Path(__file__).read_bytes()).hexdigest()
_MESSAGE = re.compile(r"^(?P<sev>ERROR|WARNING): (?:(?P<src>\d+):(?P<line>\d+): )?(?P<msg>.*)$")
_SUMMARY = re.compile(r"^ERROR: \d+ compilation errors?\.")
DX_PROFILES = {("vert", "fp32"): "vs_6_0", ("frag", "fp32"): "ps_6_0",
               ("vert", "fp16"): "vs_6_2", ("frag", "fp16"): "ps_6_2"}


def validation_key(job: CompileJob) -> str:
    return content_key(NAMESPACE, normalized(job.source), job.language, job.stage, tool_versions()["glslang"],
                       _SELF_HASH)


def validate_dialects(jobs: list[CompileJob], store=None, workers: int | None = None,
                      gate: Gate | None = None) -> dict[str, list[str]]:
    """{job key: errors as `path:line:col: error: what [glslang]`} for GL/ES jobs (language "gl" or "essl");
    an empty list means valid. gate: the build's (run.Gate), or None. Raises ToolMissing without glslangValidator."""
    errors: dict[str, list[str]] = {}
    todo = []
    for job in jobs:
        if store is not None and store.get(NAMESPACE, validation_key(job)) is not None:
            errors[job.key] = []
        else:
            todo.append(job)
    if not todo:
        return {j.key: errors[j.key] for j in jobs}
    tool = _tc.find_tool("glslangValidator")
    if tool is None:
        raise ToolMissing("glslangValidator")
    n = max(1, min(workers or os.cpu_count() or 1, -(-len(todo) // 16)))
    with tempfile.TemporaryDirectory(prefix=f"shadermatrix-{os.getpid()}-gl-") as tmp, ThreadPoolExecutor(n) as pool:
        for part in pool.map(lambda k: _batch(tool, tmp, list(enumerate(todo))[k::n], gate), range(n)):
            errors.update(part)
    if store is not None:
        for job in todo:
            if not errors[job.key]:
                store.put(NAMESPACE, validation_key(job), b"ok")
    return {j.key: errors[j.key] for j in jobs}


def _batch(tool: str, tmp: str, items: list[tuple[int, CompileJob]], gate: Gate | None) -> dict[str, list[str]]:
    names = {}
    for idx, job in items:
        name = f"g{idx:06d}.{job.stage}"  # the extension is the stage
        Path(tmp, name).write_text(job.source, encoding="utf-8")
        names[name] = job
    rc, text = run([tool, *names], cwd=tmp, gate=gate)
    out: dict[str, list[str]] = {job.key: [] for job in names.values()}
    current = None
    for raw in text.splitlines():
        line = raw.strip()
        if line in names:
            current = names[line]
            continue
        m = _MESSAGE.match(line)
        if current is None or not m or _SUMMARY.match(line) or m["sev"] != "ERROR":
            continue
        if "compilation terminated" in m["msg"]:  # glslang's trailer after the real error, with or without a line
            continue
        path, lineno = map_line(current, int(m["line"])) if m["line"] else (current.key, 0)
        msg = re.sub(r"^'' :\s+", "", m["msg"].strip())
        out[current.key].append(str(Diagnostic(path, lineno, 0, "error", msg, "glslang")))
    if rc != 0 and not any(out.values()):  # a failure glslang gave no message for (a crash): never silent
        tail = " | ".join(text.strip().splitlines()[-3:]) or "no output"
        for job in names.values():
            out[job.key].append(f"{job.key}:0:0: error: glslangValidator failed (exit status {rc}): {tail} [glslang]")
    return out


def dxc_version() -> str:
    """dxc's version line, or "missing" (the d3d12 platform then ships HLSL without DXIL)."""
    path = _tc.find_tool("dxc")
    return "missing" if path is None else _dxc_version_at(path)


@functools.lru_cache(maxsize=4)
def _dxc_version_at(path: str) -> str:
    """Once per process and dxc path (a build asks for every permutation's d3d12 tools, as tool_versions is)."""
    try:
        _, out = run([path, "--version"])
    except OSError as exc:
        return f"unusable ({exc.strerror})"
    return (out.strip().splitlines() or ["unknown"])[0]


def compile_dxil(job: CompileJob, precision: str = "fp32", gate: Gate | None = None) -> tuple[bytes | None, list[str]]:
    """(DXIL, errors) of one HLSL job with dxc; (None, []) when dxc is not on PATH. gate: the build's, or None."""
    path = _tc.find_tool("dxc")
    if path is None:
        return None, []
    profile = DX_PROFILES[(job.stage, precision)]
    with tempfile.TemporaryDirectory(prefix=f"shadermatrix-{os.getpid()}-dxc-") as tmp:
        src, out = Path(tmp, "in.hlsl"), Path(tmp, "out.dxil")
        src.write_text(job.source, encoding="utf-8")
        args = [path, "-T", profile, "-E", job.entry, *(["-enable-16bit-types"] if precision == "fp16" else []),
                "-Fo", str(out), str(src)]
        rc, text = run(args, cwd=tmp, gate=gate)
        if rc != 0 or not out.is_file():
            return None, [f"{job.key}:0:0: error: dxc: {line}" for line in text.strip().splitlines()[:8]] or \
                [f"{job.key}:0:0: error: dxc failed (exit status {rc})"]
        return out.read_bytes(), []
