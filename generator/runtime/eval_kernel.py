"""Eval kernels on the device: a BRDF spec's compute kernel in one language, fed samples, read back.

Buffer layout (docs/design/runtime.md, "Eval kernels"): binding 0 the samples, 3 vec4s per
sample (L, V, N) or 4 with T (xyz; w unused); binding 1 the result, one vec4
per sample (f_r in xyz); binding 2 a uniform block: uvec4 info (x = sample
count) then the parameters packed in vec4s (link.interface.layout); for kernels that sample
textures, texture k's image at binding 3 + 2k (SAMPLED_IMAGE) and its sampler at
4 + 2k (SAMPLER). The w of the first vec4 (L.w) carries an optional per-sample
id as a float (0 when none is given: the switch kernel reads ``int(L.w)`` as
its BRDF id). Buffers grow as needed and are reused between runs. A dispatch
covers at most maxComputeWorkGroupCount[0] workgroups of 64, and each storage
buffer at most maxStorageBufferRange bytes (lavapipe: 128 MiB, 2.8 M samples),
so larger inputs run in chunks.

Kernels run on the device of an :class:`EvalSession`, which whoever evaluates
makes and closes; it keeps the kernels it compiled, so repeated evaluations
compile and create each pipeline once.
"""
from __future__ import annotations

import hashlib
from collections import OrderedDict
from dataclasses import dataclass

import numpy as np

from ..lang.errors import UserError
from .compute import SAMPLED_IMAGE, SAMPLER, STORAGE, UNIFORM, ComputePipeline
from .device import Device, validation_requested
from .images import Image, texels

WORKGROUP = 64  # local_size_x of backends/*/templates/eval.*.j2
TEXTURE_BINDING = 3  # texture k: image at TEXTURE_BINDING + 2k, its sampler at TEXTURE_BINDING + 2k + 1
MAX_EXACT_ID = 1 << 24  # ids travel as float32 in L.w: exact for |id| <= 2^24
TEXTURE_CACHE_BYTES = 256 << 20  # uploaded images one kernel keeps (least recently used go first)


def texture_bindings(k: int) -> tuple[int, int]:
    """(image binding, sampler binding) of texture k in an eval kernel's set 0."""
    return TEXTURE_BINDING + 2 * k, TEXTURE_BINDING + 2 * k + 1


@dataclass(frozen=True, eq=False)
class Texture:
    """One texture input of an eval kernel.

    `data`: (H, W, C) for a 2D texture or (6, H, W, C) for a cube (faces +X, -X,
    +Y, -Y, +Z, -Z), C ≤ 4 (missing channels read 0, alpha 1), float32 (other
    floats are converted) or uint8. `srgb`: uint8 texels are sRGB-encoded and the
    sampler decodes rgb (R8G8B8A8_SRGB); otherwise uint8 is UNORM and float32
    linear. `cube`: None infers it from the rank.

    EvalKernel.run/load take a list of these, or in their place a bare array
    (linear) or an ``(array, srgb)`` tuple.
    """

    data: np.ndarray
    srgb: bool = False
    cube: bool | None = None

    @staticmethod
    def of(t) -> "Texture":
        if isinstance(t, Texture):
            return t
        if isinstance(t, tuple):
            if len(t) != 2 or not isinstance(t[1], (bool, np.bool_)):
                raise TypeError("a texture tuple is (array, srgb: bool)")
            return Texture(t[0], bool(t[1]))
        return Texture(t)


class KernelError(UserError, RuntimeError):
    """An eval kernel failed to compile or validate: a brick one compiler rejects (or a generator bug)."""


def max_dispatch_samples(limits, vec4s_per_sample: int) -> int:
    """Samples one dispatch takes: the workgroup count, and each storage buffer within maxStorageBufferRange."""
    storage = int(limits.maxStorageBufferRange)
    return min(int(limits.maxComputeWorkGroupCount[0]) * WORKGROUP,
               storage // (16 * vec4s_per_sample),  # the samples buffer
               storage // 16)  # the result buffer, one vec4 per sample


class EvalKernel:
    """One compiled eval kernel: `run` evaluates f_r for a batch of samples.

    `textures` is how many textures the kernel samples: set 0 is then 0 samples
    (storage), 1 result (storage), 2 params (uniform), and for texture k the image
    at 3 + 2k (SAMPLED_IMAGE) and its sampler at 4 + 2k (SAMPLER; every texture
    gets the device's one filter, :class:`~.device.Sampler`). Uploaded images are
    cached per content (shape, dtype, sRGB flag and a BLAKE2 digest of the bytes),
    so runs with the same arrays upload once; arrays changed in place upload again.
    """

    def __init__(self, device: Device, spirv: bytes, tangent: bool, param_vec4s: int, textures: int = 0):
        vk = device.vk
        self.device, self.tangent = device, tangent
        self.vec4s_per_sample = 4 if tangent else 3
        self.param_vec4s = max(param_vec4s, 1)
        self.textures = int(textures)
        if self.textures < 0:
            raise ValueError(f"textures must be >= 0, got {textures}")
        self.pipeline = ComputePipeline(device, spirv,
                                        (STORAGE, STORAGE, UNIFORM) + (SAMPLED_IMAGE, SAMPLER) * self.textures)
        self.max_samples = max_dispatch_samples(device.limits, self.vec4s_per_sample)
        self.params = device.buffer(16 * (1 + self.param_vec4s), vk.VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT)
        self.sampler = device.sampler() if self.textures else None
        self.samples = self.result = None
        self.capacity = self.count = 0
        self.bound: list[Image] | None = None  # the images bound at 3, 5, ... (None: none yet)
        self._images: OrderedDict = OrderedDict()  # content key -> Image, least recently used first
        self.uploads = 0  # images uploaded so far (the cache's misses)

    def _reserve(self, n: int) -> None:
        if n <= self.capacity:
            return
        vk = self.device.vk
        self.release()
        usage = vk.VK_BUFFER_USAGE_STORAGE_BUFFER_BIT
        self.samples = self.device.buffer(16 * self.vec4s_per_sample * n, usage)
        self.result = self.device.buffer(16 * n, usage)
        self.capacity = n
        self.pipeline.bind({0: self.samples, 1: self.result, 2: self.params})

    # ------------------------------------------------------------ textures
    def _upload(self, texture) -> Image:
        t = Texture.of(texture)
        arr, cube = texels(t.data, t.cube)
        digest = hashlib.blake2b(memoryview(arr).cast("B"), digest_size=16).digest()
        key = (arr.shape, arr.dtype.str, bool(t.srgb), cube, digest)
        img = self._images.get(key)
        if img is not None and img.handle is not None:
            self._images.move_to_end(key)
            return img
        img = self.device.image(arr, srgb=t.srgb, cube=cube)
        self.uploads += 1
        self._images[key] = img
        return img

    def _evict(self, keep=()) -> None:
        """Destroy least recently used images beyond TEXTURE_CACHE_BYTES, never bound ones or `keep`."""
        keep = {id(i) for i in list(self.bound or ()) + list(keep)}
        total = sum(i.nbytes for i in self._images.values())
        for key in list(self._images):
            if total <= TEXTURE_CACHE_BYTES:
                break
            img = self._images[key]
            if id(img) in keep:
                continue
            total -= img.nbytes
            img.destroy()
            del self._images[key]

    def bind_textures(self, textures) -> None:
        """Upload (or find cached) and bind the kernel's `textures` inputs, one per texture it samples."""
        textures = list(textures)
        if len(textures) != self.textures:
            raise ValueError(f"the kernel samples {self.textures} texture(s), got {len(textures)}")
        images = [self._upload(t) for t in textures]
        res = {}
        for k, img in enumerate(images):
            bi, bs = texture_bindings(k)
            res[bi], res[bs] = img, self.sampler
        self.bound = images
        if res:
            self.pipeline.bind(res)
            self._evict()

    # ------------------------------------------------------------ samples
    def load(self, vectors: list[np.ndarray], block: np.ndarray, lo: int = 0, hi: int | None = None,
             ids: np.ndarray | None = None, textures=None) -> None:
        """Copy samples lo:hi of float32 arrays [L, V, N(, T)] (N, 3) and the parameter block to the device.

        `ids`: optional int array (N,) whose samples lo:hi go, as floats, into L.w (else L.w = 0).
        `textures`: one input per texture the kernel samples (see :class:`Texture`); None keeps
        the ones bound by the previous load/run (a kernel with textures needs them once).
        """
        hi = len(vectors[0]) if hi is None else hi
        if hi - lo > self.max_samples:
            raise ValueError(f"one dispatch takes at most {self.max_samples} samples, got {hi - lo}")
        w = None if ids is None else _ids(ids, len(vectors[0]))
        self._prepare_textures(textures)
        self._fill(vectors, block, lo, hi, w)

    def _prepare_textures(self, textures) -> None:
        if textures is not None:
            self.bind_textures(textures)
        elif self.textures and self.bound is None:
            raise ValueError(f"the kernel samples {self.textures} texture(s): pass textures=[...]")

    def _fill(self, vectors, block, lo: int, hi: int, w: np.ndarray | None) -> None:
        n = hi - lo
        self._reserve(n)
        s = self.samples.array(np.float32)[: n * self.vec4s_per_sample * 4].reshape(n, self.vec4s_per_sample, 4)
        for k, v in enumerate(vectors[: self.vec4s_per_sample]):
            s[:, k, :3] = v[lo:hi]
            s[:, k, 3] = 0.0
        if w is not None:
            s[:, 0, 3] = w[lo:hi]
        p = self.params.array(np.uint32)
        p[:4] = (n, 0, 0, 0)
        self.params.array(np.float32)[4: 4 + block.size] = block.reshape(-1)
        self.count = n

    def run(self, vectors: list[np.ndarray], block: np.ndarray, ids: np.ndarray | None = None,
            textures=None) -> np.ndarray:
        """f_r (N, 3) float32 for float32 arrays [L, V, N(, T)] of shape (N, 3) and a parameter block.

        `ids` (N,) ints go into L.w; `textures` are the kernel's texture inputs (see :meth:`load`).
        """
        count = len(vectors[0])
        out = np.empty((count, 3), np.float32)
        w = None if ids is None else _ids(ids, count)
        self._prepare_textures(textures)
        for lo in range(0, count, self.max_samples):
            hi = min(count, lo + self.max_samples)
            self._fill(vectors, block, lo, hi, w)
            self.pipeline.dispatch(-(-(hi - lo) // WORKGROUP))
            out[lo:hi] = self.result.array(np.float32)[: 4 * (hi - lo)].reshape(-1, 4)[:, :3]
        return out

    def time(self, repeats: int = 1) -> list[float]:
        """Device seconds of `repeats` dispatches over the loaded samples (timestamp queries)."""
        if not self.count:
            raise ValueError("load() samples before timing")
        groups = -(-self.count // WORKGROUP)
        return [self.pipeline.dispatch(groups, timed=True) for _ in range(repeats)]

    def release(self, textures: bool = False) -> None:
        """Free the sample and result buffers (the pipeline stays; the next load allocates again).

        With `textures`, also the cached images (the next load/run then needs textures again).
        """
        for b in (self.samples, self.result):
            if b is not None:
                b.destroy()
        self.samples = self.result = None
        self.capacity = self.count = 0
        if textures:
            for img in self._images.values():
                img.destroy()
            self._images.clear()
            self.bound = None


def _ids(ids, count: int) -> np.ndarray:
    """Per-sample ids (count,) as the float32 L.w carries them: integers, exact in float32."""
    a = np.asarray(ids)
    if a.shape != (count,):
        raise ValueError(f"ids must have shape ({count},), got {a.shape}")
    if a.dtype.kind not in "iub":
        raise TypeError(f"ids must be integers, got {a.dtype}")
    if a.size and np.abs(a.astype(np.int64)).max() > MAX_EXACT_ID:
        raise ValueError(f"ids travel as float32 in L.w: |id| must be <= {MAX_EXACT_ID}")
    return a.astype(np.float32)


def compile_kernel(source, device: Device, tangent: bool, param_vec4s: int, textures: int = 0) -> EvalKernel:
    """Compile one composed eval Source (validated, spirv-opt -O) and create its pipeline.

    `textures`: how many textures the kernel samples (set 0 bindings 3 + 2k and 4 + 2k, see EvalKernel).
    A kernel using 16-bit floats (an fp16 kernel: SPIR-V Float16) needs a device with fp16 (Device.fp16):
    its pipeline raises runtime.device.Fp16Unsupported otherwise (Device.fit_spirv).
    """
    from ..toolchain import CompileJob, compile_many

    key = f"eval-{hashlib.sha256(source.text.encode()).hexdigest()[:12]}.comp.{source.language}"
    job = CompileJob(key, source.language, "comp", source.text, line_map=tuple(map(tuple, source.line_map)))
    res = compile_many([job])[key]
    if not res.ok:
        raise KernelError(f"the {source.language} eval kernel does not compile: "
                          + "; ".join(e.replace("\n", " ") for e in res.errors())
                          + " — fix the brick at that line (or evaluate with another --target)")
    return EvalKernel(device, res.spirv, tangent, param_vec4s, textures)  # ComputePipeline fits its capabilities


class EvalSession:
    """The device eval kernels run on, and what is compiled for it: owned by whoever evaluates on the GPU (the
    `eval` and `accuracy` commands make one per run, a test session one for its tests) and closed by it.

    The device opens on first use (a session that runs nothing on the GPU opens none), with the validation layer
    on when `validation` is True (None: when SHADERMATRIX_VALIDATION=1). Kernels are kept per key (`kernels`,
    the EvalKernel of a spec in a language, which lives on this device), and SPIR-V per source (`spirv`), so
    repeated evaluations compile and create each pipeline once; closing the session destroys them with the
    device. Use as a context manager, or call close().
    """

    def __init__(self, validation: bool | None = None):
        self.validation = validation_requested() if validation is None else validation
        self.kernels: dict = {}  # key -> EvalKernel on self.device
        self.spirv: dict = {}  # (language, source text, overrides) -> SPIR-V of a shade-style kernel
        self._device: Device | None = None
        self.closed = False

    @property
    def device(self) -> Device:
        """This session's device (opened now if it is not yet: VulkanUnavailable without one)."""
        if self.closed:
            raise RuntimeError("this eval session is closed: make a new EvalSession")
        if self._device is None:
            self._device = Device(validation=self.validation)
        return self._device

    @property
    def opened(self) -> bool:
        """Whether the device is open (a session that ran nothing on the GPU has none)."""
        return self._device is not None

    def release(self) -> None:
        """Free what the kept kernels hold between runs (sample and result buffers, uploaded images): their
        pipelines stay, the next run allocates again."""
        for k in self.kernels.values():
            if isinstance(k, EvalKernel):
                k.release(textures=True)

    def close(self) -> None:
        """Destroy the kernels and close the device (its tear-down's validation messages stay in its messages)."""
        self.kernels.clear()  # their buffers and pipelines are the device's: it destroys them
        self.spirv.clear()
        if self._device is not None:
            self._device.close()
        self.closed = True

    def __enter__(self) -> EvalSession:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
