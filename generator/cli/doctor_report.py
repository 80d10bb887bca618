"""`shadermatrix doctor`: is every external tool here, in the pinned version?

Pins come from pyproject.toml ``[tool.shadermatrix.tools]`` (the versions
scripts/setup.sh installs). naga must match exactly (its output is in the
goldens); Debian packages are compared on their upstream version, and a
different one is a warning, not a failure. A missing tool or no lavapipe
device is a failure.
"""
from __future__ import annotations

import re
import sys
import tomllib

from .. import toolchain
from ..runtime import probe

# tool -> (pin key in pyproject, version pattern in `tool --version`)
_TOOLS = {
    "glslc": ("glslc", r"shaderc v?(\S+)"),
    "glslangValidator": ("glslang-tools", r"Glslang Version: (?:\d+:)?(\S+)"),
    "spirv-val": ("spirv-tools", r"SPIRV-Tools v(\S+)"),
    "spirv-opt": ("spirv-tools", r"SPIRV-Tools v(\S+)"),
    "spirv-as": ("spirv-tools", r"SPIRV-Tools v(\S+)"),
    "naga": ("naga", r"^(\S+)"),
}


def pinned_tools() -> dict[str, str]:
    path = toolchain.REPO_ROOT / "pyproject.toml"
    try:
        with open(path, "rb") as f:
            return dict(tomllib.load(f).get("tool", {}).get("shadermatrix", {}).get("tools", {}))
    except (OSError, tomllib.TOMLDecodeError):
        return {}


def _upstream(version: str) -> str:
    """Debian version -> upstream part: "12.0.0-2" -> "12.0.0", "2023.2-1" -> "2023.2"."""
    return re.sub(r"-[0-9][^-]*$", "", version)


def run_doctor(out=None) -> int:
    out = out or sys.stdout
    pins = pinned_tools()
    failed = False
    rows = []
    for tool, (pin_key, pattern) in _TOOLS.items():
        path = toolchain.find_tool(tool)
        pin = pins.get(pin_key, "?")
        if path is None:
            rows.append(("MISSING", tool, "-", pin, "run `make setup` (scripts/setup.sh)"))
            failed = True
            continue
        version = toolchain._version_of(tool, lambda text: (m.group(1) if (m := re.search(pattern, text, re.M)) else None))
        if tool == "naga":
            status = "ok" if version == pin else "MISMATCH"
            failed |= status != "ok"
        else:
            status = "ok" if _upstream(version) == _upstream(pin) else "warn"
        rows.append((status, tool, version, pin, path))

    devices, reason = probe.vulkan_status()
    lvp = [d for d in devices if d["name"].startswith("llvmpipe")]
    pin = f"mesa-vulkan-drivers {pins.get('mesa-vulkan-drivers', '?')}"
    if lvp:
        rows.append(("ok", "lavapipe", f"Vulkan {lvp[0]['api_version']}", pin, lvp[0]["name"]))
    else:
        failed = True
        others = ", ".join(d["name"] for d in devices) or reason or "no device"
        rows.append(("MISSING", "lavapipe", "-", pin, f"no llvmpipe device ({others})"))

    print("shadermatrix doctor", file=out)
    header = ("status", "tool", "version", "pinned", "path / note")
    widths = [max(len(str(r[i])) for r in rows + [header]) for i in range(4)]
    for row in [header] + rows:
        print("  " + "  ".join(str(c).ljust(w) for c, w in zip(row, widths)) + "  " + row[4], file=out)
    print("all tools present" if not failed else "some tools are missing or wrong: run `make setup`", file=out)
    return 3 if failed else 0  # the CLI's exit code for an environment that lacks a tool or the device


if __name__ == "__main__":
    sys.exit(run_doctor())
