"""What the toolchain is given and gives back: compile jobs, their results and diagnostics, and the target every
tool is held to."""
from __future__ import annotations

from dataclasses import dataclass, field

TARGET_ENV = "vulkan1.1"      # every tool gets this target environment
SPIRV_VERSION = "1.3"         # what glslc emits for vulkan1.1; naga is told the same
SPIRV_MAGIC = 0x07230203
STAGES = ("vert", "frag", "comp")


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
    language: str       # a shading language of generator.backends (its front end compiles the source)
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
    # the tools' seconds for this shader (cache.apportion: its share of its front-end batch and its own SPIR-V
    # steps), as the store recorded them when it was served from there; None when not known (an entry stored
    # before times were recorded). Not compared: two compiles of one shader are the same result.
    seconds: float | None = field(default=None, compare=False)
    cache_key: str | None = field(default=None, compare=False)  # compile_many's: the jobs one compile served

    def errors(self) -> list[str]:
        """The error diagnostics as text; never empty for a failed job."""
        lines = [str(d) for d in self.diagnostics if d.severity == "error"]
        return lines or ([] if self.ok else [f"{self.key}: compile failed"])
