"""Input keys: the sha256 of everything an output of a build depends on (the incremental build compares them).

A permutation's key covers its key text, the source of every brick it reads, the scene values of the objects
that use it, the generator's own sources and templates, the tools' versions, the languages and platforms; the
ubershader's the same without the scene values (it reads none); the scene's what the manifest's scene-wide
tables hold beyond the permutations.
"""
from __future__ import annotations

import functools
import hashlib
from dataclasses import dataclass
from pathlib import Path

from ..io import content_key
from ..lang import SourceError
from ..library.bricks import BUILTIN_BRICKS, Library
from ..scene.load import Scene
from ..spec.permutation import SpecError
from ..spec.resolve import Resolved, resolve
from .platforms import all_tools

_PACKAGE = Path(__file__).resolve().parents[1]  # generator/ (the templates too: backends/*/templates/)


@dataclass(frozen=True)
class Keys:
    permutations: dict[str, str]  # hash -> input key
    ubershader: str
    scene: str


@functools.lru_cache(maxsize=1)
def own_sources() -> str:
    """sha256 of the generator's own code and templates (relative path and bytes of every file)."""
    h = hashlib.sha256()
    for p in sorted(_PACKAGE.rglob("*")):
        # the built-in bricks (package data inside generator/ when installed) are keyed per permutation
        if p.is_file() and p.suffix in (".py", ".j2", ".toml") and BUILTIN_BRICKS not in p.parents:
            h.update(str(p.relative_to(_PACKAGE.parent)).encode() + b"\0" + p.read_bytes() + b"\0")
    return h.hexdigest()


def build_key(version: str, tools: dict, languages, platforms) -> str:
    """What every output of a build depends on: this generator (its version and its own sources), the tools'
    versions, the languages and platforms. The version and tools are those the manifest records."""
    return content_key("build-v1", version, own_sources(), tools, list(languages), list(platforms),
                       all_tools(platforms))


def scene_keys(base: str, scene: Scene, lib: Library, keep_removed: bool, pack: bool) -> Keys:
    """Every permutation's key, the ubershader's and the scene's, under the build key `base`."""
    users: dict[str, list[dict]] = {}
    for o in scene.objects:
        users.setdefault(o["permutation"], []).append(o)
    keys, shapes = {}, {}
    for h, perm in sorted(scene.permutations.items()):
        keys[h], shapes[h] = _perm_key(base, scene, lib, perm, users.get(h, []))
    uber = content_key(base, "ubershader", [shapes[h] for h in sorted(shapes)])
    tables = content_key(base, scene.name, sorted((k, list(v)) for k, v in scene.light_sets.items()),
                         [[o["name"], o["material"], o["light_set"], o["permutation"]] for o in scene.objects],
                         sorted(repr(m) for m in scene.materials.values()),
                         sorted(repr(x) for x in scene.lights.values()), keep_removed, *(["pack"] if pack else []))
    return Keys(keys, uber, tables)


def _perm_key(base: str, scene: Scene, lib: Library, perm, objs: list[dict]) -> tuple[str, str]:
    """(Everything a permutation's outputs depend on, the same without the scene values); objs: the objects
    drawn with it."""
    try:
        bricks = _bricks_of(resolve(perm, lib))
    except (SourceError, SpecError) as e:  # it will fail to compose too: key it by the error
        bricks = {"error": str(e)}
    mats = sorted({o["material"] for o in objs})
    lights = sorted({ln for o in objs for ln in o["lights"]})
    values = {"objects": [[o["name"], o["material"], o["light_set"], list(o["lights"])] for o in objs],
              "materials": [repr(scene.materials[m]) for m in mats], "lights": [repr(scene.lights[ln]) for ln in lights]}
    shape = content_key(base, perm.canonical(), sorted(bricks.items()))
    return content_key(shape, values), shape


def _bricks_of(r: Resolved) -> dict[str, str]:
    """{display path: source hash} of every brick a resolved permutation reads: its BRDF's, its packing's (the
    normal filler within), each light's and its shadow filter's, its output's."""
    nodes = [x for top in (*r.brdf, r.packing, *(lt.shadow for lt in r.lights)) for x in top.tree]
    return {b.display_path: b.module.source_hash for b in [*(n.brick for n in nodes), *(lt.brick for lt in r.lights),
                                                            r.output]}
