"""What a build leaves for the next one to read: the previous manifest and the build's own record beside it.

The record (STATE, deterministic: no times) holds every input key, the manifest's sha256 and every file's
size, so that a build with nothing to do knows it without reading the manifest; and the templates composed
with, for the depfile of a build that composes nothing.
"""
from __future__ import annotations

import json
import os
from pathlib import Path

from ..io import atomic_write, sha256
from .keys import Keys
from .platforms import platform_files
from .texture_outputs import texture_files

STATE = ".shadermatrix-state.json"


def record(out: Path, manifest: dict, text: bytes, keys: Keys, kept: int, templates: set[str]) -> None:
    """Write the record of the build that just wrote `manifest` (as bytes `text`); `templates`: those it composed
    with; kept: the units it kept (permutations and the ubershader) — it adds the last build's templates then,
    which composed them."""
    templates = set(templates)
    if kept:
        templates.update(read(out).get("templates", []))
    ok = all(e.get("status") == "ok" for e in manifest["permutations"]) and \
        (manifest.get("ubershader") or {}).get("status", "ok") == "ok"
    entries = [*manifest["permutations"], *manifest.get("removed", []), manifest.get("ubershader") or {},
               *(manifest.get("depth_shaders") or {}).values()] if manifest.get("artifacts") != "packs" else []
    # (build --pack-only: the entries' artifacts are in the packs, listed below)
    state = {"manifest_sha256": sha256(text), "complete": ok, "keys": keys.permutations, "ubershader": keys.ubershader,
             "scene": keys.scene,
             "files": {rel: (out / rel).stat().st_size for e in entries for rel, _ in items(e)}
             | {p["path"]: p["size"] for p in manifest.get("packs", [])}
             | {t["path"]: t["bytes"] for t in manifest.get("tables", [])}
             | texture_files(manifest),
             "templates": sorted(templates)}
    atomic_write(out / STATE, (json.dumps(state, sort_keys=True) + "\n").encode())


def read(out: Path) -> dict:
    """The last build's record (empty when there is none or it does not read as one)."""
    try:
        state = json.loads((out / STATE).read_text())
    except (OSError, ValueError):
        return {}
    return state if isinstance(state, dict) else {}


def up_to_date(out: Path, keys: Keys) -> int | None:
    """The number of files the last build left when nothing at all needs doing (its record has these keys,
    the manifest is the one it wrote, every file it listed has its size), else None."""
    state = read(out)
    try:
        if not (state.get("complete") and state.get("keys") == keys.permutations
                and state.get("ubershader") == keys.ubershader and state.get("scene") == keys.scene):
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


def previous(out: Path) -> dict:
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
              and all(isinstance(x, str) for e in [*perms, uber] for pair in items(e) for x in pair))
    except (AttributeError, TypeError, KeyError):
        ok = False
    return m if ok else {}


def items(entry: dict):
    """(path, sha256) of every file a manifest entry lists."""
    for stages in entry.get("languages", {}).values():
        for item in stages.values():
            yield from ((item[f], item[f"{f}_sha256"]) for f in ("source", "spirv") if f in item)
    yield from platform_files(entry)


def files(entry: dict) -> int:
    return sum(1 for _ in items(entry))


def intact(out: Path, entry: dict) -> bool:
    """Every file an entry lists is there with the sha256 it records."""
    try:
        return all(sha256((out / rel).read_bytes()) == digest for rel, digest in items(entry))
    except (OSError, TypeError, KeyError, AttributeError):
        return False
