"""Where the external tools are looked for, and the versions they are pinned to.

The package may be installed anywhere (a clone's venv, a wheel in a studio's environment), so nothing
here reads the repository: the pins are package data and the tools are searched, in this order, in

1. ``SHADERMATRIX_TOOLS`` — directories, separated as in PATH, put before everything else (a CI image's
   tool folder, a naga built elsewhere);
2. the scripts directory of the Python environment that runs shadermatrix (a venv's ``bin/``):
   `make setup` links the naga it builds there, and ``.venv/bin/shadermatrix`` is usually run without
   activating the venv, so this directory is not on PATH;
3. ``PATH``.
"""
from __future__ import annotations

import functools
import os
import sysconfig
import tomllib
from importlib import resources

TOOLS_ENV = "SHADERMATRIX_TOOLS"
PINS_FILE = "pins.toml"  # beside this module, package data


def tool_dirs() -> list[str]:
    """The directories searched for a tool, first match wins (see the module docstring)."""
    dirs = [d for d in os.environ.get(TOOLS_ENV, "").split(os.pathsep) if d]
    scripts = sysconfig.get_path("scripts")
    if scripts:
        dirs.append(scripts)
    dirs += [d for d in os.environ.get("PATH", os.defpath).split(os.pathsep) if d]
    return dirs


@functools.lru_cache(maxsize=1)
def pinned_versions() -> dict[str, str]:
    """{tool or Debian package: pinned version} from pins.toml (what scripts/setup.sh installs)."""
    text = resources.files(__package__).joinpath(PINS_FILE).read_text(encoding="utf-8")
    return {k: str(v) for k, v in tomllib.loads(text).items()}
