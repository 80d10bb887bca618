"""Eval kernels on the device: a BRDF spec's compute kernel in one language, fed samples, read back.

Buffer layout (NOTES.md, "Eval kernel"): binding 0 the samples, 3 vec4s per
sample (L, V, N) or 4 with T (xyz; w unused); binding 1 the result, one vec4
per sample (f_r in xyz); binding 2 a uniform block: uvec4 info (x = sample
count) then one vec4 per parameter (four per mat4). Buffers grow as needed and
are reused between runs. A dispatch covers at most maxComputeWorkGroupCount[0]
workgroups of 64, and each storage buffer at most maxStorageBufferRange bytes
(lavapipe: 128 MiB, 2.8 M samples), so larger inputs run in chunks.

One process-wide device (:func:`shared_device`) carries a cache of kernels per
(language, source text), so repeated evaluations compile and create each
pipeline once.
"""
from __future__ import annotations

import hashlib

import numpy as np

from ..lang.errors import UserError
from .compute import STORAGE, UNIFORM, ComputePipeline
from .device import Device, validation_requested

WORKGROUP = 64  # local_size_x of templates/*/eval.*.j2


class KernelError(UserError, RuntimeError):
    """An eval kernel failed to compile or validate: a brick one compiler rejects (or a generator bug)."""


def max_dispatch_samples(limits, vec4s_per_sample: int) -> int:
    """Samples one dispatch takes: the workgroup count, and each storage buffer within maxStorageBufferRange."""
    storage = int(limits.maxStorageBufferRange)
    return min(int(limits.maxComputeWorkGroupCount[0]) * WORKGROUP,
               storage // (16 * vec4s_per_sample),  # the samples buffer
               storage // 16)  # the result buffer, one vec4 per sample


class EvalKernel:
    """One compiled eval kernel: `run` evaluates f_r for a batch of samples."""

    def __init__(self, device: Device, spirv: bytes, tangent: bool, param_vec4s: int):
        vk = device.vk
        self.device, self.tangent = device, tangent
        self.vec4s_per_sample = 4 if tangent else 3
        self.param_vec4s = max(param_vec4s, 1)
        self.pipeline = ComputePipeline(device, spirv, (STORAGE, STORAGE, UNIFORM))
        self.max_samples = max_dispatch_samples(device.limits, self.vec4s_per_sample)
        self.params = device.buffer(16 * (1 + self.param_vec4s), vk.VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT)
        self.samples = self.result = None
        self.capacity = self.count = 0

    def _reserve(self, n: int) -> None:
        if n <= self.capacity:
            return
        vk = self.device.vk
        self.release()
        usage = vk.VK_BUFFER_USAGE_STORAGE_BUFFER_BIT
        self.samples = self.device.buffer(16 * self.vec4s_per_sample * n, usage)
        self.result = self.device.buffer(16 * n, usage)
        self.capacity = n
        self.pipeline.bind([self.samples, self.result, self.params])

    def load(self, vectors: list[np.ndarray], block: np.ndarray, lo: int = 0, hi: int | None = None) -> None:
        """Copy samples lo:hi of float32 arrays [L, V, N(, T)] (N, 3) and the parameter block to the device."""
        hi = len(vectors[0]) if hi is None else hi
        n = hi - lo
        if n > self.max_samples:
            raise ValueError(f"one dispatch takes at most {self.max_samples} samples, got {n}")
        self._reserve(n)
        s = self.samples.array(np.float32)[: n * self.vec4s_per_sample * 4].reshape(n, self.vec4s_per_sample, 4)
        for k, v in enumerate(vectors[: self.vec4s_per_sample]):
            s[:, k, :3] = v[lo:hi]
            s[:, k, 3] = 0.0
        p = self.params.array(np.uint32)
        p[:4] = (n, 0, 0, 0)
        self.params.array(np.float32)[4: 4 + block.size] = block.reshape(-1)
        self.count = n

    def run(self, vectors: list[np.ndarray], block: np.ndarray) -> np.ndarray:
        """f_r (N, 3) float32 for float32 arrays [L, V, N(, T)] of shape (N, 3) and a parameter block."""
        count = len(vectors[0])
        out = np.empty((count, 3), np.float32)
        for lo in range(0, count, self.max_samples):
            hi = min(count, lo + self.max_samples)
            self.load(vectors, block, lo, hi)
            self.pipeline.dispatch(-(-(hi - lo) // WORKGROUP))
            out[lo:hi] = self.result.array(np.float32)[: 4 * (hi - lo)].reshape(-1, 4)[:, :3]
        return out

    def time(self, repeats: int = 1) -> list[float]:
        """Device seconds of `repeats` dispatches over the loaded samples (timestamp queries)."""
        if not self.count:
            raise ValueError("load() samples before timing")
        groups = -(-self.count // WORKGROUP)
        return [self.pipeline.dispatch(groups, timed=True) for _ in range(repeats)]

    def release(self) -> None:
        """Free the sample and result buffers (the pipeline stays; the next load allocates again)."""
        for b in (self.samples, self.result):
            if b is not None:
                b.destroy()
        self.samples = self.result = None
        self.capacity = self.count = 0


def compile_kernel(source, device: Device, tangent: bool, param_vec4s: int) -> EvalKernel:
    """Compile one composed eval Source (validated, spirv-opt -O) and create its pipeline."""
    from ..toolchain import CompileJob, compile_many

    key = f"eval-{hashlib.sha256(source.text.encode()).hexdigest()[:12]}.comp.{source.language}"
    job = CompileJob(key, source.language, "comp", source.text, line_map=tuple(map(tuple, source.line_map)))
    res = compile_many([job])[key]
    if not res.ok:
        raise KernelError(f"the {source.language} eval kernel does not compile: "
                          + "; ".join(e.replace("\n", " ") for e in res.errors())
                          + " — fix the brick at that line (or evaluate with another --target)")
    return EvalKernel(device, res.spirv, tangent, param_vec4s)


_SHARED: Device | None = None


def shared_device(validation: bool | None = None) -> Device:
    """The process-wide lavapipe device (opened on first use; reopened if `validation` changes).

    ``validation=None`` keeps the open device, or opens one with the layer on
    when SHADERMATRIX_VALIDATION=1.
    """
    global _SHARED
    if _SHARED is not None and (validation is None or _SHARED.validation == validation):
        return _SHARED
    close_shared()
    _SHARED = Device(validation=validation_requested() if validation is None else validation)
    return _SHARED


def close_shared() -> None:
    """Close the process-wide device and forget its kernels."""
    global _SHARED
    if _SHARED is not None:
        _SHARED.close()
        _SHARED = None
