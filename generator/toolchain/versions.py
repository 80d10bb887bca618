"""The versions file: what every build depends on of the generator and the tools, in one small file whose bytes
change only when one of them does.

A build writes it into its output tree (``OUT/.shadermatrix-versions``) and lists it in its depfile;
``shadermatrix versions --write FILE``, which a build system runs on every invocation, rewrites it only when a
byte changes, so that its mtime moves on an upgrade (``make setup``, a new generator, an edit of the generator's
code) and at no other time (assemble/depfile.py). Here, not in assemble/, so that the command imports only the
toolchain: it runs on every ``make``.
"""
from __future__ import annotations

import functools
import hashlib
import json
from pathlib import Path

from .. import __version__
from ..io import atomic_write
from ..library.bricks import BUILTIN_BRICKS
from .platforms import dxc_version
from .run import tool_versions

_PACKAGE = Path(__file__).resolve().parents[1]  # generator/


@functools.lru_cache(maxsize=1)
def code_hash() -> str:
    """sha256 of the generator's code and templates (every .py, .j2 and .toml file of the package: its relative path
    and bytes); the built-in bricks aside, when installed inside it: a permutation's key holds those it reads."""
    h = hashlib.sha256()
    for p in sorted(_PACKAGE.rglob("*")):
        if p.suffix in (".py", ".j2", ".toml") and BUILTIN_BRICKS not in p.parents and "__pycache__" not in p.parts \
                and p.is_file():
            h.update(str(p.relative_to(_PACKAGE.parent)).encode() + b"\0" + p.read_bytes() + b"\0")
    return h.hexdigest()


def versions() -> bytes:
    """The file's bytes: the generator's version and code hash, every tool's version (dxc's too, "missing" where it
    is not on PATH), the same whichever platforms a build writes: one file, whatever wrote it."""
    tools = {**tool_versions(), "dxc": dxc_version()}
    doc = {"generator": f"shadermatrix {__version__}", "code": code_hash(), "tools": dict(sorted(tools.items()))}
    return (json.dumps(doc, indent=2) + "\n").encode()


def write_versions(path) -> bool:
    """Write the versions file at `path` when its bytes change (True then); else touch nothing."""
    return atomic_write(Path(path), versions())
