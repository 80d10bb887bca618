"""The front ends: a source in a shading language -> SPIR-V 1.3 for vulkan1.1, by the driver its back end names.

A back end declares its front end (generator.backends.FrontEnd, on its Language): the driver and what the
language asks of it. The drivers here know the compilers and nothing of the languages:

- ``glslc``: many files in one process (``-x``/``-fshader-stage``/``-fentry-point`` apply to the files after
  them, so GLSL and HLSL of all stages share a batch). glslc carries on past a failing file and still writes
  the other outputs, but its diagnostics name the ``#line`` path, not the input file. So when a batch prints
  anything, it is rerun with the language's *sentinel* file after each input, which always fails with
  ``#error SHADERMATRIX_SENTINEL``; the sentinel's message closes the previous job's diagnostics. A job that
  has no output and no parsed error (a crash, an unknown message format) is recompiled alone.
- ``naga``: one process per file (naga converts one input per run), about 2 ms each, with the job's
  pipeline-overridable constants resolved.
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from ..backends import FRONT_ENDS, FrontEnd
from .diagnostics import GLSLC_DIAG, failure, has_error, parse_glslc, parse_naga
from .model import SPIRV_VERSION, TARGET_ENV, CompileJob, Diagnostic
from .run import Gate

SENTINEL = "SHADERMATRIX_SENTINEL"

Front = tuple[CompileJob, "bytes | None", list[Diagnostic]]  # a job, its front end's module (None: failed), messages


def front_end(job: CompileJob) -> FrontEnd:
    return FRONT_ENDS[job.language]


def _ordered(groups) -> list[str]:
    """The flags of several tuples once each, in first-seen order."""
    return list(dict.fromkeys(flag for group in groups for flag in group))


def glslc_batch(glslc: str, tmp: str, items: list[tuple[int, CompileJob]], gate: Gate,
                sentinels: bool = False) -> list[Front]:
    """Compile jobs with one glslc process.

    Optimistic: without sentinels first. Only when glslc printed diagnostics
    for a batch of several jobs is the batch run again with a sentinel after
    every job, so that each message can be given to its job.
    """
    ends = [front_end(job) for _, job in items]
    args = [glslc, f"--target-env={TARGET_ENV}", *_ordered(fe.process_flags for fe in ends), "-c"]
    names: list[tuple[str, str, str]] = []
    for (idx, job), fe in zip(items, ends):
        src, out = f"j{idx:06d}.{job.language}", f"j{idx:06d}.spv"  # glslc: x.glsl -> x.spv
        sentinel = f"s{idx:06d}.{job.language}"
        Path(tmp, src).write_text(job.source, encoding="utf-8")
        args += [*fe.flags, f"-fshader-stage={job.stage}", f"-fentry-point={job.entry}", src]
        if sentinels:
            Path(tmp, sentinel).write_text(fe.sentinel.format(message=SENTINEL), encoding="utf-8")
            args.append(sentinel)
        names.append((src, out, sentinel))
    rc, text = gate.run(args, cwd=tmp)
    lines = text.splitlines()
    if not sentinels and len(items) > 1 and any(GLSLC_DIAG.match(x) for x in lines):
        return glslc_batch(glslc, tmp, items, gate, sentinels=True)

    # Give each job its lines: job i's messages precede sentinel i's.
    chunks: list[list[str]] = [[] for _ in items]
    if sentinels:
        pos = 0
        for line in lines:
            if pos < len(items) and line.startswith(names[pos][2] + ":") and SENTINEL in line:
                pos += 1
            elif pos < len(items):
                chunks[pos].append(line)
    elif len(items) == 1:
        chunks[0] = lines

    results: list[Front] = []
    for (idx, job), (src, out, _), job_lines in zip(items, names, chunks):
        out_path = Path(tmp, out)
        spv = out_path.read_bytes() if out_path.is_file() else None
        diags = parse_glslc("\n".join(job_lines), job, src)
        if spv is None and not has_error(diags):
            if len(items) > 1:  # failed inside a batch with nothing said about it: retry alone
                results.extend(glslc_batch(glslc, tmp, [(idx, job)], gate))
                continue
            diags.append(failure(job, "glslc", rc, text))
        results.append((job, spv, diags))
    return results


def naga_batch(naga: str, tmp: str, items: list[tuple[int, CompileJob]], gate: Gate) -> list[Front]:
    """Translate each job with a naga process of its own (naga reads one file per run)."""
    return [_naga_one(naga, tmp, idx, job, gate) for idx, job in items]


def _naga_one(naga: str, tmp: str, idx: int, job: CompileJob, gate: Gate) -> Front:
    src, out = f"j{idx:06d}.{job.language}", f"j{idx:06d}.spv"
    Path(tmp, src).write_text(job.source, encoding="utf-8")
    env = dict(os.environ, NO_COLOR="1", RUST_LOG="off")
    over = ["--override", ",".join(f"{n}={int(v)}" for n, v in job.overrides)] if job.overrides else []
    rc, text = gate.run([naga, "--spirv-version", SPIRV_VERSION, *front_end(job).flags, "--entry-point", job.entry,
                         *over, src, out], cwd=tmp, env=env)
    out_path = Path(tmp, out)
    spv = out_path.read_bytes() if rc == 0 and out_path.is_file() else None
    diags = parse_naga(text, job)
    if spv is None and not has_error(diags):
        diags.append(failure(job, "naga", rc, text))
    return job, spv, diags


@dataclass(frozen=True)
class Driver:
    """How a compiler is run: the executable, its batch function and how many jobs one process takes."""

    tool: str
    batch: object  # (tool path, temp dir, [(index, job)], gate) -> [Front]
    most: int  # jobs per process at most
    least: int  # jobs per process at least before the jobs are spread over more processes than one per worker

    def parts(self, items: list, workers: int) -> list[list]:
        """`items` dealt into batches: one per worker (each of at least `least`), as many more as `most` needs."""
        n = max(min(workers, len(items) // self.least), -(-len(items) // self.most), 1)
        return [items[k::n] for k in range(n)]


# Measured on 2 cores (Debian glslc 2023.2, 50 small fragment shaders): one glslc process for all 50 takes 0.16 s
# (GLSL) against 5.4 s for a process each; at 8 jobs a batch that start-up is already paid for.
DRIVERS: dict[str, Driver] = {
    "glslc": Driver("glslc", glslc_batch, most=256, least=8),
    "naga": Driver("naga", naga_batch, most=1, least=1),
}


def check(job: CompileJob) -> None:
    """ValueError for a job whose language has no front end this toolchain drives."""
    fe = FRONT_ENDS.get(job.language)
    if fe is None:
        raise ValueError(f"{job.key}: unknown language/stage {job.language!r}/{job.stage!r} "
                         f"(shading languages: {', '.join(FRONT_ENDS)})")
    if fe.tool not in DRIVERS:
        raise ValueError(f"{job.key}: the front end of {job.language} names the tool {fe.tool!r}, which "
                         f"generator/toolchain/frontends.py has no driver for (drivers: {', '.join(DRIVERS)})")
