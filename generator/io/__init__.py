"""Atomic, change-only file writes, the content-addressed store (Store), and progress policy.

Every artifact is written to a temporary name in its directory and renamed, so
an interrupted or failed build never leaves a half-written file and never
damages what an earlier build produced.
"""
from __future__ import annotations

import hashlib
import json
import os
import sys
import itertools
import threading
from pathlib import Path

_TMP_SERIAL = itertools.count()


def sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def atomic_write(path: Path, data: bytes, dirs: dict | None = None) -> bool:
    """Write `data` to `path` atomically; returns False (and touches nothing) when unchanged.

    Atomic against the process dying at any instant (Ctrl-C, SIGTERM, kill -9): a reader sees the old
    file or the new one, never a part. Not fsync'ed: a power cut may leave a recent file empty, which
    the next build notices (a size or sha256 that is not the recorded one) and rebuilds; fsync per file
    cost more than the rest of writing a 1,000-permutation build (docs/design/build.md, "No fsync").

    dirs: what a writer that alone writes a tree (a build, under its lock) knows of it — {directory: the names
    in it}, each directory made (or found) and listed once, the names written since added — so that a new
    file is not first opened to compare (a build writes thousands of new files into a few directories). A
    name listed is compared as always. Plain os calls, no pathlib: a build's writing is mostly this function,
    and the kernel's part (four calls for a new file) is all of it that is left.
    """
    path = os.fspath(path)
    parent, name = os.path.split(path)
    parent = parent or "."
    names = None
    if dirs is not None:
        names = dirs.get(parent)
        if names is None:
            os.makedirs(parent, exist_ok=True)
            names = dirs[parent] = set(os.listdir(parent))
    if names is None or name in names:
        try:
            with open(path, "rb") as f:
                if f.read() == data:
                    return False
        except OSError:
            pass
    if names is None:
        os.makedirs(parent, exist_ok=True)
    # Created with mode 0666 and O_EXCL: the kernel applies the umask, as for any file a program writes
    # (tempfile.mkstemp would give 0600). The random part: a killed process's leftover of the same pid
    # (containers reuse pids run after run) never stands in the way.
    tmp = os.path.join(parent, f".{name}.{os.getpid()}-{next(_TMP_SERIAL)}-{os.urandom(4).hex()}.tmp")
    fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_CLOEXEC", 0), 0o666)
    try:
        try:
            view = memoryview(data)
            while view:
                view = view[os.write(fd, view):]
        finally:
            os.close(fd)
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise
    if names is not None:
        names.add(name)
    return True


def show_progress() -> bool:
    """Progress bars on a terminal, quiet in CI and in pipes."""
    return sys.stderr.isatty() and os.environ.get("CI", "").lower() not in ("1", "true")


# ------------------------------------------------------------------ the content-addressed store

def content_key(*parts) -> str:
    """sha256 of everything that determines an artifact (JSON-able parts, in order)."""
    return sha256(json.dumps(parts, sort_keys=True, separators=(",", ":")).encode())


def default_cache_dir() -> Path | None:
    """$SHADERMATRIX_CACHE_DIR, else $XDG_CACHE_HOME/shadermatrix, else ~/.cache/shadermatrix (a per-user
    directory, never the source tree); None when there is no home directory to put it in."""
    if os.environ.get("SHADERMATRIX_CACHE_DIR"):
        return Path(os.environ["SHADERMATRIX_CACHE_DIR"])
    base = os.environ.get("XDG_CACHE_HOME")
    if not base:
        try:
            base = str(Path.home() / ".cache")
        except RuntimeError:  # no $HOME and no passwd entry (some containers)
            return None
    return Path(base) / "shadermatrix"


class Store:
    """A content-addressed cache: an entry is named by the sha256 of everything that determines it.

    Layout: ``<root>/<namespace>/<key[:2]>/<key>``; an entry holds its payload followed by the payload's
    sha256 (32 bytes). Entries are written atomically (a temporary name, then a rename) and verified on
    every read: a short or damaged entry is counted as corrupt, removed and reported as a miss, so it is
    rebuilt, never served. Safe to share between threads and between concurrent processes (a rename
    replaces an entry whole; two writers of one key write the same result, their times aside).
    """

    def __init__(self, root):
        self.root = Path(root)
        self.hits = self.misses = self.corrupt = self.written = 0
        self.unwritable = ""  # why puts stopped (a read-only or full cache): the build goes on without them
        self._lock = threading.Lock()

    def _path(self, namespace: str, key: str) -> Path:
        return self.root / namespace / key[:2] / key

    def _count(self, what: str) -> None:
        with self._lock:
            setattr(self, what, getattr(self, what) + 1)

    def get(self, namespace: str, key: str) -> bytes | None:
        path = self._path(namespace, key)
        try:
            data = path.read_bytes()
        except OSError:
            self._count("misses")
            return None
        payload, digest = data[:-32], data[-32:]
        if len(data) < 32 or hashlib.sha256(payload).digest() != digest:
            self._count("corrupt")
            self._count("misses")
            try:
                path.unlink()
            except OSError:
                pass
            return None
        self._count("hits")
        return payload

    def put(self, namespace: str, key: str, payload: bytes) -> None:
        """Store an entry; a cache that cannot be written (read-only, full, not a directory) is said once on
        stderr and then left alone: the build never fails for its cache."""
        if self.unwritable:
            return
        try:
            if atomic_write(self._path(namespace, key), payload + hashlib.sha256(payload).digest()):
                self._count("written")
        except OSError as e:
            with self._lock:
                if not self.unwritable:
                    self.unwritable = f"{e.filename or self.root}: {e.strerror or e}"
                    print(f"warning: the compile cache cannot be written ({self.unwritable}) — building without "
                          "storing into it", file=sys.stderr)

    def entries(self) -> dict[str, tuple[int, int]]:
        """{namespace: (entries, bytes)} of what is stored now."""
        out = {}
        if not self.root.is_dir():
            return out
        for ns in sorted(p for p in self.root.iterdir() if p.is_dir()):
            files = [f for f in ns.glob("*/*") if f.is_file() and not f.name.startswith(".")]
            out[ns.name] = (len(files), sum(f.stat().st_size for f in files))
        return out

    def clear(self) -> int:
        """Remove every entry (and leftover temporary file); returns how many files went."""
        gone = 0
        if not self.root.is_dir():
            return gone
        for ns in (p for p in self.root.iterdir() if p.is_dir()):
            for f in ns.glob("*/*"):
                if f.is_file():
                    f.unlink()
                    gone += 1
        return gone
