"""`shadermatrix build`: a scene's permutations → sources, SPIR-V and manifest.json.

Compose every permutation in every language, compile them all in batches,
write what changed atomically, then the manifest (with each shader's static
cost, read from the optimized SPIR-V already in hand). A permutation that
fails (brick error, compiler error) is reported and the others still build.
"""
from __future__ import annotations

import functools
import hashlib
import json
import os
from dataclasses import dataclass, field
from pathlib import Path

from .. import __version__
from ..library.bricks import BUILTIN_BRICKS, Library
from ..io import atomic_write, content_key, sha256
from ..analysis import cost_dict
from ..spec.permutation import SpecError, parse_brdf, parse_spec
from ..scene.load import Scene
from ..backends import LANGUAGES, template_file, template_name
from ..lang import SourceError
from ..link.uber import coverage
from ..toolchain import CompileStats, tool_versions
from ..toolchain.scenes import job_key, source_jobs
from ..link.values import uploads
from .outputs import clean_leftovers, collect_garbage, locked, shown, write_depfile
from .platforms import PLATFORMS, all_tools, dialects_of, platform_files, write_platforms
from .reflection import scene_tables

_PACKAGE = Path(__file__).resolve().parents[1]  # generator/ (the templates too: backends/*/templates/)


STATE = ".shadermatrix-state.json"  # the build's own record beside the manifest (deterministic: no times)


@dataclass
class BuildResult:
    out: Path
    failures: list[str] = field(default_factory=list)
    written: int = 0
    unchanged: int = 0
    compile: CompileStats = field(default_factory=CompileStats)  # shaders: jobs, distinct, cached, compiled
    kept: int = 0  # permutations up to date: not composed, compiled or analysed
    store: object = None  # the io.Store used, or None
    up_to_date: bool = False  # nothing at all to do: the manifest was not even read
    aliased: int = 0  # SPIR-V files another item of this build already wrote (identical modules: one file)
    costs: dict = field(default_factory=dict)  # SPIR-V sha256 -> cost dict: each module analysed once per build
    templates: set = field(default_factory=set)  # template files worker processes read
    platforms: tuple = PLATFORMS  # what this build writes (assemble/platforms.py)
    _manifest: dict | None = None
    _done: set = field(default_factory=set)  # files this build has written or found in place

    @property
    def ok(self) -> bool:
        return not self.failures

    @property
    def manifest(self) -> dict:
        """The build's manifest (read from out/manifest.json when the build had no need to)."""
        if self._manifest is None:
            self._manifest = json.loads((self.out / "manifest.json").read_text())
        return self._manifest

    @manifest.setter
    def manifest(self, value: dict) -> None:
        self._manifest = value


def build_scene(scene: Scene, lib: Library, out: Path, languages=LANGUAGES, store=None, depfile=None,
                workers: int | None = None, executor=None, keep_removed: bool = False, pack: bool = False,
                platforms=PLATFORMS) -> BuildResult:
    """Build every permutation of `scene` into `out`; see the module docstring.

    store: an io.Store (the content-addressed cache): compiled shaders and their costs are served from it
    and put into it; None compiles everything. depfile: where to write a Make-syntax depfile (or None).
    workers: tool processes at once (default: the core count); executor: where compiles run instead
    (toolchain/dask.py). Neither changes a byte of the output. keep_removed: the outputs of permutations that
    left the scene stay, listed under the manifest's ``removed`` (marked so), instead of being deleted.
    pack: also write one shader pack per platform (assemble/pack.py), listed under the manifest's ``packs``.
    platforms: what to write besides the SPIR-V checks of every language (assemble/platforms.py: vulkan, d3d12,
    gl, webgpu; one tree each, OUT/<platform>/, and per permutation a ``platforms`` section in the manifest).

    Incremental: each permutation's manifest entry records ``input_key``, the sha256 of everything its
    outputs depend on (its key, the source of every brick it reads, the scene values of the objects that
    use it, the generator's own sources and templates, the tools' versions, the languages). A permutation
    whose key is that of the previous manifest's entry, and whose files are all there with their recorded
    sha256, is neither composed nor compiled nor analysed: its entry is kept as it was. The ubershader
    likewise (its key covers every permutation's key and bricks, not the scene values: it reads none).

    Consistent at every instant: artifacts are named by their content (``<hash>.<stage>.<sha12>.<ext>``)
    and never overwritten; the manifest is replaced last, atomically, and only then are the files it no
    longer names removed. A permutation that fails keeps its last good entry and files, marked
    ``"status": "stale"`` with the errors and the failing sources beside (``failed_sources``).
    One build at a time per output directory (outputs.locked); an interrupted build's leftovers are
    removed by the next one.
    """
    out = Path(out)
    with locked(out):
        clean_leftovers(out)
        res = _build(scene, lib, out, languages, store, workers, executor, keep_removed, pack, tuple(platforms))
        if depfile is not None:
            write_depfile(depfile, shown(out / "manifest.json"), _deps(scene, lib, out))
    return res


def _deps(scene: Scene, lib: Library, out: Path) -> list[str]:
    """Every file the build read: the scene, every brick the library loaded, every template composed with
    (this process's, and the last build's for what it kept)."""
    templates = _state(out).get("templates", [])
    return [shown(scene.path), *(shown(b.path) for b in lib.bricks.values()),
            *(shown(template_file(t)) for t in sorted(templates))]


def _templates_read(also=()) -> list[str]:
    """The names of the templates composed with ("glsl/fragment.glsl.j2"): this process's and `also` (workers'
    file paths)."""
    import sys
    compose = sys.modules.get("generator.compose")
    read = set(also) | set(compose.loaded_templates() if compose is not None else ())
    return sorted(template_name(p) for p in read)


def _build(scene: Scene, lib: Library, out: Path, languages, store, workers=None, executor=None,
           keep_removed: bool = False, pack: bool = False, platforms=PLATFORMS) -> BuildResult:
    res = BuildResult(out, store=store, platforms=platforms)
    base = _globals(languages, platforms)
    users: dict[str, list[dict]] = {}
    for o in scene.objects:
        users.setdefault(o["permutation"], []).append(o)
    keys, shapes, parts = {}, {}, {}
    for h, perm in sorted(scene.permutations.items()):
        keys[h], shapes[h] = _perm_key(base, scene, lib, perm, users.get(h, []), parts)
    # the ubershader reads no scene values: its key is the permutations' keys without them
    uber_key = content_key(base, "ubershader", [shapes[h] for h in sorted(shapes)])
    # what the manifest's scene-wide tables hold beyond the permutations: name, light sets, objects in order
    scene_key = content_key(base, scene.name, sorted((k, list(v)) for k, v in scene.light_sets.items()),
                            [[o["name"], o["material"], o["light_set"], o["permutation"]] for o in scene.objects],
                            sorted(repr(m) for m in scene.materials.values()), sorted(repr(x) for x in scene.lights.values()),
                            keep_removed, *(["pack"] if pack else []))
    files = _up_to_date(out, keys, uber_key, scene_key)
    if files is not None:  # the record of the last build says every key and file is as it left them
        res.up_to_date, res.kept, res.unchanged = True, len(keys), files + 1
        return res
    previous = _previous(out)
    old = {e["hash"]: e for e in previous.get("permutations", [])}
    kept = {}
    for h, perm in sorted(scene.permutations.items()):
        e = old.get(h)
        if e is not None and e.get("input_key") == keys[h] and e.get("status") == "ok" and _intact(out, e):
            kept[h] = e
    from ..toolchain.scenes import compile_scene  # composing (Jinja and the emitters) only when needed
    from .parallel import MIN_PERMUTATIONS, compile_scene_parallel
    old_uber = previous.get("ubershader") or {}
    uber_kept = old_uber.get("input_key") == uber_key and old_uber.get("status") == "ok" and _intact(out, old_uber)
    uber_unit = None if uber_kept else _compose_ubershader(scene, lib, languages)
    extra = source_jobs("ubershader", uber_unit[0].sources) if isinstance(uber_unit, tuple) else []
    todo = Scene(**{**scene.__dict__, "permutations": {h: p for h, p in scene.permutations.items() if h not in kept}})
    built: dict[str, dict] = {}

    def head(h: str) -> dict:
        perm = scene.permutations[h]
        return {"id": perm.canonical(), "hash": h, "input_key": keys[h], "objects": scene.users.get(h, []),
                "languages": {}}

    dialects = dialects_of(platforms)
    dxil = _dxil_step() if "d3d12" in platforms else None

    def written(pairs, part):  # a compiled chunk: written and analysed while the next chunks compile
        checked = _validate_dialects(pairs, store) if dialects else {}
        for h, c in pairs:
            entry = {**head(h), "bricks": dict(sorted(c.bricks.items())), "interface": c.interface.as_dict(),
                     "uploads": uploads(scene, h, c, users.get(h, []))}
            errs = _write_all(res, out, h, c.sources, part, entry)
            if not errs:
                errs = write_platforms(lambda rel, data: _count(res, atomic_write(out / rel, data)), h, c, entry,
                                       platforms, checked, scene.permutations[h].precision, dxil)
                if errs:  # failed_sources stays: a failing GL core source is written beside (write_platforms)
                    entry.pop("platforms", None)
                    entry["languages"] = {}
            built[h] = _settle(res, entry, errs, old.get(h), out, _failure_head(scene, h, users.get(h, [])))

    n = workers or os.cpu_count() or 1
    if executor is None and n > 1 and len(todo.permutations) >= MIN_PERMUTATIONS:  # compose and analyse there too
        composed, errors, results = compile_scene_parallel(todo, lib, languages, store=store, stats=res.compile,
                                                           extra=extra, workers=n, on_done=written, costs=res.costs,
                                                           templates=res.templates, dialects=dialects)
    else:
        composed, errors, results = compile_scene(todo, lib, languages, store=store, stats=res.compile, extra=extra,
                                                  workers=workers, executor=executor, on_done=written,
                                                  dialects=dialects)
    res.kept = len(kept)

    entries = []
    for h, perm in sorted(scene.permutations.items()):
        if h in kept:
            entries.append(kept[h])
            res.unchanged += _files(kept[h])
        elif h in built:
            entries.append(built[h])
        else:  # it did not compose
            entries.append(_settle(res, head(h), list(errors.get(h, [])), old.get(h), out,
                                   _failure_head(scene, h, users.get(h, []))))
    if uber_kept:
        uber = old_uber
        res.unchanged += _files(uber)
    else:
        uber = _ubershader(res, scene, lib, out, uber_unit, results, uber_key, old_uber)
    res.manifest = {
        "generator": f"shadermatrix {__version__}",
        "scene": scene.name,
        "tools": tool_versions(),
        "languages": list(languages),
        "platforms": list(platforms),
        "permutations": entries,
        "ubershader": uber,
        **scene_tables(scene, composed, previous),
    }
    if keep_removed:  # what left the scene stays, listed as such (its files intact), until a build without the flag
        gone = [e for e in [*previous.get("permutations", []), *previous.get("removed", [])]
                if e["hash"] not in scene.permutations and e.get("status") in ("ok", "stale", "removed")
                and _intact(out, e)]
        res.manifest["removed"] = [{**e, "status": "removed"} for e in sorted({e["hash"]: e for e in gone}.values(),
                                                                             key=lambda e: e["hash"])]
    from .tables import write_tables  # baked lookup tables the shaders sample (content-named, like packs)
    tables = write_tables(out, lib, res.manifest, lambda changed: _count(res, changed), previous, base)
    if tables:
        res.manifest["tables"] = tables
    if pack:  # written before the manifest that names them (content-named: the old ones stay until after it)
        from .pack import write_packs
        res.manifest["packs"] = write_packs(out, res.manifest, lambda changed: _count(res, changed))
    if res.manifest == previous and (out / "manifest.json").is_file():  # nothing changed: not even re-encoded
        _count(res, False)
        text = (out / "manifest.json").read_bytes()
    else:
        text = (json.dumps(res.manifest, indent=2, sort_keys=False) + "\n").encode()
        _count(res, atomic_write(out / "manifest.json", text))
    collect_garbage(out, res.manifest)  # the new manifest is in place: drop what it no longer names
    from .pack import collect_packs
    from .tables import collect_tables
    collect_packs(out, res.manifest)
    collect_tables(out, res.manifest)
    _record(out, res.manifest, text, keys, uber_key, res.kept, scene_key, res.templates)  # last: the no-op check trusts it
    return res


def _failure_head(scene: Scene, h: str, objs: list[dict]) -> tuple[str, str]:
    """Where the scene asks for permutation h (its first object's material key), and which it is."""
    line, col = scene.where.get(h, (1, 1))
    names = [o["name"] for o in objs]
    who = ", ".join(names[:3]) + (f" and {len(names) - 3} more" if len(names) > 3 else "")
    first = objs[0] if objs else {"material": "?", "light_set": "?"}
    return (f"{scene.path}:{line}:{col}: permutation {h} (material '{first['material']}', light set "
            f"'{first['light_set']}'; objects {who}) does not build", scene.permutations[h].canonical())


def _settle(res: BuildResult, entry: dict, errs: list[str], old: dict | None, out: Path,
            what: tuple[str, str]) -> dict:
    """An entry's status: ok; or, when it failed, its last good entry kept whole and marked stale.

    what: the failure's located head (the scene position that asks for it) and the key it stands for."""
    if not errs:
        entry["status"] = "ok"
        entry.pop("failed_sources", None)
        return entry
    failed = entry.get("failed_sources", {})
    stale = old is not None and old.get("status") in ("ok", "stale") and _intact(out, old)
    kept = "its last good outputs stay, marked stale" if stale else "it has no outputs yet"
    head, key = what
    res.failures.append("\n  ".join([f"{head} — fix the errors below ({kept})", *([key] if key else []), *errs]))
    if stale:
        return {**old, "status": "stale", "errors": errs, "failed_sources": failed}
    return {**entry, "languages": {}, "status": "failed", "errors": errs, "failed_sources": failed}


def _record(out: Path, manifest: dict, text: bytes, keys: dict, uber_key: str, kept: int, scene_key: str,
            workers_read=()) -> None:
    """What the next build checks first: every input key, the manifest's sha256, every file's size; and the
    templates composed with (for the depfile of a build that composes nothing)."""
    templates = set(_templates_read(workers_read))
    if kept:
        templates.update(_state(out).get("templates", []))
    ok = all(e.get("status") == "ok" for e in manifest["permutations"]) and \
        (manifest.get("ubershader") or {}).get("status", "ok") == "ok"
    entries = [*manifest["permutations"], *manifest.get("removed", []), manifest.get("ubershader") or {}]
    state = {"manifest_sha256": sha256(text), "complete": ok, "keys": keys, "ubershader": uber_key, "scene": scene_key,
             "files": {rel: (out / rel).stat().st_size for e in entries for rel, _ in _items(e)}
             | {p["path"]: p["size"] for p in manifest.get("packs", [])}
             | {t["path"]: t["bytes"] for t in manifest.get("tables", [])},
             "templates": sorted(templates)}
    atomic_write(out / STATE, (json.dumps(state, sort_keys=True) + "\n").encode())


def _state(out: Path) -> dict:
    """The last build's record (empty when there is none or it does not read as one)."""
    try:
        state = json.loads((out / STATE).read_text())
    except (OSError, ValueError):
        return {}
    return state if isinstance(state, dict) else {}


def _up_to_date(out: Path, keys: dict, uber_key: str, scene_key: str) -> int | None:
    """The number of files the last build left when nothing at all needs doing (its record has these keys,
    the manifest is the one it wrote, every file it listed has its size), else None."""
    state = _state(out)
    try:
        if not (state.get("complete") and state.get("keys") == keys and state.get("ubershader") == uber_key
                and state.get("scene") == scene_key):
            return None
        if sha256((out / "manifest.json").read_bytes()) != state["manifest_sha256"]:
            return None
        root = os.fspath(out)  # os.path, not pathlib: 10,000 Path objects cost more than the stat calls
        for rel, size in state["files"].items():
            if os.stat(os.path.join(root, rel)).st_size != size:
                return None
        return len(state["files"])
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return None


@functools.lru_cache(maxsize=1)
def _own_sources() -> str:
    """sha256 of the generator's own code and templates (relative path and bytes of every file)."""
    h = hashlib.sha256()
    for root in (_PACKAGE,):
        for p in sorted(root.rglob("*")):
            # the built-in bricks (package data inside generator/ when installed) are keyed per permutation
            if p.is_file() and p.suffix in (".py", ".j2", ".toml") and BUILTIN_BRICKS not in p.parents:
                h.update(str(p.relative_to(root.parent)).encode() + b"\0" + p.read_bytes() + b"\0")
    return h.hexdigest()


def _globals(languages, platforms=PLATFORMS) -> str:
    return content_key("build-v1", __version__, _own_sources(), tool_versions(), list(languages), list(platforms),
                       all_tools(platforms))


def _perm_key(base: str, scene: Scene, lib: Library, perm, objs: list[dict], memo: dict) -> tuple[str, str]:
    """(Everything a permutation's outputs depend on (see build_scene), the same without the scene values);
    objs: the objects drawn with it; memo: the bricks of each part, shared by the calls of one build (the
    permutations of a scene share their materials' BRDFs, their packings and their lights)."""
    try:
        bricks = {}
        for part in (("brdf", perm.brdf), ("packing", perm.packing), ("output", perm.output),
                     *(("light", lk) for lk in perm.lights)):
            if part not in memo:
                memo[part] = _bricks_of(part, lib)
            if isinstance(memo[part], Exception):
                raise memo[part]
            bricks.update(memo[part])
    except (SourceError, SpecError) as e:  # it will fail to compose too: key it by the error
        bricks = {"error": str(e)}
    mats = sorted({o["material"] for o in objs})
    lights = sorted({ln for o in objs for ln in o["lights"]})
    values = {"objects": [[o["name"], o["material"], o["light_set"], list(o["lights"])] for o in objs],
              "materials": [repr(scene.materials[m]) for m in mats], "lights": [repr(scene.lights[ln]) for ln in lights]}
    shape = content_key(base, perm.canonical(), sorted(bricks.items()))
    return content_key(shape, values), shape


def _bricks_of(part: tuple, lib: Library):
    """{display path: source hash} of the bricks one part of a permutation key reads, or the error it raises."""
    kind, value = part
    try:
        if kind in ("light", "output"):  # a light brick (and its shadow filter's spec), an output brick
            brick = lib.get(kind, value.light if kind == "light" else value)
            if brick is None:
                raise SourceError("<key>", 1, 1, f"unknown {kind} brick in {value}", f"name a known {kind} brick")
            nodes, extra = (parse_spec(value.shadow, lib, ("shadow",)) if kind == "light" else []), [brick]
        else:
            nodes, extra = (parse_brdf(value, lib) if kind == "brdf" else parse_spec(value, lib, ("packing",))), []
    except (SourceError, SpecError) as e:
        return e
    return {b.display_path: b.module.source_hash for b in [*(x.brick for n in nodes for x in n.walk()), *extra]}


def _previous(out: Path) -> dict:
    """The manifest an earlier build left; an unreadable or malformed one (edited by hand, damaged) counts as
    none: everything is rebuilt."""
    try:
        m = json.loads((out / "manifest.json").read_text())
    except (OSError, ValueError):
        return {}
    if not isinstance(m, dict):
        return {}
    perms, uber = m.get("permutations", []), m.get("ubershader") or {}
    try:
        ok = (isinstance(perms, list) and isinstance(uber, dict)
              and all(isinstance(e, dict) and isinstance(e.get("hash"), str) for e in perms)
              and all(isinstance(x, str) for e in [*perms, uber] for pair in _items(e) for x in pair))
    except (AttributeError, TypeError, KeyError):
        ok = False
    return m if ok else {}


def _items(entry: dict):
    for stages in entry.get("languages", {}).values():
        for item in stages.values():
            yield from ((item[f], item[f"{f}_sha256"]) for f in ("source", "spirv") if f in item)
    yield from platform_files(entry)


def _files(entry: dict) -> int:
    return sum(1 for _ in _items(entry))


def _intact(out: Path, entry: dict) -> bool:
    """Every file an entry lists is there with the sha256 it records."""
    try:
        return all(sha256((out / rel).read_bytes()) == digest for rel, digest in _items(entry))
    except (OSError, TypeError, KeyError, AttributeError):
        return False


def _write_all(res: BuildResult, out: Path, name: str, sources, results, entry: dict) -> list[str]:
    """Write a unit's sources and SPIR-V (content-named) into `entry` only when every one compiled; else
    write the failing sources beside, as ``<name>.<stage>.failed.<lang>``, and return the errors."""
    errs, failed = [], {}
    for src in sources:
        r = results[job_key(name, src.stage, src.language)]
        if not (r.ok and r.spirv):
            rel = f"vulkan/{src.language}/{name}.{src.stage}.failed.{src.language}"
            _count(res, atomic_write(out / rel, src.text.encode()))
            failed[f"{src.language}.{src.stage}"] = rel
            errs += r.errors()
    if errs:
        entry["failed_sources"] = failed
        return errs
    for src in sources:
        r = results[job_key(name, src.stage, src.language)]
        entry["languages"].setdefault(src.language, {})[src.stage] = _write(res, out, name, src, r)
    return []


def _write(res: BuildResult, out: Path, name: str, src, r) -> dict:
    """Write one compiled source and its SPIR-V under content names; returns its manifest item."""
    data = src.text.encode()
    src_sha, spv_sha = sha256(data), sha256(r.spirv)
    if "vulkan" not in res.platforms:  # the SPIR-V checks ran (and their costs are recorded); nothing to ship
        return {"source_sha256": src_sha, "spirv_sha256": spv_sha, "cost": _cost(res, spv_sha, r.spirv)}
    rel_src = f"vulkan/{src.language}/{name}.{src.stage}.{src_sha[:12]}.{src.language}"
    # SPIR-V is named by its content alone: identical modules (the vertex shaders of most permutations) are
    # one file, and every manifest item that has them names it (aliased); sources keep their own header
    rel_spv = f"vulkan/{src.language}/{spv_sha[:16]}.{src.stage}.spv"
    _count(res, atomic_write(out / rel_src, data))
    if rel_spv in res._done:
        res.aliased += 1
    else:
        res._done.add(rel_spv)
        _count(res, atomic_write(out / rel_spv, r.spirv))
    return {"source": rel_src, "source_sha256": src_sha, "spirv": rel_spv, "spirv_sha256": spv_sha,
            "cost": _cost(res, spv_sha, r.spirv)}


def _cost(res: BuildResult, sha: str, spirv: bytes) -> dict:
    """A module's cost, analysed once per build (a worker's, or here) whatever the store holds."""
    cost = res.costs.get(sha)
    if cost is None:
        cost = res.costs[sha] = cost_dict(spirv, res.store)
    return cost


def _validate_dialects(pairs, store) -> dict[str, list[str]]:
    """glslangValidator's errors (job key -> errors) for the platform dialect sources of a compiled chunk."""
    from ..toolchain import CompileJob
    from ..toolchain.platforms import validate_dialects
    jobs = [CompileJob(job_key(h, s.stage, s.language), s.language, s.stage, s.text, line_map=tuple(s.line_map))
            for h, c in pairs for s in c.dialects]
    return validate_dialects(jobs, store) if jobs else {}


def _dxil_step():
    """The DXC step of the d3d12 platform, or None when no dxc is on PATH (docs/guide/install.md: where to get one)."""
    from ..toolchain import CompileJob, find_tool
    from ..toolchain.platforms import compile_dxil
    if find_tool("dxc") is None:
        return None
    return lambda name, src, precision: compile_dxil(
        CompileJob(job_key(name, src.stage, "dxil"), "hlsl", src.stage, src.text), precision)


def _compose_ubershader(scene: Scene, lib: Library, languages):
    """(Composed, Uber) of the scene's ubershader, the compose error as text, or None without permutations."""
    from ..compose.uber import compose_ubershader
    perms = [p for _, p in sorted(scene.permutations.items())]
    if not perms:
        return None
    try:
        return compose_ubershader(perms, lib, languages)
    except SourceError as e:
        return str(e)


def _ubershader(res: BuildResult, scene: Scene, lib: Library, out: Path, unit, results, key: str, old: dict) -> dict:
    """The fallback ubershader of the scene's matrix: sources, SPIR-V, its tables and Interface.

    The build fails, naming the value, when an axis value of the matrix is not reachable in it.
    """
    if unit is None:
        return {}
    if isinstance(unit, str):
        return _settle(res, {"input_key": key, "languages": {}}, [unit], old, out, _uber_failure_head(scene))
    c, u = unit
    perms = [p for _, p in sorted(scene.permutations.items())]
    entry = {"input_key": key, "hash": c.hash, "languages": {}, "tables": u.tables(), "interface": c.interface.as_dict()}
    errs = [f"coverage: {p}" for p in coverage(u, perms, lib)]
    errs += _write_all(res, out, "ubershader", c.sources, results, entry)
    return _settle(res, entry, errs, old, out, _uber_failure_head(scene))


def _uber_failure_head(scene: Scene) -> tuple[str, str]:
    line, col = scene.head_at
    return (f"{scene.path}:{line}:{col}: the scene's ubershader (the fallback for all {len(scene.permutations)} "
            "permutations) does not build", "")


def _count(res: BuildResult, changed: bool) -> None:
    if changed:
        res.written += 1
    else:
        res.unchanged += 1
