"""Baked tables as build artifacts: KTX2 files beside the shaders, listed in the manifest.

A permutation (or the ubershader) that samples a texture a brick declares as a table
(reference/tables.py) needs the table's texels at run time; the engine loads them from
``OUT/tables/<table>.<W>x<H>.<format>.<sha12>.ktx2`` (io/ktx2.py: one level, RGBA, linear). The file
name carries the texels' sha256, so a changed baker writes a new file and never overwrites one a
manifest names; the manifest's ``tables`` list says, per table: the texture name the shaders bind, the
table, path, sha256 of the file, format, size, bytes, the reference it is baked from, its filtered error
against that reference (`table_error`; for a painted or fitted table, which has no exact function, the
tolerance its brick declares, judged on the BRDF by `shadermatrix accuracy`), and which permutations (and whether the ubershader) sample it. Files of
``tables/`` that the new manifest no longer names are removed after it is in place.
"""
from __future__ import annotations

import hashlib
from pathlib import Path

from .. import __version__
from ..io import atomic_write, content_key
from ..lang.errors import UserError

TABLES_DIR = "tables"


def _users(manifest: dict, names) -> dict[str, list[str]]:
    """{texture name: hashes of the ok permutations (and "ubershader") that bind it}."""
    users: dict[str, list[str]] = {}
    entries = [*manifest.get("permutations", []), {**(manifest.get("ubershader") or {}), "hash": "ubershader"}]
    for e in entries:
        stages = [s for s in (e.get("interface") or {}).values() if isinstance(s, dict)]
        bound = {t.get("name") for s in stages for t in s.get("textures", [])}
        for name in sorted(bound & set(names)):
            users.setdefault(name, []).append(e["hash"])
    return users


def _intact(out: Path, row: dict) -> bool:
    try:
        return hashlib.sha256((out / row["path"]).read_bytes()).hexdigest() == row["sha256"]
    except (OSError, KeyError, TypeError):
        return False


def write_tables(out: Path, lib, manifest: dict, count=None, previous: dict | None = None, base: str = "") -> list[dict]:
    """Bake and write every table the manifest's shaders sample; their manifest entries, by texture name.
    count(changed: bool) is told of each file (written, or already there with these bytes). A table whose
    `input_key` (base: the build's key of the generator's own code and tools; the table, size, format and the
    files its baker reads) is that of the `previous` manifest's row, with its file intact, keeps that row:
    neither baked nor measured again."""
    from ..reference.tables import baked, inputs, lookup, sha256, table_error
    from ..io.ktx2 import encode

    decl = lib.tables()
    users = _users(manifest, decl)
    old = {r.get("texture"): r for r in (previous or {}).get("tables", [])}
    rows = []
    for name in sorted(users):
        d = decl[name]
        w, h = d["size"]
        try:
            key = content_key(base, "table", d["table"], w, h, d["format"], d["tolerance"], inputs(d["table"]))
        except LookupError:  # an unknown table: said below, with the brick
            key = ""
        kept = old.get(name)
        if key and kept is not None and kept.get("input_key") == key and _intact(out, kept):
            rows.append({**kept, "brick": d["brick"], "used_by": sorted(users[name])})
            if count is not None:
                count(False)
            continue
        try:
            stored = baked(d["table"], d["size"], d["format"])
        except (LookupError, ValueError) as e:  # an unknown table, a size or format its baker refuses
            raise UserError(f"brick '{d['brick']}', texture '{name}': table '{d['table']}' at {w}x{h} "
                            f"{d['format']}: {e}") from None
        cube = lookup(d["table"]).cube
        data = encode(stored, d["format"], cube=cube, writer=f"shadermatrix {__version__}")
        digest = hashlib.sha256(data).hexdigest()
        rel = f"{TABLES_DIR}/{d['table']}.{w}x{h}.{d['format']}.{digest[:12]}.ktx2"
        path = out / rel
        changed = not (path.is_file() and path.read_bytes() == data)
        if changed:
            path.parent.mkdir(parents=True, exist_ok=True)
            atomic_write(path, data)
        if count is not None:
            count(changed)
        # the filtered table against its exact function; a painted or fitted table has none: its error is the
        # BRDF's (`shadermatrix accuracy`), judged at the tolerance its brick declares
        err = table_error(d["table"], d["size"], d["format"]) or {
            "measured_on": "the BRDF (shadermatrix accuracy)", "brick_tolerance": d["tolerance"]}
        rows.append({"texture": name, "table": d["table"], "brick": d["brick"], "path": rel, "sha256": digest,
                     "texels_sha256": sha256(stored), "format": d["format"], "size": [w, h],
                     "dimension": "cube" if cube else "2d", "bytes": len(data), "reference": lookup(d["table"]).reference,
                     "error": err, "used_by": sorted(users[name]), "input_key": key})
    return rows


def collect_tables(out: Path, manifest: dict) -> int:
    """Remove the files of OUT/tables that the (new, already written) manifest does not name."""
    keep = {t["path"] for t in manifest.get("tables", [])}
    d, gone = out / TABLES_DIR, 0
    if not d.is_dir():
        return 0
    for p in d.iterdir():
        if p.is_file() and not p.name.startswith(".") and f"{TABLES_DIR}/{p.name}" not in keep:
            p.unlink(missing_ok=True)
            gone += 1
    return gone
