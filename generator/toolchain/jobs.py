"""Compile jobs of composed sources, named by their unit, stage and language (what every caller of compile_many
looks results up by). Any object with language, stage, text and line_map is a source: the toolchain reads
composed text, it does not compose."""
from __future__ import annotations

from . import CompileJob


def job_key(name: str, stage: str, lang: str) -> str:
    """The key of unit `name`'s (a permutation hash, "ubershader") `stage` shader in `lang`."""
    return f"{name}.{stage}.{lang}"


def source_jobs(name: str, sources) -> list[CompileJob]:
    """One compile job per source of unit `name`."""
    return [CompileJob(job_key(name, s.stage, s.language), s.language, s.stage, s.text, line_map=tuple(s.line_map))
            for s in sources]
