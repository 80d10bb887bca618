"""`shadermatrix costs`: measured cost tables per permutation of a scene, or per brick."""
from __future__ import annotations

import sys

from ...lang.errors import EnvironmentMissing, UsageError, UserError
from ...measure.budget import EXAMPLE as BUDGET_EXAMPLE, RADV_NAMES, SPIRV_NAMES as BUDGET_NAMES

HELP = "cost tables (texture, ALU, transcendental, branches, registers) per permutation of a scene, or per brick"


def add_arguments(p) -> None:
    p.add_argument("scene", nargs="?", help="scene file (TOML, or glTF 2.0 .gltf/.glb): one row per permutation and stage")
    p.add_argument("--per-brick", action="store_true",
                   help="per-brick table instead: each brick's cost against a trivial stand-in")
    p.add_argument("--bricks", action="append", metavar="DIR", default=[],
                   help="an extra brick directory (repeatable)")
    p.add_argument("--format", choices=("md", "csv", "json"), default="md", help="output format (default md)")
    p.add_argument("--cache-dir", metavar="DIR", help="the compile cache (default: as `build`'s)")
    p.add_argument("--no-cache", action="store_true",
                   help="compile everything; by default shaders come from the compile cache `build` fills")
    p.add_argument("--gpu", nargs="?", const="default", metavar="FAMILIES",
                   help="add AMD compiler statistics from Mesa RADV's null device (no GPU needed) for these "
                        "comma-separated families; alone: polaris10,navi21,vangogh,navi31")
    p.add_argument("--sort", metavar="NAME", choices=BUDGET_NAMES,
                   help="rows in descending order of this count (the same names as --budget); default: by hash")
    p.add_argument("--diff", metavar="OLD.json",
                   help="instead of the tables: what changed against an earlier `costs --format json` report, "
                        "shader by shader and count by count, and a helped/hurt summary per count as Mesa's "
                        "shader-db reports (Markdown)")
    p.add_argument("--budget", metavar="[FAMILY.]NAME=N,...",
                   help=f"per-shader limits, e.g. {BUDGET_EXAMPLE}: SPIR-V counts ({', '.join(BUDGET_NAMES)}) and, "
                        f"after an AMD family (which holds until the next one; spirv. goes back), RADV's statistics "
                        f"({', '.join(RADV_NAMES)}; waves_per_simd is a least). Every shader over one is a line "
                        "located at the scene's material and the exit code is 1 (a CI holds the budget)")
    p.add_argument("--course", action="store_true",
                   help="Markdown: beside our counts, Hoffman & Baker 2006's figures (a column per permutation; "
                        "per brick, a section of the course's models). CSV and JSON always carry them")
    p.add_argument("--explain-languages", action="store_true",
                   help="Markdown: a section on where GLSL, HLSL and WGSL differ, opcode by opcode, and why. "
                        "JSON always carries it")
    p.add_argument("--gpu-ir", metavar="DIR",
                   help="with --gpu: save each shader's NIR, ACO IR and disassembly as DIR/<family>/<key>.<stage>.txt")




def read_report(path: str) -> list[dict]:
    """The rows of an earlier `costs --format json` report (a bad file: one error line, exit 1)."""
    import json
    from pathlib import Path

    from ...lang.errors import read_text
    try:
        rows = json.loads(read_text(Path(path), "costs report"))["rows"]
        if not all(isinstance(r, dict) and {"table", "subject", "stage", "language"} <= r.keys() for r in rows):
            raise TypeError
    except (ValueError, KeyError, TypeError):
        raise UserError(f"{path}: not a `costs --format json` report — write one with "
                        "`shadermatrix costs SCENE --format json > OLD.json` before the change") from None
    return rows


def factored_errors(models, lib) -> dict:
    """{model: {"factored": error}}: each factored form's float32 hemisphere max relative error against the
    direct model's reference (its bricks' references are the direct ones), in NumPy — what its tables add."""
    from ...eval import accuracy
    out: dict = {}
    for m in models:
        if m.form != "factored" or not m.spec or not set(m.requires) <= {b.id for b in lib.bricks.values()}:
            continue
        v = accuracy.run([m.spec], ["numpy"], ["float32"], lib)["verdicts"][0]  # accuracy's default hemisphere
        out.setdefault(m.name, {})["factored"] = v["hemisphere_max_rel"]
    return out


def _gpu_request(args, budget):
    """The RADV families to compile for: --gpu's, then those a budget names (None: no AMD figures)."""
    from ...measure.budget import families as budget_families
    wanted = budget_families(budget or ())
    if args.gpu is None and not wanted:
        if args.gpu_ir:
            raise UsageError("--gpu-ir needs --gpu — e.g. `--gpu navi21 --gpu-ir out/isa`")
        return None
    from ...measure.gpu import GpuRequest
    from ...runtime.gpu_stats import DEFAULT_FAMILIES, check_families
    from ...scene.load import SCENE_SUFFIXES
    families: tuple = ()
    if args.gpu is not None:
        if "/" in args.gpu or args.gpu.lower().endswith(SCENE_SUFFIXES):  # `costs --gpu SCENE`: the scene taken for families
            raise UsageError(f"--gpu {args.gpu}: that is a file, not AMD families — put the scene first "
                             f"(`costs SCENE --gpu`) or write `--gpu=navi21,...`")
        try:
            families = check_families(DEFAULT_FAMILIES if args.gpu == "default" else args.gpu.split(","))
        except ValueError as e:
            raise UsageError(f"--gpu {args.gpu}: {e}") from None
    return GpuRequest(tuple(dict.fromkeys(families + wanted)), args.gpu_ir)


def run(args) -> int:
    from ...measure.budget import parse as parse_budget
    budget = parse_budget(args.budget) if args.budget else None
    old_rows = read_report(args.diff) if args.diff else None
    if bool(args.scene) == bool(args.per_brick):
        raise UsageError("give a SCENE or --per-brick (one of them) — e.g. `shadermatrix costs scenes/example.toml` "
                         "or `shadermatrix costs --per-brick`")
    from ...measure.plans import brick_rows, course_models, load_cost_library, scene_rows
    from ...measure.report import markdown, to_csv, to_json

    from ...io import Store, default_cache_dir
    root = args.cache_dir or default_cache_dir()
    store = None if args.no_cache or root is None else Store(root)
    gpu = _gpu_request(args, budget)
    models, model_errors, scene = None, None, None
    if args.per_brick:
        lib = load_cost_library(args.bricks)
        rows = brick_rows(lib, gpu=gpu, store=store)
        subject, title, models = "bricks", "Costs per brick", course_models()[0]
        model_errors = factored_errors(models, lib)
    else:
        from ...library.bricks import load_library
        from ...scene.load import load_scene
        lib = load_library(args.bricks)
        scene = load_scene(args.scene, lib)
        rows = scene_rows(scene, lib, gpu=gpu, store=store)
        subject, title = scene.name, f"Costs of scene {scene.name}"
    if args.sort:  # the costliest first (stable: equal rows keep their order); rows without a cost last
        from ...measure.report import _value
        rows.sort(key=lambda r: -_value(r, args.sort) if r.cost is not None else float("inf"))
    if args.diff:
        from ...measure.diff import diff
        sys.stdout.write(diff(rows, old_rows, args.diff))
    elif args.format == "md":
        sys.stdout.write(markdown(rows, title, models, gpu, course=args.course, languages=args.explain_languages,
                                  model_errors=model_errors))
    elif args.format == "csv":
        sys.stdout.write(to_csv(rows))
    else:
        sys.stdout.write(to_json(rows, subject, models, gpu, model_errors=model_errors))
    return _verdict(rows, gpu, budget, scene)


def _verdict(rows, gpu, budget, scene) -> int:
    """The errors (RADV's, the compilers', the budget's, one line each) and the exit status."""
    for why in sorted((gpu.errors or {}).values()) if gpu is not None else ():
        print(f"error: {why}", file=sys.stderr)
    failed = sorted({f"{r.subject} ({r.language}): {r.error}" for r in rows if r.error})
    for f in failed:
        print(f"error: {f}", file=sys.stderr)
    over = []
    if budget:
        from ...measure.budget import check
        over, shaders = check(rows, budget, scene)
        for o in over:
            print(f"error: {o.line}", file=sys.stderr)
        print(f"budget {', '.join(x.text() for x in budget)}: {len(over)} of {shaders} shaders over "
              "(a shader: one stage, in every language)", file=sys.stderr)
    unchecked = [x.text() for x in budget or () if x.family] if gpu is not None and gpu.note else []
    if failed or over or (gpu is not None and gpu.errors):
        if gpu is not None and gpu.note:
            print(f"error: {gpu.note}", file=sys.stderr)
        return 1
    if unchecked:  # a budget on AMD figures that could not be measured is not held: never a pass
        raise EnvironmentMissing(f"{gpu.note} — the budget's {', '.join(unchecked)} not checked")
    if gpu is not None and gpu.note:  # asked for and not there: the table came without them, and the exit says so
        raise EnvironmentMissing(f"{gpu.note} (the tables above leave the AMD columns out)")
    return 0
