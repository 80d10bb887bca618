"""A no-op build known before the scene is loaded: what the last build read, recorded, checked first.

A build of 10,000 permutations with nothing to do spent ~10 s loading the scene and making its keys before the
record of the last build (state.py) could say so. So a build the CLI runs leaves a record (``record``): the
request (scene, brick directories, platforms, languages, --keep-removed, --pack or --pack-only, --depfile),
the scene's size, mtime and sha256, the size and mtime of every file the build could have read (the
generator's own code and templates, every brick file of every brick directory, the images and table sources
the scene names), the path, size and mtime of every tool whose version the keys hold, and the size, mtime and
inode of the outputs the build ends with (the manifest, the state record, the versions file) and the
depfile's sha256. It is kept in the compile cache (namespace ``noop-v1``, keyed by the output directory's
absolute path), not in the output tree: it holds this machine's paths, mtimes and inodes, and the tree stays
byte-identical wherever it is built; `cache clear` removes it, a build without a cache has none.

The next build with the same request checks it first (``check``): the same scene bytes, the same files, no
file added to or removed from a brick directory or the generator, the same tools, the outputs as the record
left them, and every file the state record lists there: each directory of the tree with the mtime and inode
the record saw (a file removed, added or renamed into it changes its directory's mtime), and the size of each
file of a directory the record could not vouch for (one modified less than DIR_MARGIN_NS before the record: a
file timestamp is the kernel's coarse clock, a tick behind, so a change within that tick could leave the same
mtime). A no-op that checked a directory file by file vouches for it in the record once it is old enough. A file
rewritten in place under its own name is not seen — as Make and Ninja, which never read an
output's bytes, the record trusts that only the build writes its outputs. Then it is a no-op, said as the full
path says it, and it writes nothing. Any doubt — no record, another request, a stat that differs, a glTF
scene (its buffers are not listed) — is the full path, which loads the scene and decides from the keys as
before; only a build that succeeded records, so the full path also replaces a record it outgrew.

The record is written only for inputs that were already there when the build began: an input whose mtime is
less than ``MARGIN_NS`` before the build started may have changed while it read it (and coarse timestamps,
FAT's 2 s, would hide it), so no record is written and the next build takes the full path and records then.
docs/design/build.md ("A no-op before the scene is loaded") says why.
"""
from __future__ import annotations

import hashlib
import json
import os
from dataclasses import asdict, dataclass, field
from pathlib import Path

from .. import __version__

NOOP = "noop-v1"  # the compile cache's namespace (io.Store) of the records
FORMAT = 1
MARGIN_NS = 2_000_000_000  # coarse file timestamps: FAT's are 2 s apart
DIR_MARGIN_NS = 100_000_000  # an output directory modified this close to its record is checked file by file
_PACKAGE = Path(__file__).resolve().parents[1]  # generator/
_CODE = (".py", ".j2", ".toml")  # what keys.source_files and the versions file hash of it
TOOLS = ("glslc", "glslangValidator", "spirv-val", "spirv-opt", "naga", "dxc")  # whose versions the keys hold


@dataclass(frozen=True)
class Request:
    """What a `build` invocation asks for that decides its outputs; `started` (time.time_ns() before anything was
    read) and `warnings` (the lines the build printed before building, replayed by a no-op) are not compared."""

    scene: str  # absolute
    bricks: tuple[str, ...]  # the extra brick directories, absolute, in order
    platforms: tuple[str, ...]
    languages: tuple[str, ...]
    keep_removed: bool
    pack: str  # "" | "pack" | "only"
    depfile: str | None = None  # absolute
    target: str | None = None  # the depfile's target as the depfile writes it
    cwd: str | None = None  # with a depfile: its paths are relative to the working directory
    started: int = field(default=0, compare=False)
    warnings: tuple[str, ...] = field(default=(), compare=False)

    def key(self) -> dict:
        """The compared fields as the record holds them (JSON: tuples read back as lists)."""
        return json.loads(json.dumps({k: v for k, v in asdict(self).items() if k not in ("started", "warnings")}))


def _stat(path) -> list[int] | None:
    try:
        st = os.stat(path)
    except OSError:
        return None
    return [st.st_size, st.st_mtime_ns]


def _outputs_stat(path) -> list[int] | None:
    try:
        st = os.stat(path)
    except OSError:
        return None
    return [st.st_size, st.st_mtime_ns, st.st_ino]


def _code_files() -> list[str]:
    """The generator's code and templates (every file a build's keys hash of it, and any beside them)."""
    out = []
    for root, dirs, files in os.walk(_PACKAGE):
        dirs[:] = sorted(d for d in dirs if d != "__pycache__" and not d.startswith("."))
        out += [os.path.join(root, f) for f in sorted(files) if f.endswith(_CODE)]
    return out


def _brick_files(dirs) -> list[str]:
    """Every brick file of the brick directories, as load_library finds them."""
    return [str(p) for d in dirs for p in sorted(Path(d).rglob("*.py"))]


def _tools() -> dict[str, list | None]:
    from ..toolchain import find_tool
    out = {}
    for name in TOOLS:
        path = find_tool(name)
        out[name] = None if path is None else [os.path.realpath(path), *(_stat(path) or [None, None])]
    return out


def _sha256(path) -> str | None:
    try:
        return hashlib.sha256(Path(path).read_bytes()).hexdigest()
    except OSError:
        return None


def _key(out) -> str:
    return hashlib.sha256(f"{NOOP}\0{os.path.abspath(out)}".encode()).hexdigest()


def record(out: Path, request: Request, scene, lib, res, templates, store) -> bool:
    """Record in `store` (io.Store) what the build that just ended in `out` (successfully, under its lock) read and
    left; True when written. templates: those its units were composed with (the depfile's). No record when an input
    changed too close to the build's start to be sure which version it read (module docstring): the stale one goes
    too."""
    from .depfile import VERSIONS, inputs
    from .state import STATE
    scene_path = Path(scene.path).resolve()
    listed = [str((Path.cwd() / f).resolve()) for f in inputs(scene, lib, out, templates)]
    versions = str((Path(out) / VERSIONS).resolve())
    extra = sorted({f for f in listed if f != versions and not os.path.isdir(f)} - {str(scene_path)})
    code, bricks = _code_files(), _brick_files([_builtin(), *request.bricks])
    files = {f: _stat(f) for f in [*code, *bricks, *extra]}
    scene_stat = _stat(scene_path)
    newest = max([s[1] for s in [*files.values(), scene_stat] if s is not None], default=0)
    if scene_path.suffix.lower() != ".toml" or None in files.values() or scene_stat is None \
            or newest > request.started - MARGIN_NS:
        forget(out, store)
        return False
    try:
        tools = _tools()
    except RuntimeError:  # no tool may be looked up here (SHADERMATRIX_FORBID_TOOLS): nothing to compare with
        forget(out, store)
        return False
    outputs = {name: _outputs_stat(Path(out) / name) for name in ("manifest.json", STATE, VERSIONS)}
    try:
        tree = _tree_stat(os.fspath(out), _dirs(json.loads((Path(out) / STATE).read_bytes())["files"]), vouch=True)
    except (OSError, ValueError, KeyError, TypeError):
        forget(out, store)
        return False
    doc = {"format": FORMAT, "generator": f"shadermatrix {__version__}", "request": request.key(),
           "scene": {"stat": scene_stat, "sha256": _sha256(scene_path)},
           "code": code, "bricks": bricks, "files": files, "tools": tools, "outputs": outputs, "tree": tree,
           "depfile": _sha256(request.depfile) if request.depfile else None,
           "summary": {"scene": scene.name, "permutations": len(scene.permutations),
                       "packs": [p["path"] for p in res.manifest.get("packs", [])] if request.pack else []},
           "warnings": list(request.warnings)}
    store.put(NOOP, _key(out), (json.dumps(doc, sort_keys=True) + "\n").encode())  # unchanged: not rewritten
    return True


def forget(out: Path, store) -> None:
    """Void the record of `out` (a build that failed, or whose inputs no record can vouch for): an empty one."""
    store.put(NOOP, _key(out), b"{}\n")


def check(out: Path, request: Request, store) -> dict | None:
    """The record's summary and warnings when the build `request` asks for has nothing to do (module docstring),
    with "unchanged": the files it left; None on any doubt (the full path decides)."""
    from .state import STATE
    out = Path(out)
    try:
        doc = json.loads(store.get(NOOP, _key(out)) or b"{}")
        if doc.get("format") != FORMAT or doc.get("generator") != f"shadermatrix {__version__}" \
                or doc.get("request") != request.key():
            return None
        scene = doc["scene"]
        if _stat(request.scene) != scene["stat"] or _sha256(request.scene) != scene["sha256"]:
            return None
        if any(_outputs_stat(out / name) != st for name, st in doc["outputs"].items()):
            return None
        if _code_files() != doc["code"] or _brick_files([_builtin(), *request.bricks]) != doc["bricks"]:
            return None
        if any(_stat(f) != st for f, st in doc["files"].items()) or _tools() != doc["tools"]:
            return None
        if request.depfile and _sha256(request.depfile) != doc["depfile"]:
            return None
        state = json.loads((out / STATE).read_bytes())
        if not state.get("complete"):
            return None
        root, tree = os.fspath(out), doc["tree"]
        if _tree_stat(root, tree) != tree:  # the directories it vouched for, as it left them
            return None
        rest = _dirs(state["files"]) - set(tree)
        if rest and not _sizes_match(root, {rel: size for rel, size in state["files"].items()
                                            if rel.rpartition("/")[0] in rest}):  # the others' files, one by one
            return None
        if rest and (later := _tree_stat(root, rest, vouch=True)):  # found intact and now old enough: vouched
            store.put(NOOP, _key(out), (json.dumps({**doc, "tree": {**tree, **later}}, sort_keys=True) + "\n").encode())
        return {**doc["summary"], "warnings": doc["warnings"], "unchanged": len(state["files"]) + 1}
    except (OSError, ValueError, KeyError, TypeError, AttributeError, RuntimeError):
        return None


def _tree_stat(root: str, dirs, vouch: bool = False) -> dict[str, list[int]]:
    """{directory (relative to root, "" the root): [mtime_ns, inode]} of `dirs`; vouch (when recording): only
    those modified at least DIR_MARGIN_NS ago (the module docstring), the others left out."""
    import time
    now, out = time.time_ns(), {}
    for d in sorted(dirs):
        st = os.stat(os.path.join(root, d) if d else root)
        if not vouch or now - st.st_mtime_ns >= DIR_MARGIN_NS:
            out[d] = [st.st_mtime_ns, st.st_ino]
    return out


def _dirs(files: dict) -> set[str]:
    """The directories (relative) holding `files` (relative paths)."""
    return {rel.rpartition("/")[0] for rel in files}


def _sizes_match(root: str, files: dict[str, int]) -> bool:
    """Whether every file of `files` (path relative to root -> size) is there with its size. Stat'ed relative to
    its directory's descriptor: 170,000 files of a 10,000-permutation tree take ~0.6 s so, ~0.8 s by whole paths."""
    if not hasattr(os, "O_DIRECTORY") or os.stat not in os.supports_dir_fd:  # e.g. Windows: by whole paths
        return all(os.stat(os.path.join(root, rel)).st_size == size for rel, size in files.items())
    by_dir: dict[str, list[tuple[str, int]]] = {}
    for rel, size in files.items():
        d, _, name = rel.rpartition("/")
        by_dir.setdefault(d, []).append((name, size))
    for d, items in by_dir.items():
        fd = os.open(os.path.join(root, d) if d else root, os.O_RDONLY | os.O_DIRECTORY)
        try:
            for name, size in items:
                if os.stat(name, dir_fd=fd).st_size != size:
                    return False
        finally:
            os.close(fd)
    return True


def _builtin() -> str:
    from ..library.bricks import BUILTIN_BRICKS
    return str(BUILTIN_BRICKS)
