"""`shadermatrix build`: a scene's shader matrix in every language, validated, with manifest.json."""
from __future__ import annotations

import json
import signal
import sys
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace

from ...lang.errors import UsageError, UserError

HELP = "build a scene's shader matrix per platform (vulkan, d3d12, gl, webgpu) and manifest.json"


def add_arguments(p) -> None:
    p.add_argument("scene", help="scene file (TOML, or glTF 2.0 .gltf/.glb)")
    p.add_argument("--out", required=True, help="output directory")
    p.add_argument("--platform", metavar="LIST",
                   help="comma-separated, from vulkan, d3d12, gl, webgpu (default all): one tree OUT/<platform>/ "
                        "each; vulkan: SPIR-V (and the GLSL/HLSL/WGSL it was made from), d3d12: HLSL for SM 6 (and "
                        "DXIL with a dxc on PATH), gl: GLSL 4.50 core and ES 3.10, webgpu: WGSL. Every language is "
                        "compiled to SPIR-V and validated whichever are chosen")
    p.add_argument("--bricks", action="append", metavar="DIR",
                   help="an extra brick directory (repeatable)")
    p.add_argument("--cache-dir", metavar="DIR",
                   help="the content-addressed compile cache (default: $SHADERMATRIX_CACHE_DIR, else "
                        "$XDG_CACHE_HOME/shadermatrix, else ~/.cache/shadermatrix)")
    p.add_argument("--no-cache", action="store_true",
                   help="compile everything; read and write no cache (worker processes share a private one for "
                        "this build only, removed when it ends)")
    p.add_argument("-j", "--jobs", type=int, metavar="N",
                   help="worker processes composing, compiling and analysing (default: the core count; from 64 "
                        "permutations, else N tool processes); the output is the same for any N")
    p.add_argument("--executor", metavar="dask://HOST:PORT",
                   help="compose, compile and analyse on a Dask distributed cluster, this process writing (its workers "
                        "need this shadermatrix and the pinned tools, one thread each: docs/guide/build.md)")
    p.add_argument("--keep-removed", action="store_true",
                   help="keep the outputs of permutations that left the scene, listed under the manifest's "
                        "\"removed\" (default: they are deleted)")
    p.add_argument("--pack", action="store_true",
                   help="also write one shader pack per platform, DIR/packs/<platform>.<key16>.smpack (an index and "
                        "the platform's artifacts; format: generator/assemble/pack.py), listed under the manifest's "
                        "\"packs\"")
    p.add_argument("--pack-only", action="store_true",
                   help="the packs (as --pack) and the manifest without the loose artifacts: no source, SPIR-V or "
                        "platform file per permutation (10,000 permutations are ~90,000 files otherwise); the "
                        "manifest says \"artifacts\": \"packs\" and still lists every artifact's path and sha256, "
                        "its bytes in the pack of its platform")
    p.add_argument("-q", "--quiet", action="store_true",
                   help="no per-permutation lines and no progress bar: the summary line and errors only")
    p.add_argument("--explain", action="store_true",
                   help="say why: each permutation rebuilt and the input that changed (a brick, template or source "
                        "file with its old and new sha256, a tool version, a scene value), and how many permutations "
                        "each changed input reached (with --json: the summary's \"explain\")")
    p.add_argument("--json", action="store_true",
                   help="print the summary as one JSON object on stdout (counts, seconds, failures) instead of text")
    p.add_argument("--validate-ir", action="store_true",
                   help="debug: check the IR the link stage builds for every permutation and the ubershader against "
                        "the emitters' invariants (generator/lang/validate.py) before compiling; a violation is a "
                        "generator bug, reported and exit 1")
    p.add_argument("--depfile", metavar="PATH",
                   help="write a Make-syntax depfile (Ninja: deps = gcc) for the --stamp file (else OUT/manifest.json):"
                        " what the scene's permutations read, the brick directories and OUT/.shadermatrix-versions")
    p.add_argument("--stamp", metavar="FILE",
                   help="replace FILE after every build that succeeds (not after one that fails): the target of a "
                        "Make, Ninja or CMake rule, which then reruns only when an input is newer than it")


def summary(scene, res, out, seconds: float, pack: bool = False) -> dict:
    """`build --json`: what the summary line says, as data (an engine's build reads it instead of parsing text)."""
    c = res.compile
    perms = [] if res.up_to_date else res.manifest["permutations"]
    status = {s: sum(1 for p in perms if p["status"] == s) for s in ("ok", "failed", "stale")}
    n = len(scene.permutations)
    return {"scene": scene.name, "manifest": f"{out}/manifest.json", "permutations": n,
            "up_to_date": n if res.up_to_date else res.kept,
            "built": 0 if res.up_to_date else status["ok"] - res.kept,
            "failed": status["failed"], "stale": status["stale"],
            "shaders": c.jobs, "distinct": c.distinct, "merged": c.jobs - c.distinct, "from_cache": c.cached,
            "compiled": c.compiled, "files_written": res.written, "files_unchanged": res.unchanged,
            "spirv_shared": res.aliased, "seconds": round(seconds, 3), "ok": res.ok,
            "failures": list(res.failures),
            **({"packs": [p["path"] for p in res.manifest.get("packs", [])]} if pack else {})}


def _explained(scene, res):
    """Why the build rebuilt what it did (assemble/inputs.py); a no-op rebuilt nothing."""
    from ...assemble.inputs import Explained
    if res.explain is None:
        ids = {h: p.canonical() for h, p in scene.permutations.items()}
        return Explained(len(ids), False, ids, {}, None)
    return res.explain.explained()


def _interrupter(gate):
    """The handler of Ctrl-C and SIGTERM during the build of `gate`: its tools are killed at once (whatever thread
    runs them: none waits for a batch to finish), then the build unwinds like Ctrl-C (atomic writes remove their
    temporary files)."""
    def interrupted(signum, frame):
        gate.stop()
        raise KeyboardInterrupt
    return interrupted


def _request(args, platforms):
    """What this invocation asks for that decides the outputs (assemble/noop.Request), or None where a no-op
    must be decided by the full path: --explain (it says why), --validate-ir (it checks the IR), a glTF scene."""
    import os
    import time

    from ...assemble.noop import Request
    from ...backends import LANGUAGES
    if args.explain or args.validate_ir or not str(args.scene).lower().endswith(".toml"):
        return None
    absolute = [os.path.abspath(d) for d in args.bricks or ()]
    target = None
    if args.depfile:
        from ...assemble.depfile import shown
        target = str(args.stamp) if args.stamp is not None else shown(Path(args.out) / "manifest.json")
    return Request(os.path.abspath(args.scene), tuple(absolute), tuple(platforms), tuple(LANGUAGES),
                   bool(args.keep_removed), "only" if args.pack_only else "pack" if args.pack else "",
                   os.path.abspath(args.depfile) if args.depfile else None, target,
                   os.getcwd() if args.depfile else None, started=time.time_ns())


def _known_noop(args, request, started: float) -> bool:
    """Whether the last build's record says this one has nothing to do (assemble/noop.py); then say so, as the
    full path would, replay its warnings and replace the stamp."""
    import time

    from ...assemble import BuildResult
    from ...assemble.depfile import touch
    from ...assemble.noop import check
    from ...assemble.outputs import locked
    from ...io import Store, default_cache_dir
    out, root = Path(args.out), args.cache_dir or default_cache_dir()
    if args.no_cache or root is None or not (out / "manifest.json").is_file():  # the record is in the cache
        return False
    with locked(out):
        hit = check(out, request, Store(root))
        if hit is None:
            return False
        if args.stamp is not None:
            touch(args.stamp)
    for w in hit["warnings"]:
        print(f"warning: {w}", file=sys.stderr)
    seconds = time.perf_counter() - started
    if args.json:
        scene = SimpleNamespace(name=hit["scene"], permutations=range(hit["permutations"]))
        res = BuildResult(out, unchanged=hit["unchanged"], kept=hit["permutations"], up_to_date=True)
        res.manifest = {"packs": [{"path": p} for p in hit["packs"]]}
        print(json.dumps(summary(scene, res, args.out, seconds, args.pack or args.pack_only), indent=2))
        return True
    print(f"{hit['scene']}: {hit['permutations']} permutations up to date: 0 composed, 0 compiled; "
          f"0 files written, {hit['unchanged']} unchanged → {args.out}/manifest.json ({seconds:.2f} s)")
    return True


def run(args) -> int:
    from ...library.bricks import load_library
    from ...assemble import BuildContext, build
    from ...scene.load import load_scene
    import time

    from ...io import Store, default_cache_dir, show_progress
    started = time.perf_counter()
    if args.no_cache and args.cache_dir:
        raise UsageError("--no-cache and --cache-dir contradict each other — give one")
    if args.jobs is not None and args.jobs < 1:
        raise UsageError(f"-j {args.jobs}: give at least one job")
    if args.pack_only and args.keep_removed:
        raise UsageError("--pack-only and --keep-removed: the packs hold only what this build builds, so removed "
                         "permutations could keep no outputs — give one")
    if args.executor and not args.executor.startswith("dask://"):
        raise UsageError(f"--executor {args.executor}: write dask://HOST:PORT")
    from ...assemble.platforms import PLATFORMS, parse_platforms
    try:
        platforms = parse_platforms(args.platform) if args.platform is not None else list(PLATFORMS)
    except ValueError as e:
        raise UsageError(f"--platform: {e}") from None
    request = _request(args, platforms)
    if request is not None and _known_noop(args, request, started):  # nothing loaded: assemble/noop.py
        return 0
    try:
        lib = load_library(args.bricks or (), strict=False)  # a broken brick fails the build once a scene reaches it
        scene = load_scene(args.scene, lib)
    except UserError as e:
        if args.json:  # a script reading stdout gets its answer too
            print(json.dumps({"ok": False, "failures": [str(e)]}, indent=2))
        raise
    warnings = [f"{e} (no permutation of this scene uses the brick; `shadermatrix bricks --check` checks every brick)"
                for e in lib.errors]  # what the scene reaches has loaded (resolving it raises a broken brick's error)
    from ...spec.resolve import fp16_warnings
    warnings += fp16_warnings(scene.permutations.values(), lib)  # bricks marked "fp16": "unsafe: ..."
    from ...assemble.entries import ubershader_warning
    warnings += [w for w in [ubershader_warning(scene)] if w]
    for w in warnings:
        print(f"warning: {w}", file=sys.stderr)
    if request is not None:
        request = replace(request, warnings=tuple(warnings))
    if args.validate_ir:
        from ...link.checked import ir_violations
        found = ir_violations([p for _, p in sorted(scene.permutations.items())], lib)
        for v in found:
            print(f"internal error: {v} — the generator built invalid IR: please report it with the scene",
                  file=sys.stderr)
        if found:
            return 1
    root = args.cache_dir or default_cache_dir()
    if root is None and not args.no_cache:
        print("note: no home directory for the compile cache — building without it (--cache-dir DIR to keep one)",
              file=sys.stderr)
    store = None if args.no_cache or root is None else Store(root)
    executor = None
    if args.executor:
        from ...toolchain.dask import DaskExecutor
        executor = DaskExecutor(args.executor)
    ctx = BuildContext(lib, platforms=platforms, store=store, progress=show_progress() and not args.quiet,
                       jobs=args.jobs, executor=executor)
    handlers = {sig: signal.signal(sig, _interrupter(ctx.gate)) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        res = build(scene, Path(args.out), ctx, depfile=args.depfile, keep_removed=args.keep_removed,
                    pack="only" if args.pack_only else args.pack, stamp=args.stamp, request=request)
    finally:
        if executor is not None:
            executor.close()
        for sig, handler in handlers.items():
            signal.signal(sig, handler)
    seconds = time.perf_counter() - started
    why = _explained(scene, res) if args.explain else None
    if args.json:
        print(json.dumps({**summary(scene, res, args.out, seconds, args.pack or args.pack_only),
                          **({"explain": why.as_dict()} if why is not None else {})}, indent=2))
        for f in res.failures:
            print(f"error: {f}", file=sys.stderr)
        return 0 if res.ok else 1
    for line in why.lines() if why is not None else []:
        print(line)
    if res.up_to_date:
        print(f"{scene.name}: {len(scene.permutations)} permutations up to date: 0 composed, 0 compiled; "
              f"0 files written, {res.unchanged} unchanged → {args.out}/manifest.json ({seconds:.2f} s)")
        return 0
    perms = res.manifest["permutations"]
    ok = sum(1 for p in perms if p["status"] == "ok")
    stale = sum(1 for p in perms if p["status"] == "stale")
    if not args.quiet:
        print(f"{scene.name}: {len(scene.objects)} objects, {len(scene.materials)} materials, "
              f"{len(scene.lights)} lights → {len(perms)} permutations × {len(res.manifest['languages'])} languages"
              f" → {', '.join(res.manifest.get('platforms', []))}")
        for p in perms:
            print(f"  {p['status']:<6} {p['hash']}  {p['id']}  [{', '.join(p.get('platforms') or p['languages'])}]  ({', '.join(p['objects'])})")
    uber = res.manifest.get("ubershader") or {}
    if uber and not args.quiet:
        t = uber.get("tables", {})
        print(f"  {uber['status']:<6} ubershader    {len(t.get('variants', []))} material variants, light types "
              f"{', '.join(t.get('light_types', []))}, shadows {', '.join(t.get('shadows', []))}: every permutation reachable"
              if uber["status"] == "ok" else f"  {uber['status']:<6} ubershader")
    c = res.compile
    print(f"{ok}/{len(perms)} permutations valid SPIR-V in every language ({res.kept} up to date, "
          f"{len(perms) - ok - stale} failed, {stale} stale); {c.jobs} shaders, {c.distinct} distinct "
          f"({c.jobs - c.distinct} merged), {c.cached} from the cache, {c.compiled} compiled; "
          f"{res.written} files written, {res.unchanged} unchanged, {res.aliased} SPIR-V shared → "
          f"{args.out}/manifest.json ({seconds:.1f} s)")
    for p in res.manifest.get("packs", []) if args.pack or args.pack_only else []:
        print(f"  pack {p['path']}: {p['entries']} entries, {p['size']} bytes")
    for f in res.failures:
        print(f"error: {f}", file=sys.stderr)
    return 0 if res.ok else 1
