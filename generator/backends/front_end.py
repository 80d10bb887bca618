"""How a shading language's text becomes SPIR-V: which compiler runs it and what the language asks of that
compiler. Each back end declares one (its context.py, on its Language); the toolchain reads the declaration and
has no branch on a language's name, so a language is added by adding its package.

The drivers (generator/toolchain/frontends.py) own what every language gets alike: the target environment, the
SPIR-V version, the stage and the entry point. A declaration holds only what differs between languages.
"""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class FrontEnd:
    # The driver: "glslc" (glslang: many files in one process, the language named per file) or "naga" (one
    # file per run).
    tool: str
    # Given before each file of this language (glslc: "-x", "hlsl"; naga: its translation options).
    flags: tuple[str, ...] = ()
    # Given once to a process that compiles at least one file of this language. One glslc process compiles
    # files of several languages, so such a flag must change nothing for the others (HLSL's 16-bit types).
    process_flags: tuple[str, ...] = ()
    # glslc only: a file in this language that always fails with `#error {message}` (the driver fills in the
    # message). A batch that printed diagnostics is rerun with one after each file, whose error closes the
    # previous file's messages; in the same language as the file, so glslang does not switch front ends.
    sentinel: str = ""

    def key(self) -> list:
        """What of this declaration decides a module's bytes (part of the toolchain's cache keys): the sentinel
        only splits messages, so it is not here."""
        return [self.tool, list(self.flags), list(self.process_flags)]
