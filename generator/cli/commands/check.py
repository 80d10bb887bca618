"""`shadermatrix check SCENE [--golden DIR]`: compile and validate every permutation × platform, as a CI does.

One line per check, `ok <hash>-<platform>` or the failure as the brick line that caused it
(assemble/checks.py: what each platform's check validates), then a summary; with --golden DIR, the
emitted sources are compared with DIR/<platform>/<hash>.<stage>.<ext> and every drift is printed as a
unified diff (--update-golden writes them instead). Exit 1 on a failure or a drift. A permutation whose
GLSL ES 3.10 does not validate passes its gl check with a note, as `build` ships GLSL 4.50 core alone
for it. The same checks run as pytest tests through the plugin: `pytest --shadermatrix-scene SCENE`.
"""
from __future__ import annotations

import sys
from pathlib import Path

from ...lang.errors import UsageError

HELP = "compile and validate every permutation × platform of a scene (a CI's check); --golden DIR diffs the sources"


def add_arguments(p) -> None:
    p.add_argument("scene", help="scene file (TOML, or glTF 2.0 .gltf/.glb)")
    p.add_argument("--platform", metavar="LIST",
                   help="comma-separated, from vulkan, d3d12, gl, webgpu (default all)")
    p.add_argument("--golden", metavar="DIR",
                   help="compare the emitted sources with DIR/<platform>/<hash>.<stage>.<ext>")
    p.add_argument("--update-golden", action="store_true", help="with --golden: write the emitted sources there")
    p.add_argument("--languages", metavar="LIST",
                   help="comma-separated, from glsl, hlsl, wgsl (default all): the platforms made from them "
                        "(vulkan: from any, compiling only these)")
    p.add_argument("--cache-dir", metavar="DIR", help="the compile cache (default: as `build`'s)")
    p.add_argument("--no-cache", action="store_true", help="compile everything; read and write no cache")
    p.add_argument("--bricks", action="append", metavar="DIR", default=[],
                   help="an extra brick directory (repeatable)")


def selection(platform: str | None, languages: str | None, flag: str = "--") -> tuple[list[str], list[str]]:
    """(platforms checked, languages) of the options' text; UsageError naming the option (flag: its prefix)."""
    from ...assemble.checks import checked_platforms
    from ...assemble.platforms import PLATFORM_TABLE, PLATFORMS, parse_platforms
    from ...backends import LANGUAGES, parse_languages
    opt_p, opt_l = ("--platform", "--languages") if flag == "--" else (f"{flag}platforms", f"{flag}languages")
    try:
        plats = parse_platforms(platform) if platform else list(PLATFORMS)
    except ValueError as e:
        raise UsageError(f"{opt_p}: {e}") from None
    try:
        langs = parse_languages(languages) if languages else list(LANGUAGES)
    except ValueError as e:
        raise UsageError(f"{opt_l}: {e}") from None
    if not checked_platforms(plats, langs):
        made = ", ".join(f"{p}: {'/'.join(PLATFORM_TABLE[p].checked_from)}" for p in PLATFORMS)
        raise UsageError(f"{opt_p} {','.join(plats)} with {opt_l} {','.join(langs)} checks nothing — a platform is "
                         f"checked when it is made from one of the languages ({made})")
    return checked_platforms(plats, langs), langs


def run(args) -> int:
    from ...assemble.checks import check_notes, checks, default_store, golden_diff, run_checks, stale_golden
    from ...io import atomic_write
    from ...library.bricks import load_library
    from ...scene.load import load_scene

    plats, langs = selection(args.platform, args.languages)
    if args.update_golden and not args.golden:
        raise UsageError("--update-golden needs --golden DIR — e.g. --golden tests/golden/scene --update-golden")
    lib = load_library(args.bricks)
    scene = load_scene(args.scene, lib)
    store = None if args.no_cache else default_store(args.cache_dir)
    failed = drifted = 0
    todo = checks(scene, plats, langs)
    emitted: set[str] = set()
    for c, res in zip(todo, run_checks(scene, lib, todo, store)):  # compiled in one batch
        emitted.update(res.sources)
        if res.errors:
            failed += 1
            print(f"FAIL {c.id} ({', '.join(c.objects)}):", file=sys.stderr)
            for e in res.errors:
                print(f"  {e}", file=sys.stderr)
            continue
        if args.golden and args.update_golden:
            for rel, text in res.sources.items():
                atomic_write(Path(args.golden) / rel, text.encode())
        elif args.golden:
            diff = golden_diff(Path(args.golden), res.sources)
            if diff:
                drifted += 1
                print(f"DRIFT {c.id} ({', '.join(c.objects)}):", file=sys.stderr)
                sys.stderr.writelines(diff)
                continue
        print(f"ok {c.id}" + "".join(f"  # {n}" for n in res.notes))
    stale = []
    if args.golden and not failed:  # golden sources of permutations that left the scene
        stale = stale_golden(Path(args.golden), todo, emitted)
        for rel in stale:
            if args.update_golden:
                (Path(args.golden) / rel).unlink()
            else:
                print(f"DRIFT {rel}: a golden source no permutation of the scene emits "
                      "(--update-golden removes it)", file=sys.stderr)
        stale = [] if args.update_golden else stale
    for note in check_notes(c.platform for c in todo):
        print(f"note: {note}", file=sys.stderr)
    print(f"{len(todo) - failed - drifted} of {len(todo)} checks pass ({len(scene.permutations)} permutations × "
          f"{len(plats)} platform{'s' if len(plats) != 1 else ''}: {', '.join(plats)}); {failed} failed, "
          f"{drifted} drifted from the golden sources"
          + (f"; {len(stale)} golden files left over" if stale else ""), file=sys.stderr)
    return 1 if failed or drifted or stale else 0
