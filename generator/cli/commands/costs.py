"""`shadermatrix costs`: measured cost tables per permutation of a scene, or per brick."""
from __future__ import annotations

import re
import sys

from ...lang.errors import EnvironmentMissing, UsageError, UserError

HELP = "cost tables (texture, ALU, transcendental, branches, registers) per permutation of a scene, or per brick"


BUDGET_NAMES = ("texture", "alu", "transcendental", "alu_t", "branches", "registers", "instructions", "loads",
                "alu_scalar")  # the counts a budget or a sort names (measure/report.py MD_COLUMNS)


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
                        "shader by shader and count by count (Markdown)")
    p.add_argument("--budget", metavar="NAME=MAX,...",
                   help=f"per-shader limits, e.g. alu=60,texture=4,registers=32 (names: {', '.join(BUDGET_NAMES)}): "
                        "every shader over one is listed and the exit code is 1 (a CI holds the budget)")
    p.add_argument("--course", action="store_true",
                   help="Markdown: beside our counts, Hoffman & Baker 2006's figures (a column per permutation; "
                        "per brick, a section of the course's models). CSV and JSON always carry them")
    p.add_argument("--explain-languages", action="store_true",
                   help="Markdown: a section on where GLSL, HLSL and WGSL differ, opcode by opcode, and why. "
                        "JSON always carries it")
    p.add_argument("--gpu-ir", metavar="DIR",
                   help="with --gpu: save each shader's NIR, ACO IR and disassembly as DIR/<family>/<key>.<stage>.txt")




def parse_budget(text: str) -> dict[str, int]:
    """--budget alu=60,texture=4 → {"alu": 60, "texture": 4}."""
    out = {}
    for item in text.split(","):
        name, eq, value = (x.strip() for x in item.partition("="))
        if name not in BUDGET_NAMES or not eq or not re.fullmatch(r"[0-9]+", value) or name in out:
            raise UsageError(f"--budget {text!r}: {item.strip()!r} is not NAME=MAX with NAME one of "
                             f"{', '.join(BUDGET_NAMES)} (each once) and MAX a whole number — write e.g. "
                             "--budget alu=60,texture=4,registers=32")
        out[name] = int(value)
    return out


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


def over_budget(rows, budget: dict[str, int]) -> list[str]:
    """One line per shader over a limit: what it is (permutation, objects, stage, language) and by how much."""
    from ...measure.report import _value
    lines = []
    for r in rows:
        over = [f"{name} {_value(r, name)} > {limit}" for name, limit in budget.items()
                if r.cost is not None and _value(r, name) > limit]
        if over:
            who = f" ({', '.join(r.objects)})" if r.objects else ""
            what = r.table if r.table == r.subject else f"{r.table} {r.subject}"  # "ubershader", not twice
            lines.append(f"over budget: {what}{who} {r.stage} {r.language}: {', '.join(over)}")
    return lines


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


def run(args) -> int:
    budget = parse_budget(args.budget) if args.budget else None
    old_rows = read_report(args.diff) if args.diff else None
    if bool(args.scene) == bool(args.per_brick):
        raise UsageError("give a SCENE or --per-brick (one of them) — e.g. `shadermatrix costs scenes/example.toml` "
                         "or `shadermatrix costs --per-brick`")
    from ...measure.plans import brick_rows, course_models, load_cost_library, scene_rows
    from ...measure.report import diff, markdown, to_csv, to_json

    from ...io import Store, default_cache_dir
    root = args.cache_dir or default_cache_dir()
    store = None if args.no_cache or root is None else Store(root)
    gpu = None
    if args.gpu is not None:
        from ...measure.gpu import GpuRequest
        from ...runtime.gpu_stats import DEFAULT_FAMILIES, check_families
        from ...scene.load import SCENE_SUFFIXES
        if "/" in args.gpu or args.gpu.lower().endswith(SCENE_SUFFIXES):  # `costs --gpu SCENE`: the scene taken for families
            raise UsageError(f"--gpu {args.gpu}: that is a file, not AMD families — put the scene first "
                             f"(`costs SCENE --gpu`) or write `--gpu=navi21,...`")
        try:
            families = check_families(DEFAULT_FAMILIES if args.gpu == "default" else args.gpu.split(","))
        except ValueError as e:
            raise UsageError(f"--gpu {args.gpu}: {e}") from None
        gpu = GpuRequest(families, args.gpu_ir)
    elif args.gpu_ir:
        raise UsageError("--gpu-ir needs --gpu — e.g. `--gpu navi21 --gpu-ir out/isa`")
    models, model_errors = None, None
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
        sys.stdout.write(diff(rows, old_rows, BUDGET_NAMES, args.diff))
    elif args.format == "md":
        sys.stdout.write(markdown(rows, title, models, gpu, course=args.course, languages=args.explain_languages,
                                  model_errors=model_errors))
    elif args.format == "csv":
        sys.stdout.write(to_csv(rows))
    else:
        sys.stdout.write(to_json(rows, subject, models, gpu, model_errors=model_errors))
    for why in sorted((gpu.errors or {}).values()) if gpu is not None else ():
        print(f"error: {why}", file=sys.stderr)
    failed = sorted({f"{r.subject} ({r.language}): {r.error}" for r in rows if r.error})
    for f in failed:
        print(f"error: {f}", file=sys.stderr)
    over = over_budget(rows, budget) if budget else []
    for line in over:
        print(f"error: {line}", file=sys.stderr)
    if budget:
        shaders = sum(1 for r in rows if r.cost is not None)
        print(f"budget {', '.join(f'{k} ≤ {v}' for k, v in budget.items())}: {len(over)} of {shaders} shaders over",
              file=sys.stderr)
    if failed or over or (gpu is not None and gpu.errors):
        if gpu is not None and gpu.note:
            print(f"error: {gpu.note}", file=sys.stderr)
        return 1
    if gpu is not None and gpu.note:  # asked for and not there: the table came without them, and the exit says so
        raise EnvironmentMissing(f"{gpu.note} (the tables above leave the AMD columns out)")
    return 0
