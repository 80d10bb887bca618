"""A scene's environments: what lights its objects after the lights (image-based lighting), and which light sets.

    [scene]
    environment = "sky"               # optional: the environment of every light set that names none itself

    [environments.sky]
    sky = "default"                   # the procedural default sky (eval/ibl_env.py sky) — or:
    # image = "studio.hdr"            # a Radiance .hdr, equirectangular, +Y up, relative to the scene's folder
    rotation = 30.0                   # degrees about +Y (default 0)
    intensity = 1.0                   # scales its radiance (default 1)
    size = 64                         # the prefiltered radiance cube's face, texels: a power of two 4..512
    light_sets = ["indoor"]           # optional: the light sets it lights instead of [scene].environment
    brick = "split_sum"               # optional: the environment brick (library kind "environment")

A light set's environment is the one whose `light_sets` names it, else `[scene].environment`, else none. A light
set with an environment makes every permutation it lights carry the brick (`;environment=split_sum`): the
environment's image is data (the Lights block's SH9 values, the radiance cube), so two environments of one brick
share their shaders. Errors are located, `path:line:col: what — what to do`; an unknown key is the schema's
(scene/schema.py), with the closest name.
"""
from __future__ import annotations

import difflib
from dataclasses import dataclass
from pathlib import Path

from ..library.bricks import Library
from .locate import Locator

DEFAULT_BRICK = "split_sum"
DEFAULT_SIZE = 64  # eval/ibl_env.py CUBE_SIZE: 7 levels, 64² to 1², bake ~10 s on this machine
SIZES = tuple(1 << k for k in range(2, 10))  # 4 … 512
SKIES = ("default",)


@dataclass(frozen=True)
class Environment:
    """One [environments.NAME]: its image (a path) or procedural sky, its rotation (degrees about +Y), intensity,
    the radiance cube's face size, and its brick."""

    name: str
    image: Path | None = None  # the .hdr file, resolved against the scene's folder
    sky: str = ""  # "default": the procedural sky
    rotation: float = 0.0
    intensity: float = 1.0
    size: int = DEFAULT_SIZE
    brick: str = DEFAULT_BRICK
    source: str = ""  # as the scene writes it: the image path, or "sky:default"

    @property
    def levels(self) -> int:
        """The radiance cube's mip levels: the full chain of a size² face down to 1²."""
        return self.size.bit_length()


def read_environments(loc: Locator, data: dict, scene, lib: Library) -> None:
    """scene.environments and scene.environment_of (light set name → environment name), checked."""
    table = data.get("environments", {})
    folder = Path(scene.path).parent
    for name, e in table.items():
        header = f"environments.{name}"
        if ("image" in e) == ("sky" in e):
            raise loc.error(loc.find(header, "image") if "image" in e else loc.find(header),
                            f"environment '{name}' needs one of image and sky" + (", not both" if "image" in e else ""),
                            'write image = "file.hdr" (relative to the scene) or sky = "default"')
        image = None
        if "image" in e:
            image = (folder / e["image"]).resolve()
            if not image.is_file():
                raise loc.error(loc.find(header, "image"), f"environment '{name}': image '{e['image']}' not found "
                                f"(looked in {folder})", "give a Radiance .hdr file's path relative to the scene")
            if image.suffix.lower() != ".hdr":
                raise loc.error(loc.find(header, "image"), f"environment '{name}': '{e['image']}' is not a Radiance "
                                ".hdr file", "convert the image to Radiance RGBE (.hdr)")
        elif e["sky"] not in SKIES:
            close = difflib.get_close_matches(str(e["sky"]), SKIES, n=1)
            raise loc.error(loc.find(header, "sky"), f"environment '{name}': unknown sky {e['sky']!r}",
                            (f"did you mean '{close[0]}'? " if close else "") + f"skies: {', '.join(SKIES)}")
        size = e.get("size", DEFAULT_SIZE)
        if size not in SIZES:
            raise loc.error(loc.find(header, "size"), f"environment '{name}': size {size} is not a power of two "
                            f"from {SIZES[0]} to {SIZES[-1]}", f"write size = {DEFAULT_SIZE}")
        intensity = float(e.get("intensity", 1.0))
        if not 0.0 <= intensity <= 1e6:
            raise loc.error(loc.find(header, "intensity"), f"environment '{name}': intensity {intensity} is outside "
                            "[0, 1e6]", "write intensity = 1.0")
        rotation = float(e.get("rotation", 0.0))
        if not -1e4 <= rotation <= 1e4:
            raise loc.error(loc.find(header, "rotation"), f"environment '{name}': rotation {rotation} is not an "
                            "angle in degrees", "write rotation = 30.0 (degrees about +Y)")
        brick = e.get("brick", DEFAULT_BRICK)
        if lib.get("environment", brick) is None:
            known = [b.id for b in lib.of_kind("environment")]
            close = difflib.get_close_matches(brick, known, n=1)
            raise loc.error(loc.find(header, "brick"), f"environment '{name}': unknown environment brick '{brick}'",
                            (f"did you mean '{close[0]}'? " if close else "") + f"known: {', '.join(known) or 'none'}")
        scene.environments[name] = Environment(name, image, e.get("sky", ""), rotation, intensity, size, brick,
                                               e["image"] if image is not None else f"sky:{e['sky']}")
    default = data.get("scene", {}).get("environment")
    if default is not None and default not in scene.environments:
        close = difflib.get_close_matches(default, list(scene.environments), n=1)
        raise loc.error(loc.find("scene", "environment"), f"[scene] environment '{default}' is not declared",
                        (f"did you mean '{close[0]}'? " if close else "") +
                        f"declare [environments.{default}] or use one of: {', '.join(scene.environments) or 'none'}")
    chosen: dict[str, str] = {}
    for name, e in table.items():
        for s in e.get("light_sets", []):
            where = loc.find(f"environments.{name}", "light_sets")
            if s not in scene.light_sets:
                close = difflib.get_close_matches(s, list(scene.light_sets), n=1)
                raise loc.error(where, f"environment '{name}' lights unknown light set '{s}'",
                                (f"did you mean '{close[0]}'? " if close else "") +
                                f"light sets: {', '.join(scene.light_sets) or 'none defined'}")
            if s in chosen:
                raise loc.error(where, f"light set '{s}' is lit by environment '{chosen[s]}' and '{name}'",
                                "name each light set in one environment's light_sets")
            chosen[s] = name
    for s in scene.light_sets:
        env = chosen.get(s, default)
        if env is not None:
            scene.environment_of[s] = env
            scene.environment_at[s] = loc.find(f"environments.{env}")
