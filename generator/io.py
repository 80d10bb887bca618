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

# The process's umask, read once at import (os.umask both sets and returns it): mkstemp creates
# files 0600, and an artifact must get the ordinary permissions every other file gets.
_UMASK = os.umask(0o022)
os.umask(_UMASK)


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
        os.fchmod(fd, 0o666 & ~_UMASK)
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
