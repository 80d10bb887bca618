"""`shadermatrix matrix SCENE [--explain]`: how the scene's matrix is pruned, stage by stage, and why.

Counts: the full product of the axes the scene declares (BRDFs, packings, light
configurations, output, precision), those the bricks' constraints allow, those
the objects draw, and — after a build through the compile cache — those left
when permutations with identical optimized SPIR-V merge. With --explain: every
axis value kept or dropped and why, the combinations the constraints forbid and
why, and the objects of every permutation; and what each value costs: the permutations it adds and the compile
time of their own shaders, from the times the compile cache records (scene/explain.py).
"""
from __future__ import annotations

import json
import sys
import tempfile
from pathlib import Path

HELP = "how a scene's matrix is pruned: full product, valid, used, merged; --explain says why, value by value"


def add_arguments(p) -> None:
    p.add_argument("scene", help="scene file (TOML, or glTF 2.0 .gltf/.glb)")
    p.add_argument("--explain", action="store_true",
                   help="every axis value kept or dropped and why, the permutations it adds and their shaders' "
                        "recorded compile time, the forbidden combinations, each permutation's objects")
    p.add_argument("--format", choices=("md", "json"), default="md", help="report format (default md)")
    p.add_argument("--no-compile", action="store_true",
                   help="leave out the merged count (it builds the scene, through the compile cache)")
    p.add_argument("--cache-dir", metavar="DIR", help="the compile cache (default: as `build`'s)")
    p.add_argument("--no-cache", action="store_true", help="compile everything; read and write no cache")
    p.add_argument("--bricks", action="append", metavar="DIR", default=[],
                   help="an extra brick directory (repeatable)")


def spirv_identities(scene, lib, cache_dir, no_cache: bool = False) -> tuple[dict[str, tuple], list[str], dict]:
    """({permutation hash: its SPIR-V (sha256 per language and stage)}, the build's failures, {permutation hash:
    {cache key: recorded compile seconds or None}}), from a build into a temporary directory through the compile
    cache."""
    from ...assemble import BuildContext, build
    from ...assemble.checks import default_store
    from ...io import show_progress
    ctx = BuildContext(lib, store=None if no_cache else default_store(cache_dir), progress=show_progress())
    with tempfile.TemporaryDirectory(prefix="shadermatrix-matrix-") as tmp:
        res = build(scene, Path(tmp), ctx)
        ids = {p["hash"]: tuple(sorted((lang, stage, item.get("spirv_sha256") or item["spirv"])
                                       for lang, stages in p["languages"].items() for stage, item in stages.items()))
               for p in res.manifest["permutations"] if p.get("status") == "ok"}
        shaders: dict[str, dict] = {}
        for job, (key, seconds) in res.shaders.items():
            unit = job.split(".", 1)[0]  # toolchain/jobs.py: <unit>.<stage>.<language>
            if unit in scene.permutations and key is not None:
                shaders.setdefault(unit, {})[key] = seconds
        return ids, list(res.failures), shaders


def run(args) -> int:
    from ...library.bricks import load_library
    from ...scene.explain import markdown, report
    from ...scene.load import load_scene

    lib = load_library(args.bricks)
    scene = load_scene(args.scene, lib)
    spirv, failures, shaders = (None, [], None) if args.no_compile else \
        spirv_identities(scene, lib, args.cache_dir, args.no_cache)
    rep = report(scene, lib, spirv, shaders)
    sys.stdout.write(markdown(rep, args.explain) if args.format == "md" else json.dumps(rep, indent=1) + "\n")
    for f in failures:  # a permutation that does not compile is not merged with anything: say so, exit 1
        print(f"error: {f}", file=sys.stderr)
    return 1 if failures else 0
