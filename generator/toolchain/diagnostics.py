"""The tools' messages as Diagnostics, located at brick lines.

GLSL/HLSL sources carry ``#line N "bricks/x.py"`` (GLSL with ``#extension GL_GOOGLE_cpp_style_line_directive :
require``); glslc then reports ``bricks/x.py:N: error: ...`` (no column: col 0). Lines outside any ``#line`` are
reported against the job key. naga reports ``┌─ file.wgsl:LINE:COL``; those lines go through
``CompileJob.line_map``. spirv-opt and spirv-val name no source line: their messages are the job key's.
"""
from __future__ import annotations

import bisect
import re

from .model import CompileJob, Diagnostic


def map_line(job: CompileJob, line: int) -> tuple[str, int]:
    """Generated line of ``job`` -> (path, line) through ``job.line_map``."""
    if not job.line_map:
        return job.key, line
    idx = bisect.bisect_right([e[0] for e in job.line_map], line) - 1
    if idx < 0:
        return job.key, line
    gen, path, src = job.line_map[idx]
    return str(path), int(src) + line - int(gen)


GLSLC_DIAG = re.compile(r"^(?P<path>.+?):(?:(?P<line>\d+):)? (?P<sev>(?:fatal )?error|warning): (?P<msg>.*)$")
_GLSLC_SUMMARY = re.compile(r"^\d+ (?:errors?|warnings?)( and \d+ warnings?)? generated\.$")


def parse_glslc(text: str, job: CompileJob, src_name: str) -> list[Diagnostic]:
    diags: list[dict] = []
    for raw in text.splitlines():
        line = raw.rstrip()
        if not line or _GLSLC_SUMMARY.match(line):
            continue
        m = GLSLC_DIAG.match(line)
        if not m:
            if diags:
                diags[-1]["message"] += " | " + line.strip()
            continue
        path, lineno = m["path"], int(m["line"] or 0)
        if path in (src_name, "glslc") or path.endswith("/" + src_name):
            path, lineno = map_line(job, lineno)
        sev = "warning" if m["sev"] == "warning" else "error"
        msg = re.sub(r"^'' :\s+", "", m["msg"].strip())  # glslang's empty-token prefix
        diags.append(dict(path=path, line=lineno, col=0, severity=sev, message=msg, tool="glslc"))
    return [Diagnostic(**d) for d in diags]


ANSI = re.compile(r"\x1b\[[0-9;]*[A-Za-z]")
_NAGA_HEAD = re.compile(r"^(?P<sev>error|warning)(?:\[[^\]]*\])?: (?P<msg>.*)$")
_NAGA_LOC = re.compile(r"^\s*┌─\s*(?P<path>.+?):(?P<line>\d+):(?P<col>\d+)")
_NAGA_NOTE = re.compile(r"^\s*= (?P<note>.*)$")
_NAGA_SOURCE = re.compile(r"^\s*(?P<line>\d+)\s+│")  # a numbered source line of the snippet
_NAGA_EXPR_LABEL = re.compile(r"\^+\s+naga::ir::Expression")


def parse_naga(text: str, job: CompileJob) -> list[Diagnostic]:
    """naga's diagnostics. A validation error's header points at the whole function; the
    snippet underlines the offending expression below its source line, so that line wins."""
    diags: list[dict] = []
    source_line = 0
    for raw in ANSI.sub("", text).splitlines():
        if m := _NAGA_HEAD.match(raw):
            diags.append(dict(path=job.key, line=0, col=0, severity=m["sev"], message=m["msg"].strip(), tool="naga"))
            source_line = 0
        elif diags and (m := _NAGA_LOC.match(raw)) and diags[-1]["line"] == 0:
            path, line = map_line(job, int(m["line"]))
            diags[-1].update(path=path, line=line, col=int(m["col"]))
        elif diags and (m := _NAGA_SOURCE.match(raw)):
            source_line = int(m["line"])
        elif diags and source_line and _NAGA_EXPR_LABEL.search(raw):
            path, line = map_line(job, source_line)
            diags[-1].update(path=path, line=line, col=0)  # the line map has no columns
        elif diags and (m := _NAGA_NOTE.match(raw)):
            diags[-1]["message"] += ": " + m["note"].strip()
    return [Diagnostic(**d) for d in diags]


def parse_spirv_tool(text: str, job: CompileJob, tool: str) -> list[Diagnostic]:
    diags = []
    for line in text.splitlines():
        if m := re.match(r"^(error|warning): (.*)$", line.strip()):
            diags.append(Diagnostic(job.key, 0, 0, m[1], m[2].strip(), tool))
        elif diags and line.strip():
            d = diags[-1]
            diags[-1] = Diagnostic(d.path, d.line, d.col, d.severity, f"{d.message} | {line.strip()}", tool)
    return diags


def failure(job: CompileJob, tool: str, rc: int, text: str) -> Diagnostic:
    """The error of a tool that failed without a message this module can read (a crash, an unknown format)."""
    tail = " | ".join(ANSI.sub("", text).strip().splitlines()[-5:]) or "no output"
    return Diagnostic(job.key, 0, 0, "error", f"{tool} failed (exit status {rc}): {tail}", tool)


def has_error(diags: list[Diagnostic]) -> bool:
    return any(d.severity == "error" for d in diags)
