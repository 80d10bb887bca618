"""`shadermatrix build`: a scene's permutations → sources, SPIR-V and manifest.json.

Compose every permutation in every language, compile them all in batches,
write what changed atomically, then the manifest (with each shader's static
cost, read from the optimized SPIR-V already in hand). A permutation that
fails (brick error, compiler error) is reported and the others still build.

The stage, in the order a build runs it: context.py (BuildContext: what every step reads), keys.py (the
input keys), state.py (what the last build left), loop.py (the compile loop: in this process, or in worker
processes through parallel.py and workers.py, or on a Dask cluster through cluster.py), entries.py (a chunk's
manifest entries and files, made where it compiled), write.py (content-named artifacts), platforms.py,
reflection.py, tables.py, pack.py, outputs.py (the output tree: lock, leftovers, garbage), depfile.py (the depfile,
the stamp and the versions file a build system reads).
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

from .. import __version__
from ..scene.load import Scene
from ..toolchain import CompileStats, tool_versions
from ..toolchain.jobs import source_jobs
from . import state
from .context import BuildContext
from .entries import Entries, compose_ubershader, encode_manifest, replay
from .keys import build_key, scene_keys
from .loop import compile_permutations, in_workers
from .manifest import FORMAT_VERSION, check as check_manifest, conventions, material_states
from .outputs import clean_leftovers, collect_garbage, locked
from .platforms import PLATFORMS
from .reflection import scene_tables
from .write import Writer

STATE = state.STATE

__all__ = ["BuildContext", "BuildResult", "build", "STATE"]


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
    templates: set = field(default_factory=set)  # the templates this build composed with, by name
    platforms: tuple = PLATFORMS  # what this build writes (assemble/platforms.py)
    explain: object = None  # why it rebuilt what it did (inputs.Rebuild: .explained()); None on a no-op
    shaders: dict = field(default_factory=dict)  # job key -> (cache key, compile seconds or None): what each cost
    _manifest: dict | None = None

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


def build(scene: Scene, out: Path, ctx: BuildContext, depfile=None, keep_removed: bool = False,
          pack: bool = False, stamp=None, request=None) -> BuildResult:
    """Build every permutation of `scene` into `out`; see the module docstring.

    ctx: the library, languages, platforms, compile cache, progress bar, jobs and executor (context.py).
    The store (the content-addressed cache) serves compiled shaders and their costs and takes new ones; jobs and
    the executor change no byte of the output. depfile: where to write a Make-syntax depfile (or None), for the
    target `stamp` when one is given (else OUT/manifest.json). stamp: a file replaced after every build that
    succeeds (none when it fails), so that a build system compares the inputs with the build's end (depfile.py).
    request: what the command line asked for (noop.Request), or None: a build that succeeds then records what it
    read (in ctx.store), so that the next one with the same request knows it is a no-op before loading the scene
    (noop.py).
    keep_removed: the outputs of permutations that
    left the scene stay, listed under the manifest's ``removed`` (marked so), instead of being deleted.
    pack: also write one shader pack per platform (assemble/pack.py), listed under the manifest's ``packs``.
    ctx.platforms: what to write besides the SPIR-V checks of every language (assemble/platforms.py: vulkan,
    d3d12, gl, webgpu; one tree each, OUT/<platform>/, and per permutation a ``platforms`` section in the
    manifest).

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
    from .depfile import VERSIONS, inputs, shown, touch, write_depfile, write_versions
    out = Path(out)
    with locked(out):
        clean_leftovers(out)
        write_versions(out / VERSIONS)  # before any output: a depfile names it, the stamp comes after it
        res = _Build(scene, out, ctx, keep_removed, pack).run()
        if depfile is not None:  # the templates: recorded by this build, and by the last ones for what it kept
            write_depfile(depfile, str(stamp) if stamp is not None else shown(out / "manifest.json"),
                          inputs(scene, ctx.library, out, state.read(out).get("templates", [])))
        if stamp is not None and res.ok:
            touch(stamp)
        if request is not None and ctx.store is not None:  # last, under the lock: what the next build checks first
            from . import noop
            if res.ok:
                noop.record(out, request, scene, ctx.library, res, state.read(out).get("templates", []), ctx.store)
            else:
                noop.forget(out, ctx.store)
    return res


class _Build:
    """One build of `scene` into `out`: the steps of run() share the context, the keys and what the last
    build left, instead of passing them along."""

    def __init__(self, scene: Scene, out: Path, ctx: BuildContext, keep_removed: bool, pack: bool):
        self.scene, self.out, self.ctx, self.keep_removed, self.pack = scene, out, ctx, keep_removed, pack
        self.res = BuildResult(out, store=ctx.store, platforms=ctx.platforms)
        self.writer = Writer(out, ctx, self.res)
        self.users: dict[str, list[dict]] = {}  # the objects drawn with each permutation
        for o in scene.objects:
            self.users.setdefault(o["permutation"], []).append(o)
        self.tools = tool_versions()
        self.base = build_key(__version__, self.tools, ctx.languages, ctx.platforms)
        self.keys = scene_keys(self.base, scene, ctx.library, keep_removed, pack)
        self.entries = Entries(scene, self.keys.permutations, self.keys.ubershader, self.users)  # entries.py
        self.previous: dict = {}
        self.old: dict[str, dict] = {}  # the previous manifest's entries by hash
        self.built: dict[str, dict] = {}
        self.texts: dict[str, tuple] = {}  # hash -> (its built entry, its text, its holes): encode_manifest
        self.uber_kept = False
        self.kept: set[str] = set()
        self.pack_only = pack == "only"  # build --pack-only: the artifacts go to the packs alone (spool.py)
        self.packed = None  # then: what the last build's packs hold (spool.Packed)
        if self.pack_only:
            from .spool import Spool
            self.writer.spool = Spool(out)

    def run(self) -> BuildResult:
        scene, out, res, keys = self.scene, self.out, self.res, self.keys
        files = state.up_to_date(out, keys)
        if files is not None:  # the record of the last build says every key and file is as it left them
            res.up_to_date, res.kept, res.unchanged = True, len(keys.permutations), files + 1
            return res
        self.previous = state.previous(out)
        if self.pack_only:
            from .spool import Packed
            self.packed = Packed(out, self.previous)
        self.old = {e["hash"]: e for e in self.previous.get("permutations", [])}
        kept = {h: e for h in sorted(scene.permutations) if (e := self.old.get(h)) is not None
                and e.get("input_key") == keys.permutations[h] and e.get("status") == "ok" and self.intact(e, h)}
        old_uber = self.previous.get("ubershader") or {}
        uber_kept = (scene.ubershader and old_uber.get("input_key") == keys.ubershader and old_uber.get("status") == "ok"
                     and self.intact(old_uber, "ubershader"))
        self.uber_kept = uber_kept  # the record keeps the last build's templates for it (it is not composed)
        self.kept = set(kept)  # what the explanation of this build leaves out (inputs.py)
        todo = {h: p for h, p in scene.permutations.items() if h not in kept}
        remote = in_workers(self.ctx, len(todo))  # then the ubershader is composed where the chunks are
        uber_unit = None if uber_kept or remote or not scene.ubershader else \
            compose_ubershader(scene, self.ctx.library, self.ctx.languages)
        extra = []
        if isinstance(uber_unit, tuple):
            extra = source_jobs("ubershader", uber_unit[0].sources)
            res.templates.update(uber_unit[0].templates)
        compiled = compile_permutations(self.ctx, todo, extra, self._written, res.compile, res.costs, self.entries,
                                        ubershader=remote and not uber_kept and scene.ubershader)
        res.templates.update(compiled.templates)
        res.shaders = {k: (r.cache_key, r.seconds) for k, r in compiled.results.items()}
        res.kept = len(kept)
        entries = []
        for h in sorted(scene.permutations):
            if h in kept:
                entries.append(kept[h])
                res.unchanged += self.files(kept[h])
            elif h in self.built:
                entries.append(self.built[h])
            else:  # it did not compose
                entries.append(self._settle(self._head(h), list(compiled.errors.get(h, [])), self.old.get(h),
                                            _failure_head(scene, h, self.users.get(h, []))))
        if uber_kept:
            uber = old_uber
            res.unchanged += self.files(uber)
        else:
            made = compiled.ubershader if remote else self.entries.ubershader(self.ctx, uber_unit, compiled.results,
                                                                              res.costs)
            uber = self._ubershader(made, old_uber)
        res.manifest = {
            "format_version": FORMAT_VERSION,
            "generator": f"shadermatrix {__version__}",
            "scene": scene.name,
            "tools": self.tools,
            "languages": list(self.ctx.languages),
            "platforms": list(self.ctx.platforms),
            **({"artifacts": "packs"} if self.pack_only else {}),
            "conventions": conventions(self.ctx.platforms),
            "permutations": entries,
            "ubershader": uber,
            **material_states(scene, scene_tables(scene, compiled.composed, self.previous, self.ctx.platforms)),
        }
        from .depth import write_depth_passes  # the shadowed lights' depth passes: their shaders, their descriptions
        write_depth_passes(self)
        self._finish()
        return res

    def _head(self, h: str) -> dict:
        return self.entries.head(self.ctx.library, h)

    def _written(self, pairs, part, made=None) -> None:
        """A compiled chunk: its entries made (entries.py; `made`: by the worker that compiled it), its files written
        and each entry settled, while the next chunks compile."""
        if made is None:
            made = self.entries.make(self.ctx, pairs, part, self.res.costs)
        for h, m in made.items():
            replay(self.writer, m.files)
            if self.pack_only:
                self.writer.spool.settle(m.entry, h, self.ctx.platforms)
            self.built[h] = self._settle(m.entry, m.errors, self.old.get(h),
                                         _failure_head(self.scene, h, self.users.get(h, [])))
            if m.text is not None:
                self.texts[h] = (self.built[h], m.text, m.holes)

    def _finish(self) -> None:
        """The removed entries, tables and packs, then the manifest, then what it no longer names goes, then the
        record the next build reads first."""
        out, res, previous = self.out, self.res, self.previous
        if self.keep_removed:  # what left the scene stays, listed as such (its files intact), until a build without it
            gone = [e for e in [*previous.get("permutations", []), *previous.get("removed", [])]
                    if e["hash"] not in self.scene.permutations and e.get("status") in ("ok", "stale", "removed")
                    and state.intact(out, e)]
            res.manifest["removed"] = [{**e, "status": "removed"}
                                       for e in sorted({e["hash"]: e for e in gone}.values(), key=lambda e: e["hash"])]
        from .tables import write_tables  # baked lookup tables the shaders sample (content-named, like packs)
        tables = write_tables(out, self.ctx.library, res.manifest, self.writer.count, previous, self.base)
        if tables:
            res.manifest["tables"] = tables
        from .texture_outputs import collect_textures, write_textures  # the materials' images, as KTX2 with mips
        write_textures(out, self.scene, res.manifest, self.writer.count, previous, self.base)
        if self.pack:  # written before the manifest that names them (content-named: the old ones stay until after it)
            from .pack import write_packs
            res.manifest["packs"] = write_packs(out, res.manifest, self.writer.count,
                                                self._fetch if self.pack_only else None)
            if self.pack_only:
                self.writer.spool.close()
        check_manifest(res.manifest)  # before it replaces the last one (SHADERMATRIX_CHECK_MANIFEST: the tests)
        if res.manifest == previous and (out / "manifest.json").is_file():  # nothing changed: not even re-encoded
            self.writer.count(False)
            text = (out / "manifest.json").read_bytes()
        else:
            text = encode_manifest(res.manifest, self.texts)  # json.dumps(indent=2), the entries' texts made already
            self.writer.put("manifest.json", text)
        collect_garbage(out, _loose(res.manifest) if self.pack_only else res.manifest)  # what it no longer names
        from .pack import collect_packs
        from .tables import collect_tables
        collect_packs(out, res.manifest)
        collect_tables(out, res.manifest)
        collect_textures(out, res.manifest)
        from .inputs import record as record_inputs  # what the keys were made of: the next build's --explain
        res.explain = record_inputs(self)
        state.record(out, res.manifest, text, self.keys, res.kept + self.uber_kept,  # units kept, not composed
                     res.templates)  # last: the no-op check trusts it

    def _settle(self, entry: dict, errs: list[str], old: dict | None, what: tuple[str, str]) -> dict:
        """An entry's status: ok; or, when it failed, its last good entry kept whole and marked stale.

        what: the failure's located head (the scene position that asks for it) and the key it stands for."""
        if not errs:
            entry["status"] = "ok"
            entry.pop("failed_sources", None)
            return entry
        failed = entry.get("failed_sources", {})
        stale = old is not None and old.get("status") in ("ok", "stale") and not self.pack_only \
            and state.intact(self.out, old)  # --pack-only: the packs hold what builds, no stale outputs
        kept = "its last good outputs stay, marked stale" if stale else "it has no outputs yet"
        head, key = what
        self.res.failures.append("\n  ".join([f"{head} — fix the errors below ({kept})", *([key] if key else []),
                                              *errs]))
        if stale:
            return {**old, "status": "stale", "errors": errs, "failed_sources": failed}
        return {**entry, "languages": {}, "status": "failed", "errors": errs, "failed_sources": failed}

    def _ubershader(self, made, old: dict) -> dict:
        """The fallback ubershader of the scene's matrix (entries.Entries.ubershader: made here or by a worker):
        its files written, its entry settled."""
        if made is None:
            return {}
        replay(self.writer, made.files)
        if self.pack_only:
            self.writer.spool.settle(made.entry, "ubershader", self.ctx.platforms)
        return self._settle(made.entry, made.errors, old, _uber_failure_head(self.scene))


    def intact(self, entry: dict, name: str) -> bool:
        """Whether the last build's `entry` (unit `name`) may be kept: its files are there with their sha256 (state.py);
        with --pack-only, or the last build's packs hold all of it (spool.Packed)."""
        return state.intact(self.out, entry) or (self.packed is not None and self.packed.intact(entry, name))

    def files(self, entry: dict) -> int:
        """The files of a kept entry that stay in the tree (none with --pack-only)."""
        return 0 if self.pack_only else state.files(entry)

    def _fetch(self, rel: str) -> bytes:
        """An artifact for the packs of a --pack-only build: from this build's spool, the last build's packs, or a
        loose file an earlier build left."""
        data = self.writer.spool.get(rel)
        if data is None:
            data = self.packed.fetch(rel)
        if data is None and (self.out / rel).is_file():
            data = (self.out / rel).read_bytes()
        if data is None:
            from .pack import PackError
            raise PackError(f"{self.out / rel}: in neither this build nor the last build's packs — build again "
                            "(without --pack-only once if it persists)")
        return data


def _loose(manifest: dict) -> dict:
    """What a --pack-only manifest names as files of the tree, for collect_garbage: its tables, textures and the
    failing units' sources, not the entries' artifacts (the packs hold them; loose ones an earlier build left go)."""
    def bare(e: dict) -> dict:
        return {"hash": e.get("hash"), "failed_sources": e.get("failed_sources", {})}
    return {**manifest, "permutations": [bare(e) for e in manifest["permutations"]],
            "removed": [bare(e) for e in manifest.get("removed", [])], "ubershader": bare(manifest.get("ubershader") or {}),
            "depth_shaders": {k: bare(e) for k, e in (manifest.get("depth_shaders") or {}).items()}}


def _failure_head(scene: Scene, h: str, objs: list[dict]) -> tuple[str, str]:
    """Where the scene asks for permutation h (its first object's material key), and which it is."""
    line, col = scene.where.get(h, (1, 1))
    names = [o["name"] for o in objs]
    who = ", ".join(names[:3]) + (f" and {len(names) - 3} more" if len(names) > 3 else "")
    first = objs[0] if objs else {"material": "?", "light_set": "?"}
    return (f"{scene.path}:{line}:{col}: permutation {h} (material '{first['material']}', light set "
            f"'{first['light_set']}'; objects {who}) does not build", scene.permutations[h].canonical())


def _uber_failure_head(scene: Scene) -> tuple[str, str]:
    line, col = scene.head_at
    return (f"{scene.path}:{line}:{col}: the scene's ubershader (the fallback for all {len(scene.permutations)} "
            "permutations) does not build", "")
