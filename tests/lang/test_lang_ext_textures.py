"""2D and cube textures: lavapipe's linear clamp-to-edge sampler and the NumPy target read the same texels.

tests/bricks/lang/ext_texture.py samples a 2D and a cube texture, declared as ir.Global
resources, in a compute kernel per language; the images are float RGBA, so the
filter's arithmetic is all that separates GPU and NumPy. Cube directions keep a
texel away from face edges, where Vulkan filters across faces and NumPy clamps.
"""
import numpy as np
import pytest

from generator.lang import ir, parse_module
from generator.lang.types import TEXTURE2D, TEXTURECUBE
from generator.backends import get_target
from tests.lavapipe import device, no_validation_messages  # noqa: F401  (fixtures)
from tests.regen_goldens import REPO

BRICK = REPO / "tests" / "bricks" / "lang" / "ext_texture.py"
GLOBALS = [ir.Global("img", TEXTURE2D, 0, 2), ir.Global("cube", TEXTURECUBE, 0, 4)]

SHELL = {
    "glsl": "#version 450\n{header}\nlayout(local_size_x = 1) in;\n"
            "layout(std430, set = 0, binding = 0) readonly buffer S {{ vec4 s[]; }} smp;\n"
            "layout(std430, set = 0, binding = 1) buffer R {{ vec4 r[]; }} res;\n{functions}\n"
            "void main() {{ uint i = gl_GlobalInvocationID.x;\n"
            "  res.r[2u * i] = {flat}(img, {s_img}, smp.s[2u * i].xy);\n"
            "  res.r[2u * i + 1u] = {env}(cube, {s_cube}, smp.s[2u * i + 1u].xyz); }}\n",
    "hlsl": "[[vk::binding(0, 0)]] StructuredBuffer<float4> smp : register(t0, space0);\n"
            "[[vk::binding(1, 0)]] RWStructuredBuffer<float4> res : register(u1, space0);\n{functions}\n"
            "[numthreads(1, 1, 1)] void main(uint3 id : SV_DispatchThreadID) {{ uint i = id.x;\n"
            "  res[2u * i] = {flat}(img, {s_img}, smp[2u * i].xy);\n"
            "  res[2u * i + 1u] = {env}(cube, {s_cube}, smp[2u * i + 1u].xyz); }}\n",
    "wgsl": "@group(0) @binding(0) var<storage, read> smp: array<vec4<f32>>;\n"
            "@group(0) @binding(1) var<storage, read_write> res: array<vec4<f32>>;\n{functions}\n"
            "@compute @workgroup_size(1) fn main(@builtin(global_invocation_id) id: vec3<u32>) {{ let i = id.x;\n"
            "  res[2u * i] = {flat}(img, {s_img}, smp[2u * i].xy);\n"
            "  res[2u * i + 1u] = {env}(cube, {s_cube}, smp[2u * i + 1u].xyz); }}\n",
}


def inputs(rng, n=400, h=5, w=7, c=6):
    img = rng.uniform(-1, 1, (h, w, 4)).astype(np.float32)
    cube = rng.uniform(-1, 1, (6, c, c, 4)).astype(np.float32)
    uv = rng.uniform(-0.25, 1.25, (n, 2))
    d = rng.normal(size=(n * 4, 3))
    a = np.abs(d)
    ma, mid = a.max(1), np.sort(a, 1)[:, 1]
    d = d[(mid / ma < 1 - 2.0 / c) & (ma - mid > 1e-3)][:n]  # a texel away from every face edge
    assert len(d) == n
    samples = np.zeros((n, 2, 4), np.float32)
    samples[:, 0, :2], samples[:, 1, :3] = uv, d
    return img, cube, samples


@pytest.mark.lavapipe
@pytest.mark.toolchain
def test_lavapipe_and_numpy_sample_the_same_texels(device):
    from generator.toolchain import CompileJob, compile_many
    from tests.ext_vulkan_images import Image, run_sampling_kernel

    m = parse_module(BRICK.read_text(), str(BRICK.relative_to(REPO)))
    img, cube, samples = inputs(np.random.default_rng(11))
    nt = get_target("numpy")
    fns = nt.load(nt.emit([], list(m.functions.values())), np.float32)
    want = np.stack([fns["flat"](img, samples[:, 0, :2]), fns["env"](cube, samples[:, 1, :3])], 1).astype(np.float64)
    jobs = []
    for lang, shell in SHELL.items():
        t = get_target(lang)
        text = t.emit([], list(m.functions.values()), GLOBALS).text
        jobs.append(CompileJob(f"tex.{lang}", lang, "comp", shell.format(
            header=t.header(), functions=text, flat=t.ident("flat"), env=t.ident("env"),
            s_img=t.sampler_name("img"), s_cube=t.sampler_name("cube"))))
    compiled = compile_many(jobs)
    images = [Image(device, img), Image(device, cube, cube=True)]
    try:
        for job in jobs:
            r = compiled[job.key]
            assert r.ok, "\n".join(r.errors())
            got = run_sampling_kernel(device, r.spirv, samples, 2, images).astype(np.float64)
            # lavapipe filters float formats in float32 (measured: 7e-7 on texels in [-1, 1]); a wrong
            # texel, face or half-texel offset would be off by ~0.1
            np.testing.assert_allclose(got, want, rtol=0, atol=4e-6,
                                       err_msg=f"{job.language}: lavapipe and NumPy sample differently")
    finally:
        for i in images:
            i.destroy()
