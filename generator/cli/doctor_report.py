"""`shadermatrix doctor`: is every external tool here, in the pinned version, and how to get what is not?

Pins come from generator/toolchain/pins.toml (package data: the versions scripts/setup.sh installs),
so an installed package checks itself as a clone does. naga must match exactly (its output is in the
goldens); Debian packages are compared on their upstream version, and a different one is a warning, not
a failure. A missing tool or no lavapipe device is a failure, and its row says how to install it.
"""
from __future__ import annotations

import os
import re
import sys
import sysconfig

from .. import toolchain
from ..runtime import probe

# tool -> (pin key in pins.toml, version pattern in `tool --version`)
_TOOLS = {
    "glslc": ("glslc", r"shaderc v?(\S+)"),
    "glslangValidator": ("glslang-tools", r"Glslang Version: (?:\d+:)?(\S+)"),
    "spirv-val": ("spirv-tools", r"SPIRV-Tools v(\S+)"),
    "spirv-opt": ("spirv-tools", r"SPIRV-Tools v(\S+)"),
    "spirv-as": ("spirv-tools", r"SPIRV-Tools v(\S+)"),
    "naga": ("naga", r"^(\S+)"),
}


def pinned_tools() -> dict[str, str]:
    return toolchain.pinned_versions()


def how_to_get(pin_key: str, pin: str) -> str:
    """The command that installs a pinned tool (what scripts/setup.sh runs for it) on Debian 12."""
    if pin_key == "naga":
        return (f"`cargo install naga-cli --locked --version {pin}` (into ~/.cargo/bin: put that on PATH or "
                f"in ${toolchain.TOOLS_ENV}; a clone: `make setup`)")
    suite = " -t bookworm-backports" if "bpo" in pin else ""
    return f"`apt-get install{suite} {pin_key}={pin}` (a clone: `make setup`)"


def _rows(pins: dict[str, str]) -> tuple[list[tuple], bool]:
    failed = False
    rows = []
    for tool, (pin_key, pattern) in _TOOLS.items():
        path = toolchain.find_tool(tool)
        pin = pins.get(pin_key, "?")
        if path is None:
            rows.append(("MISSING", tool, "-", pin, "install: " + how_to_get(pin_key, pin)))
            failed = True
            continue
        version = toolchain.version_of(tool, lambda text: (m.group(1) if (m := re.search(pattern, text, re.M)) else None))
        if tool == "naga":
            status = "ok" if version == pin else "MISMATCH"
            failed |= status != "ok"
        else:
            status = "ok" if _upstream(version) == _upstream(pin) else "warn"
        rows.append((status, tool, version, pin, path if status == "ok" else f"{path}; pinned: {how_to_get(pin_key, pin)}"))

    devices, reason = probe.vulkan_status()
    lvp = [d for d in devices if d["name"].startswith("llvmpipe")]
    pin = pins.get("mesa-vulkan-drivers", "?")
    shown = f"mesa-vulkan-drivers {pin}"
    if lvp:
        rows.append(("ok", "lavapipe", f"Vulkan {lvp[0]['api_version']}", shown, lvp[0]["name"]))
    else:
        failed = True
        others = ", ".join(d["name"] for d in devices) or reason or "no device"
        rows.append(("MISSING", "lavapipe", "-", shown,
                     f"no llvmpipe device ({others}); install: {how_to_get('mesa-vulkan-drivers', pin)}"))
    return rows, failed


def _upstream(version: str) -> str:
    """Debian version -> upstream part: "12.0.0-2" -> "12.0.0", "2023.2-1" -> "2023.2"."""
    return re.sub(r"-[0-9][^-]*$", "", version)


def run_doctor(out=None) -> int:
    out = out or sys.stdout
    rows, failed = _rows(pinned_tools())
    print("shadermatrix doctor", file=out)
    env = os.environ.get(toolchain.TOOLS_ENV)
    first = f"${toolchain.TOOLS_ENV}={env}" if env else f"${toolchain.TOOLS_ENV} (unset)"
    print(f"  tools are looked for in {first}, then {sysconfig.get_path('scripts')}, then PATH", file=out)
    header = ("status", "tool", "version", "pinned", "path / note")
    widths = [max(len(str(r[i])) for r in rows + [header]) for i in range(4)]
    for row in [header] + rows:
        print("  " + "  ".join(str(c).ljust(w) for c, w in zip(row, widths)) + "  " + row[4], file=out)
    print("all tools present" if not failed else "some tools are missing or wrong: install them as their rows say",
          file=out)
    return 3 if failed else 0  # the CLI's exit code for an environment that lacks a tool or the device


if __name__ == "__main__":
    sys.exit(run_doctor())
