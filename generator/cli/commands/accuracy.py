"""`shadermatrix accuracy`: error of every target and dtype against the float64 references.

    shadermatrix accuracy [SPEC ... | SCENE] [--targets numpy,glsl,hlsl,wgsl] [--dtypes float64,float32,float16]
                          [--format md|json] [--out FILE] [--samples K] [--fail-above TOL] [--reference FILE.py ...]

Without SPECs: every BRDF brick (each diffuse term, each specular term with
each slot filler at least once; --all-combinations: every combination). With
a scene file: exactly the scene's materials, each its BRDF at its own parameter
values (a parameter a packing reads from a texture is measured at the
material's factor, the value the texture is multiplied by). Without --targets: numpy, GLSL, HLSL and
WGSL; without a lavapipe device that is an error (exit 3), never a silent
numpy-only report: pass --targets numpy to run without one. Two sample sets per spec: a
stratified hemisphere (K⁴ samples) and the stress set (see generator/eval/accuracy.py).
A spec or material whose bricks have no float64 reference is measured all the same: the plausibility
checks (generator/eval/plausibility.py) and every target's precision error against the NumPy target of
its own formula at float64; --reference FILE.py runs a file of the user's that registers independent
references (user code, run only when named: generator/eval/user_references.py).
Exit status 1 when any float32 evaluation gives NaN or Inf (or, with
--fail-above, a float32 hemisphere error exceeds TOL), a plausibility check fails (located at the
material's scene line), or on bad input.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

from ... import DTYPES, GPU_TARGETS
from ...lang.errors import UsageError

HELP = "error of every target × dtype against the float64 references: hemisphere and stress set (Markdown/JSON)"
ACCURACY_TARGETS = ("numpy",) + GPU_TARGETS
MAX_STRATA = 40  # K⁴ = 2,560,000 (l, v) pairs; one spec takes ~1.5 GB and 10 s (K grows memory as K⁴)


def add_arguments(p) -> None:
    p.add_argument("specs", nargs="*", metavar="SPEC|SCENE", help="BRDF specs (default: every BRDF brick, each slot "
                   "filler at least once; see --all-combinations), or one scene file (.toml, .gltf, .glb): its materials, "
                   "each at its own parameters")
    p.add_argument("--all-combinations", action="store_true",
                   help="without SPECs: every combination of slot fillers (default: each filler at least once)")
    p.add_argument("--targets", metavar="LIST",
                   help=f"comma-separated, from {', '.join(ACCURACY_TARGETS)} (default: all; the GPU languages "
                        "need a lavapipe device: without one, exit 3 unless --targets leaves them out)")
    p.add_argument("--dtypes", metavar="LIST",
                   help="comma-separated, from float64, float32, float16 (default all; GPU targets run float32, and "
                        "float16 where the device reports shaderFloat16: by default a device without it skips the "
                        "GPU float16 runs with the reason; asked for by --dtypes and --targets, exit 3)")
    p.add_argument("--format", choices=("md", "json"), default="md", help="report format (default md)")
    p.add_argument("--out", metavar="FILE", help="write the report to FILE (atomically) instead of stdout")
    p.add_argument("--samples", type=int, default=12, metavar="K",
                   help=f"hemisphere strata per dimension: K⁴ (l, v) pairs (default 12, at most {MAX_STRATA})")
    p.add_argument("--fail-above", type=float, metavar="TOL",
                   help="the tolerance of the verdict: a spec fails (exit 1) when its float32 hemisphere max relative "
                        "error exceeds TOL (default 1e-3) or float32 gives a NaN or Inf")
    p.add_argument("--detail", action="store_true",
                   help="Markdown: every target's errors per sample set and the stress set by parameter value, "
                        "below the verdicts")
    p.add_argument("--bricks", action="append", metavar="DIR", help="an extra brick directory (repeatable)")
    p.add_argument("--reference", action="append", metavar="FILE.py",
                   help="a Python file registering float64 references for engine bricks with @reference(kind, id) "
                        "(repeatable; user code: it is run, and only when named here)")


def _list(value: str, allowed: tuple, what: str) -> list[str]:
    items = [v.strip() for v in value.split(",") if v.strip()]
    bad = [v for v in items if v not in allowed]
    if bad or not items:
        raise UsageError(f"unknown {what} {', '.join(map(repr, bad)) or '(none given)'} — "
                         f"use a comma-separated list from {', '.join(allowed)}")
    return items


def _is_scene(arg: str) -> bool:
    from ...scene.load import SCENE_SUFFIXES
    return arg.lower().endswith(SCENE_SUFFIXES)


def scene_materials(path: Path, lib) -> dict:
    """{"material: brdf": (brdf, params)} of a scene's materials, in the scene's order: the BRDF parameters
    the material sets (packing and output parameters left out); the others take the bricks' defaults."""
    from ...eval.accuracy import declared_params
    from ...scene.load import load_scene
    scene = load_scene(path, lib)
    out = {}
    for m in scene.materials.values():
        declared = declared_params(m.brdf, lib)
        out[f"{m.name}: {m.brdf}"] = (m.brdf, {k: v for k, v in m.params.items() if k in declared})
    return out


def material_locations(path: Path, materials: dict) -> dict[str, str]:
    """{label: "path:line:col"} of each material's `brdf =` in a TOML scene (a glTF scene: its path, 1:1)."""
    if path.suffix.lower() != ".toml":
        return {label: f"{path}:1:1" for label in materials}
    from ...scene.load import read_toml
    _data, loc = read_toml(path, "scene", "fix the scene file's syntax")
    return {label: "{}:{}:{}".format(path, *loc.find(f"materials.{label.partition(': ')[0]}", "brdf"))
            for label in materials}


def plausibility_errors(report: dict, where: dict[str, str], materials: dict | None) -> list[str]:
    """One line per failed plausibility check: at the material's scene line (a spec: its string), what failed."""
    out = []
    for r in report.get("plausibility", []):
        label = r["spec"]
        at = where.get(label, f"spec string '{label}':1:1")
        what = (f"material '{label.partition(': ')[0]}' ({label.partition(': ')[2]})" if materials and label in materials
                else f"BRDF '{label}'")
        for c in (c for c in r["checks"] if not c["pass"]):
            todo = ('declare "reciprocal": "no: why" in the BRICK of a brick that is not reciprocal by design, or fix '
                    "its formula" if c["check"] == "reciprocity" else
                    'declare "fp16": "unsafe: why" in the BRICK, or guard the formula in half'
                    if c["check"] == "float16 finite" else "fix the brick's formula or the material's parameters")
            out.append(f"{at}: {what}: plausibility check '{c['check']}' fails: {c['detail']} — {todo}")
    return out


def run(args) -> int:
    from ...runtime.eval_kernel import EvalSession

    with EvalSession() as session:  # the GPU targets' device and kernels, for this run (opened on first use)
        return _run(args, session)


def _run(args, session) -> int:
    from ...eval import accuracy
    from ...eval.user_references import user_references
    from ...library.bricks import load_library
    from ...io import atomic_write
    from ...eval.evaluate import EvalError
    from ...spec.permutation import SpecError
    from ...reference import ReferenceMissing
    from ...runtime.device import VulkanUnavailable

    try:
        if not 1 <= args.samples <= MAX_STRATA:
            raise UsageError(f"--samples {args.samples} is outside 1 … {MAX_STRATA} (K⁴ sample pairs) — "
                             f"give a number of strata in that range (default 12)")
        dtypes = _list(args.dtypes or ",".join(DTYPES), DTYPES, "dtype")
        if args.targets:
            targets = _list(args.targets, ACCURACY_TARGETS, "target")
        else:
            targets = accuracy.default_targets()
            if targets == ["numpy"]:
                raise VulkanUnavailable("no lavapipe Vulkan device for the GPU targets (`shadermatrix doctor` says "
                                        "why; `make setup` installs it) — or pass --targets numpy to run without")
        lib = load_library(args.bricks or ())
        materials, where = None, {}
        if args.all_combinations and args.specs:
            raise UsageError("--all-combinations chooses the specs itself — give it without SPECs or a scene")
        scenes = [s for s in args.specs if _is_scene(s)]
        if len(scenes) > 1:
            raise UsageError(f"one scene file at a time — run shadermatrix accuracy {scenes[0]}, then the others")
        if scenes:
            if len(args.specs) != 1:
                raise UsageError("give either BRDF specs or one scene file, not both — "
                                 f"e.g. shadermatrix accuracy {scenes[0]}")
            materials = scene_materials(Path(args.specs[0]), lib)
            where = material_locations(Path(args.specs[0]), materials)
            specs = list(materials)
        else:
            specs = args.specs or accuracy.default_specs(lib, full=args.all_combinations)
        if not accuracy.runs(targets, dtypes, session):
            raise UsageError(f"no target runs any of the dtypes {', '.join(dtypes)} — "
                             "GPU targets run float32 and float16; add float32 or the numpy target")
        tol = accuracy.DEFAULT_TOL if args.fail_above is None else args.fail_above
        with user_references(args.reference) as user:
            report = accuracy.run(specs, targets, dtypes, lib, hemisphere_k=args.samples, tol=tol,
                                  materials=materials, session=session, user=user)
    except (EvalError, SpecError, ReferenceMissing) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    text = accuracy.markdown(report, args.detail) if args.format == "md" else json.dumps(report, indent=1) + "\n"
    if args.out:
        atomic_write(Path(args.out), text.encode())
    else:
        sys.stdout.write(text)

    f32 = [r for r in report["results"] if r["dtype"] == "float32"]
    bad = [r for r in f32 if r["nan"] or r["inf"]]
    worst = max((r for r in f32 if r["set"] == "hemisphere"), key=lambda r: r["max_rel"], default=None)
    for r in bad:
        print(f"error: {r['spec']} {r['target']}/float32 ({r['set']}): {r['nan']} NaN, {r['inf']} Inf",
              file=sys.stderr)
    failed = [v for v in report["verdicts"] if not v["pass"]]
    for v in failed:
        own = v.get("tolerance", tol)
        if v["hemisphere_max_rel"] is not None and v["hemisphere_max_rel"] > own:
            why = "--fail-above" if own == tol else "the brick's declared tolerance, or --fail-above if larger"
            print(f"error: {v['spec']} {v['hemisphere_target']}/{'/'.join(v['dtypes'])}: hemisphere max relative "
                  f"error {v['hemisphere_max_rel']:.3g} exceeds the tolerance {own:g} ({why})", file=sys.stderr)
    implausible = plausibility_errors(report, where, materials)
    for line in implausible:
        print(f"error: {line}", file=sys.stderr)
    for v in report["verdicts"]:
        if v.get("reference", {}).get("kind") == "none":
            print(f"note: {v['spec']}: no float64 reference for {', '.join(v['reference']['missing'])} — plausibility "
                  "checks and the precision error against its own formula instead (--reference FILE.py adds one)",
                  file=sys.stderr)
    skipped = report.get("skipped", [])
    for sk in (x for x in skipped if not x["run"].endswith("/float64")):  # float64 on a GPU: never, by design
        print(f"note: not run: {sk['run']} — {sk['why']}", file=sys.stderr)
    too_big = bool(failed)
    print(f"{len(specs) - len(failed)} of {len(specs)} specs pass; {len(specs)} specs × {', '.join(report['runs'])}: "
          f"{'no' if not bad else len(bad)} float32 NaN/Inf"
          + (f"; worst float32 hemisphere error {worst['max_rel']:.2e} ({worst['spec']}, {worst['target']})"
             if worst else "") + (f" → {args.out}" if args.out else ""), file=sys.stderr)
    if bad or too_big:
        return 1
    asked = args.dtypes and args.targets and "float16" in dtypes
    missing = [sk for sk in skipped if sk["run"].endswith("/float16") and sk["run"].split("/")[0] in GPU_TARGETS]
    if asked and missing:  # asked for by name and the device cannot: the environment, never silently skipped
        from ...runtime.device import Fp16Unsupported
        raise Fp16Unsupported(f"{', '.join(sk['run'] for sk in missing)}: {missing[0]['why']} "
                              "(the report above leaves them out)")
    return 0
