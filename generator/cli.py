"""The `shadermatrix` command line."""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from . import __version__
from .lang import SourceError


def _library(args):
    from .bricks import load_library
    return load_library(args.bricks or ())


def cmd_bricks(args) -> int:
    """List every brick: kind, slots, parameters and citation."""
    lib = _library(args)
    rows = []
    for (kind, bid), b in sorted(lib.bricks.items()):
        rows.append({
            "id": bid, "kind": kind, "path": b.display_path, "cite": b.cite,
            "summary": b.doc.splitlines()[0] if b.doc else "",
            "slots": {s: {"kind": v["kind"], "default": v["default"],
                          "fillers": [x.id for x in lib.of_kind(v["kind"])]} for s, v in b.slots.items()},
            "params": {p.name: {"type": str(p.ty), "range": list(p.range) if p.range else None,
                                "default": p.default, "doc": p.doc} for p in b.params.values()},
            "textures": sorted(b.textures),
        })
    if args.json:
        print(json.dumps(rows, indent=2))
        return 0
    for r in rows:
        print(f"{r['kind']:<10} {r['id']:<24} {r['summary']}")
        print(f"{'':<35}cite: {r['cite']}")
        for s, v in r["slots"].items():
            print(f"{'':<35}slot {s} ({v['kind']}, default {v['default']}): {', '.join(v['fillers'])}")
        for name, p in r["params"].items():
            rng = f" in [{p['range'][0]}, {p['range'][1]}]" if p["range"] else ""
            print(f"{'':<35}param {name}: {p['type']}{rng}, default {p['default']}")
        for t in r["textures"]:
            print(f"{'':<35}texture {t}")
    return 0


def cmd_build(args) -> int:
    """Build a scene's shader matrix."""
    from .build import build_scene
    from .scene import load_scene
    lib = _library(args)
    scene = load_scene(args.scene, lib)
    res = build_scene(scene, lib, Path(args.out))
    perms = res.manifest["permutations"]
    ok = sum(1 for p in perms if p["status"] == "ok")
    print(f"{scene.name}: {len(scene.objects)} objects, {len(scene.materials)} materials, "
          f"{len(scene.lights)} lights → {len(perms)} permutations × {len(res.manifest['languages'])} languages")
    for p in perms:
        langs = ", ".join(f"{lang}" for lang in p["languages"])
        print(f"  {p['status']:<6} {p['hash']}  {p['id']}  [{langs}]  ({', '.join(p['objects'])})")
    print(f"{ok}/{len(perms)} permutations valid SPIR-V in every language; "
          f"{res.written} files written, {res.unchanged} unchanged → {args.out}/manifest.json")
    for f in res.failures:
        print(f"error: {f}", file=sys.stderr)
    return 0 if res.ok else 1


def cmd_doctor(args) -> int:
    """Which tools are present, their versions, and whether lavapipe is there."""
    from .doctor import run_doctor
    return run_doctor()


def parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="shadermatrix", description=__doc__)
    p.add_argument("--version", action="version", version=f"shadermatrix {__version__}")
    sub = p.add_subparsers(dest="command", required=True)

    def with_bricks(sp):
        sp.add_argument("--bricks", action="append", metavar="DIR", help="an extra brick directory (repeatable)")
        return sp

    sp = with_bricks(sub.add_parser("bricks", help=cmd_bricks.__doc__))
    sp.add_argument("--json", action="store_true", help="machine-readable output")
    sp.set_defaults(func=cmd_bricks)

    sp = with_bricks(sub.add_parser("build", help=cmd_build.__doc__))
    sp.add_argument("scene", help="scene file (TOML)")
    sp.add_argument("--out", required=True, help="output directory")
    sp.set_defaults(func=cmd_build)

    sp = sub.add_parser("doctor", help=cmd_doctor.__doc__)
    sp.set_defaults(func=cmd_doctor)
    return p


def main(argv=None) -> int:
    args = parser().parse_args(argv)
    try:
        return args.func(args)
    except SourceError as e:
        print(f"error: {e}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
