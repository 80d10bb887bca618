"""Render a scene's objects offscreen with the shader matrix, the ubershader, or both as a hybrid.

Hoffman & Baker 2006: "use Ubershader as fallback, shader matrix as a cache". Modes:
- `specialized`: every draw uses its permutation's pipeline, all created before the first frame;
- `ubershader`: every draw uses the ubershader;
- `hybrid`: a draw whose specialized pipeline exists uses it; the others draw with the
  ubershader while a worker thread creates their pipelines in order of first use. After the
  requested frames the queue is drained and one more frame is drawn (`steady`): it uses no
  ubershader.

Placement (documented in NOTES.md, "Renderer"): each object is a unit UV sphere; objects
stand in a row along x, 2.5 apart, in scene order; the camera looks at the row's centre
from above and in front. Textures are generated: an sRGB albedo checker, a normal map of
known bumps; shadow maps are cleared to the far plane (everything lit) until the depth
pass exists. Pipelines are created through a persisted pipeline cache
(runtime/pipeline_cache.py).
"""
from __future__ import annotations

import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

MODES = ("specialized", "ubershader", "hybrid")
SPACING = 2.5


@dataclass
class Frame:
    cpu_ms: float
    gpu_ms: float | None
    draws_ubershader: int
    draws_specialized: int


@dataclass
class Report:
    mode: str
    language: str
    size: tuple[int, int]
    frames: list[Frame] = field(default_factory=list)
    steady: Frame | None = None
    time_to_first_frame_ms: float = 0.0
    pipelines_created: int = 0
    pipeline_create_ms: list[float] = field(default_factory=list)
    pipeline_cache_hits: int = 0
    cache_problem: str = ""

    def as_dict(self) -> dict:
        from dataclasses import asdict
        return asdict(self)


def _textures(device):
    """A 16×16 sRGB checker albedo, a 32×32 normal map of bumps, a lit (depth 1) shadow map."""
    j, i = np.meshgrid(np.arange(16), np.arange(16))
    albedo = np.where(((i // 4 + j // 4) % 2 == 0)[..., None], [230, 200, 120], [90, 140, 200]).astype(np.uint8)
    v, u = np.meshgrid((np.arange(32) + 0.5) / 32, (np.arange(32) + 0.5) / 32, indexing="ij")
    t = np.stack([0.5 * np.sin(2 * np.pi * 4 * u), 0.5 * np.cos(2 * np.pi * 3 * v), np.ones_like(u)], -1)
    t /= np.linalg.norm(t, axis=-1, keepdims=True)
    nmap = np.round((t + 1.0) / 2.0 * 255.0).astype(np.uint8)
    shadow = np.ones((4, 4, 4), np.float32)
    return {"albedo_map": device.image(albedo, srgb=True), "normal_map": device.image(nmap),
            "shadow_map": device.image(shadow)}


def camera(n: int, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    """(eye, view_proj) looking at a row of n objects (see the module docstring)."""
    from . import graphics as gx

    eye = np.array([0.0, 2.5, 3.0 + 1.6 * n])
    return eye, gx.perspective(40.0, width / height, 0.1, 100.0) @ gx.look_at(eye, (0.0, 0.0, 0.0))


def placement(i: int, n: int) -> np.ndarray:
    """The model matrix of object i of n: a unit sphere in the row along x."""
    model = np.eye(4)
    model[0, 3] = (i - (n - 1) / 2.0) * SPACING
    return model


def _entries(ids: np.ndarray, data: np.ndarray) -> np.ndarray:
    """Storage-buffer entries: ids as int32 in the first vec4, then the data vec4s (link/uber.py)."""
    raw = np.zeros((len(ids), 1 + data.shape[1], 4), np.float32)
    raw[:, 1:, :] = data
    raw = raw.view(np.uint32)
    raw[:, 0, :] = ids.astype(np.int32).view(np.uint32)
    return raw


def render_scene(scene, lib, mode: str, frames: int, out, size=(256, 160), language: str = "glsl",
                 device=None, progress: bool = False, uber_ids: str = "buffer") -> Report:
    """Render `frames` frames of `scene` into out/frame_NNNN.png; returns the report (also out/report.json).

    uber_ids: "buffer" (the variant read from the material entry: one ubershader pipeline) or
    "specialization" (the variant as specialization constant 0: one ubershader pipeline per material
    variant from the one module; WGSL: naga resolves the override per pipeline).
    """
    from ..link.values import uploads
    from ..compose import compose_permutation
    from ..compose.uber import compose_ubershader
    from ..io import atomic_write
    from ..lang.errors import UserError
    from ..toolchain import CompileJob, compile_many
    from . import graphics as gx
    from .device import Device, validation_requested
    from ..link.uber import SPEC_VARIANT
    from .meshes import uv_sphere
    from .pipeline_cache import PipelineCacheFile

    if mode not in MODES:
        raise UserError(f"unknown mode {mode!r} — use one of {', '.join(MODES)}")
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise UserError(f"{out} is a file — give --out a directory")
    out.mkdir(parents=True, exist_ok=True)
    W, H = size
    perms = dict(sorted(scene.permutations.items()))
    composed = {h: compose_permutation(p, lib, (language,)) for h, p in perms.items()}
    spec_ids = uber_ids == "specialization"
    uber, u = compose_ubershader(list(perms.values()), lib, (language,), specialized=spec_ids)
    jobs = {}
    for tag, c in [*composed.items(), ("ubershader", uber)]:
        for s in c.sources:
            jobs[(tag, s.stage)] = CompileJob(f"{tag}.{s.stage}.{language}", language, s.stage, s.text,
                                              line_map=tuple(map(tuple, s.line_map)))
            if tag == "ubershader" and spec_ids and language == "wgsl" and s.stage == "frag":
                for k in range(len(u.variants)):  # WebGPU resolves an override when the pipeline is made
                    jobs[(f"ubershader{k}", "frag")] = CompileJob(f"ubershader{k}.frag.wgsl", language, "frag", s.text,
                                                                  line_map=tuple(map(tuple, s.line_map)),
                                                                  overrides=((str(SPEC_VARIANT), k),))
    results = compile_many(jobs.values())
    bad = [e for r in results.values() if not r.ok for e in r.errors()]
    if bad:
        raise UserError(f"{len(bad)} shader(s) do not compile: {bad[0]} — run `shadermatrix build` for all errors")
    spv = {k: results[j.key].spirv for k, j in jobs.items()}

    own_device = device is None
    device = device or Device(validation=validation_requested())
    owned = []
    try:
        report = Report(mode, language, (W, H))
        cache = PipelineCacheFile(device, out / f"pipeline_cache.{language}.bin")
        report.cache_problem = cache.problem
        target = gx.OffscreenTarget(device, W, H)
        sphere = gx.GpuMesh(device, uv_sphere(24, 48))
        textures, sampler = _textures(device), device.sampler()
        owned += [target, sphere, *textures.values(), sampler, cache]
        vk = device.vk
        U, S = vk.VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, vk.VK_BUFFER_USAGE_STORAGE_BUFFER_BIT

        def buf(raw, usage):
            raw = np.frombuffer(bytes(raw), np.uint8) if isinstance(raw, (bytes, bytearray)) else np.asarray(raw)
            b = device.buffer(raw.nbytes, usage)
            b.write(raw)
            owned.append(b)
            return b

        def make_pipeline(tag, iface, variant=None):
            t0 = time.perf_counter()
            frag, spec = spv[(tag, "frag")], None
            if variant is not None:
                if language == "wgsl":
                    frag = spv[(f"{tag}{variant}", "frag")]
                else:
                    spec = {SPEC_VARIANT: variant}
            p = gx.GraphicsPipeline(device, target, spv[(tag, "vert")], frag, iface.vertex_inputs,
                                    gx.layouts_from_interface(iface), cache=cache, specialization=spec)
            report.pipeline_create_ms.append((time.perf_counter() - t0) * 1e3)
            report.pipelines_created += 1
            report.pipeline_cache_hits += p.cache_hit  # the driver's creation feedback
            return p

        n = len(scene.objects)
        eye, vp = camera(n, W, H)
        variant = {v.key: k for k, v in enumerate(u.variants)}
        draws = []
        materials = sorted({o["material"] for o in scene.objects})
        mat_rows, mat_ids = [], []
        for name in materials:  # MaterialEntry m: the variant and the material's specialized Material block
            obj = next(o for o in scene.objects if o["material"] == name)
            p = perms[obj["permutation"]]
            up = next(x for x in uploads(scene, obj["permutation"], composed[obj["permutation"]])
                      if x["material"] == name)
            data = np.zeros((u.material_vec4s, 4), np.float32)
            block = np.frombuffer(bytes.fromhex(up.get("Material", "")), np.float32).reshape(-1, 4)
            data[:len(block)] = block
            k = variant[(p.brdf, p.packing, p.output)]
            mat_ids.append((k, 0, 0, 0))
            mat_rows.append(data)
        material_buffer = buf(_entries(np.array(mat_ids), np.stack(mat_rows)), S)
        light_buffers = {}
        for set_name, names in scene.light_sets.items():
            ids, rows, shadow_slot = [], [], 0
            for ln in names:
                L = scene.lights[ln]
                vals = {k: L.params.get(k, s.default) for k, s in _light_specs(lib, L).items()}
                data = np.zeros((u.light_vec4s, 4), np.float32)
                for pname, (j, ty) in u.light_layouts[(L.type, L.shadow)].items():
                    val = np.asarray(vals[pname], np.float32).reshape(-1)
                    for c in range(0, len(val), 4):
                        data[j + c // 4, :len(val[c:c + 4])] = val[c:c + 4]
                textured = bool([t for t in lib.get("shadow", L.shadow.split("(")[0]).textures])
                ids.append((u.light_types.index(L.type), u.shadows.index(L.shadow), shadow_slot if textured else 0, 0))
                shadow_slot += textured
                rows.append(data)
            light_buffers[set_name] = buf(_entries(np.array(ids), np.stack(rows)), S)
        frame_buf = buf(gx.frame_bytes(vp, eye), U)
        for i, obj in enumerate(scene.objects):
            h = obj["permutation"]
            c = composed[h]
            frame = frame_buf
            obj_buf = buf(gx.object_bytes(placement(i, n)), U)
            up = next(x for x in uploads(scene, h, c) if x["material"] == obj["material"]
                      and x["light_set"] == obj["light_set"])
            spec = {(0, 0): frame, (2, 0): obj_buf}
            if c.interface.block("Lights"):
                spec[(0, 1)] = buf(bytes.fromhex(up["Lights"]), U)
            if c.interface.block("Material"):
                spec[(1, 0)] = buf(bytes.fromhex(up["Material"]), U)
            for t in c.interface.textures:
                spec[(t.set, t.binding)], spec[(t.set, t.binding + 1)] = textures[t.param], sampler
            ub = {(0, 0): frame, (2, 0): obj_buf, (0, 1): light_buffers[obj["light_set"]],
                  (1, 0): buf(np.array([materials.index(obj["material"]), 0, 0, 0], np.int32), U),
                  (1, 1): material_buffer}
            for t in uber.interface.textures:
                ub[(t.set, t.binding)], ub[(t.set, t.binding + 1)] = textures[t.param], sampler
            draws.append((h, spec, ub))

        specialized: dict[str, object] = {}
        order = list(dict.fromkeys(h for h, _, _ in draws))  # first use
        start = time.perf_counter()
        uber_pipes = {}
        if mode != "specialized":
            for k in (sorted({m[0] for m in mat_ids}) if spec_ids else [None]):
                uber_pipes[k] = make_pipeline("ubershader", uber.interface, k)
        uber_of = {h: (variant[(perms[h].brdf, perms[h].packing, perms[h].output)] if spec_ids else None)
                   for h in perms}
        worker = None
        if mode == "specialized":
            for h in order:
                specialized[h] = make_pipeline(h, composed[h].interface)
        elif mode == "hybrid":
            def create():
                for h in order:
                    specialized[h] = make_pipeline(h, composed[h].interface)
            worker = threading.Thread(target=create, name="pipelines", daemon=True)
            worker.start()
        owned_pipelines = lambda: [*uber_pipes.values(), *specialized.values()]  # noqa: E731

        def draw_frame(index: int | None) -> Frame:
            t0 = time.perf_counter()
            items, nu, ns = [], 0, 0
            for h, spec, ub in draws:
                pipe = specialized.get(h) if mode != "ubershader" else None
                if pipe is not None:
                    items.append(gx.DrawItem(pipe, sphere, spec))
                    ns += 1
                else:
                    items.append(gx.DrawItem(uber_pipes[uber_of[h]], sphere, ub))
                    nu += 1
            gpu = target.draw(items, clear=(0.06, 0.07, 0.09, 1.0))
            image = target.read()
            if index is not None:
                gx.save_png(image, out / f"frame_{index:04d}.png")
            return Frame((time.perf_counter() - t0) * 1e3, gpu, nu, ns)

        for f in range(frames):
            report.frames.append(draw_frame(f))
            if f == 0:
                report.time_to_first_frame_ms = (time.perf_counter() - start) * 1e3
            if progress:
                print(f"\rframe {f + 1}/{frames}", end="", flush=True)
        if progress:
            print()
        if worker is not None:
            worker.join()
        report.steady = draw_frame(None)
        owned += owned_pipelines()
        cache.save()
        import json
        atomic_write(out / "report.json", (json.dumps(report.as_dict(), indent=2) + "\n").encode())
        return report
    finally:
        for obj in reversed(owned):
            obj.destroy()
        if own_device:
            device.close()


def _light_specs(lib, light) -> dict:
    from ..library.params import spec_params
    from ..matrix.permutation import Node, parse_spec

    return spec_params([Node(lib.get("light", light.type), ()), parse_spec(light.shadow, lib, ("shadow",))[0]])
