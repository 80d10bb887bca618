"""The Vulkan runtime on lavapipe, with the Khronos validation layer on: any validation message fails.

Without a Vulkan device these tests skip with the reason; under CI=true they fail.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tests.conftest import require_tool
from tests.lavapipe import device, no_validation_messages, open_device  # noqa: F401 (fixtures)

pytestmark = pytest.mark.lavapipe

REPO = Path(__file__).resolve().parents[2]

DOUBLE = """#version 450
layout(local_size_x = 64) in;
layout(set = 0, binding = 0, std430) readonly buffer In { float x[]; } src;
layout(set = 0, binding = 1, std430) writeonly buffer Out { float y[]; } dst;
layout(set = 0, binding = 2) uniform Params { uvec4 info; } params;
void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i < params.info.x) { dst.y[i] = 2.0 * src.x[i] + 1.0; }
}
"""


@pytest.fixture(scope="module")
def double_spirv():
    for t in ("glslc", "spirv-val", "spirv-opt"):
        require_tool(t)
    from generator.toolchain import CompileJob, compile_many

    res = compile_many([CompileJob("double.comp.glsl", "glsl", "comp", DOUBLE)])["double.comp.glsl"]
    assert res.ok, res.diagnostics
    return res.spirv


def make_pipeline(device, spirv, n):
    from generator.runtime.compute import STORAGE, UNIFORM, ComputePipeline

    vk = device.vk
    src = device.buffer(4 * n, vk.VK_BUFFER_USAGE_STORAGE_BUFFER_BIT)
    dst = device.buffer(4 * n, vk.VK_BUFFER_USAGE_STORAGE_BUFFER_BIT)
    params = device.buffer(16, vk.VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT)
    pipe = ComputePipeline(device, spirv, (STORAGE, STORAGE, UNIFORM))
    pipe.bind([src, dst, params])
    params.array(np.uint32)[:4] = (n, 0, 0, 0)
    return pipe, src, dst


def test_device_is_lavapipe_with_timestamps(device):
    assert device.name.startswith("llvmpipe")
    assert device.timestamp_bits > 0 and device.timestamp_period_ns > 0


def test_dispatch_computes_and_reads_back(device, double_spirv):
    n = 1000  # not a multiple of the workgroup size: the bounds check matters
    pipe, src, dst = make_pipeline(device, double_spirv, n)
    x = np.random.default_rng(0).normal(size=n).astype(np.float32)
    src.write(x)
    dst.array(np.float32)[:] = np.nan
    pipe.dispatch(-(-n // 64))
    np.testing.assert_array_equal(dst.array(np.float32)[:n], 2.0 * x + 1.0)


def test_timestamps_give_positive_durations(device, double_spirv):
    n = 1 << 16
    pipe, src, _ = make_pipeline(device, double_spirv, n)
    src.write(np.ones(n, np.float32))
    times = [pipe.dispatch(n // 64, timed=True) for _ in range(3)]
    assert all(np.isfinite(t) and t > 0.0 for t in times), times
    assert pipe.dispatch(n // 64) is None  # untimed dispatches return nothing


def test_validation_layer_reports_misuse(double_spirv):
    """The collector is live: a wrong descriptor type is reported (by a device of its own)."""
    from generator.runtime.compute import STORAGE, UNIFORM, ComputePipeline

    dev = open_device()
    try:
        uniform = dev.buffer(64, dev.vk.VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT)
        pipe = ComputePipeline(dev, double_spirv, (STORAGE, STORAGE, UNIFORM))
        pipe.bind([uniform, uniform, uniform])  # uniform-only buffers written as storage descriptors
    finally:
        dev.close()
    assert any(m.severity == "error" and "VkWriteDescriptorSet" in m.id_name for m in dev.messages), dev.messages


@pytest.mark.parametrize("fails", ["host_memory_type", "vkMapMemory"])
def test_buffer_whose_memory_fails_leaks_nothing(monkeypatch, fails):
    """A failed allocation or mapping destroys the VkBuffer (and frees the memory): closing reports no leak."""
    dev = open_device()
    try:
        def fail(*args):
            raise MemoryError("out of host memory (test)")

        monkeypatch.setattr(dev if fails == "host_memory_type" else dev.vk, fails, fail)
        with pytest.raises(MemoryError):
            dev.buffer(1 << 16, dev.vk.VK_BUFFER_USAGE_STORAGE_BUFFER_BIT)
        monkeypatch.undo()
    finally:
        dev.close()
    assert dev.messages == [], "\n".join(map(str, dev.messages))


@pytest.mark.toolchain  # compiles eval kernels
def test_eval_kernel_chunks_large_inputs(device, eval_session):
    """Inputs beyond one dispatch's workgroup limit run in chunks with the same results."""
    from generator.eval.evaluate import _param_block, gpu_kernel, program, resolve_params

    spec = "lambert+blinn_phong_normalized"
    ep = program(spec)
    kernel = gpu_kernel(spec, "glsl", None, eval_session)
    rng = np.random.default_rng(3)
    vecs = [rng.normal(size=(1000, 3)).astype(np.float32) for _ in range(3)]
    block = _param_block(ep, resolve_params(ep, {"n": 20.0}))
    whole = kernel.run(vecs, block)
    limit, kernel.max_samples = kernel.max_samples, 128
    try:
        chunked = kernel.run(vecs, block)
    finally:
        kernel.max_samples = limit
    np.testing.assert_array_equal(chunked, whole)


@pytest.mark.toolchain  # compiles eval kernels
def test_eval_kernel_chunks_respect_max_storage_buffer_range(device, eval_session):
    """A chunk's samples and results each fit one storage descriptor (lavapipe: 128 MiB, 2.8 M samples)."""
    from types import SimpleNamespace

    from generator.library.bricks import load_library
    from generator.eval.evaluate import gpu_kernel
    from generator.runtime.eval_kernel import WORKGROUP, max_dispatch_samples

    limit = int(device.limits.maxStorageBufferRange)
    groups = int(device.limits.maxComputeWorkGroupCount[0])
    probes = load_library([REPO / "tests" / "bricks" / "eval"])
    for spec, lib, vec4s in (("lambert", None, 3), ("tangent_probe", probes, 4)):  # (L, V, N), (L, V, N, T)
        kernel = gpu_kernel(spec, "glsl", lib, eval_session)
        assert kernel.vec4s_per_sample == vec4s
        assert kernel.max_samples == min(groups * WORKGROUP, limit // (16 * vec4s))
        assert 16 * vec4s * kernel.max_samples <= limit and 16 * kernel.max_samples <= limit
    small = SimpleNamespace(maxStorageBufferRange=1 << 20, maxComputeWorkGroupCount=(65535, 1, 1))
    assert max_dispatch_samples(small, 4) == (1 << 20) // 64
    wide = SimpleNamespace(maxStorageBufferRange=(1 << 32) - 1, maxComputeWorkGroupCount=(100, 1, 1))
    assert max_dispatch_samples(wide, 3) == 100 * WORKGROUP


@pytest.mark.toolchain  # compiles eval kernels
def test_eval_kernel_times_loaded_samples_and_releases_buffers(device, eval_session):
    from generator.eval.evaluate import _param_block, gpu_kernel, program, resolve_params

    spec = "lambert"
    ep = program(spec)
    kernel = gpu_kernel(spec, "wgsl", None, eval_session)
    block = _param_block(ep, resolve_params(ep, {}))
    vecs = [np.tile(np.float32([0.0, 0.0, 1.0]), (4096, 1))] * 3
    kernel.load(vecs, block)
    times = kernel.time(3)
    assert len(times) == 3 and all(np.isfinite(t) and t > 0.0 for t in times), times
    kernel.release()
    with pytest.raises(ValueError, match="load"):
        kernel.time()
    np.testing.assert_allclose(kernel.run(vecs, block), np.full((4096, 3), 0.5 / np.pi), rtol=1e-6)
