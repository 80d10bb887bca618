"""Input keys: the sha256 of everything an output of a build depends on (the incremental build compares them).

A permutation's key covers its key text, the source of every brick it reads, the scene values of the objects
that use it, the generator's own sources and templates, the tools' versions, the languages and platforms; the
ubershader's the same without the scene values (it reads none); the scene's what the manifest's scene-wide
tables hold beyond the permutations.

A key is a digest: it says that an input changed, not which. What it was made of is kept too (Keys.bricks,
build_inputs) for the build's record of its inputs (inputs.py), which the next build diffs to say why it
rebuilt what it did.
"""
from __future__ import annotations

import functools
import hashlib
from dataclasses import dataclass, field
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
    # hash -> {brick display path: its source's sha256} of every brick it reads ({"error": why} when it does not
    # resolve): what its key holds of the bricks
    bricks: dict[str, dict[str, str]] = field(default_factory=dict, compare=False)


@functools.lru_cache(maxsize=1)
def source_files() -> dict[str, str]:
    """{relative path: sha256} of the generator's own code and templates (the built-in bricks aside: they are
    keyed per permutation, by the permutations that read them)."""
    return {str(p.relative_to(_PACKAGE.parent)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(_PACKAGE.rglob("*"))
            if p.is_file() and p.suffix in (".py", ".j2", ".toml") and BUILTIN_BRICKS not in p.parents}


def own_sources() -> str:
    """sha256 of the generator's own code and templates (every file's relative path and sha256)."""
    return content_key("sources-v1", sorted(source_files().items()))


def build_inputs(version: str, tools: dict, languages, platforms) -> dict:
    """What every output of a build depends on, item by item: this generator (its version, each of its own source
    and template files), the tools' versions, the languages, the platforms and their tools' versions."""
    return {"generator": version, "sources": source_files(), "tools": dict(tools), "languages": list(languages),
            "platforms": list(platforms), "platform_tools": all_tools(platforms)}


def build_key(version: str, tools: dict, languages, platforms) -> str:
    """build_inputs as one digest (the version and tools: those the manifest records)."""
    return content_key("build-v1", version, own_sources(), tools, list(languages), list(platforms),
                       all_tools(platforms))


def scene_keys(base: str, scene: Scene, lib: Library, keep_removed: bool, pack: bool) -> Keys:
    """Every permutation's key, the ubershader's and the scene's, under the build key `base`."""
    users: dict[str, list[dict]] = {}
    for o in scene.objects:
        users.setdefault(o["permutation"], []).append(o)
    keys, shapes, bricks = {}, {}, {}
    for h, perm in sorted(scene.permutations.items()):
        keys[h], shapes[h], bricks[h] = _perm_key(base, scene, lib, perm, users.get(h, []))
    uber = content_key(base, "ubershader", [shapes[h] for h in sorted(shapes)])
    tables = content_key(base, scene.name, sorted((k, list(v)) for k, v in scene.light_sets.items()),
                         [[o["name"], o["material"], o["light_set"], o["permutation"]] for o in scene.objects],
                         sorted(repr(m) for m in scene.materials.values()),
                         sorted(repr(x) for x in scene.lights.values()), keep_removed,
                         *([sorted(repr(d) for d in scene.dynamic_sets.values())] if scene.dynamic_sets else []),
                         *(["pack"] if pack is True else [f"pack-{pack}"] if pack else []),  # "only": --pack-only
                         *([] if scene.ubershader else ["no-ubershader"]))  # [scene] ubershader = false
    return Keys(keys, uber, tables, bricks)


def _perm_key(base: str, scene: Scene, lib: Library, perm, objs: list[dict]) -> tuple[str, str, dict]:
    """(Everything a permutation's outputs depend on, the same without the scene values, the bricks it reads with
    their sources' sha256); objs: the objects drawn with it."""
    try:
        bricks = _bricks_of(resolve(perm, lib))
    except (SourceError, SpecError) as e:  # it will fail to compose too: key it by the error
        bricks = {"error": str(e)}
    mats = sorted({o["material"] for o in objs})
    lights = sorted({ln for o in objs for ln in o["lights"]})
    values = {"objects": [[o["name"], o["material"], o["light_set"], list(o["lights"])] for o in objs],
              "materials": [repr(scene.materials[m]) for m in mats], "lights": [repr(scene.lights[ln]) for ln in lights]}
    envs = sorted({scene.environment_of[o["light_set"]] for o in objs if o["light_set"] in scene.environment_of})
    if envs:  # the environments its light sets use (their values are in the Lights block); absent: keys unchanged
        values["environments"] = [_environment_key(scene.environments[e]) for e in envs]
    shape = content_key(base, perm.canonical(), sorted(bricks.items()))
    return content_key(shape, values), shape, bricks


def _environment_key(env) -> str:
    """An environment's declaration and its image's bytes (what its SH9 values are computed from)."""
    from .environments import _source_key
    return content_key(repr(env), _source_key(env))


def _bricks_of(r: Resolved) -> dict[str, str]:
    """{display path: source hash} of every brick a resolved permutation reads: its BRDF's, its packing's (the
    normal filler within), each light's and its shadow filter's, its output's."""
    nodes = [x for top in (*r.brdf, r.packing, *(lt.shadow for lt in r.lights)) for x in top.tree]
    env = [r.environment.brick] if r.environment is not None else []
    return {b.display_path: b.module.source_hash for b in [*(n.brick for n in nodes), *(lt.brick for lt in r.lights),
                                                            r.output, *env]}
