"""`shadermatrix completion bash|zsh|tcsh`: a shell completion script for every command and option.

The script is generated from the CLI's own argparse parser by shtab (static: no
Python runs at <TAB>), so it cannot drift from the options. Install it with e.g.

    shadermatrix completion bash > /etc/bash_completion.d/shadermatrix
    . <(shadermatrix completion bash)          # this shell only
"""
from __future__ import annotations

import sys

HELP = "print a shell completion script (bash, zsh or tcsh) for every command and option"
SHELLS = ("bash", "zsh", "tcsh")


def add_arguments(p) -> None:
    p.add_argument("shell", choices=SHELLS, help="the shell the script is for")


def run(args) -> int:
    try:
        import shtab
    except ImportError:
        from ...lang.errors import EnvironmentMissing
        raise EnvironmentMissing("shtab is not installed — run `make setup` (scripts/setup.sh)") from None

    from .. import parser
    sys.stdout.write(shtab.complete(parser(), shell=args.shell))
    return 0
