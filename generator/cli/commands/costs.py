"""`shadermatrix costs`: measured cost tables per permutation of a scene, or per brick."""
from __future__ import annotations

import sys

HELP = "cost tables (texture, ALU, transcendental, branches, registers) per permutation of a scene, or per brick"


def add_arguments(p) -> None:
    p.add_argument("scene", nargs="?", help="scene file (TOML): one row per permutation and stage")
    p.add_argument("--bricks", action="store_true",
                   help="per-brick table instead: each brick's cost against a trivial stand-in, and the course's models")
    p.add_argument("--brick-dir", action="append", metavar="DIR", default=[],
                   help="an extra brick directory (repeatable)")
    p.add_argument("--format", choices=("md", "csv", "json"), default="md", help="output format (default md)")
    p.add_argument("--cache-dir", metavar="DIR", help="the compile cache (default: as `build`'s)")
    p.add_argument("--no-cache", action="store_true",
                   help="compile everything; by default shaders come from the compile cache `build` fills")
    p.add_argument("--gpu", nargs="?", const="default", metavar="FAMILIES",
                   help="add AMD compiler statistics from Mesa RADV's null device (no GPU needed) for these "
                        "comma-separated families; alone: polaris10,navi21,vangogh,navi31")
    p.add_argument("--gpu-ir", metavar="DIR",
                   help="with --gpu: save each shader's NIR, ACO IR and disassembly as DIR/<family>/<key>.<stage>.txt")


def run(args) -> int:
    if bool(args.scene) == bool(args.bricks):
        print("error: give a SCENE or --bricks (one of them) — e.g. `shadermatrix costs scenes/example.toml` "
              "or `shadermatrix costs --bricks`", file=sys.stderr)
        return 2
    from ...measure.plans import brick_rows, course_models, load_cost_library, scene_rows
    from ...measure.report import markdown, to_csv, to_json

    from ...io import Store, default_cache_dir
    root = args.cache_dir or default_cache_dir()
    store = None if args.no_cache or root is None else Store(root)
    gpu = None
    if args.gpu is not None:
        from ...measure.gpu import GpuRequest
        from ...runtime.gpu_stats import DEFAULT_FAMILIES, check_families
        if "/" in args.gpu or args.gpu.endswith(".toml"):  # `costs --gpu SCENE`: the scene taken for families
            print(f"error: --gpu {args.gpu}: that is a file, not AMD families — put the scene first "
                  f"(`costs SCENE --gpu`) or write `--gpu=navi21,...`", file=sys.stderr)
            return 2
        try:
            families = check_families(DEFAULT_FAMILIES if args.gpu == "default" else args.gpu.split(","))
        except ValueError as e:
            print(f"error: --gpu {args.gpu}: {e}", file=sys.stderr)
            return 2
        gpu = GpuRequest(families, args.gpu_ir)
    elif args.gpu_ir:
        print("error: --gpu-ir needs --gpu — e.g. `--gpu navi21 --gpu-ir out/isa`", file=sys.stderr)
        return 2
    models = None
    if args.bricks:
        rows = brick_rows(load_cost_library(args.brick_dir), gpu=gpu, store=store)
        subject, title, models = "bricks", "Costs per brick", course_models()[0]
    else:
        from ...library.bricks import load_library
        from ...matrix.scene import load_scene
        lib = load_library(args.brick_dir)
        scene = load_scene(args.scene, lib)
        rows = scene_rows(scene, lib, gpu=gpu, store=store)
        subject, title = scene.name, f"Costs of scene {scene.name}"
    if args.format == "md":
        sys.stdout.write(markdown(rows, title, models, gpu))
    elif args.format == "csv":
        sys.stdout.write(to_csv(rows))
    else:
        sys.stdout.write(to_json(rows, subject, models, gpu))
    if gpu is not None and gpu.note:  # the columns are absent: say why, in one line
        print(f"note: {gpu.note}", file=sys.stderr)
    for why in sorted((gpu.errors or {}).values()) if gpu is not None else ():
        print(f"error: {why}", file=sys.stderr)
    failed = sorted({f"{r.subject} ({r.language}): {r.error}" for r in rows if r.error})
    for f in failed:
        print(f"error: {f}", file=sys.stderr)
    return 1 if failed or (gpu is not None and gpu.errors) else 0
