"""The offscreen graphics renderer: meshes, PNGs, and real permutations drawn on lavapipe.

The generator's own vertex and fragment shaders (compose_permutation) and its fragment
ubershader (compose_ubershader) are compiled by the real toolchain and drawn through
generator/runtime/graphics.py under the validation layer, 64×64.

Agreement measured on lavapipe (Mesa 25.0.7, LLVM 15.0.6), R8G8B8A8_UNORM, every pixel of
every channel (scenes below: a Blinn-Phong sphere under a point light; two spheres, one
with an sRGB albedo texture and a tangent-space normal map, one with constants):

- the specialized permutation in GLSL, HLSL and WGSL: identical images (max difference 0);
- the ubershader (material and light from storage buffers, material index from the Draw
  block) against the specialized shaders: identical images (max difference 0), in all three
  languages, also with two material variants drawn in one frame, and for the
  specialization-constant ubershader (one pipeline per variant: SpecId 0 in GLSL/HLSL,
  naga's override in WGSL).

The stated tolerance is TOL_LSB = 1 (8-bit codes), with at most 1 % of the channels allowed
to be off by it: the compute stand-ins agree to 2 float32 ulp (tests/runtime/test_uber.py), and a
difference that small can still cross a rounding boundary of the UNORM conversion.
"""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from generator.runtime.meshes import box, plane, uv_sphere
from tests.lavapipe import device, no_validation_messages  # noqa: F401 (fixtures)

LANGS = ("glsl", "hlsl", "wgsl")
W = H = 64
CLEAR = (0.1, 0.2, 0.3, 1.0)
TOL_LSB = 1
C = "constants(normal=vertex)"
TEX = "albedo_texture(normal=normal_map)"
BRDF = "lambert+blinn_phong_normalized"
LIGHT = {"position": [3.0, 1.0, 2.0], "color": [8.0, 8.0, 8.0]}
MATERIALS = {C: {"m_rho_d": [0.6, 0.4, 0.3], "m_n": 32.0}, TEX: {"m_rho_d": [0.9, 0.9, 0.9], "m_n": 16.0}}

gpu_marks = [pytest.mark.lavapipe, pytest.mark.toolchain]


# ------------------------------------------------------------------ meshes (NumPy only)

def _uv_frame_check(m):
    """Per triangle: the tangent follows +u and cross(N, T) * w follows +v (the templates' B)."""
    p, uv, idx = m.positions.astype(np.float64), m.uvs.astype(np.float64), m.indices.reshape(-1, 3)
    e1, e2 = p[idx[:, 1]] - p[idx[:, 0]], p[idx[:, 2]] - p[idx[:, 0]]
    d1, d2 = uv[idx[:, 1]] - uv[idx[:, 0]], uv[idx[:, 2]] - uv[idx[:, 0]]
    det = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
    dpdu = (e1 * d2[:, 1:2] - e2 * d1[:, 1:2]) / det[:, None]
    dpdv = (e2 * d1[:, 0:1] - e1 * d2[:, 0:1]) / det[:, None]
    t = m.tangents[idx].mean(1)
    n = m.normals[idx].mean(1)
    b = np.cross(n, t[:, :3]) * t[:, 3:4]
    # near the poles ∂P/∂u shrinks to 0: compare directions where it is well defined
    ok = np.linalg.norm(dpdu, axis=1) > 1e-3
    assert (np.einsum("ij,ij->i", dpdu[ok], t[ok, :3]) > 0).all()
    assert (np.einsum("ij,ij->i", dpdv, b) > 0).all()


@pytest.mark.parametrize("make", [lambda: uv_sphere(12, 24, radius=2.0), lambda: plane(3.0, 4, height=-1.0),
                                  lambda: box(), lambda: box((1.0, 0.5, 3.0))],
                         ids=["sphere", "plane", "box", "box-non-uniform"])
def test_meshes_are_deterministic_float32_with_unit_frames_and_outward_winding(make):
    m = make()
    assert all(a.dtype == np.float32 and a.flags.c_contiguous for a in m.attributes().values())
    assert m.indices.dtype == np.uint32 and m.index_count % 3 == 0 and int(m.indices.max()) < m.vertex_count
    assert m.positions.shape == m.normals.shape == (m.vertex_count, 3)
    assert m.tangents.shape == (m.vertex_count, 4) and m.uvs.shape == (m.vertex_count, 2)
    assert m.interleaved().shape == (m.vertex_count, 12)
    again = make()
    assert all(np.array_equal(a, b) for a, b in zip(m.attributes().values(), again.attributes().values()))
    assert np.array_equal(m.indices, again.indices)
    np.testing.assert_allclose(np.linalg.norm(m.normals, axis=1), 1.0, atol=1e-6)
    np.testing.assert_allclose(np.linalg.norm(m.tangents[:, :3], axis=1), 1.0, atol=1e-6)
    np.testing.assert_allclose(np.einsum("ij,ij->i", m.normals, m.tangents[:, :3]), 0.0, atol=1e-6)
    assert set(np.unique(m.tangents[:, 3])) <= {-1.0, 1.0}
    assert m.uvs.min() >= 0.0 and m.uvs.max() <= 1.0
    p = m.positions[m.indices.reshape(-1, 3)].astype(np.float64)
    face = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    n = m.normals[m.indices.reshape(-1, 3)].mean(1)
    assert (np.einsum("ij,ij->i", face, n) > 0).all(), "every triangle counter-clockwise seen from outside"
    _uv_frame_check(m)


def test_sphere_positions_lie_on_the_sphere_along_their_normals():
    m = uv_sphere(8, 16, radius=1.5)
    np.testing.assert_allclose(m.positions, 1.5 * m.normals, atol=1e-6)
    assert m.index_count == 3 * 2 * 16 * (8 - 1)
    with pytest.raises(ValueError):
        uv_sphere(1, 16)


def test_the_box_spans_its_size_with_flat_faces():
    m = box((2.0, 1.0, 4.0))
    assert m.vertex_count == 24 and m.index_count == 36
    np.testing.assert_array_equal(m.positions.min(0), [-1.0, -0.5, -2.0])
    np.testing.assert_array_equal(m.positions.max(0), [1.0, 0.5, 2.0])
    # every vertex lies on the face its normal names
    extent = np.array([1.0, 0.5, 2.0])
    np.testing.assert_allclose(np.einsum("ij,ij->i", m.positions, m.normals), np.abs(m.normals) @ extent)
    assert len(np.unique(m.normals, axis=0)) == 6
    with pytest.raises(ValueError):
        box((1.0, 0.0, 1.0))


def test_save_png_writes_atomically_and_round_trips(tmp_path):
    from PIL import Image

    from generator.runtime.graphics import save_png

    rng = np.random.default_rng(1)
    a = rng.integers(0, 256, (5, 7, 4), dtype=np.uint8)
    path = save_png(a, tmp_path / "x.png")
    assert np.array_equal(np.asarray(Image.open(path)), a)
    b = rng.integers(0, 256, (5, 7, 3), dtype=np.uint8)
    save_png(b, path)  # replaces
    assert np.array_equal(np.asarray(Image.open(path)), b)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["x.png"], "no temporary file left behind"
    with pytest.raises(TypeError):
        save_png(a.astype(np.float32), tmp_path / "y.png")
    assert not (tmp_path / "y.png").exists()


def test_layouts_from_an_interface_put_blocks_and_texture_pairs_at_their_bindings():
    from generator.compose import compose_permutation
    from generator.compose.uber import compose_ubershader
    from generator.library.bricks import load_library
    from generator.spec.permutation import LightKey, Permutation
    from generator.runtime.graphics import layouts_from_interface, resource_keys

    lib = load_library()
    lights = (LightKey("point", "none"),)
    c = compose_permutation(Permutation(BRDF, lights, TEX), lib, ())
    lay = layouts_from_interface(c.interface)
    assert lay == {0: {0: "uniform", 1: "uniform"},
                   1: {0: "uniform", 1: "sampled_image", 2: "sampler", 3: "sampled_image", 4: "sampler"},
                   2: {0: "uniform"}}  # the per-draw Object block
    assert resource_keys(lay)[:3] == [(0, 0), (0, 1), (1, 0)]
    cu, _ = compose_ubershader([Permutation(BRDF, lights, C)], lib, ())
    assert layouts_from_interface(cu.interface) == {0: {0: "uniform", 1: "storage"}, 1: {0: "uniform", 1: "storage"},
                                                    2: {0: "uniform"}}
    clash = SimpleNamespace(blocks=c.interface.blocks, textures=[SimpleNamespace(name="t", set=0, binding=0)])
    with pytest.raises(ValueError, match="set 0 binding 0"):
        layouts_from_interface(clash)


# ------------------------------------------------------------------ on lavapipe

def _values(slots, given):
    return {s.name: given.get(s.name, s.spec.default if s.element is None else s.spec.default[s.element])
            for s in slots}


def _translate_scale(x, s):
    m = np.diag([s, s, s, 1.0])
    m[0, 3] = x
    return m


def _textures(dev):
    """A 16×16 sRGB checker albedo and a 32×32 tangent-space normal map of bumps (uint8, RGB = (t + 1) / 2)."""
    j, i = np.meshgrid(np.arange(16), np.arange(16))
    albedo = np.where(((i // 4 + j // 4) % 2 == 0)[..., None], [230, 200, 120], [90, 140, 200]).astype(np.uint8)
    v, u = np.meshgrid((np.arange(32) + 0.5) / 32, (np.arange(32) + 0.5) / 32, indexing="ij")
    t = np.stack([0.5 * np.sin(2 * np.pi * 4 * u), 0.5 * np.cos(2 * np.pi * 3 * v), np.ones_like(u)], -1)
    t /= np.linalg.norm(t, axis=-1, keepdims=True)
    nmap = np.round((t + 1.0) / 2.0 * 255.0).astype(np.uint8)
    return dev.image(albedo, srgb=True), dev.image(nmap)


@pytest.fixture(scope="module")
def gpu(device):
    """Compiled shaders (specialized and ubershader, three languages), a 64×64 target, meshes, buffers."""
    from generator.compose import compose_permutation
    from generator.compose.uber import compose_ubershader
    from generator.eval.shade import uber_entries
    from generator.library.bricks import load_library
    from generator.link.interface import pack
    from generator.link.uber import SPEC_VARIANT
    from generator.spec.permutation import LightKey, Permutation
    from generator.runtime import graphics as gx
    from generator.toolchain import CompileJob, compile_many

    lib = load_library()
    lights = (LightKey("point", "none"),)
    perms = {C: Permutation(BRDF, lights, C), TEX: Permutation(BRDF, lights, TEX)}
    composed = {f"spec-{k}": compose_permutation(p, lib, LANGS) for k, p in perms.items()}
    ubers = {"uber-1": compose_ubershader([perms[C]], lib, LANGS),
             "uber-2": compose_ubershader([perms[TEX], perms[C]], lib, LANGS),
             "uber-2-spec": compose_ubershader([perms[TEX], perms[C]], lib, LANGS, specialized=True)}
    composed.update({k: c for k, (c, _) in ubers.items()})
    jobs, names = [], {}
    for tag, c in composed.items():
        for s in c.sources:
            # WGSL resolves the variant override when naga translates: one module per variant
            variants = (0, 1) if tag.endswith("-spec") and s.language == "wgsl" and s.stage == "frag" else (None,)
            for v in variants:
                key = f"g{len(jobs)}.{s.stage}.{s.language}"
                names[(tag, s.stage, s.language) + ((v,) if v is not None else ())] = key
                jobs.append(CompileJob(key, s.language, s.stage, s.text, line_map=tuple(map(tuple, s.line_map)),
                                       overrides=(("0", v),) if v is not None else ()))
    res = compile_many(jobs)
    bad = {k: r.errors() for k, r in res.items() if not r.ok}
    assert not bad, bad

    vk = device.vk
    U, S = vk.VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, vk.VK_BUFFER_USAGE_STORAGE_BUFFER_BIT
    owned = []

    def buf(data, usage):
        raw = np.frombuffer(bytes(data), np.uint8) if isinstance(data, (bytes, bytearray)) else data
        b = device.buffer(np.asarray(raw).nbytes, usage)
        b.write(raw)
        owned.append(b)
        return b

    target = gx.OffscreenTarget(device, W, H)
    sphere, floor = gx.GpuMesh(device, uv_sphere(24, 48)), gx.GpuMesh(device, plane(6.0, 1, height=-1.2))
    albedo, nmap = _textures(device)
    sampler = device.sampler()
    owned += [target, sphere, floor, albedo, nmap, sampler]

    def pipeline(tag, lang, variant=None):
        """A pipeline of `tag`; `variant`: the specialization-constant ubershader's material variant
        (SpecId 0 in GLSL/HLSL, the override naga resolved in WGSL)."""
        c = composed[tag]
        frag = names[(tag, "frag", lang) + ((variant,) if variant is not None and lang == "wgsl" else ())]
        spec = {SPEC_VARIANT: variant} if variant is not None and lang != "wgsl" else None
        p = gx.GraphicsPipeline(device, target, res[names[(tag, "vert", lang)]].spirv, res[frag].spirv,
                                c.interface.vertex_inputs, gx.layouts_from_interface(c.interface), specialization=spec)
        owned.append(p)
        return p

    def camera(eye):
        vp = gx.perspective(45.0, W / H, 0.1, 20.0) @ gx.look_at(eye, (0.0, 0.0, 0.0))
        return lambda model: (buf(gx.frame_bytes(vp, eye), U), buf(gx.object_bytes(model), U))  # Frame, Object

    def spec_resources(key, frame, values=None):
        """(set, binding) -> resource of the specialized permutation `key`."""
        c = composed[f"spec-{key}"]
        ls = [s for group in c.lights for s in group]
        lv = {f"l0_{k}": v for k, v in LIGHT.items()}
        out = {(0, 0): frame[0], (2, 0): frame[1],
               (0, 1): buf(pack(ls, _values(ls, lv), c.interface.block("Lights").size // 16), U),
               (1, 0): buf(pack(c.material, _values(c.material, values or MATERIALS[key]),
                                c.interface.block("Material").size // 16), U)}
        for t in c.interface.textures:
            out[(t.set, t.binding)] = albedo if t.param == "albedo_map" else nmap
            out[(t.set, t.binding + 1)] = sampler
        return out

    def uber_buffers(tag, keys):
        """The ubershader `tag`'s LightBuffer and MaterialBuffer (material m = keys[m]) as GPU bytes."""
        c, u = ubers[tag]
        variant = {v.key: k for k, v in enumerate(u.variants)}
        mats = [(variant[(perms[k].brdf, perms[k].packing, perms[k].output)], MATERIALS[k]) for k in keys]
        mat, lts = uber_entries(u, mats, [("point", "none", LIGHT)])

        def entries(e):  # ids as int32 in the first vec4, then the data vec4s (as eval/shade.uber_samples)
            raw = np.zeros((len(e["ids"]), 1 + e["data"].shape[1], 4), np.float32)
            raw[:, 1:, :] = e["data"]
            raw = raw.view(np.uint32)
            raw[:, 0, :] = e["ids"].astype(np.int32).view(np.uint32)
            return raw

        return buf(entries(lts), S), buf(entries(mat), S)

    def uber_resources(tag, frame, lights_buf, materials_buf, material):
        c, _ = ubers[tag]
        out = {(0, 0): frame[0], (2, 0): frame[1], (0, 1): lights_buf, (1, 0): buf(np.array([material, 0, 0, 0], np.int32), U),
               (1, 1): materials_buf}
        for t in c.interface.textures:
            out[(t.set, t.binding)] = albedo if t.param == "albedo_map" else nmap
            out[(t.set, t.binding + 1)] = sampler
        return out

    def frame(items):
        target.draw(items, clear=CLEAR)
        return target.read()

    yield SimpleNamespace(gx=gx, target=target, sphere=sphere, floor=floor, pipeline=pipeline, camera=camera,
                          spec_resources=spec_resources, uber_buffers=uber_buffers, uber_resources=uber_resources,
                          frame=frame, composed=composed, buf=buf, owned=owned,
                          spirv=lambda tag, stage, lang: res[names[(tag, stage, lang)]].spirv)
    for obj in reversed(owned):
        obj.destroy()


def _drain_unconsumed_interpolants(device, locations):
    """Take the validation layer's performance warnings that the vertex shader writes `locations` the fragment
    shader does not read, and only those.

    WGSL's specialization-constant ubershader: naga resolves the variant override while translating, so for
    the constants variant v_tangent and v_uv (locations 2, 3) become dead, and spirv-opt -O (SPIRV-Tools
    2023.1) then drops them from the fragment entry point. Valid Vulkan (an unread vertex output), but a
    warning; the vertex shader, shared by every variant, still writes them.
    """
    keep, seen = [], set()
    for m in device.messages:
        loc = next((x for x in locations if f"output location {x}.0 which is not consumed" in m.text), None)
        if m.id_name == "UNASSIGNED-CoreValidation-Shader-OutputNotConsumed" and loc is not None:
            seen.add(loc)
        else:
            keep.append(m)
    device.messages[:] = keep
    return seen


def _agree(a, b, what):
    d = np.abs(a.astype(np.int32) - b.astype(np.int32))
    assert d.max() <= TOL_LSB and (d > 0).mean() <= 0.01, f"{what}: max {d.max()}, {(d > 0).sum()} channels differ"
    return int(d.max())


def _sphere_mask(eye_z, radius):
    """Pixels whose centre's ray hits a sphere of `radius` at the origin, camera on +z at `eye_z` (45° fov)."""
    t = np.tan(np.radians(45.0) / 2.0)
    x = (2.0 * (np.arange(W) + 0.5) / W - 1.0) * t * (W / H)
    y = -(2.0 * (np.arange(H) + 0.5) / H - 1.0) * t  # image row 0 is the top
    dx, dy = np.meshgrid(x, y)
    d = np.stack([dx, dy, -np.ones_like(dx)], -1)
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    o = np.array([0.0, 0.0, eye_z])
    b = d @ o
    return b * b - (o @ o - radius * radius) >= 0.0


@pytest.mark.lavapipe
@pytest.mark.toolchain
def test_a_specialized_sphere_is_lit_toward_its_light_and_the_three_languages_agree(device, gpu, tmp_path):
    from PIL import Image

    new_frame = gpu.camera((0.0, 0.0, 3.0))
    f = new_frame(np.eye(4))
    images = {}
    for lang in LANGS:
        item = gpu.gx.DrawItem(gpu.pipeline(f"spec-{C}", lang), gpu.sphere, gpu.spec_resources(C, f))
        images[lang] = gpu.frame([item])
        assert gpu.target.gpu_ms is None or gpu.target.gpu_ms > 0.0
    img = images["glsl"]
    clear = np.round(np.array(CLEAR) * 255).astype(np.uint8)
    outside, inside = ~_sphere_mask(3.0, 1.0), _sphere_mask(3.0, 0.98)  # the tessellation lies within r = 1
    assert outside.sum() > 500 and inside.sum() > 2000
    assert (img[outside] == clear).all(), "background pixels are the clear colour"
    assert (img[inside] != clear).any(axis=-1).all(), "the sphere covers its pixels"
    assert img[H // 2, W // 2, :3].min() > 0, "the centre faces the light: lit"
    assert (img[..., 3] == 255).all()
    lum = img[..., :3].astype(np.float64).sum(-1)
    right, left = inside & (np.arange(W) >= W // 2)[None, :], inside & (np.arange(W) < W // 2)[None, :]
    assert lum[right].mean() > 2.0 * lum[left].mean(), "the light is on +x: the right half is brighter"
    assert img[..., :3].max() < 255, "no channel saturates: the comparison sees the shading"
    for lang in LANGS[1:]:
        _agree(images[lang], img, f"{lang} vs glsl")  # measured: identical
    res = gpu.spec_resources(C, f)
    del res[(1, 0)]
    with pytest.raises(ValueError, match=r"no resource for \(set, binding\) \[\(1, 0\)\]"):
        gpu.target.draw([gpu.gx.DrawItem(gpu.pipeline(f"spec-{C}", "glsl"), gpu.sphere, res)])
    path = gpu.gx.save_png(img, tmp_path / "sphere.png")
    assert np.array_equal(np.asarray(Image.open(path)), img)


@pytest.mark.lavapipe
@pytest.mark.toolchain
@pytest.mark.parametrize("lang", LANGS)
def test_the_ubershader_renders_the_sphere_like_the_specialized_shader(device, gpu, lang):
    """The issue's core proof: material and light from storage buffers through the switches, same pixels."""
    f = gpu.camera((0.0, 0.0, 3.0))(np.eye(4))
    spec = gpu.frame([gpu.gx.DrawItem(gpu.pipeline(f"spec-{C}", "glsl"), gpu.sphere, gpu.spec_resources(C, f))])
    lights_buf, materials_buf = gpu.uber_buffers("uber-1", [C])
    uber = gpu.frame([gpu.gx.DrawItem(gpu.pipeline("uber-1", lang), gpu.sphere,
                                      gpu.uber_resources("uber-1", f, lights_buf, materials_buf, 0))])
    assert (uber != np.round(np.array(CLEAR) * 255)).any()
    _agree(uber, spec, f"ubershader ({lang}) vs specialized (glsl)")


@pytest.mark.lavapipe
@pytest.mark.toolchain
def test_two_material_variants_in_one_frame_textured_and_constant_match_their_specialized_shaders(device, gpu):
    """Two draws per frame: a sphere with an sRGB albedo texture and a normal map (tangents, uv) and one with
    constants; specialized pipelines per permutation vs one ubershader pipeline indexing its MaterialBuffer."""
    new_frame = gpu.camera((0.0, 0.0, 3.0))
    fl, fr = new_frame(_translate_scale(-0.55, 0.5)), new_frame(_translate_scale(0.55, 0.5))
    spec = {}
    for lang in LANGS:
        spec[lang] = gpu.frame([
            gpu.gx.DrawItem(gpu.pipeline(f"spec-{TEX}", lang), gpu.sphere, gpu.spec_resources(TEX, fl)),
            gpu.gx.DrawItem(gpu.pipeline(f"spec-{C}", lang), gpu.sphere, gpu.spec_resources(C, fr))])
    for lang in LANGS[1:]:
        _agree(spec[lang], spec["glsl"], f"textured frame, {lang} vs glsl")
    left, right = spec["glsl"][:, : W // 2, :3].astype(int), spec["glsl"][:, W // 2:, :3].astype(int)
    assert len(np.unique(left.reshape(-1, 3), axis=0)) > 100, "the texture and normal map vary the left sphere"
    lights_buf, materials_buf = gpu.uber_buffers("uber-2", [TEX, C])
    for lang in LANGS:
        p = gpu.pipeline("uber-2", lang)
        uber = gpu.frame([
            gpu.gx.DrawItem(p, gpu.sphere, gpu.uber_resources("uber-2", fl, lights_buf, materials_buf, 0)),
            gpu.gx.DrawItem(p, gpu.sphere, gpu.uber_resources("uber-2", fr, lights_buf, materials_buf, 1))])
        _agree(uber, spec["glsl"], f"two-variant ubershader ({lang}) vs specialized (glsl)")
        # the specialization-constant ubershader: one pipeline per variant, the entries as before
        v0, v1 = gpu.pipeline("uber-2-spec", lang, 0), gpu.pipeline("uber-2-spec", lang, 1)
        if lang == "wgsl":
            _drain_unconsumed_interpolants(device, {2, 3})
        uber = gpu.frame([
            gpu.gx.DrawItem(v0, gpu.sphere, gpu.uber_resources("uber-2-spec", fl, lights_buf, materials_buf, 0)),
            gpu.gx.DrawItem(v1, gpu.sphere, gpu.uber_resources("uber-2-spec", fr, lights_buf, materials_buf, 1))])
        _agree(uber, spec["glsl"], f"specialization-constant ubershader ({lang}) vs specialized (glsl)")
    assert right.sum() > 0
    p = gpu.pipeline("uber-2", "glsl")
    swapped = gpu.frame([
        gpu.gx.DrawItem(p, gpu.sphere, gpu.uber_resources("uber-2", fl, lights_buf, materials_buf, 1)),
        gpu.gx.DrawItem(p, gpu.sphere, gpu.uber_resources("uber-2", fr, lights_buf, materials_buf, 0))])
    assert np.abs(swapped.astype(int) - spec["glsl"]).max() > 50, "the comparison sees the material index"


@pytest.mark.lavapipe
@pytest.mark.toolchain
def test_depth_testing_makes_the_draw_order_irrelevant_and_draws_are_timed(device, gpu):
    eye = (0.0, 1.5, 3.5)
    new_frame = gpu.camera(eye)
    f = new_frame(np.eye(4))
    p = gpu.pipeline(f"spec-{C}", "glsl")
    ball = gpu.gx.DrawItem(p, gpu.sphere, gpu.spec_resources(C, f))
    ground = gpu.gx.DrawItem(p, gpu.floor, gpu.spec_resources(C, f, {"m_rho_d": [0.3, 0.3, 0.3], "m_n": 4.0}))
    a = gpu.frame([ball, ground])
    ms = gpu.target.gpu_ms
    b = gpu.frame([ground, ball])
    assert np.array_equal(a, b)
    alone = gpu.frame([ball])
    clear = np.round(np.array(CLEAR) * 255).astype(np.uint8)
    floor_px = (a != clear).any(-1) & (alone == clear).all(-1)
    assert floor_px[H - 4:].all(), "the floor fills the bottom rows"
    assert np.array_equal(a[H // 2, W // 2], alone[H // 2, W // 2]), "the sphere in front of the floor"
    if device.timestamp_bits:
        assert ms is not None and 0.0 < ms < 10_000.0


@pytest.mark.lavapipe
def test_the_renderer_refuses_missing_resources_and_reads_before_drawing(device):
    from generator.runtime import graphics as gx

    target = gx.OffscreenTarget(device, 8, 4)
    try:
        with pytest.raises(RuntimeError, match="before any draw"):
            target.read()
        with pytest.raises(TypeError, match="GraphicsPipeline"):
            target.draw([gx.DrawItem(None, None, {})])
    finally:
        target.destroy()


def test_object_block_carries_the_inverse_transpose_so_normals_survive_non_uniform_scale():
    from generator.runtime import graphics as gx

    model = np.diag([2.0, 0.5, 1.0, 1.0])
    model[:3, 3] = (1.0, -2.0, 0.5)
    raw = np.frombuffer(gx.object_bytes(model), "<f4").reshape(2, 4, 4)  # two column-major mat4
    m, nm = raw[0].T.astype(np.float64), raw[1].T.astype(np.float64)
    np.testing.assert_allclose(m, model, rtol=1e-7)
    mesh = uv_sphere(8, 16)
    n = mesh.normals.astype(np.float64) @ nm[:3, :3].T
    t = mesh.tangents[:, :3].astype(np.float64) @ m[:3, :3].T
    np.testing.assert_allclose(np.sum(n * t, 1), 0.0, atol=1e-6)  # still perpendicular to the surface
    assert np.abs(np.sum((mesh.normals @ m[:3, :3].T) * t, 1)).max() > 0.1  # mat3(model) would not be


# ------------------------------------------------------------------ shadow matrices and the depth pass

def _clip(m, pts):
    p = np.c_[np.asarray(pts, np.float64), np.ones(len(pts))] @ np.asarray(m).T
    return p[:, :3] / p[:, 3:]


def test_a_directional_shadow_matrix_projects_along_the_light_into_vulkan_clip_space():
    from generator.runtime import graphics as gx

    rng = np.random.default_rng(3)
    pts = rng.uniform(-3.0, 3.0, (50, 3))
    for d in ([0.3, 0.9, 0.3], [0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [1.0, 0.2, -0.5]):
        m = gx.directional_shadow_matrix(d, pts)
        p = _clip(m, pts)
        assert (np.abs(p[:, :2]) <= 1.0).all() and (p[:, 2] >= 0.0).all() and (p[:, 2] <= 1.0).all()
        assert np.abs(p[:, :2]).max() > 0.9, "the bounds fill the map (a small margin)"
        u = np.asarray(d, np.float64) / np.linalg.norm(d)
        q = _clip(m, pts + 0.5 * u)  # toward the light: same texel, nearer (smaller depth)
        np.testing.assert_allclose(q[:, :2], p[:, :2], atol=1e-12)
        assert (q[:, 2] < p[:, 2]).all()
        assert gx.column_major(m)[12:15] == list(m[:3, 3]), "column-major: the translation is the last column"
    with pytest.raises(ValueError):
        gx.directional_shadow_matrix([0.0, 0.0, 0.0], pts)


def test_a_point_light_shadow_matrix_covers_the_points_from_the_light():
    from generator.runtime import graphics as gx

    rng = np.random.default_rng(4)
    pts = rng.uniform(-2.0, 2.0, (50, 3))
    pos = np.array([1.0, 6.0, 2.0])
    m = gx.point_shadow_matrix(pos, pts)
    p = _clip(m, pts)
    assert (np.abs(p[:, :2]) <= 1.0).all() and (p[:, 2] >= 0.0).all() and (p[:, 2] <= 1.0).all()
    q = _clip(m, pos + 0.7 * (pts - pos))  # along the ray from the light: same texel, nearer
    np.testing.assert_allclose(q[:, :2], p[:, :2], atol=1e-9)
    assert (q[:, 2] < p[:, 2]).all()


@pytest.mark.lavapipe
@pytest.mark.toolchain
def test_a_depth_only_pass_stores_the_analytic_depth_and_is_sampled_as_a_shadow_map(device, gpu):
    """A vertex-only pipeline renders the floor (y = −1.2, side 6) and a sphere into a DepthTarget with a
    directional shadow matrix; the read-back depth equals the floor's analytic depth where only the floor is
    seen, the sphere is nearer the light, and nothing drawn is the cleared 1.0."""
    from generator.runtime import graphics as gx
    from generator.runtime.compute import UNIFORM

    vk = device.vk
    U = vk.VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT
    n = 64
    dt = gx.DepthTarget(device, n, n)
    gpu.owned.append(dt)
    assert dt.sampled in ("depth", "r32_copy")
    feats = vk.vkGetPhysicalDeviceFormatProperties(device.physical, vk.VK_FORMAT_D32_SFLOAT).optimalTilingFeatures
    linear = bool(feats & vk.VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT)
    # lavapipe: Mesa 25.0 filters D32_SFLOAT linearly → the depth image itself; Mesa 22.3 did not → the R32 copy
    assert dt.sampled == ("depth" if linear else "r32_copy")
    c = gpu.composed[f"spec-{TEX}"]  # the vertex shader with every input
    layouts = {0: {0: UNIFORM}, 2: {0: UNIFORM}}
    with pytest.raises(ValueError, match="needs a fragment shader"):
        gx.GraphicsPipeline(device, gpu.target, gpu.spirv(f"spec-{TEX}", "vert", "glsl"), None,
                            c.interface.vertex_inputs, layouts)
    floor_pts = np.array([(x, -1.2, z) for x in (-3.0, 3.0) for z in (-3.0, 3.0)])
    light = np.array([0.4, 1.0, 0.2])
    m = gx.directional_shadow_matrix(light, np.r_[floor_pts, [(-1, -1, -1), (1, 1, 1)]])
    frame = gpu.buf(gx.frame_bytes(m, (0.0, 0.0, 0.0)), U)
    with pytest.raises(RuntimeError, match="before any draw"):
        dt.read()
    for lang in LANGS:
        pipe = gx.GraphicsPipeline(device, dt, gpu.spirv(f"spec-{TEX}", "vert", lang), None,
                                   c.interface.vertex_inputs, layouts)
        gpu.owned.append(pipe)
        dt.draw([gx.DrawItem(pipe, gpu.floor, {(0, 0): frame, (2, 0): gpu.buf(gx.object_bytes(np.eye(4)), U)})])
        floor_only = dt.read()
        dt.draw([gx.DrawItem(pipe, gpu.floor, {(0, 0): frame, (2, 0): gpu.buf(gx.object_bytes(np.eye(4)), U)}),
                 gx.DrawItem(pipe, gpu.sphere, {(0, 0): frame, (2, 0): gpu.buf(gx.object_bytes(np.eye(4)), U)})])
        both = dt.read()
        # analytic: texel centre (x, y) in clip space → the floor point there → its depth
        xs = 2.0 * (np.arange(n) + 0.5) / n - 1.0
        cx, cy = np.meshgrid(xs, xs)  # row 0 = clip y −1
        a, b = m[:2, [0, 2]], m[:2, 1] * -1.2 + m[:2, 3]
        xz = np.linalg.solve(a, np.stack([cx.ravel() - b[0], cy.ravel() - b[1]]))
        depth = (m[2, 0] * xz[0] + m[2, 2] * xz[1] + m[2, 1] * -1.2 + m[2, 3]).reshape(n, n)
        inside = (np.abs(xz[0]) < 2.9) & (np.abs(xz[1]) < 2.9)
        outside = (np.abs(xz[0]) > 3.1) | (np.abs(xz[1]) > 3.1)
        inside, outside = inside.reshape(n, n), outside.reshape(n, n)
        assert inside.sum() > 1000 and outside.sum() > 50
        np.testing.assert_allclose(floor_only[inside], depth[inside], atol=1e-5)
        assert (floor_only[outside] == 1.0).all(), "cleared to the far plane where nothing was drawn"
        # the sphere (r = 1 at the origin) is nearer the light where the texel's light ray passes within r
        g = np.stack([xz[0], np.full(n * n, -1.2), xz[1]], -1)
        u = light / np.linalg.norm(light)
        dist = np.linalg.norm(g - (g @ u)[:, None] * u, axis=-1).reshape(n, n)
        hit, miss = dist < 0.95, dist > 1.05
        assert hit.sum() > 100
        assert (both[hit] < floor_only[hit] - 1e-3).all(), "the sphere lies between the light and the floor"
        assert np.array_equal(both[miss], floor_only[miss])
    # sampled before its first draw: refused
    fresh = gx.DepthTarget(device, 8, 8)
    gpu.owned.append(fresh)
    new_frame = gpu.camera((0.0, 0.0, 3.0))
    res = gpu.spec_resources(TEX, new_frame(np.eye(4)))
    key = (1, 1)  # the albedo texture's sampled image
    assert gpu.pipeline(f"spec-{TEX}", "glsl").set_layouts[1][1] == "sampled_image"
    res[key] = fresh
    with pytest.raises(ValueError, match="before its first draw"):
        gpu.target.draw([gx.DrawItem(gpu.pipeline(f"spec-{TEX}", "glsl"), gpu.sphere, res)])
    res[key] = dt  # a drawn depth target is a sampled image like any texture
    gpu.frame([gx.DrawItem(gpu.pipeline(f"spec-{TEX}", "glsl"), gpu.sphere, res)])
