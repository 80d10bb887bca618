"""Per-permutation compile checks an engine's CI runs: `shadermatrix check` and the pytest plugin share them.

A check is one permutation of a scene on one platform, validated by the
tools that validate what `build --platform` ships for it (assemble/platforms.py):

    platform  what a check compiles and validates                       golden sources
    vulkan    GLSL, HLSL and WGSL to SPIR-V (glslc, glslang, naga),      vulkan/<hash>.<stage>.{glsl,hlsl,wgsl}
              spirv-val, spirv-opt — every language, one check
    d3d12     HLSL (Shader Model 6, `register(xN, spaceM)`) by glslang's d3d12/<hash>.<stage>.hlsl
              HLSL front end, spirv-val; DXIL by dxc when it is on PATH
    gl        GLSL 4.50 core and GLSL ES 3.10 by glslangValidator in      gl/<hash>.<stage>.glsl, and .essl where
              OpenGL mode; an ES failure is a note ("unsupported", as     ES validates
              `build` records it), a core failure fails the check
    webgpu    WGSL by naga, then spirv-val                               webgpu/<hash>.<stage>.wgsl

All checks asked for at once are composed once per permutation and compiled in one batch (identical
shaders once, through the compile cache); a failure reads as the brick line that caused it (the
compilers' diagnostics are mapped back through #line, or the GL sources' line map). Golden sources are
named by permutation, not by content, so a drift is a diff of one file. `languages` narrows what is
checked as `BuildContext(languages=...)` narrows what is built: a platform is checked when one of the
languages it is made from (its class's ``checked_from``; vulkan: any) is given, and vulkan compiles only
those given. (`build` is narrower: it writes a platform only when its platforms.PLATFORM_TABLE made_from is built,
so vulkan needs GLSL there.)
"""
from __future__ import annotations

import difflib
from dataclasses import dataclass, field
from pathlib import Path

from ..library.bricks import Library
from ..scene.load import Scene
from ..backends import LANGUAGES
from .platforms import DIALECTS, EXT, PLATFORM_TABLE, PLATFORMS

# every platform dialect, in the table's order (a batch composes those its checks need in this order)
ALL_DIALECTS = tuple(d for p in PLATFORM_TABLE.values() for d in p.dialects)
SOURCE_EXT = {**EXT, "glsl": "glsl"}  # a golden source's extension, by language or GL dialect


@dataclass(frozen=True)
class Check:
    """One permutation × platform of a scene; `languages`: those compiled to SPIR-V for it."""

    hash: str
    platform: str
    objects: tuple[str, ...]
    languages: tuple[str, ...] = ()

    @property
    def id(self) -> str:
        return f"{self.hash}-{self.platform}"

    @property
    def dialects(self) -> tuple[str, ...]:
        return DIALECTS.get(self.platform, ())


@dataclass
class Outcome:
    """What one check found: errors (none when it passes), its emitted sources by golden-relative path, and
    notes that do not fail it (GLSL ES unsupported by the permutation's bricks)."""

    errors: list[str]
    sources: dict[str, str] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)


def checks(scene: Scene, platforms=PLATFORMS, languages=LANGUAGES) -> list[Check]:
    """The checks of a scene, permutation by permutation, platforms in PLATFORMS order."""
    plats = checked_platforms(platforms, languages)
    return [Check(h, p, tuple(scene.users.get(h, ())),
                  () if p in DIALECTS else tuple(x for x in PLATFORM_TABLE[p].checked_from if x in languages))
            for h in sorted(scene.permutations) for p in plats]


def checked_platforms(platforms=PLATFORMS, languages=LANGUAGES) -> list[str]:
    """The platforms of `platforms` made from one of `languages` (vulkan from any), in PLATFORMS order."""
    return [p for p in PLATFORMS if p in platforms and set(PLATFORM_TABLE[p].checked_from) & set(languages)]


def run_checks(scene: Scene, lib: Library, todo: list[Check], store=None) -> list[Outcome]:
    """An Outcome per check, in order. Every check's shaders are compiled in one batch (the tool processes
    run in parallel, identical shaders once) and the GL dialects validated in one more, as `build` does."""
    from ..compose.batch import compose_permutations
    from ..toolchain import CompileJob, compile_many
    from ..toolchain.platforms import validate_dialects
    from ..toolchain.jobs import job_key, source_jobs

    wanted: dict[str, tuple[set, set]] = {}  # hash -> (languages, dialects) its checks need
    for c in todo:
        langs, dials = wanted.setdefault(c.hash, (set(), set()))
        langs.update(c.languages)
        dials.update(c.dialects)
    # composed in one batch per set of languages and dialects needed, in LANGUAGES order: the sources, their
    # jobs and golden files do not depend on the checks' order
    batches: dict[tuple, list] = {}
    for h, (langs, dials) in wanted.items():
        need = (tuple(x for x in LANGUAGES if x in langs), tuple(d for d in ALL_DIALECTS if d in dials))
        batches.setdefault(need, []).append((h, scene.permutations[h]))
    composed, failed = {}, {}
    for (langs, dials), items in batches.items():
        done, errors = compose_permutations(items, lib, langs, dials)
        composed.update(done)
        failed.update(errors)
    composed = {h: composed[h] for h in wanted if h in composed}  # in the checks' order, as the jobs were
    jobs = {j.key: j for h, c in composed.items() for j in source_jobs(h, c.sources)}
    dialect_jobs = [CompileJob(job_key(h, s.stage, s.language), s.language, s.stage, s.text,
                               line_map=tuple(s.line_map)) for h, c in composed.items() for s in c.dialects]
    results = compile_many(list(jobs.values()), optimize=True, validate=True, store=store) if jobs else {}
    gl_errors = validate_dialects(dialect_jobs, store) if dialect_jobs else {}
    # the build's own binary steps (d3d12's DXC; none without a dxc on PATH), for the platforms checked
    steps = {p: step for p in dict.fromkeys(c.platform for c in todo if c.hash in composed)
             if (step := PLATFORM_TABLE[p].binary_step()) is not None}
    return [Outcome(list(failed[c.hash])) if c.hash in failed
            else _outcome(c, composed[c.hash], results, gl_errors, steps.get(c.platform),
                          scene.permutations[c.hash].precision)
            for c in todo]


def _outcome(c: Check, comp, results, gl_errors, step, precision: str) -> Outcome:
    """One check's Outcome from the batch's results (job key -> CompileResult / GL errors); step: its platform's
    binary step, or None."""
    from ..toolchain.jobs import job_key
    mine = [s for s in comp.sources if s.language in c.languages]
    compiled = [results[job_key(c.hash, s.stage, s.language)] for s in mine]
    errors = [line for r in compiled if not r.ok for line in r.errors()]
    notes: list[str] = []
    sources = {f"{c.platform}/{c.hash}.{s.stage}.{SOURCE_EXT[s.language]}": s.text for s in mine}
    p = PLATFORM_TABLE[c.platform]
    if p.dialects:
        errors += _dialects(c, p, [s for s in comp.dialects if s.language in p.dialects], gl_errors, sources, notes)
    elif step is not None and not errors:
        for s in mine:
            errors += step(c.hash, s, precision)[1]
    return Outcome(errors, dict(sorted(sources.items())), notes)


def _dialects(c: Check, p, dialects, gl_errors, sources: dict, notes: list) -> list[str]:
    """A dialect platform's check (gl): the errors of its required dialects; an optional one (GLSL ES) that
    fails is a note and ships no source, as `build` records it ("unsupported")."""
    from ..toolchain.jobs import job_key
    errors = []
    unsupported = {d: es for d in p.optional_dialects
                   if (es := [e for s in dialects if s.language == d for e in gl_errors[job_key(c.hash, s.stage, d)]])}
    for s in dialects:
        if s.language not in p.optional_dialects:
            errors += gl_errors[job_key(c.hash, s.stage, s.language)]
        if s.language not in unsupported:
            sources[f"{c.platform}/{c.hash}.{s.stage}.{SOURCE_EXT[s.language]}"] = s.text
    shipped = " and ".join(p.dialect_titles[d] for d in p.dialects if d not in p.optional_dialects)
    for d, es in unsupported.items():
        notes.append(f"{p.dialect_titles[d]} unsupported (the build ships {shipped} only): {es[0]}"
                     + (f" (and {len(es) - 1} more)" if len(es) > 1 else ""))
    return errors


def check_notes(platforms) -> list[str]:
    """What the checks of `platforms` leave out on this machine (Platform.check_note: no dxc for d3d12's DXIL)."""
    return [n for p in dict.fromkeys(platforms) if (n := PLATFORM_TABLE[p].check_note())]


def run_check(scene: Scene, lib: Library, check: Check, store=None) -> Outcome:
    """The Outcome of one check."""
    return run_checks(scene, lib, [check], store)[0]


def golden_diff(golden: Path, sources: dict[str, str]) -> list[str]:
    """Unified diffs of emitted sources against `golden` (a missing golden file is a diff from nothing)."""
    out = []
    for rel, text in sorted(sources.items()):
        path = golden / rel
        old = path.read_text(encoding="utf-8") if path.is_file() else ""
        if old != text:
            out += difflib.unified_diff(old.splitlines(keepends=True), text.splitlines(keepends=True),
                                        f"golden/{rel}", f"emitted/{rel}")
    return out


def stale_golden(golden: Path, todo: list[Check], emitted: set[str]) -> list[str]:
    """Golden files (relative paths) of the kinds the checks emit that no check emitted: permutations gone
    (or a GLSL ES source the bricks no longer allow). Kinds not checked (another platform's tree, a
    language left out of vulkan's) are not looked at."""
    exts: dict[str, set[str]] = {}
    for c in todo:
        exts.setdefault(c.platform, set()).update(SOURCE_EXT[x] for x in (*c.languages, *c.dialects))
    out = []
    for plat, kinds in exts.items():
        d = golden / plat
        if d.is_dir():
            out += sorted(f"{plat}/{p.name}" for p in d.iterdir()
                          if p.is_file() and p.suffix[1:] in kinds and f"{plat}/{p.name}" not in emitted)
    return sorted(out)


def default_store(cache_dir=None):
    from ..io import Store, default_cache_dir
    root = cache_dir or default_cache_dir()
    return Store(root) if root else None
