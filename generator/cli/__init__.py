"""shadermatrix: compose shading bricks into a shader matrix (GLSL, HLSL, WGSL → SPIR-V)."""
from __future__ import annotations

import argparse
import importlib
import os
import pkgutil
import signal
import sys

from .. import __version__
from . import commands
from ..lang.errors import EnvironmentMissing, UsageError, UserError


def _command_names() -> list[str]:
    found = {m.name for m in pkgutil.iter_modules(commands.__path__)}
    return [n for n in commands.ORDER if n in found] + sorted(found - set(commands.ORDER))


EXIT_OK, EXIT_FAILED, EXIT_USAGE, EXIT_ENVIRONMENT, EXIT_INTERRUPTED, EXIT_PIPE = 0, 1, 2, 3, 130, 141
EXIT_CODES = f"""exit codes (the same for every command):
  {EXIT_OK}    done
  {EXIT_FAILED}    a failure in the inputs or the shaders (a brick, a scene, a sample file, a compiler's error)
  {EXIT_USAGE}    a usage error: an unknown option, an option's value out of its range
  {EXIT_ENVIRONMENT}    the environment lacks what the command needs: a pinned tool or the Vulkan device
       (`make setup`; `shadermatrix doctor` says what is missing) — never skipped silently
  {EXIT_INTERRUPTED}  interrupted (Ctrl-C, SIGTERM): earlier outputs are intact
  {EXIT_PIPE}  the reader of its output went away (`| head`): ended quietly, as Unix tools do"""


def parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="shadermatrix", description=__doc__, epilog=EXIT_CODES,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--version", action="version", version=f"shadermatrix {__version__}")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name in _command_names():
        mod = importlib.import_module(f"{commands.__name__}.{name}")
        sp = sub.add_parser(name, help=mod.HELP, description=mod.HELP, epilog=EXIT_CODES,
                            formatter_class=argparse.RawDescriptionHelpFormatter)
        mod.add_arguments(sp)
        sp.set_defaults(func=mod.run, parser=sp)
    return p


def _terminate(signum, frame):
    # SIGTERM unwinds like Ctrl-C, so atomic writes remove their temporary files.
    raise KeyboardInterrupt


def main(argv=None) -> int:
    args, unknown = parser().parse_known_args(argv)
    if unknown:  # the subcommand's own usage, not the top level's
        args.parser.error(f"unrecognized arguments: {' '.join(unknown)}")
    signal.signal(signal.SIGTERM, _terminate)
    try:
        return args.func(args)
    except UsageError as e:  # an option's value that cannot mean anything: one line, with what to write instead
        print(f"error: {e}", file=sys.stderr)
        return EXIT_USAGE
    except EnvironmentMissing as e:  # a pinned tool or the Vulkan device is not there
        print(f"error: {e}", file=sys.stderr)
        return EXIT_ENVIRONMENT
    except UserError as e:  # a bad input, a brick a compiler rejects
        print(f"error: {e}", file=sys.stderr)
        return EXIT_FAILED
    except BrokenPipeError:  # `shadermatrix bricks | head`: the reader went away; end quietly, as Unix tools do
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # nothing more to flush at exit
        return EXIT_PIPE
    except OSError as e:  # an output path that is a file, a full disk, no permission
        where = f"{e.filename}: " if e.filename else ""
        print(f"error: {where}{e.strerror or e} — check the path, its permissions and free space", file=sys.stderr)
        return EXIT_FAILED
    except KeyboardInterrupt:
        print("interrupted; earlier outputs are intact", file=sys.stderr)
        return EXIT_INTERRUPTED
