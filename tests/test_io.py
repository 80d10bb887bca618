"""generator/io.py: artifacts are written atomically, only when changed, with ordinary permissions."""
from __future__ import annotations

import os
import stat

from generator.io import atomic_write


def test_atomic_write_gives_the_permissions_of_an_ordinary_file(tmp_path):
    # tempfile.mkstemp creates 0600; an artifact must get what open() would give under the umask
    umask = os.umask(0o022)
    os.umask(umask)
    path = tmp_path / "a" / "out.bin"
    assert atomic_write(path, b"one")
    assert stat.S_IMODE(path.stat().st_mode) == 0o666 & ~umask
    assert path.read_bytes() == b"one"
    assert not atomic_write(path, b"one")  # unchanged: not rewritten
    assert atomic_write(path, b"two") and path.read_bytes() == b"two"
    assert stat.S_IMODE(path.stat().st_mode) == 0o666 & ~umask
    assert sorted(p.name for p in path.parent.iterdir()) == ["out.bin"]  # no temporary left behind
