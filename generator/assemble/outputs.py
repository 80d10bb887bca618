"""The output tree as a build system needs it: one build at a time, leftovers removed, what it no longer names.

- ``locked(out)``: an exclusive ``flock`` on ``out/.shadermatrix-lock`` for the whole build; a second
  build into the same directory says it is waiting (one line on stderr) and runs after the first —
  never interleaved with it. The lock goes with the process, so a killed build never leaves it held.
- ``clean_leftovers(out)``: what an interrupted build left — ``.<name>.<random>.tmp`` files in the output
  tree (io.atomic_write's temporaries) and ``shadermatrix-<pid>-*`` directories in the system temp dir
  whose process is gone.
- ``collect_garbage(out, manifest)``: artifacts are content-named, so a rebuild never overwrites a file
  the current manifest names; once the new manifest is in place, the files it no longer names
  (superseded versions, permutations that left the scene) are removed.

The depfile, the stamp and the versions file a build system reads: depfile.py.
"""
from __future__ import annotations

import errno
import fcntl
import os
import re
import shutil
import sys
import tempfile
import time
from contextlib import contextmanager
from pathlib import Path

from ..backends import LANGUAGES
from .platforms import LANGUAGE_TREE, PLATFORM_TABLE

LOCK = ".shadermatrix-lock"
# the trees a build writes (assemble/platforms.py), and the language trees of builds before platforms (emptied)
TREES = (*(f"{LANGUAGE_TREE}/{lang}" for lang in LANGUAGES), *(p.name for p in PLATFORM_TABLE.values() if p.own_files),
         *LANGUAGES)
TEMP_DIR = re.compile(r"^shadermatrix-(?:radv-)?(\d+)-")
OWN_TMP = re.compile(r"^\..+\.[^.]+\.tmp$")  # io.atomic_write: .<name>.<random>.tmp


@contextmanager
def locked(out: Path):
    if out.exists() and not out.is_dir():
        raise NotADirectoryError(errno.ENOTDIR, os.strerror(errno.ENOTDIR), str(out))
    out.mkdir(parents=True, exist_ok=True)
    fd = os.open(out / LOCK, os.O_RDWR | os.O_CREAT, 0o666)
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            print(f"waiting: another build into {out} is running", file=sys.stderr, flush=True)
            fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)  # releases the lock


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # someone else's process: alive
        return True
    return True


STALE_S = 600  # a temp dir of a process that is gone, and untouched this long, is a leftover


def clean_leftovers(out: Path) -> int:
    """Remove an interrupted build's temporary files (the output tree's own directories: the lock is ours, so
    no other build writes there) and directories (system temp dir: of a dead process, untouched for
    STALE_S seconds, since a process in another pid namespace that shares /tmp looks dead from here)."""
    gone = 0
    for d in [out, *(out / tree for tree in TREES)]:
        if not d.is_dir():
            continue
        for p in d.glob(".*.tmp"):
            if p.is_file() and OWN_TMP.match(p.name):
                p.unlink(missing_ok=True)
                gone += 1
    tmp = Path(tempfile.gettempdir())
    now = time.time()
    for d in tmp.glob("shadermatrix-*"):
        m = TEMP_DIR.match(d.name)
        try:
            old = now - d.stat().st_mtime > STALE_S
        except OSError:
            continue
        if m and d.is_dir() and old and int(m[1]) != os.getpid() and not _alive(int(m[1])):
            shutil.rmtree(d, ignore_errors=True)
            gone += 1
    return gone


def named(manifest: dict) -> set[str]:
    """Every file a manifest names (relative paths)."""
    out = set()
    for e in [*manifest.get("permutations", []), *manifest.get("removed", []), manifest.get("ubershader") or {},
              *(manifest.get("depth_shaders") or {}).values()]:
        for stages in e.get("languages", {}).values():
            for item in stages.values():
                out.update(item[k] for k in ("source", "spirv") if k in item)
        out.update(e.get("failed_sources", {}).values())
        for p, d in (e.get("platforms") or {}).items():
            out.update(a["path"] for item in d.get("stages", {}).values() for a in item.values())
    out.update(t["path"] for t in manifest.get("tables", []))  # baked lookup tables (assemble/tables.py)
    out.update(t["path"] for t in manifest.get("textures", []))  # the materials' images (assemble/texture_outputs.py)
    return out


def collect_garbage(out: Path, manifest: dict) -> int:
    """Remove the files of the output trees that the (new, already written) manifest does not name, and the
    trees left empty (a platform no longer built, the language trees of an older layout)."""
    keep, gone = named(manifest), 0
    for tree in TREES:
        d = out / tree
        if not d.is_dir():
            continue
        for p in d.iterdir():
            if p.is_file() and not p.name.startswith(".") and f"{tree}/{p.name}" not in keep:
                p.unlink(missing_ok=True)
                gone += 1
        for empty in (d, d.parent) if d.parent != out else (d,):
            try:
                empty.rmdir()
            except OSError:  # not empty
                pass
    return gone
