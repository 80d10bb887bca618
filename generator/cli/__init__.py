"""shadermatrix: compose shading bricks into a shader matrix (HLSL, GLSL, WGSL → SPIR-V)."""
from __future__ import annotations

import argparse
import importlib
import pkgutil
import signal
import sys

from .. import __version__
from . import commands
from ..lang.errors import UserError


def _command_names() -> list[str]:
    found = {m.name for m in pkgutil.iter_modules(commands.__path__)}
    return [n for n in commands.ORDER if n in found] + sorted(found - set(commands.ORDER))


def parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="shadermatrix", description=__doc__)
    p.add_argument("--version", action="version", version=f"shadermatrix {__version__}")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name in _command_names():
        mod = importlib.import_module(f"{commands.__name__}.{name}")
        sp = sub.add_parser(name, help=mod.HELP, description=mod.HELP)
        mod.add_arguments(sp)
        sp.set_defaults(func=mod.run)
    return p


def _terminate(signum, frame):
    # SIGTERM unwinds like Ctrl-C, so atomic writes remove their temporary files.
    raise KeyboardInterrupt


def main(argv=None) -> int:
    args = parser().parse_args(argv)
    signal.signal(signal.SIGTERM, _terminate)
    try:
        return args.func(args)
    except UserError as e:  # a bad input, a missing tool, a brick a compiler rejects
        print(f"error: {e}", file=sys.stderr)
        return 1
    except OSError as e:  # an output path that is a file, a full disk, no permission
        where = f"{e.filename}: " if e.filename else ""
        print(f"error: {where}{e.strerror or e} — check the path, its permissions and free space", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("interrupted; earlier outputs are intact", file=sys.stderr)
        return 130
