"""`shadermatrix tables`: the lookup tables bricks sample, and baking one into a KTX2 file an engine loads.

Without --bake: every texture a brick declares as a baked table (reference/tables.py) — brick, texture,
table, size, format, bytes, what it is baked from and its filtered error (`table_error`). With
--bake TABLE --out FILE.ktx2: the table's texels in KTX2 (io/ktx2.py) at the declaring brick's size
and format (or --size/--format); a painted table (ndf_map, fresnel_ramp, …) takes the artist's image
with --image FILE.png and normalizes it as the brick needs (the shader stays the same: an engine binds
the file in place of the build's default table). The factors of `homomorphic_factorization`
(homomorphic_p, homomorphic_q) are factored from a measured BRDF with --measured FILE.binary (MERL
format, reference/measured.py) instead of the brick's reference; the shader is the same.
"""
from __future__ import annotations

import json
import re
import sys
from pathlib import Path

from ...lang.errors import UsageError, UserError

HELP = "list the lookup tables bricks sample (size, format, error), or bake one into KTX2 (--bake)"


def add_arguments(p) -> None:
    p.add_argument("--bricks", action="append", metavar="DIR", default=[], help="an extra brick directory (repeatable)")
    p.add_argument("--format", choices=("md", "json"), default="md", help="listing format (default md)")
    p.add_argument("--bake", metavar="TABLE", help="write this table (a name from the listing) as KTX2 to --out")
    p.add_argument("--out", metavar="FILE.ktx2", help="with --bake: the file to write")
    p.add_argument("--image", metavar="FILE", help="with --bake of a painted table: the painted image (PNG)")
    p.add_argument("--measured", metavar="FILE.binary",
                   help="with --bake homomorphic_p or homomorphic_q: factor this MERL measured BRDF instead")
    p.add_argument("--size", metavar="WxH", help="with --bake: the size (default: the declaring brick's)")
    p.add_argument("--texel-format", choices=("unorm8", "fp16", "fp32"),
                   help="with --bake: the stored format (default: the declaring brick's)")


def listing(lib) -> list[dict]:
    """One row per table texture of the library (Library.tables())."""
    from ...reference.tables import lookup, table_error
    rows = []
    for tname, t in sorted(lib.tables().items()):
        d = lookup(t["table"])
        w, h = t["size"]
        texel = {"unorm8": 4, "fp16": 8, "fp32": 16}[t["format"]]
        rows.append({"brick": t["brick"], "texture": tname, "table": t["table"], "size": [w, h], "format": t["format"],
                     "dimension": "cube" if d.cube else "2d",
                     "bytes": w * h * texel * (6 if d.cube else 1), "painted": d.painted,
                     "reference": d.reference, "error": table_error(t["table"], t["size"], t["format"]),
                     "tolerance": t["tolerance"]})
    return rows


def bake(lib, args) -> int:
    from ...io.ktx2 import encode
    from ...io import atomic_write
    from ...reference.tables import TableError, baked, lookup
    from ... import __version__

    try:
        d = lookup(args.bake)
    except TableError as e:
        raise UsageError(f"--bake: {e}") from None
    decl = next((t for t in lib.tables().values() if t["table"] == args.bake), {})
    size = decl.get("size")
    if args.size:
        m = re.fullmatch(r"([0-9]+)x([0-9]+)", args.size)
        if not m or not all(1 <= int(v) <= 4096 for v in m.groups()):
            raise UsageError(f"--size {args.size!r} is not WxH, each 1 to 4096 (e.g. 256x1)")
        size = [int(m.group(1)), int(m.group(2))]
    fmt = args.texel_format or decl.get("format")
    if size is None or fmt is None:
        raise UsageError(f"no brick declares table '{args.bake}': give --size WxH and --texel-format")
    if args.image and not d.painted:
        raise UsageError(f"table '{args.bake}' is baked from its reference, not painted: drop --image")
    if args.measured:
        from ...reference.measured import MEASURED_TABLES, bake_measured
        if args.bake not in MEASURED_TABLES:
            raise UsageError(f"--measured goes with --bake {' or '.join(MEASURED_TABLES)}, not '{args.bake}'")
        try:
            stored, info = bake_measured(args.bake, args.measured, size, fmt)
        except ValueError as e:
            raise UserError(f"{args.bake}: {e}") from None
        print(f"{args.measured}: {info['used']} of {info['samples']} sample pairs measured; RMS log residual "
              + " ".join(f"{r:.3f}" for r in info["residual"]) + " (a constant: "
              + " ".join(f"{r:.3f}" for r in info["baseline"]) + ")")
    elif args.image:  # the painted baker validates the file (readable, channels, shape) and names it in errors
        from ...reference.tables_painted import bake_painted
        stored = bake_painted(args.bake, args.image, size, fmt)
    else:
        try:
            stored = baked(args.bake, size, fmt)
        except ValueError as e:
            raise UserError(f"{args.bake}: {e}") from None
    atomic_write(Path(args.out), encode(stored, fmt, cube=d.cube, writer=f"shadermatrix {__version__}"))
    print(f"{args.bake}: {size[0]}x{size[1]} {fmt}{' cube' if d.cube else ''} → {args.out}")
    return 0


def run(args) -> int:
    from ...library.bricks import load_library
    lib = load_library(args.bricks)
    if args.bake is None:
        for flag in ("out", "image", "measured", "size", "texel_format"):
            if getattr(args, flag):
                raise UsageError(f"--{flag.replace('_', '-')} goes with --bake TABLE")
    elif not args.out:
        raise UsageError("--bake needs --out FILE.ktx2")
    if args.bake:
        return bake(lib, args)
    rows = listing(lib)
    if args.format == "json":
        print(json.dumps(rows, indent=2))
        return 0
    print("| brick | texture | table | size | format | bytes | filtered error (max rel) | brick tolerance |")
    print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        err = f"{r['error']['max_rel']:.2e}" if r["error"] else ("painted" if r["painted"] else "on the BRDF")
        print(f"| `{r['brick']}` | `{r['texture']}` | `{r['table']}` | {r['size'][0]} × {r['size'][1]}"
              f"{' × 6' if r['dimension'] == 'cube' else ''} | {r['format']} | {r['bytes']} | {err} | {r['tolerance']:g} |")
    print(f"\n{len(rows)} table{'s' if len(rows) != 1 else ''}; each bake's source: "
          + "; ".join(sorted({f"{r['table']}: {r['reference']}" for r in rows})), file=sys.stderr)
    return 0
