"""`shadermatrix render`: draw a scene offscreen on lavapipe with the matrix, the ubershader, or the hybrid."""
from __future__ import annotations

import re
import sys
from pathlib import Path

from ...lang.errors import UsageError

HELP = "render a scene offscreen on lavapipe: specialized, ubershader or hybrid; PNG frames and report.json"


def add_arguments(p) -> None:
    p.add_argument("scene", help="scene file (TOML, or glTF 2.0 .gltf/.glb)")
    p.add_argument("--mode", choices=("specialized", "ubershader", "hybrid"), default="hybrid")
    p.add_argument("--frames", type=int, default=3, help="frames to draw (default 3)")
    p.add_argument("--out", required=True, help="output directory: frame_NNNN.png, report.json, the pipeline cache")
    p.add_argument("--size", default="256x160", help="WxH (default 256x160)")
    p.add_argument("--language", choices=("glsl", "hlsl", "wgsl"), default="glsl")
    p.add_argument("--bricks", action="append", default=[], metavar="DIR", help="extra brick directory")
    p.add_argument("--build", metavar="DIR", help="draw the materials' textures from this build's outputs (its "
                   "manifest.json and KTX2 files; default: write the scene's texture artifacts into --out/textures "
                   "as build does)")
    p.add_argument("--export", metavar="DIR", help="also write the frame export into DIR: frame.json and the meshes "
                   "(what an engine takes from its own scene: meshes, object matrices, camera, the shadowed lights' "
                   "matrices, as this render used them; docs/reference/frame.md)")


def run(args) -> int:
    from ...io import show_progress as progress
    from ...library.bricks import load_library
    from ...scene.load import load_scene
    from ...runtime.renderer import render_scene

    m = re.fullmatch(r"(\d+)x(\d+)", args.size)
    if not m or not (1 <= int(m[1]) <= 4096 and 1 <= int(m[2]) <= 4096):
        raise UsageError(f"--size {args.size!r} is not WxH — write e.g. --size 256x160 (1 to 4096 each)")
    if args.frames < 1:
        raise UsageError(f"--frames {args.frames} — draw at least one frame")
    lib = load_library(args.bricks)
    scene = load_scene(args.scene, lib)
    from ...runtime.device import VulkanUnavailable
    out, build = Path(args.out), None
    if args.build is not None:
        build = Path(args.build)
    elif out.is_dir() or not out.exists():  # (a file: the renderer's own error)
        # the texture part of a build, into the render's folder: the renderer reads what an engine reads
        from ...assemble.render_inputs import scene_textures
        build = scene_textures(scene, out, lib)
    environments = None
    if scene.environment_of:  # image-based lighting: SH9, the prefiltered cubes, the AmbientBRDF tables, baked
        from ...assemble.environments import bake
        environments = bake(scene, lib)
    try:
        report = render_scene(scene, lib, args.mode, args.frames, out, (int(m[1]), int(m[2])),
                              args.language, progress=progress(), build=build, export=args.export,
                              environments=environments)
    except VulkanUnavailable as e:
        raise VulkanUnavailable(f"no Vulkan device to render on: {e} — install Mesa lavapipe (`make setup`)") from None
    if report.cache_problem:
        print(f"warning: {report.cache_problem}", file=sys.stderr)
    for warning in report.shadow_warnings:  # located already: path:line:col: warning: ...
        print(warning, file=sys.stderr)
    for note in report.texture_notes:
        print(f"note: {note}", file=sys.stderr)
    last = report.steady
    print(f"{scene.name}: {len(scene.objects)} objects, {args.mode}, {args.language}, {args.frames} frames → {args.out}; "
          f"first frame {report.time_to_first_frame_ms:.1f} ms, {report.pipelines_created} pipelines; "
          f"steady frame: {last.draws_specialized} specialized / {last.draws_ubershader} ubershader draws")
    return 0
