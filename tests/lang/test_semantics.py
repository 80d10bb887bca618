"""The same brick means the same thing in GLSL, HLSL and WGSL on lavapipe and in the NumPy target.

Integer division and remainder of negatives, reserved-word renaming, selects,
column-major matrices and early returns: places where the languages differ unless
the emitters bridge them. Shaders go through the project toolchain with
`spirv-opt -O`, so a difference introduced by constant folding shows too.
"""
import numpy as np
import pytest

from generator.lang import parse_module
from generator.backends import get_target
from tests.lavapipe import device, no_validation_messages  # noqa: F401  (fixtures)
from tests.regen_goldens import REPO

BRICK = REPO / "tests" / "bricks" / "lang" / "semantics.py"
XS = np.array([-7.5, -3.2, -1.0, -0.5, 0.0, 0.5, 1.7, 3.0, 7.9], np.float32)

SHELL = {
    "glsl": "#version 450\n{header}\nlayout(local_size_x = 1) in;\n"
            "layout(std430, set = 0, binding = 0) buffer D {{ float data[]; }} buf;\n{functions}\n"
            "void main() {{ uint i = gl_GlobalInvocationID.x; buf.data[i] = {f}(buf.data[i]); }}\n",
    "hlsl": "[[vk::binding(0, 0)]] RWStructuredBuffer<float> buf : register(u0, space0);\n{functions}\n"
            "[numthreads(1, 1, 1)] void main(uint3 id : SV_DispatchThreadID) {{ buf[id.x] = {f}(buf[id.x]); }}\n",
    "wgsl": "@group(0) @binding(0) var<storage, read_write> buf: array<f32>;\n{functions}\n"
            "@compute @workgroup_size(1) fn main(@builtin(global_invocation_id) id: vec3<u32>) "
            "{{ buf[id.x] = {f}(buf[id.x]); }}\n",
}


@pytest.fixture(scope="module")
def module():
    return parse_module(BRICK.read_text(), str(BRICK.relative_to(REPO)))


def expected(module, name):
    nt = get_target("numpy")
    fns = nt.load(nt.emit(list(module.structs.values()), list(module.functions.values())), np.float64)
    return np.asarray(fns[name](XS.astype(np.float64)), np.float64)


def gpu_results(device, module, names):
    import vulkan as vk

    from generator.runtime.compute import STORAGE, ComputePipeline
    from generator.toolchain import CompileJob, compile_many

    jobs = []
    for lang, shell in SHELL.items():
        t = get_target(lang)
        functions = t.emit(list(module.structs.values()), list(module.functions.values())).text
        for name in names:
            jobs.append(CompileJob(f"{name}.{lang}", lang, "comp",
                                   shell.format(header=t.header(), functions=functions, f=t.ident(name))))
    compiled = compile_many(jobs)
    out = {}
    for job in jobs:
        r = compiled[job.key]
        assert r.ok, "\n".join(map(str, r.diagnostics))
        pipe = ComputePipeline(device, r.spirv, (STORAGE,))
        buf = device.buffer(XS.nbytes, vk.VK_BUFFER_USAGE_STORAGE_BUFFER_BIT)
        try:
            buf.write(XS)
            pipe.bind([buf])
            pipe.dispatch(len(XS))
            out[job.key] = buf.array(np.float32)[: len(XS)].astype(np.float64)
        finally:
            buf.destroy()
            pipe.destroy()
    return out


@pytest.mark.lavapipe
@pytest.mark.toolchain
def test_every_language_agrees_with_numpy(device, module):
    names = list(module.functions)
    got = gpu_results(device, module, names)
    for name in names:
        want = expected(module, name)
        for lang in SHELL:
            np.testing.assert_allclose(got[f"{name}.{lang}"], want, rtol=2e-6, atol=1e-5,
                                       err_msg=f"{name} in {lang} differs from the NumPy target")


def test_numpy_truncates_integer_division_and_remainder(module):
    # The reference the GPU languages are held to: C-like truncation, as WGSL defines it.
    np.testing.assert_array_equal(expected(module, "signed_mod")[:2], [-1 + 10 * -3 + 100 * -1, 0 + 10 * -3 - 100])
    assert expected(module, "signed_div")[0] == -2 + 10 * -3
    np.testing.assert_array_equal(expected(module, "reserved_names"), XS.astype(np.float64) * 2 + 3)
