"""Atomic, change-only file writes (the start of the content-addressed store), and progress policy.

Every artifact is written to a temporary name in its directory and renamed, so
an interrupted or failed build never leaves a half-written file and never
damages what an earlier build produced.
"""
from __future__ import annotations

import hashlib
import os
import sys
import tempfile
from pathlib import Path

def _umask() -> int:
    """The process's umask now: Linux reports it in /proc/self/status; elsewhere os.umask sets and
    returns it (restored at once). mkstemp creates files 0600; an artifact gets what open() would give."""
    try:
        with open("/proc/self/status", encoding="ascii") as f:
            for line in f:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def atomic_write(path: Path, data: bytes) -> bool:
    """Write `data` to `path` atomically; returns False (and touches nothing) when unchanged."""
    path = Path(path)
    try:
        if path.read_bytes() == data:
            return False
    except OSError:
        pass
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        os.fchmod(fd, 0o666 & ~_umask())
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise
    return True


def show_progress() -> bool:
    """Progress bars on a terminal, quiet in CI and in pipes."""
    return sys.stderr.isatty() and os.environ.get("CI", "").lower() not in ("1", "true")
