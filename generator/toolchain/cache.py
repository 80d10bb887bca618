"""Compile cache keys, and results as the content-addressed store keeps them, each with its compile time.

The time an entry records (CompileResult.seconds, "seconds" in the entry) is what the tools spent on that one
shader: the front ends compile many shaders per process (a glslc batch, a naga loop), so a batch's wall time is
apportioned over its shaders in proportion to their source size in bytes (equally when every source is empty),
and each shader's own SPIR-V steps (spirv-opt, spirv-val: one process each, per shader) are added as measured.
Wall time, on a machine shared by the other tool processes of the build: a figure for comparing shaders and
features, not a benchmark. `matrix --explain` sums these records per axis value.
"""
from __future__ import annotations

import base64
import hashlib
import json
from dataclasses import asdict, replace
from pathlib import Path

from ..io import content_key
from .frontends import front_end
from .model import SPIRV_VERSION, TARGET_ENV, CompileJob, CompileResult, Diagnostic

COMPILE_NAMESPACE = "compile-v1"
# How the tools are invoked and what is kept of their answers: the modules that write the command lines, read
# the messages and encode the results (a change in any of them must not be served an old result).
_INVOCATION = ("model.py", "frontends.py", "spirv.py", "diagnostics.py", "cache.py")
_SELF_HASH = hashlib.sha256(b"".join(Path(__file__).with_name(name).read_bytes() for name in _INVOCATION)).hexdigest()


def normalized(source: str) -> str:
    """The source without its whole-line ``//`` comments (the provenance header): comments never reach
    SPIR-V (no debug info is emitted), so shaders that differ only there compile to the same module."""
    return "\n".join(line for line in source.split("\n") if not line.lstrip().startswith("//"))


def cache_key(job: CompileJob, optimize: bool = True, validate: bool = True) -> str:
    """sha256 of everything that determines a job's SPIR-V: source (comments aside), language and the front end
    its back end declares, stage, entry point, overrides, target environment, SPIR-V version, flags, generator
    version, the tools' exact versions and the modules that invoke them. A tool upgrade changes every key."""
    from .. import __version__, toolchain  # tool_versions read at call time: tests replace it on the package
    return content_key(COMPILE_NAMESPACE, normalized(job.source), job.language, front_end(job).key(), job.stage,
                       job.entry, [list(o) for o in job.overrides], TARGET_ENV, SPIRV_VERSION, optimize, validate,
                       __version__, toolchain.tool_versions(), _SELF_HASH)


def apportion(seconds: float, jobs) -> dict[str, float]:
    """{job key: its share of a batch's `seconds`}, in proportion to each job's source size (equal shares when
    every source is empty): a front end compiles a batch in one process and says nothing of each shader's time."""
    jobs = list(jobs)
    sizes = [len(j.source) for j in jobs]
    total = sum(sizes)
    return {j.key: seconds * (n / total if total else 1 / len(jobs)) for j, n in zip(jobs, sizes)}


def encode(r: CompileResult) -> bytes:
    return json.dumps({"spirv": base64.b64encode(r.spirv).decode(),
                       "spirv_unopt": base64.b64encode(r.spirv_unopt or b"").decode(),
                       "diagnostics": [asdict(d) for d in r.diagnostics], "key": r.key,
                       "seconds": None if r.seconds is None else round(r.seconds, 6)}).encode()


def decode(data: bytes, key: str) -> CompileResult | None:
    """A stored result for job `key`, or None when the entry does not read as one (an entry without a time reads,
    its seconds None)."""
    try:
        d = json.loads(data)
        diags = [Diagnostic(**x) for x in d["diagnostics"]]
        spirv, unopt = base64.b64decode(d["spirv"]), base64.b64decode(d["spirv_unopt"])
        seconds = d.get("seconds")
        seconds = float(seconds) if isinstance(seconds, (int, float)) and not isinstance(seconds, bool) else None
    except (ValueError, KeyError, TypeError, AttributeError):
        return None
    return renamed(CompileResult(d["key"], True, spirv, unopt or None, diags, seconds), key)


def renamed(r: CompileResult, key: str) -> CompileResult:
    """A result for another job with the same cache key: diagnostics that named the first job name this one."""
    diags = [replace(d, path=key) if d.path == r.key else d for d in r.diagnostics]
    return CompileResult(key, r.ok, r.spirv, r.spirv_unopt, diags, r.seconds, r.cache_key)
