"""`shadermatrix versions`: what every build keys on of the generator and the tools, as the versions file holds it."""
from __future__ import annotations

import sys

HELP = ("print the generator's version, the hash of its code and every tool's version (JSON); --write FILE rewrites "
        "FILE only when one changed: a build system's rule run every time, that reruns the build after an upgrade")


def add_arguments(p) -> None:
    p.add_argument("--write", metavar="FILE",
                   help="write FILE (e.g. OUT/.shadermatrix-versions, which a build's depfile names) when its bytes "
                        "change, else touch nothing; prints one line when it did")


def run(args) -> int:
    from ...toolchain.versions import versions, write_versions  # not assemble/: this runs on every make
    if args.write is None:
        sys.stdout.buffer.write(versions())
        return 0
    if write_versions(args.write):
        print(f"{args.write}: the generator or a tool changed since it was written (or it was new): rewritten")
    return 0
