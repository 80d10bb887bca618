"""Render a scene's objects offscreen with the shader matrix, the ubershader, or both as a hybrid.

Hoffman & Baker 2006: "use Ubershader as fallback, shader matrix as a cache". Modes:
- `specialized`: every draw uses its permutation's pipeline, all created before the first frame;
- `ubershader`: every draw uses the ubershader;
- `hybrid`: a draw whose specialized pipeline exists uses it; the others draw with the
  ubershader while a worker thread creates their pipelines in order of first use. After the
  requested frames the queue is drained and one more frame is drawn (`steady`): it uses no
  ubershader.

Placement (documented in docs/design/scenes.md, "Placement"): read from the placement file beside the scene,
SCENE.placement.toml (:func:`placement_path`, schema in :func:`load_placement`: per object a mesh,
translate, scale, rotate_y; an optional camera); without one, each object is a unit UV sphere,
the objects stand in a row along x, 2.5 apart, in scene order, and the camera looks at the row's
centre from above and in front (:func:`camera`, :func:`placement`).

Shadows: for every light whose shadow filter samples a texture (shadow_map, pcf, pcf_hardware, vsm), a
depth pass before the first frame draws the objects of its light sets from the light (they alone cast its
shadow, as they alone receive it) with the generated depth shaders
(compose/depth.py), as the light's depth pass description says (runtime/shadow_pass.py, depth_pass: the
manifest's ``lights.<name>.depth_pass``, here for the Vulkan platform and a ``shadow_size`` square map;
runtime/depth_passes.py draws it): a masked material's objects through its mask unit (its coverage cuts
holes in the shadow), every other one through the position-only vertex stage; for a brick texture named
`shadow_moments` (vsm) the moments stage writes (d, d², 0, 1) into an RGBA32F target and the blur unit's two
fullscreen passes box-filter it on the GPU. The light's matrix is fitted to its casters' placed bounds
(shadow_pass.fit_shadow_matrix: a directional light's orthographic projection along its direction, a point
light's perspective one from its position, a spot's or uberlight's from its position along its axis covering its
cone; casters the map cannot reach are a warning located at the light, in the report's shadow_warnings) and
written into the light's shadow_matrix parameter of both paths (the specialized Lights blocks and the
ubershader's LightEntry data); the depth map is bound as the light's shadow map (pcf: a `pcf_texel` the scene leaves unset is written as 1 / shadow_size, in both paths
too), the blurred moments as its `shadow_moments`. A `texture2d_shadow`
(pcf_hardware) reads the depth pass's D32_SFLOAT image itself through a comparison sampler
(runtime/depth_images.py: linear, compareOp LESS_OR_EQUAL), where no map is drawn a lit 1×1 depth image
(depth 1.0); a device that cannot linearly filter D32_SFLOAT is refused for it.

Dynamic light sets (scene/light_sets.py): the specialized pipeline of an object lit by one reads each pair of the
set's model from its own storage buffer, filled with that pair's lights in the set's order (link/values.py
light_buffers: the bytes the manifest's uploads hold, the values a static set would upload) and bound whole, so
the loop's count is the buffer's length; a pair with no light gets a 4-byte buffer (a count of 0). The
ubershader reads the set's lights from its LightEntry buffer as for a static set.

Material textures are the build's (runtime/material_textures.py): every texture a material binds, the scene's
image or the generated one, is the KTX2 artifact the build's manifest lists for it (``materials.<m>.textures``),
sha256-checked and uploaded with its whole mip chain, read through the sampler the manifest spells for Vulkan
(``samplers[i].platforms.vulkan``), one VkSampler per distinct state; the specialized pipelines, the ubershader
and a masked material's depth pass bind the same image and sampler. Only the renderer's own inputs are made
here: a brick's baked table (reference/tables.py; read through the sampler its row of the build's ``tables``
names), the lit stand-ins of unused shadow slots, and a grey image
for an ubershader texture the drawn material does not bind (its variant never samples it). The surface state of a permutation
(spec/surface.py) is honoured by its specialized pipeline and by the ubershader alike: alpha MASK discards in
the shader, BLEND pipelines blend source-over without writing depth and are drawn after the opaque ones, back to
front (:func:`draw_order`: by the view depth of each one's bounding-box centre, ties in scene order; the frame
export's draw_order), single-sided surfaces cull their back faces, all as the manifest's render_state says (the
given build's entry, else runtime/pipeline_state.py, the function the build writes it with). The ubershader reads
a material's alpha mode and coverage values from its MaterialEntry (link/uber.py) and is drawn with the object's
render state: one ubershader pipeline per distinct (cull, blend, depth) state, and per variant with
uber_ids="specialization"; it adds a material's emission too. Vertex colours are the specialized shaders' only.
Pipelines are created through
a persisted pipeline cache (runtime/pipeline_cache.py), and when the render opens its own device,
Mesa's shader disk cache lives in out/shader_cache and the driver's hit and miss counts go into the
report (runtime/shader_cache.py).
"""
from __future__ import annotations

import json
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .placement import load_placement, make_mesh
from ..link.faces import FACE_MATRICES, faced, shadow_layers
from .shadow_pass import MOMENTS, PCF_TEXEL, SHADOW_SIZE, face_values, moments_map, shadow_textures  # noqa: F401

MODES = ("specialized", "ubershader", "hybrid")


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
    pipeline_cache_hits: int = 0  # the driver's creation feedback (VkPipelineCache; 0 on lavapipe)
    # Mesa's shader disk cache under out/shader_cache, as the driver counts it (runtime/shader_cache.py);
    # None when this render did not open the device or the driver reports no statistics
    shader_cache_hits: int | None = None
    shader_cache_misses: int | None = None
    cache_problem: str = ""
    placement: str = ""  # the placement file read, or "row" (the fallback)
    # per shadowed light: size, gpu_ms of its depth pass, how it is sampled ("depth" | "r32_copy"), its matrix
    shadow_maps: dict = field(default_factory=dict)
    # per drawn material and texture: the artifact drawn (path, levels) and its row of the manifest's samplers
    textures: dict = field(default_factory=dict)
    texture_notes: list[str] = field(default_factory=list)  # what the device clamped of a sampler state
    validation: bool = False  # whether the Khronos validation layer was on
    validation_messages: list[str] = field(default_factory=list)  # what the layer said during this render
    # per shadowed light whose map misses casters it may light (shadow_pass.uncovered): a located warning
    shadow_warnings: list[str] = field(default_factory=list)

    def as_dict(self) -> dict:
        from dataclasses import asdict
        return asdict(self)


def _textures(device, lib=None):
    """The renderer's own images: a lit (depth 1) stand-in shadow map and moments map (E[d] = E[d²] = 1; bound
    where an ubershader shadow slot is unused by a draw's lights), the baked table of a texture a brick declares
    as a table (reference/tables.py), and a linear grey 0.5 for any other name (an ubershader texture the drawn
    material does not bind). Material textures are the build's (runtime/material_textures.py)."""
    shadow = np.ones((4, 4, 4), np.float32)
    grey = np.full((1, 1, 4), 0.5, np.float32)
    return _TestTextures({"shadow_map": device.image(shadow), "shadow_moments": device.image(shadow)},
                         lambda: device.image(grey), _table_images(device, lib))


def _table_images(device, lib) -> dict:
    """{texture name: a function making its image} for every texture a brick of `lib` declares as a table."""
    from ..reference.tables import baked
    tables = lib.tables() if lib is not None else {}
    return {name: (lambda d=d: device.image(baked(d["table"], d["size"], d["format"]))) for name, d in tables.items()}


class _TestTextures(dict):
    """The renderer's own textures by brick texture name: a baked table where a brick declares one, else a
    shadow stand-in; a name with neither gets a linear 0.5 grey."""

    def __init__(self, known, make_grey, tables=None):
        super().__init__(known)
        self._make_grey = make_grey
        self._tables = tables or {}

    def __missing__(self, name):
        self[name] = self._tables[name]() if name in self._tables else self._make_grey()
        return self[name]

    def destroy(self) -> None:
        for image in self.values():
            image.destroy()


# ------------------------------------------------------------------ shadows

def _override_lights(raw: bytes, slots, lights: list[str], matrices: dict, texels: dict | None = None) -> bytes:
    """A specialized Lights block with each shadowed light's l<i>_shadow_matrix slot replaced (and its
    l<i>_pcf_texel, for the lights in `texels`)."""
    from ..link.interface import put

    data = np.frombuffer(raw, np.float32).copy()
    for s in slots:
        if s.param in FACE_MATRICES and s.light is not None and lights[s.light] in matrices:
            put(data, s, np.asarray(face_values(matrices[lights[s.light]])[s.param], np.float32))
        if s.param == PCF_TEXEL and s.light is not None and lights[s.light] in (texels or {}):
            put(data, s, texels[lights[s.light]])
    return data.tobytes()


def render_scene(scene, lib, mode: str, frames: int, out, size=(256, 160), language: str = "glsl",
                 device=None, progress: bool = False, uber_ids: str = "buffer", shadow_size: int = SHADOW_SIZE,
                 placement_file=None, build=None, export=None, environments=None) -> Report:
    """Render `frames` frames of `scene` into out/frame_NNNN.png; returns the report (also out/report.json).

    uber_ids: "buffer" (the variant read from the material entry: one ubershader pipeline) or
    "specialization" (the variant as specialization constant 0: one ubershader pipeline per material
    variant from the one module; WGSL: naga resolves the override per pipeline).
    shadow_size: the side of every light's shadow map (depth pass), in texels.
    placement_file: the placement to use (default: the scene's SCENE.placement.toml if present, else the row).
    build: the build whose texture artifacts the materials draw (a folder holding its manifest.json, or a
    runtime.material_textures.BuildOutputs); needed where a drawn material binds textures. The render state of
    a permutation its manifest lists is read from there too.
    export: a folder to write the frame export into (runtime/frame_export.py: meshes, object matrices, camera,
    the shadowed lights' matrices, as this render used them).
    environments: the scene's baked environments (runtime/environment.EnvironmentInputs, what
    assemble.environments.bake makes): needed where a light set has an environment (image-based lighting).
    """
    from ..link.values import entry_bytes, light_entry, uploads
    from ..compose import compose_permutation
    from ..compose.uber import compose_ubershader
    from ..io import atomic_write
    from ..lang.errors import UserError
    from ..toolchain import CompileJob, compile_many
    from . import graphics as gx
    from .device import Device, validation_requested
    from ..link.uber import ALPHA_IDS, EMISSIVE_IDS, SPEC_VARIANT
    from ..spec.resolve import resolve
    from .pipeline_cache import PipelineCacheFile
    from .depth_images import ComparisonSampler, DepthImage
    from . import shader_cache
    from ..compose.depth import compose_depth_units
    from ..link import link_permutation
    from ..link.values import light_buffers as pair_buffers
    from ..link.tiles import TILES_BLOCK
    from . import light_tiles
    from .depth_passes import Caster, DepthPasses, mask_interface, mask_resources
    from .material_textures import BuildOutputs, MaterialTextures
    from .pipeline_state import COLOR_FORMATS, clear_color, color_attachment, render_state
    from .shadow_pass import (VULKAN_CONVENTIONS, ShadowProblem, caster_points, casters as casters_of, depth_pass,
                              depth_plan, fit_lights, light_where, pass_units, shadowed_lights)

    if mode not in MODES:
        raise UserError(f"unknown mode {mode!r} — use one of {', '.join(MODES)}")
    if not (isinstance(shadow_size, int) and 1 <= shadow_size <= 8192):
        raise UserError(f"shadow map size {shadow_size!r} — use a whole number of texels from 1 to 8192")
    out = Path(out)
    if build is not None and not isinstance(build, BuildOutputs):
        build = BuildOutputs.read(build)
    if out.exists() and not out.is_dir():
        raise UserError(f"{out} is a file — give --out a directory")
    if export is not None and Path(export).exists() and not Path(export).is_dir():
        raise UserError(f"{export} is a file — give --export a directory")
    placed = load_placement(scene, placement_file)
    out.mkdir(parents=True, exist_ok=True)
    W, H = size
    perms = dict(sorted(scene.permutations.items()))
    resolved = {h: resolve(p, lib) for h, p in perms.items()}
    linked = {h: link_permutation(r, lib) for h, r in resolved.items()}
    composed = {h: compose_permutation(lp, lib, (language,)) for h, lp in linked.items()}
    spec_ids = uber_ids == "specialization"
    # the ubershader does not draw environments yet (link/uber.py refuses them, located): a specialized render of a
    # scene with one composes none
    uber, u = None, None
    if mode != "specialized" or not any(p.environment for p in perms.values()):
        uber, u = compose_ubershader(list(perms.values()), lib, (language,), specialized=spec_ids)
    # The depth passes' units (compose/depth.py): what the build writes for an engine, compiled here with the rest.
    shadowed_textures = shadowed_lights(scene, resolved.values())
    plan = depth_plan(shadowed_textures, linked)
    depth_units = compose_depth_units(plan, lib, (language,))
    jobs = {}
    for tag, c in [*composed.items(), *([("ubershader", uber)] if uber is not None else []), *depth_units.items()]:
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

    # Shadowed lights (their filter samples a texture) and their matrices, fitted to the placed objects.
    light_vals = {ln: {k: L.params.get(k, sp.default) for k, sp in _light_specs(lib, L).items()}
                  for ln, L in scene.lights.items()}
    sampled = shadow_textures(resolved.values())  # a used light's filter is among them
    shadowed = list(shadowed_textures)
    # each light's casters (the objects of its light sets) and its matrix fitted to their bounds
    cast_by = {ln: casters_of(scene, ln) for ln in shadowed}
    matrices, shadow_warnings = fit_lights(scene, placed, light_vals, cast_by)
    for ln in shadowed:
        light_vals[ln].update(face_values(matrices[ln]))  # a point light's six faces' (link/faces.py)
    # pcf's tap spacing: one texel of the map this render makes, unless the scene says otherwise
    texels = {ln: 1.0 / shadow_size for ln in shadowed
              if PCF_TEXEL in light_vals[ln] and PCF_TEXEL not in scene.lights[ln].params}
    for ln, v in texels.items():
        light_vals[ln][PCF_TEXEL] = v
    # what the build writes as each light's depth_pass, for the Vulkan platform and this render's map size
    passes_of = {ln: depth_pass(scene.lights[ln], shadowed_textures[ln], light_vals[ln],
                                pass_units(plan, MOMENTS in shadowed_textures[ln]), [], shadow_size,
                                {"vulkan": VULKAN_CONVENTIONS}) for ln in shadowed}

    own_device = device is None
    if own_device:  # lavapipe's compiled shaders persist under out/, and the driver counts its hits
        with shader_cache.opened(out / "shader_cache"):
            device = Device(validation=validation_requested())
    first_message = len(device.messages)
    owned = []
    report = Report(mode, language, (W, H), placement=str(placed.source) if placed.source else "row",
                    shadow_warnings=shadow_warnings)
    try:
        cache = PipelineCacheFile(device, out / f"pipeline_cache.{language}.bin")
        report.cache_problem = cache.problem
        attachment = color_attachment(lib, perms.values())
        target = gx.OffscreenTarget(device, W, H, color_format=COLOR_FORMATS[attachment])
        clear = clear_color(attachment)
        owned += [target, cache]
        # by name (sphere, plane, box) or by object (a glTF primitive's mesh, maybe instanced), and whether the
        # model matrix mirrors it (then uploaded with its winding reversed: front faces stay counter-clockwise
        # for the back-face culling of single-sided materials and for gl_FrontFacing)
        meshes, cpu_meshes = {}, {}
        key_of = [(o.mesh if isinstance(o.mesh, str) else id(o.mesh), o.mirrored) for o in placed.objects]
        for o, key in zip(placed.objects, key_of):
            if key not in meshes:
                cpu_meshes[key] = make_mesh(o.mesh, o.mirrored)
                meshes[key] = gx.GpuMesh(device, cpu_meshes[key])
                owned.append(meshes[key])
        mesh_of = [meshes[k] for k in key_of]
        # One bilinear sampler for every texture, shadow maps included: the one tap of the shadow brick then
        # compares against depth averaged over 2×2 texels, which with one bias is what keeps a point
        # light's perspective map free of acne here (a nearest sampler acnes: docs/design/runtime.md, "The renderer").
        textures, sampler = _textures(device, lib), device.sampler()
        owned += [textures, sampler]
        # the materials' own textures: the build's artifacts with their mips and samplers
        mtex = MaterialTextures(device, build, {m: getattr(scene.materials[m], "images", None) or {}
                                                for m in sorted({o["material"] for o in scene.objects})})
        owned.append(mtex)
        # the environments' radiance cubes and the lit BRDFs' AmbientBRDF tables (runtime/environment.py)
        from .environment import EnvironmentTextures
        etex = EnvironmentTextures(device, environments, scene)
        owned.append(etex)
        env_values = environments.values() if environments is not None else None

        def material_texture(t, material):
            """(image, sampler) of material texture t: the build's artifact and its sampler where the material
            binds one, else the renderer's own (a baked table, grey; a lit depth image if compared)."""
            if t.compare:
                return depth_compared(None), sampler_of(t)
            if mtex.row(material, t.param) is not None:
                return mtex.image(material, t.param), mtex.sampler(material, t.param)
            return textures[t.param], mtex.table_sampler(t.param) or sampler  # a table: the state its row names
        vk = device.vk
        U, S = vk.VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, vk.VK_BUFFER_USAGE_STORAGE_BUFFER_BIT

        def buf(raw, usage):
            raw = np.frombuffer(bytes(raw), np.uint8) if isinstance(raw, (bytes, bytearray)) else np.asarray(raw)
            b = device.buffer(raw.nbytes, usage)
            b.write(raw)
            owned.append(b)
            return b

        def make_pipeline(tag, iface, variant=None, state=None):
            t0 = time.perf_counter()
            frag, spec = spv[(tag, "frag")], None
            if variant is not None:
                if language == "wgsl":
                    frag = spv[(f"{tag}{variant}", "frag")]
                else:
                    spec = {SPEC_VARIANT: variant}
            p = gx.GraphicsPipeline(device, target, spv[(tag, "vert")], frag, iface.vertex_inputs,
                                    gx.layouts_from_interface(iface), cache=cache, specialization=spec,
                                    render_state=state or states.get(tag))  # the ubershader: the drawn object's
            owned.append(p)  # released whatever happens next (list.append is atomic: the worker may call this)
            report.pipeline_create_ms.append((time.perf_counter() - t0) * 1e3)
            report.pipelines_created += 1
            report.pipeline_cache_hits += p.cache_hit  # the driver's creation feedback
            return p

        object_bufs = [buf(gx.object_bytes(o.model), U) for o in placed.objects]
        # Each permutation's pipeline state is the manifest's render_state: the build's entry where a build is
        # given that lists it, else the same function's value (runtime/pipeline_state.py, what the build writes):
        # back faces culled for a single-sided surface (TOML or glTF), blending and no depth write for blend.
        entries = (build.manifest.get("permutations") or []) if build is not None else []
        listed = {e.get("hash"): e["render_state"] for e in entries
                  if isinstance(e, dict) and isinstance(e.get("render_state"), dict)}
        states = {h: listed.get(h) or render_state(p.surface) for h, p in perms.items()}

        # Depth passes: every object drawn from each shadowed light by the generated depth units, as its
        # depth_pass description says (runtime/depth_passes.py).
        shadow_maps, moments, face_maps = {}, {}, {}
        if shadowed:
            passes = DepthPasses(device, spv, {n: c.interface for n, c in depth_units.items()}, owned, cache)
            casters = []
            for i, obj in enumerate(scene.objects):
                h, res = obj["permutation"], {}
                if h in plan.masked:  # its material's Material block and coverage texture, as its colour pass binds them
                    up = next(x for x in uploads(scene, h, composed[h], environments=env_values) if x["material"] == obj["material"])
                    mi = mask_interface(depth_units, h)
                    bound = {t.param: material_texture(t, obj["material"]) for t in mi.textures}
                    res = mask_resources(mi, buf(bytes.fromhex(up["Material"]), U),
                                         {n: im for n, (im, _) in bound.items()}, sampler)
                    for t in mi.textures:  # each coverage texture with its own sampler
                        res[(t.set, t.binding + 1)] = bound[t.param][1]
                casters.append(Caster(mesh_of[i], object_bufs[i], h, res))
            for ln in shadowed:
                desc = passes_of[ln]
                try:  # a point light's six faces, each drawn as one map and copied into its layer
                    drawn = passes.draw_layers(desc, list(face_values(matrices[ln]).values()),
                                               np.append(caster_points(placed, cast_by[ln]).mean(0), 1.0),
                                               [casters[i] for i in cast_by[ln]])
                except ShadowProblem as e:  # what the device cannot draw for this light's filter
                    raise light_where(scene, ln).error(f"light '{ln}': {e.message}", e.hint) from None
                if drawn.depth is not None:
                    shadow_maps[ln] = drawn.depth
                if drawn.moments is not None:
                    moments[ln] = drawn.moments
                # each layer's own map, for a buffer light's pair array (pair_array)
                face_maps[ln] = [d.blurred.image if d.blurred is not None else d.depth for d in drawn.faces or [drawn]]
                report.shadow_maps[ln] = {"size": desc["size"], "gpu_ms": drawn.gpu_ms,
                                          "sampled": drawn.depth.sampled if drawn.depth is not None else "moments",
                                          "pipeline_ms": drawn.pipeline_ms, "depth_units": drawn.units,
                                          "shadow_matrix": matrices[ln], "layers": len(drawn.faces) or 1}

        eye, vp = placed.camera(W, H)
        variant = {v.key: k for k, v in enumerate(u.variants)} if u is not None else {}
        draws = []
        materials = sorted({o["material"] for o in scene.objects})
        light_buffers, slot_lights = {}, {}
        if uber is not None:  # the ubershader's MaterialEntry and LightEntry buffers
            mat_rows, mat_ids = [], []
            for name in materials:  # MaterialEntry m: the variant and the material's specialized Material block
                obj = next(o for o in scene.objects if o["material"] == name)
                p = perms[obj["permutation"]]
                up = next(x for x in uploads(scene, obj["permutation"], composed[obj["permutation"]], environments=env_values)
                          if x["material"] == name)
                data = np.zeros((u.material_vec4s, 4), np.float32)
                block = np.frombuffer(bytes.fromhex(up.get("Material", "")), np.float32).reshape(-1, 4)
                k = variant[(p.brdf, p.packing, p.output)]
                n = max([0] + [s.index + s.width for s in u.variants[k].slots])  # the bricks' part: the surface's
                data[:n] = block[:n]  # values come after it, and the ubershader reads them from data[surface_at]
                if u.surface_at is not None:
                    at = {s.param: s for s in composed[obj["permutation"]].material if s.light is None}
                    data[u.surface_at, :2] = [block[at[x].index, at[x].component] if x in at else 0.0
                                              for x in ("base_alpha", "alpha_cutoff")]
                    if "emissive" in at:  # and the emission after them (a vec3: three components of its vec4)
                        e = at["emissive"]
                        data[u.surface_at + 1, :3] = block[e.index, e.component:e.component + 3]
                mat_ids.append((k, ALPHA_IDS[p.surface.alpha], EMISSIVE_IDS[p.surface.emissive], 0))
                mat_rows.append(data)
            material_buffer = buf(entry_bytes(np.array(mat_ids), np.stack(mat_rows)), S)
            for set_name, names in scene.light_sets.items():
                ids, rows, shadow_slot = [], [], 0
                slot_lights[set_name] = []  # ubershader shadow-map slot j -> the light whose map it is
                dyn, pair_slot, layer_of = scene.dynamic_sets.get(set_name), {}, {}
                for ln in names:
                    L = scene.lights[ln]
                    data = light_entry(u, L.type, L.shadow, light_vals[ln])
                    textured = bool(sampled[L.shadow])
                    slot, first = shadow_slot, 0
                    if textured and dyn is not None:  # a buffer pair's lights share its array: one slot, their layers
                        pair = dyn.pair_of(L)
                        if pair not in pair_slot:
                            pair_slot[pair] = shadow_slot
                            slot_lights[set_name].append(("pair", pair))
                            shadow_slot += 1
                        slot, first = pair_slot[pair], layer_of.get(pair, 0)
                        layer_of[pair] = first + shadow_layers(L.type)
                    elif textured:
                        slot_lights[set_name].append(ln)
                        shadow_slot += 1
                    # ids.w: faces (1: a point light's six) + 2 × its first layer (link/uber.py)
                    ids.append((u.light_types.index(L.type), u.shadows.index(L.shadow), slot if textured else 0,
                                int(faced(L.type, sampled[L.shadow])) + 2 * first))
                    rows.append(data)
                if rows:
                    light_buffers[set_name] = buf(entry_bytes(np.array(ids), np.stack(rows)), S)

        def empty_lights():  # a light set with no lights: one all-zero entry (a light of colour 0; a storage
            # buffer range cannot be empty)
            if "empty" not in light_buffers:
                light_buffers["empty"] = buf(np.zeros((1, 1 + u.light_vec4s, 4), np.float32), S)
            return light_buffers["empty"]

        def light_texture(t, light_name):
            """A light's texture: its depth pass's map (or its moments), or the lit stand-in."""
            if t.param == MOMENTS and light_name in moments:
                return moments[light_name]
            if t.compare:  # a depth image for a comparison sampler: the depth pass's own, or a lit (1.0) one
                return depth_compared(shadow_maps.get(light_name), light_name)
            return shadow_maps[light_name] if light_name in shadow_maps else textures[t.param]

        pair_arrays = {}  # (dynamic set, pair index, texture) -> its lights' maps, in the layers of one array

        def pair_array(set_name, i, t):
            """The shadow array of pair i of dynamic set `set_name` that texture t reads: its lights' layers (one, or
            a point light's six), in the set's order of them (link/values.py writes each one's first layer so)."""
            from .depth_images import LayeredImage

            key = (set_name, i, t.param)
            dyn = scene.dynamic_sets[set_name]
            if t.param not in sampled.get(dyn.model[i].shadow, {}):  # an ubershader slot's texture of another filter
                return stand_in(t)
            if key not in pair_arrays:
                names = [ln for ln in scene.light_sets[set_name] if dyn.pair_of(scene.lights[ln]) == i]
                layers = [m for ln in names for m in face_maps.get(ln, [])]
                if t.compare and layers:
                    depth_compared(layers[0], names[0])  # refused where the device cannot compare D32 depth
                pair_arrays[key] = LayeredImage(device, layers) if layers else stand_in(t)
                owned.append(pair_arrays[key])
            return pair_arrays[key]

        def stand_in(t):
            """A light texture no light's depth pass provides: the lit stand-in (a lit depth image if compared)."""
            return as_layers(t, depth_compared(None) if t.compare else textures[t.param], lit=True)

        layered_once = {}  # a 2D map bound where an ubershader's filter reads arrays: a copy as one layer

        def as_layers(t, image, lit=False):
            """`image` as texture t declares it: itself, or (t a 2D array, image one map) a one-layer array of it
            (lit: of its format and size, every texel 1, as the lit stand-ins are)."""
            from .depth_images import LayeredImage

            if t.dim != "2d_array" or getattr(image, "layers", 1) > 1 or isinstance(image, LayeredImage):
                return image
            if id(image) not in layered_once:
                layered_once[id(image)] = LayeredImage(device, [image], clear=1.0 if lit else None)
                owned.append(layered_once[id(image)])
            return layered_once[id(image)]

        compared = {}  # a texture2d_shadow's sampler and lit stand-in, made on first use

        def sampler_of(t):
            """The sampler bound with texture t: the comparison sampler for a texture2d_shadow."""
            if not t.compare:
                return sampler
            if "sampler" not in compared:
                compared["sampler"] = ComparisonSampler(device)
                owned.append(compared["sampler"])
            return compared["sampler"]

        def depth_compared(dt, light_name=None):
            """What a texture2d_shadow reads: depth target dt (its D32_SFLOAT image), or a lit 1×1 stand-in."""
            if dt is not None:
                if dt.sampled != "depth":
                    raise light_where(scene, light_name).error(
                        f"light '{light_name}': {device.name} cannot linearly filter {dt.depth_format} depth: no "
                        "comparison sampler for a texture2d_shadow (pcf_hardware)", 'use shadow = "pcf"')
                return dt
            if "lit" not in compared:
                compared["lit"] = DepthImage(device, np.ones((1, 1), np.float32))
                owned.append(compared["lit"])
            return compared["lit"]

        frame_buf = buf(gx.frame_bytes(vp, eye), U)
        tile_bufs = {}  # light set -> its LightTiles buffer (the camera is the render's one)
        for i, obj in enumerate(scene.objects):
            h = obj["permutation"]
            c = composed[h]
            frame = frame_buf
            obj_buf = object_bufs[i]
            up = next(x for x in uploads(scene, h, c, environments=env_values) if x["material"] == obj["material"]
                      and x["light_set"] == obj["light_set"])
            spec = {(0, 0): frame, (2, 0): obj_buf}
            lb = c.interface.block("Lights")
            if lb:
                spec[(lb.set, lb.binding)] = buf(_override_lights(bytes.fromhex(up["Lights"]), lb.slots, obj["lights"],
                                                                  matrices, texels), U)
            if c.interface.block("Material"):
                spec[(1, 0)] = buf(bytes.fromhex(up["Material"]), U)
            dyn = scene.dynamic_sets.get(obj["light_set"])
            if dyn is not None and shadowed:  # the fitted matrices of its shadowed lights, in their elements
                fitted = {ln: {**face_values(matrices[ln]), **({PCF_TEXEL: texels[ln]} if ln in texels else {})}
                          for ln in obj["lights"] if ln in matrices}
                up = {**up, "light_buffers": {n: d.hex() for n, d in
                                              pair_buffers(scene, obj["lights"], dyn, c, fitted).items()}}
            for name, data in up.get("light_buffers", {}).items():  # a dynamic set: each pair's lights (link/values.py)
                blk = c.interface.block(name)  # no light of the pair: a range below the stride, a count of 0
                spec[(blk.set, blk.binding)] = buf(bytes.fromhex(data) or bytes(4), S)
            tb = c.interface.block(TILES_BLOCK)
            if tb is not None:  # a tiled set: its lights culled against the screen's tiles (runtime/light_tiles.py)
                if obj["light_set"] not in tile_bufs:
                    lists = light_tiles.cull(lib, scene, obj["lights"], dyn, vp, (W, H))
                    tile_bufs[obj["light_set"]] = buf(light_tiles.tile_words(lists, (W, H)).tobytes(), S)
                spec[(tb.set, tb.binding)] = tile_bufs[obj["light_set"]]
            for t in c.interface.textures:
                if t.environment and t.group == "light":  # the light set's environment's radiance cube
                    res, smp = etex.radiance(obj["light_set"])
                elif t.environment:  # the material's BRDF's AmbientBRDF table
                    res, smp = etex.table(scene.materials[obj["material"]].brdf, sampler)
                elif t.group == "light" and dyn is not None:  # a buffer light's pair: one array of its lights' maps
                    res, smp = pair_array(obj["light_set"], t.light, t), sampler_of(t)
                elif t.group == "light":
                    res, smp = light_texture(t, obj["lights"][t.light]), sampler_of(t)
                else:
                    mtex.check_binding(obj["material"], t)
                    res, smp = material_texture(t, obj["material"])
                spec[(t.set, t.binding)], spec[(t.set, t.binding + 1)] = res, smp
            ub = None
            if uber is not None:
                ub = {(0, 0): frame, (2, 0): obj_buf,
                      (1, 0): buf(np.array([materials.index(obj["material"]), 0, 0, 0], np.int32), U),
                      (1, 1): material_buffer}
                lbuf = uber.interface.block("LightBuffer")
                if lbuf is not None:  # a scene without lights has an ubershader without a light buffer
                    ub[(lbuf.set, lbuf.binding)] = light_buffers.get(obj["light_set"]) or empty_lights()
                for t in uber.interface.textures:  # the draw's material's textures and samplers, as the specialized path's
                    if t.group == "light":
                        slots = slot_lights[obj["light_set"]]
                        if t.light >= len(slots):
                            res = stand_in(t)
                        elif isinstance(slots[t.light], tuple):  # a dynamic set's pair: its one array
                            res = pair_array(obj["light_set"], slots[t.light][1], t)
                        else:
                            res = as_layers(t, light_texture(t, slots[t.light]))
                        smp = sampler_of(t)
                    else:
                        mtex.check_binding(obj["material"], t, ubershader=True)
                        res, smp = material_texture(t, obj["material"])
                    ub[(t.set, t.binding)], ub[(t.set, t.binding + 1)] = res, smp
            draws.append((h, spec, ub, mesh_of[i]))
        report.textures, report.texture_notes = mtex.report(), list(mtex.notes)

        # blended surfaces after the opaque ones, back to front (draw_order), in scene order otherwise
        blended_last = draw_order(placed, vp, [perms[d[0]].surface.alpha == "blend" for d in draws])
        draws = [draws[i] for i in blended_last]
        frame_export = None
        if export is not None:  # written once the frames are drawn: a failed render leaves the last export alone
            from .frame_export import FrameExport, placed_meshes
            frame_export = FrameExport(scene.name, (W, H), attachment, clear, eye, gx.column_major(vp),
                                       *placed_meshes(placed.objects, key_of, cpu_meshes), draw_order=blended_last,
                                       lights={ln: {"shadow_matrix": face_values(matrices[ln])["shadow_matrix"],
                                                    "faces": matrices[ln] if "faces" in passes_of[ln] else None,
                                                    "pcf_texel": texels.get(ln),
                                                    "size": passes_of[ln]["size"],
                                                    "eye": caster_points(placed, cast_by[ln]).mean(0),
                                                    "casters": cast_by[ln]}
                                               for ln in shadowed})
        specialized: dict[str, object] = {}
        order = list(dict.fromkeys(h for h, _, _, _ in draws))  # first use
        start = time.perf_counter()
        # the ubershader's pipelines: one per (variant, when it is a specialization constant) and distinct render
        # state of the objects drawn (few: cull back or none, blended or not), each object's its permutation's
        uber_pipes = {}
        state_key = {h: json.dumps({k: states[h][k] for k in ("blend", "cull", "depth")}, sort_keys=True)
                     for h in perms}  # what a pipeline holds (a mask's alpha mode and cutoff are the shader's)
        uber_of = {h: (variant[(perms[h].brdf, perms[h].packing, perms[h].output)] if spec_ids else None, state_key[h])
                   for h in perms}
        if mode != "specialized":
            for h in order:
                if uber_of[h] not in uber_pipes:
                    uber_pipes[uber_of[h]] = make_pipeline("ubershader", uber.interface, uber_of[h][0], states[h])
        worker = None
        if mode == "specialized":
            for h in order:
                specialized[h] = make_pipeline(h, composed[h].interface)
        elif mode == "hybrid":
            failed: list[BaseException] = []

            def create():
                try:
                    for h in order:
                        specialized[h] = make_pipeline(h, composed[h].interface)
                except BaseException as e:  # re-raised on the main thread after join()
                    failed.append(e)
            worker = threading.Thread(target=create, name="pipelines", daemon=True)
            worker.start()

        def draw_frame(index: int | None) -> Frame:
            t0 = time.perf_counter()
            items, nu, ns = [], 0, 0
            for h, spec, ub, mesh in draws:
                pipe = specialized.get(h) if mode != "ubershader" else None
                if pipe is not None:
                    items.append(gx.DrawItem(pipe, mesh, spec))
                    ns += 1
                else:
                    items.append(gx.DrawItem(uber_pipes[uber_of[h]], mesh, ub))
                    nu += 1
            gpu = target.draw(items, clear=clear)
            image = target.read()
            if index == 0:  # drawn and read back; writing the PNG is not part of it
                report.time_to_first_frame_ms = (time.perf_counter() - start) * 1e3
            if index is not None:
                gx.save_png(image, out / f"frame_{index:04d}.png")
            return Frame((time.perf_counter() - t0) * 1e3, gpu, nu, ns)

        try:
            for f in range(frames):
                report.frames.append(draw_frame(f))
                if progress:
                    print(f"\rframe {f + 1}/{frames}", end="", flush=True)
            if progress:
                print()
        finally:
            if worker is not None:
                worker.join()
        if worker is not None and failed:
            raise failed[0]
        report.steady = draw_frame(None)
        cache.save()
        if frame_export is not None:
            from .frame_export import write_export
            write_export(export, frame_export)
    finally:
        for obj in reversed(owned):
            obj.destroy()
        if own_device:
            stats = shader_cache.closed(device.close)
            if stats is not None:
                report.shader_cache_hits, report.shader_cache_misses = stats
        report.validation = bool(device.validation)
        report.validation_messages = [str(m) for m in device.messages[first_message:]]
    atomic_write(out / "report.json", (json.dumps(report.as_dict(), indent=2) + "\n").encode())
    return report


def draw_order(placed, view_proj, blended: list[bool]) -> list[int]:
    """The objects' draw order: the opaque (and masked) ones first, in scene order, then the blended ones back to
    front — by the view depth of their world-space bounding box's centre (its distance along the camera's forward:
    the clip-space w of view_proj × centre, for the renderer's perspective cameras), farthest first, ties in scene
    order. Source-over blending then composes a nearer surface over a farther one wherever their boxes'
    centres are ordered as the surfaces are (not for interpenetrating surfaces: no per-fragment sorting)."""
    def depth(i):
        corners = placed.objects[i].corners()
        centre = 0.5 * (corners.min(0) + corners.max(0))
        return float((np.asarray(view_proj, np.float64) @ np.append(centre, 1.0))[3])
    opaque = [i for i, b in enumerate(blended) if not b]
    return opaque + sorted((i for i, b in enumerate(blended) if b), key=lambda i: -depth(i))


def _light_specs(lib, light) -> dict:
    from ..spec.resolve import light_params

    return light_params(lib, light.type, light.shadow)
