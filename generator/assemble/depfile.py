"""What a build system needs to run a build exactly when an input changed: the depfile, the stamp, the versions file.

- ``inputs(scene, lib, out)``: what the scene's permutations and ubershader read — the scene, the images its
  materials name, the bricks the permutations reach (not every brick the library loaded: editing a brick no
  permutation uses reruns nothing), the templates composed with, the files the tables those bricks sample are
  baked from — and, beside them, every brick directory (its mtime moves when a file is added or removed there,
  so a new brick is a change) and the versions file.
- ``VERSIONS`` (``OUT/.shadermatrix-versions``, toolchain/versions.py): the generator's version and the hash of
  its code, every tool's version. Rewritten (by every build, and by ``shadermatrix versions --write FILE``, which
  a build system runs on every invocation) only when one of them changes, so that its mtime moves on an upgrade
  and at no other time: a depfile dependency like any other, it reruns the build after ``make setup`` or a new
  generator.
- ``write_depfile(path, target, deps)``: Make syntax, which Ninja reads too (``deps = gcc``), with an empty rule
  per dependency (gcc's ``-MP``: a dependency that goes away reruns the build instead of stopping Make).
- ``touch(path)``: the stamp, replaced after every build that succeeded: its mtime is the build's end.
"""
from __future__ import annotations

import os
from pathlib import Path

from ..lang.errors import UserError
from ..toolchain.versions import write_versions

__all__ = ["VERSIONS", "escape", "inputs", "shown", "touch", "write_depfile", "write_versions"]

VERSIONS = ".shadermatrix-versions"
SKIPPED_DIRS = ("__pycache__",)  # a brick directory's folders that hold no bricks


def shown(path) -> str:
    """A dependency as the build system invoked us sees it: relative to the working directory when inside it."""
    p = Path(path).resolve()
    try:
        return str(p.relative_to(Path.cwd().resolve()))
    except ValueError:
        return str(p)


def _bricks(scene, lib) -> list:
    """Every brick a permutation of `scene` reads: its BRDF's terms and their fillers, its packing's (the normal
    filler within), each light's and its shadow filter's, its output's; the ubershader reads these too."""
    from ..lang import SourceError
    from ..spec.permutation import SpecError
    from ..spec.resolve import resolve
    found = {}
    for _, perm in sorted(scene.permutations.items()):
        try:
            r = resolve(perm, lib)
        except (SourceError, SpecError):  # it fails to compose: the build fails, and no stamp is written
            continue
        nodes = [x for top in (*r.brdf, r.packing, *(lt.shadow for lt in r.lights)) for x in top.tree]
        env = [r.environment.brick] if r.environment is not None else []
        for b in [*(n.brick for n in nodes), *(lt.brick for lt in r.lights), r.output, *env]:
            found[(b.kind, b.id)] = b
    return list(found.values())


def _table_sources(bricks) -> list[Path]:
    """The files the tables these bricks sample are baked from (a painted table's image)."""
    from ..reference.tables import lookup
    out = []
    for b in bricks:
        for d in b.textures.values():
            if d.get("table"):
                try:
                    out.extend(Path(p) for p in lookup(d["table"]).sources)
                except LookupError:  # an unknown table fails the build, naming the brick
                    pass
    return out


def brick_dirs(lib) -> list[Path]:
    """Every folder of the library's brick directories: adding a brick file to one changes its mtime."""
    out = []
    for d in lib.dirs:
        d = Path(d)
        out.append(d)
        out.extend(p for p in sorted(d.rglob("*")) if p.is_dir() and p.name not in SKIPPED_DIRS
                   and not p.name.startswith(".") and not set(SKIPPED_DIRS) & set(p.relative_to(d).parts))
    return out


def inputs(scene, lib, out: Path, templates) -> list[str]:
    """The depfile's dependencies of a build of `scene` into `out` (module docstring); templates: the names of
    those composed with (this build's and the last ones', for what it kept)."""
    from ..backends import template_file
    from .texture_outputs import image_files
    bricks = sorted(_bricks(scene, lib), key=lambda b: (b.kind, b.id))
    files = [scene.path, *scene.extra.get("inputs", ()), *image_files(scene), *(b.path for b in bricks), *_table_sources(bricks),
             *(template_file(t) for t in sorted(templates)), *brick_dirs(lib), Path(out) / VERSIONS]
    return sorted({shown(f) for f in files})


_SPECIAL = {" ": "\\ ", "#": "\\#", ":": "\\:", "$": "$$"}


def escape(path: str) -> str:
    """`path` as Make and Ninja read it in a depfile (Ninja's parser follows Make's rules): ``\\ `` for a space,
    ``\\#``, ``\\:``, ``$$``; a backslash stays itself, except before one of those or at the end, where the two
    tools would read it differently: such a path, or one with a line break, is refused."""
    if "\n" in path or "\r" in path:
        raise UserError(f"--depfile: the path {path!r} has a line break, which a depfile cannot hold — rename it")
    if path.endswith("\\") or any(path[i - 1] == "\\" for i, c in enumerate(path) if i and c in _SPECIAL):
        where = "at its end" if path.endswith("\\") else "before a space, '#', ':' or '$'"
        raise UserError(f"--depfile: the path {path!r} has a backslash {where}, which Make and Ninja read "
                        "differently — rename it")
    return "".join(_SPECIAL.get(c, c) for c in path)


def write_depfile(path: Path, target: str, deps) -> bool:
    """``target: dep dep ...`` (one dependency per line) and an empty rule per dependency, atomically; False
    when the file was already so."""
    from ..io import atomic_write
    deps = [escape(d) for d in sorted(set(deps))]
    lines = [f"{escape(target)}:"] + [f"  {d}" for d in deps]
    text = " \\\n".join(lines) + "\n" + "".join(f"\n{d}:" for d in deps) + "\n"
    return atomic_write(Path(path), text.encode())


def touch(path: Path) -> None:
    """Replace the stamp file (atomically: a new file renamed over the old one), so that its mtime is now."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.parent / f".{path.name}.{os.getpid()}-{os.urandom(4).hex()}.tmp"
    try:
        tmp.write_bytes(b"shadermatrix build: succeeded\n")
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)
