"""A switch, runtime-bounded loops, arrays and both buffer kinds agree on lavapipe and in NumPy.

tests/bricks/lang/ext_gpu.py is emitted in GLSL, HLSL and WGSL, wrapped in a compute kernel
(binding 0: samples (k, x), 1: results, 2: the lights storage buffer, 3: the lobes
uniform buffer, declared by Target.emit(globals=)), compiled with spirv-opt -O and run;
the NumPy target gets the same buffer bytes through NumpyTarget.unpack_buffer.
"""
import numpy as np
import pytest

from generator.lang import ir, parse_module
from generator.backends import get_target
from tests.lavapipe import device, no_validation_messages  # noqa: F401  (fixtures)
from tests.regen_goldens import REPO

BRICK = REPO / "tests" / "bricks" / "lang" / "ext_gpu.py"

SHELL = {
    "glsl": "#version 450\n{header}\nlayout(local_size_x = 1) in;\n"
            "layout(std430, set = 0, binding = 0) readonly buffer S {{ vec4 s[]; }} smp;\n"
            "layout(std430, set = 0, binding = 1) buffer R {{ vec4 r[]; }} res;\n{functions}\n"
            "void main() {{ uint i = gl_GlobalInvocationID.x; vec4 a = smp.s[i]; "
            "res.r[i] = {f}(int(a.x), a.y); }}\n",
    "hlsl": "[[vk::binding(0, 0)]] StructuredBuffer<float4> smp : register(t0, space0);\n"
            "[[vk::binding(1, 0)]] RWStructuredBuffer<float4> res : register(u1, space0);\n{functions}\n"
            "[numthreads(1, 1, 1)] void main(uint3 id : SV_DispatchThreadID) {{ float4 a = smp[id.x]; "
            "res[id.x] = {f}(int(a.x), a.y); }}\n",
    "wgsl": "@group(0) @binding(0) var<storage, read> smp: array<vec4<f32>>;\n"
            "@group(0) @binding(1) var<storage, read_write> res: array<vec4<f32>>;\n{functions}\n"
            "@compute @workgroup_size(1) fn main(@builtin(global_invocation_id) id: vec3<u32>) "
            "{{ let a = smp[id.x]; res[id.x] = {f}(i32(a.x), a.y); }}\n",
}


@pytest.fixture(scope="module")
def module():
    return parse_module(BRICK.read_text(), str(BRICK.relative_to(REPO)))


def inputs(rng, n=97, m=5):
    k = np.concatenate([np.arange(-1, 13), rng.integers(-1, 13, n - 14)]).astype(np.float32)
    x = rng.uniform(0.05, 1.0, n).astype(np.float32)
    samples = np.zeros((n, 4), np.float32)
    samples[:, 0], samples[:, 1] = k, x
    lights = np.zeros((m, 12), np.float32)
    lights[:, :8] = rng.uniform(-1, 1, (m, 8))
    lights[:, 8:12].view(np.int32)[:] = np.arange(4 * m).reshape(m, 4) % 4  # kinds 0, 1, 2, 3
    lobes = np.zeros((4, 8), np.float32)
    lobes[:, :4] = rng.uniform(0, 1, (4, 4))
    lobes[:, 4:] = rng.uniform(0.5, 3, (4, 4))
    return samples, lights, lobes


def globals_of(module):
    return [ir.Global("lights", module.globals["lights"].ty, 0, 2), ir.Global("lobes_ub", module.globals["lobes_ub"].ty, 0, 3)]


def numpy_results(module, samples, lights, lobes):
    nt = get_target("numpy")
    resources = {"lights": nt.unpack_buffer(module.structs["Light"], lights),
                 "lobes_ub": nt.unpack_buffer(module.structs["Lobe"], lobes)}
    emitted = nt.emit(list(module.structs.values()), list(module.functions.values()), globals_of(module))
    fns = nt.load(emitted, np.float32, resources)
    return np.asarray(fns["eval_sample"](samples[:, 0].astype(np.int32), samples[:, 1]), np.float64)


def gpu_results(device, module, samples, lights, lobes):
    import vulkan as vk

    from generator.runtime.compute import STORAGE, UNIFORM, ComputePipeline
    from generator.toolchain import CompileJob, compile_many

    jobs = []
    for lang, shell in SHELL.items():
        t = get_target(lang)
        functions = t.emit(list(module.structs.values()), list(module.functions.values()), globals_of(module)).text
        jobs.append(CompileJob(f"ext_gpu.{lang}", lang, "comp",
                               shell.format(header=t.header(), functions=functions, f=t.ident("eval_sample"))))
    compiled = compile_many(jobs)
    storage, uniform = vk.VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk.VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT
    out = {}
    for job in jobs:
        r = compiled[job.key]
        assert r.ok, "\n".join(r.errors())
        pipe = ComputePipeline(device, r.spirv, (STORAGE, STORAGE, STORAGE, UNIFORM))
        bufs = [device.buffer(samples.nbytes, storage), device.buffer(samples.nbytes, storage),
                device.buffer(lights.nbytes, storage), device.buffer(lobes.nbytes, uniform)]
        try:
            bufs[0].write(samples)
            bufs[2].write(lights)
            bufs[3].write(lobes)
            pipe.bind(bufs)
            pipe.dispatch(len(samples))
            out[job.language] = bufs[1].array(np.float32).reshape(-1, 4)[: len(samples)].astype(np.float64)
        finally:
            for b in bufs:
                b.destroy()
            pipe.destroy()
    return out


@pytest.mark.lavapipe
@pytest.mark.toolchain
def test_switch_loops_arrays_and_buffers_agree_on_lavapipe_and_numpy(device, module):
    rng = np.random.default_rng(2024)
    samples, lights, lobes = inputs(rng)
    want = numpy_results(module, samples, lights, lobes)
    assert np.isfinite(want).all()
    # every switch arm is taken: k = -1, 3, 7..9 and the default; light kinds 0..3
    assert {-1, 3, 7, 8, 9, 0, 12} <= set(samples[:, 0].astype(int).tolist())
    got = gpu_results(device, module, samples, lights, lobes)
    for lang, values in got.items():
        np.testing.assert_allclose(values, want, rtol=2e-5, atol=2e-5, err_msg=f"{lang} differs from NumPy")
    # the GPU really read the buffers: without lights the results change
    no_lights = numpy_results(module, samples, lights[:0], lobes)
    assert not np.allclose(no_lights, want)
