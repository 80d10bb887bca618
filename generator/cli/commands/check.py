"""`shadermatrix check SCENE [--golden DIR]`: compile and validate every permutation × language, as a CI does.

One line per check (`ok` or the failure as the brick line that caused it), then a
summary; with --golden DIR, the emitted sources are compared with
DIR/<language>/<hash>.<stage>.<language> and every drift is printed as a unified
diff (--update-golden writes them instead). Exit 1 on a failure or a drift.
The same checks run as pytest tests through the plugin: `pytest --shadermatrix-scene SCENE`.
"""
from __future__ import annotations

import sys
from pathlib import Path

from ...lang.errors import UsageError

HELP = "compile and validate every permutation × language of a scene (a CI's check); --golden DIR diffs the sources"


def add_arguments(p) -> None:
    p.add_argument("scene", help="scene file (TOML, or glTF 2.0 .gltf/.glb)")
    p.add_argument("--golden", metavar="DIR", help="compare the emitted sources with DIR/<language>/<hash>.<stage>.<ext>")
    p.add_argument("--update-golden", action="store_true", help="with --golden: write the emitted sources there")
    p.add_argument("--languages", metavar="LIST", help="comma-separated, from glsl, hlsl, wgsl (default all)")
    p.add_argument("--cache-dir", metavar="DIR", help="the compile cache (default: as `build`'s)")
    p.add_argument("--no-cache", action="store_true", help="compile everything; read and write no cache")
    p.add_argument("--bricks", action="append", metavar="DIR", default=[],
                   help="an extra brick directory (repeatable)")


def run(args) -> int:
    from ...build.checks import checks, default_store, golden_diff, run_checks, stale_golden
    from ...io import atomic_write
    from ...library.bricks import load_library
    from ...matrix.scene import load_scene
    from ...targets import LANGUAGES, parse_languages

    try:
        langs = parse_languages(args.languages) if args.languages else list(LANGUAGES)
    except ValueError as e:
        raise UsageError(f"--languages: {e}") from None
    if args.update_golden and not args.golden:
        raise UsageError("--update-golden needs --golden DIR — e.g. --golden tests/golden/scene --update-golden")
    lib = load_library(args.bricks)
    scene = load_scene(args.scene, lib)
    store = None if args.no_cache else default_store(args.cache_dir)
    failed = drifted = 0
    todo = checks(scene, langs)
    emitted: set[str] = set()
    for c, (errors, sources) in zip(todo, run_checks(scene, lib, todo, store)):  # compiled in one batch
        emitted.update(sources)
        if errors:
            failed += 1
            print(f"FAIL {c.id} ({', '.join(c.objects)}):", file=sys.stderr)
            for e in errors:
                print(f"  {e}", file=sys.stderr)
            continue
        if args.golden and args.update_golden:
            for rel, text in sources.items():
                atomic_write(Path(args.golden) / rel, text.encode())
        elif args.golden:
            diff = golden_diff(Path(args.golden), sources)
            if diff:
                drifted += 1
                print(f"DRIFT {c.id} ({', '.join(c.objects)}):", file=sys.stderr)
                sys.stderr.writelines(diff)
                continue
        print(f"ok {c.id}")
    stale = []
    if args.golden and not failed:  # golden sources of permutations that left the scene
        stale = stale_golden(Path(args.golden), langs, emitted)
        for rel in stale:
            if args.update_golden:
                (Path(args.golden) / rel).unlink()
            else:
                print(f"DRIFT {rel}: a golden source no permutation of the scene emits "
                      "(--update-golden removes it)", file=sys.stderr)
        stale = [] if args.update_golden else stale
    print(f"{len(todo) - failed - drifted} of {len(todo)} checks pass ({len(scene.permutations)} permutations × "
          f"{len(langs)} languages); {failed} failed, {drifted} drifted from the golden sources"
          + (f"; {len(stale)} golden files left over" if stale else ""), file=sys.stderr)
    return 1 if failed or drifted or stale else 0
