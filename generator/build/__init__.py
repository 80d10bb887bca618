"""`shadermatrix build`: a scene's permutations → sources, SPIR-V and manifest.json.

Compose every permutation in every language, compile them all in batches,
write what changed atomically, then the manifest (with each shader's static
cost, read from the optimized SPIR-V already in hand). A permutation that
fails (brick error, compiler error) is reported and the others still build.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

from .. import __version__
from ..library.bricks import Library
from ..io import atomic_write, sha256
from ..analysis import cost_dict
from ..matrix.scene import Scene
from ..targets import LANGUAGES
from ..compose.uber import compose_ubershader
from ..lang import SourceError
from ..link.uber import coverage
from ..toolchain import CompileJob, CompileStats, compile_many, tool_versions
from ..toolchain.scenes import compile_scene, job_key
from ..link.values import uploads
from .reflection import scene_tables


@dataclass
class BuildResult:
    manifest: dict
    failures: list[str] = field(default_factory=list)
    written: int = 0
    unchanged: int = 0
    compile: CompileStats = field(default_factory=CompileStats)  # shaders: jobs, distinct, cached, compiled
    store: object = None  # the io.Store used, or None

    @property
    def ok(self) -> bool:
        return not self.failures


def build_scene(scene: Scene, lib: Library, out: Path, languages=LANGUAGES, store=None) -> BuildResult:
    """Build every permutation of `scene` into `out`; see the module docstring.

    store: an io.Store (the content-addressed cache): compiled shaders and their costs are served from it
    and put into it; None compiles everything."""
    out = Path(out)
    res = BuildResult(manifest={}, store=store)
    composed, errors, results = compile_scene(scene, lib, languages, store=store, stats=res.compile)

    entries = []
    for h, perm in sorted(scene.permutations.items()):
        entry = {"id": perm.canonical(), "hash": h, "objects": scene.users.get(h, []), "languages": {}}
        errs = list(errors.get(h, []))
        c = composed.get(h)
        if c is not None:
            entry["bricks"] = dict(sorted(c.bricks.items()))
            entry["interface"] = c.interface.as_dict()
            entry["uploads"] = uploads(scene, h, c)
            for src in c.sources:
                item, bad = _write(res, out, h, src, results[job_key(h, src.stage, src.language)])
                errs += bad
                entry["languages"].setdefault(src.language, {})[src.stage] = item
        entry["status"] = "failed" if errs else "ok"
        if errs:
            entry["errors"] = errs
            res.failures.append(f"{h} ({perm.canonical()}):\n  " + "\n  ".join(errs))
        entries.append(entry)
    res.manifest = {
        "generator": f"shadermatrix {__version__}",
        "scene": scene.name,
        "tools": tool_versions(),
        "languages": list(languages),
        "permutations": entries,
        "ubershader": _ubershader(res, scene, lib, out, languages),
        **scene_tables(scene, composed),
    }
    text = json.dumps(res.manifest, indent=2, sort_keys=False) + "\n"
    _count(res, atomic_write(out / "manifest.json", text.encode()))
    return res


def _write(res: BuildResult, out: Path, name: str, src, r) -> tuple[dict, list[str]]:
    """Write one compiled source (and its SPIR-V); returns its manifest item and its errors."""
    data = src.text.encode()
    if r.ok and r.spirv:
        rel_src = f"{src.language}/{name}.{src.stage}.{src.language}"
        rel_spv = f"{src.language}/{name}.{src.stage}.spv"
        _count(res, atomic_write(out / rel_src, data))
        _count(res, atomic_write(out / rel_spv, r.spirv))
        return {"source": rel_src, "source_sha256": sha256(data), "spirv": rel_spv,
                "spirv_sha256": sha256(r.spirv), "cost": cost_dict(r.spirv, res.store)}, []
    # A source that does not compile goes beside, under its own name: an earlier
    # build's source and SPIR-V stay a matching pair.
    rel_src = f"{src.language}/{name}.{src.stage}.failed.{src.language}"
    _count(res, atomic_write(out / rel_src, data))
    return {"source": rel_src, "source_sha256": sha256(data)}, r.errors()


def _ubershader(res: BuildResult, scene: Scene, lib: Library, out: Path, languages) -> dict:
    """The fallback ubershader of the scene's matrix: sources, SPIR-V, its tables and Interface.

    The build fails, naming the value, when an axis value of the matrix is not reachable in it.
    """
    perms = [p for _, p in sorted(scene.permutations.items())]
    if not perms:
        return {}
    try:
        c, u = compose_ubershader(perms, lib, languages)
    except SourceError as e:
        res.failures.append(f"ubershader:\n  {e}")
        return {"status": "failed", "errors": [str(e)]}
    problems = coverage(u, perms, lib)
    jobs = [CompileJob(job_key("ubershader", s.stage, s.language), s.language, s.stage, s.text,
                       line_map=tuple(s.line_map)) for s in c.sources]
    results = compile_many(jobs, optimize=True, validate=True, store=res.store, stats=res.compile)
    entry = {"hash": c.hash, "languages": {}, "tables": u.tables(), "interface": c.interface.as_dict()}
    errs = [f"coverage: {p}" for p in problems]
    for src in c.sources:
        item, bad = _write(res, out, "ubershader", src, results[job_key("ubershader", src.stage, src.language)])
        errs += bad
        entry["languages"].setdefault(src.language, {})[src.stage] = item
    entry["status"] = "failed" if errs else "ok"
    if errs:
        entry["errors"] = errs
        res.failures.append("ubershader:\n  " + "\n  ".join(errs))
    return entry


def _count(res: BuildResult, changed: bool) -> None:
    if changed:
        res.written += 1
    else:
        res.unchanged += 1
