"""generator/io.py: artifacts are written atomically, only when changed, with ordinary permissions."""
from __future__ import annotations

import stat
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
WRITE = """
import os, stat, sys
os.umask(int(sys.argv[2], 8))
from generator.io import atomic_write
assert atomic_write(sys.argv[1], b"one")
assert not atomic_write(sys.argv[1], b"one")  # unchanged: not rewritten
print(oct(stat.S_IMODE(os.stat(sys.argv[1]).st_mode)))
"""


def test_atomic_write_gives_the_permissions_the_umask_gives(tmp_path):
    # tempfile.mkstemp creates 0600; an artifact must get what open() would give under the umask
    for umask, want in (("022", 0o644), ("002", 0o664)):
        path = tmp_path / umask / "out.bin"
        r = subprocess.run([sys.executable, "-c", WRITE, str(path), umask], capture_output=True, text=True,
                           cwd=REPO, timeout=60)
        assert r.returncode == 0, r.stderr
        assert int(r.stdout, 8) == want and stat.S_IMODE(path.stat().st_mode) == want
        assert path.read_bytes() == b"one"
        assert sorted(p.name for p in path.parent.iterdir()) == ["out.bin"]  # no temporary left behind
