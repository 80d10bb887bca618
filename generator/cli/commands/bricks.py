"""`shadermatrix bricks`: every brick with kind, slots, parameters and citation."""
from __future__ import annotations

import json

HELP = "list every brick: kind, slots, parameters (type, range, default), citation"


def add_arguments(p) -> None:
    p.add_argument("--bricks", action="append", metavar="DIR",
                   help="an extra brick directory (repeatable)")
    p.add_argument("--json", action="store_true", help="machine-readable output")
    p.add_argument("--check", action="store_true",
                   help="validate every brick, whether or not a scene uses it (a build fails only on the bricks its "
                        "permutations reach): one located error line each and exit 1, else one line and exit 0")


def rows(lib) -> list[dict]:
    out = []
    for (kind, bid), b in sorted(lib.bricks.items()):
        out.append({
            "id": bid, "kind": kind, "path": b.display_path, "cite": b.cite,
            "summary": b.doc.splitlines()[0] if b.doc else "",
            "slots": {s: {"kind": v["kind"], "default": v.get("default"),  # None: an optional slot, empty unless filled
                          "fillers": [x.id for x in lib.of_kind(v["kind"])]} for s, v in b.slots.items()},
            "params": {p.name: {"type": str(p.ty), "range": list(p.range) if p.range else None,
                                "default": p.default, "doc": p.doc} for p in b.params.values()},
            "textures": sorted(b.textures),
        })
    return out


def check(dirs, as_json: bool) -> int:
    """`bricks --check`: every brick that does not load, located; exit 1 when there is one."""
    import sys
    from ...library.bricks import load_library
    lib = load_library(dirs, strict=False)
    if as_json:
        print(json.dumps({"valid": len(lib.bricks), "errors": [str(e) for e in lib.errors]}, indent=2))
        return 1 if lib.errors else 0
    for e in lib.errors:
        print(f"error: {e}", file=sys.stderr)
    total = len(lib.bricks) + len(lib.errors)
    print(f"{len(lib.bricks)} of {total} bricks valid" + (f", {len(lib.errors)} with errors" if lib.errors else ""))
    return 1 if lib.errors else 0


def run(args) -> int:
    from ...library.bricks import load_library
    if args.check:
        return check(args.bricks or (), args.json)
    table = rows(load_library(args.bricks or ()))
    if args.json:
        print(json.dumps(table, indent=2))
        return 0
    for r in table:
        print(f"{r['kind']:<10} {r['id']:<24} {r['summary']}")
        print(f"{'':<35}cite: {r['cite']}")
        for s, v in r["slots"].items():
            dflt = f"default {v['default']}" if v["default"] else "optional, empty by default"
            print(f"{'':<35}slot {s} ({v['kind']}, {dflt}): {', '.join(v['fillers'])}")
        for name, p in r["params"].items():
            rng = f" in [{p['range'][0]}, {p['range'][1]}]" if p["range"] else ""
            print(f"{'':<35}param {name}: {p['type']}{rng}, default {p['default']}")
        for t in r["textures"]:
            print(f"{'':<35}texture {t}")
    return 0
