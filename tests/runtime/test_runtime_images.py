"""Sampled textures and per-sample ids in compute eval kernels, on lavapipe under the validation layer.

Hand-written compute kernels (GLSL, and HLSL/WGSL for the bindings) sample 2D and
cube images through :class:`generator.runtime.eval_kernel.EvalKernel`: set 0 is
0 samples, 1 result, 2 params, then texture k's image at 3 + 2k and its sampler at
4 + 2k. Results are compared with a float64 NumPy bilinear clamp-to-edge reference
written here (texel centres at (i + 0.5) / W, level 0), the filter that
generator/backends/numpy/resources.py reproduces.

Agreement measured on lavapipe (Mesa 25.0.7, LLVM 15.0.6), 200 000 random uv in
[-0.2, 1.2]² per case, max abs difference GPU - float64 reference (Mesa 22.3.6 gives the
same figures on the same inputs):

- R32G32B32A32_SFLOAT: 2.9e-7 (random) and up to 4.3e-7 (a 0/1 checkerboard) on 5x7
  textures with texel values in [0, 1], 9.6e-8 at 256x128, 4.6e-5 at 1000x1000:
  lavapipe filters float formats in float32 with no visible sub-texel weight
  quantization; the error is float32 rounding of uv * W - 0.5, which grows with
  the texture size, so the tolerance is ``FLOAT_TOL(W, H)``
  = 1e-6 + 2 * max(W, H) * 2^-24 per unit of texel contrast.
  Cube maps (8x8 faces, directions of any length) agree to 5.5e-7 away from face
  edges; within half a texel of an edge Vulkan filters seamlessly across faces
  and the per-face NumPy reference does not (differences up to 0.60 there).
- R8G8B8A8_UNORM: the filtered value comes back requantized to multiples of
  1/255 (weights in steps of 1/256 per axis, 8-bit result): max 1.49/255 (0.0058)
  on the test's random texels, 0.50/255 on a 256x1 0-to-255 ramp; texel centres
  exact (7.4e-8). Tolerance 2/255, a bound of the filter: a bilinear weight quantized
  to 1/256 per axis is off by at most 1/512 on each, so by about 1/255 of the texel
  contrast for both, plus the 0.5/255 of rounding the result to 8 bits (measured:
  other random 5x7 textures at 10^6 uv 1.43-1.60/255, 0|255 texels up to 1.70/255,
  the same on Mesa 22.3.6).
- R8G8B8A8_SRGB: rgb is decoded before filtering, and filtering is float (a 0|255
  checkerboard: 4.0e-7); lavapipe's decode approximates the sRGB EOTF to within
  1.19e-3 absolute (worst near code 218, 0.70 linear); alpha stays linear (7.4e-8).
  Tolerance 1.5e-3.
"""
from __future__ import annotations

import types

import numpy as np
import pytest

from tests.lavapipe import device, no_validation_messages, open_device  # noqa: F401 (fixtures)

pytestmark = [pytest.mark.lavapipe, pytest.mark.toolchain]

UNORM_TOL = 2.0 / 255   # the filter's bound (see above); measured 1.49 / 255 on the test's inputs
SRGB_TOL = 1.5e-3       # measured 1.19e-3 (the decode's error)
CUBE_TOL = 2e-6         # measured 5.5e-7 (8x8 faces, away from face edges)


def FLOAT_TOL(w: int, h: int) -> float:  # noqa: N802 (reads as the constant it is per size)
    """Tolerance for float textures of W x H with texel contrast ≤ 1 (measured: 4.3e-7 at 5x7)."""
    return 1e-6 + 2.0 * max(w, h) * 2.0 ** -24


# ---------------------------------------------------------------- references (float64)

def bilinear(img: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """Bilinear, clamp-to-edge, texel centres at (i + 0.5) / W: img (H, W, 4), uv (N, 2) -> (N, 4)."""
    img, uv = np.asarray(img, np.float64), np.asarray(uv, np.float64)
    h, w = img.shape[:2]
    x, y = uv[:, 0] * w - 0.5, uv[:, 1] * h - 0.5
    x0, y0 = np.floor(x), np.floor(y)
    ax, ay = (x - x0)[:, None], (y - y0)[:, None]
    i0, i1 = (np.clip(x0 + d, 0, w - 1).astype(np.intp) for d in (0, 1))
    j0, j1 = (np.clip(y0 + d, 0, h - 1).astype(np.intp) for d in (0, 1))
    return ((img[j0, i0] * (1 - ax) + img[j0, i1] * ax) * (1 - ay)
            + (img[j1, i0] * (1 - ax) + img[j1, i1] * ax) * ay)


def cube_face(d: np.ndarray):
    """Vulkan "Cube Map Face Selection": (face, s, t) of directions d (N, 3)."""
    d = np.asarray(d, np.float64)
    rx, ry, rz = d.T
    ax, ay, az = np.abs(d).T
    use_x = (ax >= ay) & (ax >= az)
    use_y = ~use_x & (ay >= az)
    face = np.where(use_x, np.where(rx >= 0, 0, 1), np.where(use_y, np.where(ry >= 0, 2, 3), np.where(rz >= 0, 4, 5)))
    sc = np.choose(face, [-rz, rz, rx, rx, rx, -rx])
    tc = np.choose(face, [-ry, -ry, rz, -rz, -ry, -ry])
    ma = np.choose(face, [ax, ax, ay, ay, az, az])
    return face, 0.5 * (sc / ma + 1.0), 0.5 * (tc / ma + 1.0)


def cube_dir(face: np.ndarray, s: np.ndarray, t: np.ndarray) -> np.ndarray:
    """A direction (ma = 1) that cube_face maps to (face, s, t): the inverse of the table above."""
    sc, tc = 2.0 * s - 1.0, 2.0 * t - 1.0
    one = np.ones_like(sc)
    rows = {0: (one, -tc, -sc), 1: (-one, -tc, sc), 2: (sc, one, tc),
            3: (sc, -one, -tc), 4: (sc, -tc, one), 5: (-sc, -tc, -one)}
    out = np.empty((len(sc), 3))
    for f, (x, y, z) in rows.items():
        m = face == f
        out[m] = np.stack([x[m], y[m], z[m]], -1)
    return out


def cube_bilinear(faces: np.ndarray, d: np.ndarray) -> np.ndarray:
    face, s, t = cube_face(d)
    out = np.empty((len(face), 4))
    for f in range(6):
        m = face == f
        out[m] = bilinear(faces[f], np.stack([s[m], t[m]], -1))
    return out


def srgb_eotf(c):
    """sRGB encoded [0, 1] -> linear (IEC 61966-2-1)."""
    c = np.asarray(c, np.float64)
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


# ---------------------------------------------------------------- kernels

GLSL = """#version 450
layout(local_size_x = 64) in;
layout(set = 0, binding = 0, std430) readonly buffer Samples {{ vec4 s[]; }} samples;
layout(set = 0, binding = 1, std430) writeonly buffer Result {{ vec4 r[]; }} result;
layout(set = 0, binding = 2, std140) uniform Params {{ uvec4 info; vec4 data[1]; }} params;
{decls}
void main() {{
    uint i = gl_GlobalInvocationID.x;
    if (i >= params.info.x) {{ return; }}
    vec4 L = samples.s[3u * i];
    vec4 V = samples.s[3u * i + 1u];
    result.r[i] = {expr};
}}
"""
TEX2D = "layout(set = 0, binding = {b}) uniform texture2D t{k};\nlayout(set = 0, binding = {s}) uniform sampler s{k};"
TEXCUBE = TEX2D.replace("texture2D", "textureCube")

# The same two-texture kernel in all three languages: texture 0 a 2D image sampled at V.xy,
# texture 1 a cube sampled in direction L.xyz; the result is their sum.
TWO = {
    "glsl": GLSL.format(decls=TEX2D.format(b=3, s=4, k=0) + "\n" + TEXCUBE.format(b=5, s=6, k=1),
                        expr="textureLod(sampler2D(t0, s0), V.xy, 0.0) + textureLod(samplerCube(t1, s1), L.xyz, 0.0)"),
    "hlsl": """StructuredBuffer<float4> samples : register(t0, space0);
RWStructuredBuffer<float4> result : register(u1, space0);
cbuffer Params : register(b2, space0) { uint4 info; float4 data[1]; };
[[vk::binding(3, 0)]] Texture2D<float4> t0;
[[vk::binding(4, 0)]] SamplerState s0;
[[vk::binding(5, 0)]] TextureCube<float4> t1;
[[vk::binding(6, 0)]] SamplerState s1;
[numthreads(64, 1, 1)]
void main(uint3 gid : SV_DispatchThreadID) {
    uint i = gid.x;
    if (i >= info.x) { return; }
    float4 L = samples[3u * i];
    float4 V = samples[3u * i + 1u];
    result[i] = t0.SampleLevel(s0, V.xy, 0.0) + t1.SampleLevel(s1, L.xyz, 0.0);
}
""",
    "wgsl": """struct Params { info: vec4<u32>, data: array<vec4<f32>, 1> }
@group(0) @binding(0) var<storage, read> samples: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read_write> result: array<vec4<f32>>;
@group(0) @binding(2) var<uniform> params: Params;
@group(0) @binding(3) var t0: texture_2d<f32>;
@group(0) @binding(4) var s0: sampler;
@group(0) @binding(5) var t1: texture_cube<f32>;
@group(0) @binding(6) var s1: sampler;
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= params.info.x) {
        return;
    }
    let L = samples[3u * i];
    let V = samples[3u * i + 1u];
    result[i] = textureSampleLevel(t0, s0, V.xy, 0.0) + textureSampleLevel(t1, s1, L.xyz, 0.0);
}
""",
}


def kernel(session, text: str, textures: int, language: str = "glsl"):
    """compile_kernel on a hand-written Source, on the eval session's device, kept by the session per text."""
    from generator.runtime.eval_kernel import compile_kernel

    key = ("test_runtime_images", language, text)
    if key not in session.kernels:
        src = types.SimpleNamespace(text=text, language=language, line_map=())
        session.kernels[key] = compile_kernel(src, session.device, False, 1, textures=textures)
    return session.kernels[key]


def kernel_2d(session, expr: str, cube: bool = False):
    decls = (TEXCUBE if cube else TEX2D).format(b=3, s=4, k=0)
    return kernel(session, GLSL.format(decls=decls, expr=expr), 1)


BLOCK = np.zeros(4, np.float32)


def run_raw(k, L, V=None, textures=None, ids=None) -> np.ndarray:
    """All four result components (run returns xyz; alpha is read from the result buffer)."""
    n = len(L)
    z = np.zeros((n, 3), np.float32)
    rgb = k.run([np.asarray(L, np.float32), z if V is None else np.asarray(V, np.float32), z], BLOCK,
                ids=ids, textures=textures)
    raw = k.result.array(np.float32)[: 4 * n].reshape(n, 4).astype(np.float64)
    np.testing.assert_array_equal(rgb, raw[:, :3].astype(np.float32))
    return raw


def uv_points(w: int, h: int, rng, n: int = 20000) -> np.ndarray:
    """Chosen uv: texel centres, edges and corners, between texels, outside [0, 1]; then random ones."""
    cx, cy = (np.arange(w) + 0.5) / w, (np.arange(h) + 0.5) / h
    centres = np.stack(np.meshgrid(cx, cy), -1).reshape(-1, 2)
    mids = np.stack(np.meshgrid(np.arange(1, w) / w, np.arange(1, h) / h), -1).reshape(-1, 2)
    quarter = centres + np.float64([0.25 / w, 0.75 / h])
    edges = np.float64([[0, 0], [1, 1], [0, 1], [1, 0], [0.5, 0], [0.5, 1], [0, 0.5], [1, 0.5],
                        [0.5 / w, 0.5 / h], [1 - 0.5 / w, 1 - 0.5 / h]])
    outside = np.float64([[-0.3, 0.5], [1.7, 0.5], [0.5, -2.0], [0.5, 1.01], [-5, -5], [9, 9], [-0.1, 1.3]])
    rand = rng.uniform(-0.25, 1.25, (n, 2))
    return np.concatenate([centres, mids, quarter, edges, outside, rand]).astype(np.float32)


def lv(uv: np.ndarray) -> np.ndarray:
    L = np.zeros((len(uv), 3), np.float32)
    L[:, :2] = uv
    return L


# ---------------------------------------------------------------- (a) float 2D

@pytest.mark.parametrize("call", ["texture", "textureLod"])
@pytest.mark.parametrize("w, h", [(7, 5), (256, 128)])
def test_float_texture_is_bilinear_clamp_to_edge(device, eval_session, call, w, h):
    rng = np.random.default_rng(w)
    k = kernel_2d(eval_session, "texture(sampler2D(t0, s0), L.xy)" if call == "texture"
                  else "textureLod(sampler2D(t0, s0), L.xy, 0.0)")
    img = rng.uniform(0, 1, (h, w, 4)).astype(np.float32)
    uv = uv_points(w, h, rng)
    got = run_raw(k, lv(uv), textures=[img])
    want = bilinear(img, uv)
    err = np.abs(got - want).max()
    assert err <= FLOAT_TOL(w, h), f"max abs error {err:.3g} > {FLOAT_TOL(w, h):.3g}"
    # texel centres read the texel, corners and far outside points the clamped corner texel
    np.testing.assert_allclose(got[: w * h].reshape(h, w, 4), img, atol=FLOAT_TOL(w, h), rtol=0)
    corners = {(-5, -5): img[0, 0], (9, 9): img[-1, -1], (0, 0): img[0, 0], (1, 1): img[-1, -1]}
    for (u, v), texel in corners.items():
        i = np.flatnonzero((uv[:, 0] == u) & (uv[:, 1] == v))[0]
        np.testing.assert_allclose(got[i], texel, atol=FLOAT_TOL(w, h), rtol=0)


def test_float_filter_agreement_on_contrast(device, eval_session):
    """A 0/1 checkerboard (maximal texel contrast) at 200 000 uv: measured max 4.2e-7."""
    rng = np.random.default_rng(7)
    k = kernel_2d(eval_session, "textureLod(sampler2D(t0, s0), L.xy, 0.0)")
    img = np.repeat((np.indices((5, 7)).sum(0) % 2)[..., None], 4, -1).astype(np.float32)
    uv = rng.uniform(-0.2, 1.2, (200_000, 2)).astype(np.float32)
    err = np.abs(run_raw(k, lv(uv), textures=[img]) - bilinear(img, uv)).max()
    assert err <= FLOAT_TOL(7, 5), err


def test_fewer_channels_expand_like_vulkan(device, eval_session):
    """(H, W, C<4) textures get 0 for missing colour channels and alpha 1, as Vulkan expands formats."""
    k = kernel_2d(eval_session, "textureLod(sampler2D(t0, s0), L.xy, 0.0)")
    img = np.float32([[[0.25, 0.5], [0.75, 1.0]]])  # (1, 2, 2): two channels
    got = run_raw(k, lv(np.float32([[0.25, 0.5], [0.75, 0.5]])), textures=[img])
    np.testing.assert_allclose(got, [[0.25, 0.5, 0, 1], [0.75, 1.0, 0, 1]], atol=1e-6)


# ---------------------------------------------------------------- (b) uint8: UNORM and sRGB

def test_unorm8_texture_filters_within_one_step(device, eval_session):
    rng = np.random.default_rng(8)
    k = kernel_2d(eval_session, "textureLod(sampler2D(t0, s0), L.xy, 0.0)")
    img = rng.integers(0, 256, (5, 7, 4), dtype=np.uint8)
    uv = uv_points(7, 5, rng, 200_000)
    got = run_raw(k, lv(uv), textures=[img])
    err = np.abs(got - bilinear(img / 255.0, uv)).max()
    assert err <= UNORM_TOL, f"{err * 255:.3f}/255"
    np.testing.assert_allclose(got[:35].reshape(5, 7, 4), img / 255.0, atol=1e-6, rtol=0)


def test_srgb_texture_decodes_with_the_eotf_before_filtering(device, eval_session):
    k = kernel_2d(eval_session, "textureLod(sampler2D(t0, s0), L.xy, 0.0)")
    code = np.arange(256, dtype=np.uint8)
    img = np.stack([code, 255 - code, code[::-1] // 2, code], -1).reshape(16, 16, 4)  # every code, alpha = code
    c = (np.arange(16) + 0.5) / 16
    centres = np.stack(np.meshgrid(c, c), -1).reshape(-1, 2).astype(np.float32)
    got = run_raw(k, lv(centres), textures=[(img, True)])
    want = np.concatenate([srgb_eotf(img[..., :3].reshape(-1, 3) / 255.0), img[..., 3:].reshape(-1, 1) / 255.0], -1)
    err = np.abs(got - want)
    assert err[:, :3].max() <= SRGB_TOL, err[:, :3].max()
    assert err[:, 3].max() <= 1e-6  # alpha is not decoded
    assert got[0, 0] == 0.0 and got[255, 0] == 1.0

    # decoded before filtering: halfway between codes 0 and 255 is linear 0.5, not eotf(0.5) = 0.214
    from generator.runtime.eval_kernel import Texture

    pair = np.uint8([[[0, 0, 0, 0], [255, 255, 255, 255]]])
    mid = run_raw(k, lv(np.float32([[0.5, 0.5]])), textures=[Texture(pair, srgb=True)])
    np.testing.assert_allclose(mid[0], 0.5, atol=1e-6)
    unorm = run_raw(k, lv(np.float32([[0.5, 0.5]])), textures=[(pair, False)])
    np.testing.assert_allclose(unorm[0], 0.5, atol=UNORM_TOL)

    # and filtered in float: random codes at random uv against the filtered decoded texels
    rng = np.random.default_rng(9)
    rnd = rng.integers(0, 256, (5, 7, 4), dtype=np.uint8)
    uv = uv_points(7, 5, rng, 50_000)
    lin = np.concatenate([srgb_eotf(rnd[..., :3] / 255.0), rnd[..., 3:] / 255.0], -1)
    err = np.abs(run_raw(k, lv(uv), textures=[(rnd, True)]) - bilinear(lin, uv)).max()
    assert err <= SRGB_TOL, err


# ---------------------------------------------------------------- (c) cube

def test_cube_texture_samples_the_face_of_the_direction(device, eval_session):
    rng = np.random.default_rng(10)
    w = 8
    faces = rng.uniform(0, 1, (6, w, w, 4)).astype(np.float32)
    k = kernel_2d(eval_session, "textureLod(samplerCube(t0, s0), L.xyz, 0.0)", cube=True)
    # Interior points only (the bilinear footprint inside one face): Vulkan filters seamlessly
    # across face edges, the per-face reference does not.
    face = np.repeat(np.arange(6), 3000)
    s, t = (rng.uniform(0.5 / w, 1 - 0.5 / w, face.size) for _ in range(2))
    centre = (np.arange(w) + 0.5) / w
    face = np.concatenate([face, np.repeat(np.arange(6), w * w)])
    s = np.concatenate([s, np.tile(np.tile(centre, w), 6)])
    t = np.concatenate([t, np.tile(np.repeat(centre, w), 6)])
    d = cube_dir(face, s, t) * rng.uniform(0.05, 20.0, (face.size, 1))  # any length
    d = d.astype(np.float32)
    f2, s2, t2 = cube_face(d)
    assert (f2 == face).all()  # the directions select the intended faces
    got = run_raw(k, d, textures=[faces])
    err = np.abs(got - cube_bilinear(faces, d)).max()
    assert err <= CUBE_TOL, err
    # at texel centres: the texels of each face, in Vulkan's layer order +X, -X, +Y, -Y, +Z, -Z
    np.testing.assert_allclose(got[-6 * w * w:].reshape(6, w, w, 4), faces, atol=CUBE_TOL, rtol=0)
    # the axes themselves: the centre of each face (bilinear between its four middle texels)
    axes = np.float32([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]])
    np.testing.assert_allclose(run_raw(k, axes, textures=[faces]), faces[:, 3:5, 3:5].mean((1, 2)), atol=CUBE_TOL)


@pytest.mark.parametrize("language", ["glsl", "hlsl", "wgsl"])
def test_two_textures_at_bindings_3_4_and_5_6(device, eval_session, language):
    """A 2D image + sampler at 3, 4 and a cube image + sampler at 5, 6, in every language."""
    rng = np.random.default_rng(11)
    k = kernel(eval_session, TWO[language], 2, language)
    assert k.pipeline.bindings == ("storage", "storage", "uniform", "sampled_image", "sampler",
                                   "sampled_image", "sampler")
    img = rng.uniform(0, 1, (5, 7, 4)).astype(np.float32)
    faces = rng.uniform(0, 1, (6, 4, 4, 4)).astype(np.float32)
    n = 4000
    face = rng.integers(0, 6, n)
    d = cube_dir(face, *(rng.uniform(0.5 / 4, 1 - 0.5 / 4, n) for _ in range(2))).astype(np.float32)
    uv = rng.uniform(-0.2, 1.2, (n, 2)).astype(np.float32)
    V = np.zeros((n, 3), np.float32)
    V[:, :2] = uv
    got = run_raw(k, d, V, textures=[img, faces])
    err = np.abs(got - (bilinear(img, uv) + cube_bilinear(faces, d))).max()
    assert err <= FLOAT_TOL(7, 5) + CUBE_TOL, err
    with pytest.raises(ValueError, match="2 texture"):
        k.run([d, V, V], BLOCK, textures=[img])


# ---------------------------------------------------------------- (d) ids in L.w

IDS = GLSL.format(decls="", expr="vec4(L.w, float(int(L.w)), L.x, float(i))")


def test_ids_travel_in_L_w(device, eval_session):
    k = kernel(eval_session, IDS, 0)
    n = 1000
    rng = np.random.default_rng(12)
    ids = rng.integers(-50, 50, n)
    ids[:4] = (0, 1 << 24, -(1 << 24), 7)
    L = rng.normal(size=(n, 3)).astype(np.float32)
    z = np.zeros((n, 3), np.float32)
    got = run_raw(k, L, ids=ids)
    np.testing.assert_array_equal(got[:, 0], ids)
    np.testing.assert_array_equal(got[:, 1], ids)  # int(L.w) is the id again
    np.testing.assert_array_equal(got[:, 2], L[:, 0])  # xyz unchanged
    np.testing.assert_array_equal(run_raw(k, L)[:, 0], 0.0)  # without ids L.w is 0
    # in chunks, each chunk gets its own slice of the ids
    limit, k.max_samples = k.max_samples, 64
    try:
        chunked = k.run([L, z, z], BLOCK, ids=ids.astype(np.int32))  # the result buffer holds the last chunk
    finally:
        k.max_samples = limit
    np.testing.assert_array_equal(chunked[:, :2], got[:, :2])
    # load() takes them too (samples lo:hi of the whole array)
    k.load([L, z, z], BLOCK, 100, 300, ids=ids)
    k.pipeline.dispatch(-(-200 // 64))
    np.testing.assert_array_equal(k.result.array(np.float32)[: 4 * 200].reshape(-1, 4)[:, 0], ids[100:300])
    for bad, exc in ((ids.astype(np.float32), TypeError), (ids[:-1], ValueError),
                     (np.full(n, (1 << 24) + 1), ValueError)):
        with pytest.raises(exc):
            k.run([L, z, z], BLOCK, ids=bad)


# ---------------------------------------------------------------- uploads, binding and lifetime

def test_uploads_are_cached_per_content(device, eval_session):
    from generator.runtime.eval_kernel import Texture

    k = kernel_2d(eval_session, "textureLod(sampler2D(t0, s0), L.xy, 0.0)")
    rng = np.random.default_rng(13)
    img = rng.integers(0, 256, (4, 4, 4), dtype=np.uint8)
    L = lv(np.float32([[0.125, 0.125]]))
    z = np.zeros((1, 3), np.float32)
    before = k.uploads
    a = run_raw(k, L, textures=[img])
    run_raw(k, L, textures=[img])
    run_raw(k, L, textures=[img.copy()])  # equal content: the same image
    run_raw(k, L, textures=[Texture(img)])
    run_raw(k, L)  # textures=None keeps the bound ones
    assert k.uploads == before + 1
    s = run_raw(k, L, textures=[(img, True)])  # sRGB is another image
    assert k.uploads == before + 2 and not np.allclose(s, a)
    img[0, 0] = 255 - img[0, 0]  # changed in place: uploaded again
    np.testing.assert_allclose(run_raw(k, L, textures=[img])[0], img[0, 0] / 255.0, atol=1e-6)
    assert k.uploads == before + 3
    k.load([L, z, z], BLOCK)  # load keeps the bound textures too
    k.release(textures=True)
    with pytest.raises(ValueError, match="texture"):
        k.run([L, z, z], BLOCK)
    with pytest.raises(ValueError, match="texture"):
        k.load([L, z, z], BLOCK)
    run_raw(k, L, textures=[img])
    assert k.uploads == before + 4


def test_bind_checks_resource_kinds(device, eval_session):
    from generator.runtime.compute import SAMPLED_IMAGE, SAMPLER, ComputePipeline

    k = kernel_2d(eval_session, "textureLod(sampler2D(t0, s0), L.xy, 0.0)")
    pipe = k.pipeline
    img = device.image(np.zeros((2, 2, 4), np.float32))
    with pytest.raises(TypeError, match="binding 3 is sampled_image"):
        pipe.bind({3: k.sampler})
    with pytest.raises(TypeError, match="binding 4 is sampler"):
        pipe.bind({4: img})
    with pytest.raises(TypeError, match="binding 0 is storage"):
        pipe.bind({0: img})
    with pytest.raises(ValueError, match="binding 9"):
        pipe.bind({9: img})
    with pytest.raises(ValueError, match="5 bindings"):
        pipe.bind([img])
    img.destroy()
    with pytest.raises(TypeError, match="destroyed"):
        pipe.bind({3: img})
    with pytest.raises(ValueError, match="unknown binding kinds"):
        ComputePipeline(device, b"", ("storage", "texture"))
    assert (SAMPLED_IMAGE, SAMPLER) == ("sampled_image", "sampler")


def test_texel_shapes_and_formats_are_checked(device):
    vk = device.vk
    with pytest.raises(ValueError, match="8-bit"):
        device.image(np.zeros((2, 2, 4), np.float32), srgb=True)
    with pytest.raises(ValueError, match="square"):
        device.image(np.zeros((6, 2, 3, 4), np.uint8))
    with pytest.raises(ValueError, match=r"\(6, H, W, C\)"):
        device.image(np.zeros((2, 2, 4), np.uint8), cube=True)
    with pytest.raises(ValueError, match="channels"):
        device.image(np.zeros((2, 2, 5), np.uint8))
    with pytest.raises(TypeError, match="uint8"):
        device.image(np.zeros((2, 2, 4), np.int32))
    for data, srgb, fmt, cube in ((np.zeros((3, 2, 4)), False, vk.VK_FORMAT_R32G32B32A32_SFLOAT, False),
                                  (np.zeros((3, 2, 4), np.uint8), False, vk.VK_FORMAT_R8G8B8A8_UNORM, False),
                                  (np.zeros((6, 2, 2, 4), np.uint8), True, vk.VK_FORMAT_R8G8B8A8_SRGB, True)):
        img = device.image(data, srgb=srgb)
        assert (img.format, img.cube, img.layers) == (fmt, cube, 6 if cube else 1)
        img.upload(np.ones_like(data))  # re-upload: the layout transitions again from UNDEFINED
        img.destroy()


def test_close_releases_images_and_samplers():
    """Images, samplers and kernels die with their device; the layer's leak check is live."""
    from generator.runtime.images import Image, Sampler

    dev = open_device()
    try:
        dev.image(np.zeros((4, 4, 4), np.float32))
        dev.image(np.zeros((6, 4, 4, 4), np.uint8), srgb=True)
        early = dev.image(np.zeros((1, 1, 4), np.uint8))
        dev.sampler()
        early.destroy()
        early.destroy()  # twice is harmless
        assert sum(isinstance(o, (Image, Sampler)) for o in dev._owned) == 3
    finally:
        dev.close()
    assert dev.messages == [], "\n".join(map(str, dev.messages))

    dev = open_device()
    try:
        leaked = dev.image(np.zeros((2, 2, 4), np.float32))
        dev._owned.remove(leaked)  # forget it: vkDestroyDevice then finds it alive
    finally:
        dev.close()
    assert any("VkImage" in m.text for m in dev.messages), dev.messages
