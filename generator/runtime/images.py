"""Sampled images and samplers, on a :class:`~.device.Device`.

:class:`Image` is a sampled 2D or cube image uploaded from NumPy arrays through a staging buffer: level 0,
and optionally the rest of its mip chain (a texture artifact's levels, io/ktx2.decode_levels).
:class:`Sampler` is by default the project's own filter, exactly the one the NumPy target reproduces
(generator/backends/numpy/resources.py): bilinear, clamp-to-edge, texel centres at (i + 0.5) / W, level 0;
given a state in Vulkan's words (a manifest's ``samplers[i].platforms.vulkan``, assemble/samplers.py) it is
that state, with what the device cannot do clamped and said in :attr:`Sampler.notes`.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .device import VulkanUnavailable

if TYPE_CHECKING:
    from .device import Device

FORMAT_FEATURE_TRANSFER_DST = 0x00008000  # core in Vulkan 1.1; the binding has only a _KHR alias, = None


def _image_format(vk, dtype, srgb: bool):
    if dtype == np.float32:
        if srgb:
            raise ValueError("srgb=True needs uint8 texels (sRGB formats are 8-bit); float data is linear")
        return vk.VK_FORMAT_R32G32B32A32_SFLOAT
    if dtype == np.float16:  # a baked fp16 table (reference/tables.py)
        if srgb:
            raise ValueError("srgb=True needs uint8 texels (sRGB formats are 8-bit); float data is linear")
        return vk.VK_FORMAT_R16G16B16A16_SFLOAT
    if dtype == np.uint8:
        return vk.VK_FORMAT_R8G8B8A8_SRGB if srgb else vk.VK_FORMAT_R8G8B8A8_UNORM
    raise TypeError(f"texels must be float32, float16 or uint8, got {dtype}")


def texels(data, cube: bool | None = None) -> tuple[np.ndarray, bool]:
    """(array, cube): `data` as a C-contiguous (layers, H, W, 4) float32, float16 or uint8 array.

    (H, W, C) is a 2D texture, (6, H, W, C) a cube (faces +X, -X, +Y, -Y, +Z, -Z, as
    Vulkan orders layers of a cube view); C ≤ 4 channels, the missing ones filled as
    Vulkan expands formats with fewer components (0, alpha 1 / 255); a 2D texture
    may also come as (1, H, W, C), the shape this returns. float16 stays (R16G16B16A16_SFLOAT),
    other float dtypes become float32; integer data other than uint8 is refused.
    """
    a = np.asarray(data)
    if cube is None:
        cube = a.ndim == 4 and a.shape[0] == 6
    if not cube and a.ndim == 4 and a.shape[0] == 1:  # already (layers, H, W, C), as this returns it
        a = a[0]
    if a.ndim != (4 if cube else 3) or (cube and a.shape[0] != 6):
        raise ValueError(f"a {'cube' if cube else '2D'} texture is {'(6, H, W, C)' if cube else '(H, W, C)'}, "
                         f"got shape {a.shape}")
    if a.dtype.kind == "f" and a.dtype not in (np.float32, np.float16):
        a = a.astype(np.float32)
    if a.dtype not in (np.float32, np.float16, np.uint8):
        raise TypeError(f"texels must be float32, float16 or uint8, got {a.dtype}")
    if not cube:
        a = a[None]
    h, w, c = a.shape[1:]
    if not (1 <= c <= 4) or h < 1 or w < 1:
        raise ValueError(f"a texture needs H, W ≥ 1 and 1-4 channels, got {a.shape[1:]}")
    if cube and h != w:
        raise ValueError(f"cube faces must be square, got {h}x{w}")
    if c < 4:
        full = np.zeros(a.shape[:3] + (4,), a.dtype)
        full[..., 3] = 255 if a.dtype == np.uint8 else 1.0
        full[..., :c] = a
        a = full
    return np.ascontiguousarray(a), bool(cube)


def _level_shape(height: int, width: int, i: int) -> tuple[int, int]:
    """Level i's (H, W) under the floor convention of Vulkan and KTX2: max(1, H >> i) × max(1, W >> i)."""
    return max(1, height >> i), max(1, width >> i)


class Image:
    """A sampled image: 2D, or cube (6 layers, CUBE_COMPATIBLE, a CUBE view); level 0, and its further mip
    levels when `mips` gives them (level i of max(1, H >> i) × max(1, W >> i) texels, same dtype and channels;
    any number of levels up to the full chain; the view covers them all).

    Formats: float32 texels are VK_FORMAT_R32G32B32A32_SFLOAT, float16 R16G16B16A16_SFLOAT; uint8 texels are
    R8G8B8A8_UNORM, or R8G8B8A8_SRGB with ``srgb=True`` (sampling then decodes
    rgb with the sRGB EOTF before filtering; alpha stays linear). `data` is
    (H, W, C) or (6, H, W, C) (see :func:`texels`). The texels go through a
    host-visible staging buffer and one one-time command buffer with the layout
    transitions UNDEFINED → TRANSFER_DST_OPTIMAL → SHADER_READ_ONLY_OPTIMAL, the
    layout the image stays in (:attr:`layout`) for compute shaders to sample.
    Owned by its device: released by Device.close unless destroyed earlier.
    """

    aspect = "VK_IMAGE_ASPECT_COLOR_BIT"  # the aspect that holds the texels (DepthImage: the depth aspect)
    levels = 1  # mip levels (the subclasses that draw or upload depth have one)

    def __init__(self, device: "Device", data, srgb: bool = False, cube: bool | None = None, mips=()):
        vk = device.vk
        arr, self.cube = texels(data, cube)
        self.device, self.srgb = device, bool(srgb)
        self.layers, self.height, self.width = arr.shape[:3]
        self.dtype = arr.dtype
        more = self._mip_levels(mips)
        self.levels = 1 + len(more)
        self.format = _image_format(vk, arr.dtype, self.srgb)
        self.layout = vk.VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL
        self.nbytes = arr.nbytes + sum(m.nbytes for m in more)
        feats = vk.vkGetPhysicalDeviceFormatProperties(device.physical, self.format).optimalTilingFeatures
        need = (vk.VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT | vk.VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT
                | FORMAT_FEATURE_TRANSFER_DST)
        if feats & need != need:
            raise VulkanUnavailable(f"{device.name} cannot sample format {self.format} with linear filtering "
                                    "from optimal tiling")
        self._realize(arr, more)

    def _mip_levels(self, mips) -> list[np.ndarray]:
        """Levels 1, 2, … as (layers, h, w, 4) arrays of this image's dtype, each checked against its size."""
        out = []
        full = max(self.width, self.height).bit_length()  # floor(log2(max(W, H))) + 1 levels down to 1 × 1
        if len(mips) >= full:
            raise ValueError(f"{1 + len(mips)} levels for a {self.width}x{self.height} image: its full chain has {full}")
        for i, m in enumerate(mips, 1):
            a, _ = texels(m, self.cube)
            want = (self.layers, *_level_shape(self.height, self.width, i), 4)
            if a.shape != want or a.dtype != self.dtype:
                raise ValueError(f"mip level {i} is {a.shape[1:3]} {a.dtype}, not {want[1:3]} {self.dtype} "
                                 f"(max(1, size >> {i}) texels of level 0's type)")
            out.append(a)
        return out

    def _realize(self, arr: np.ndarray, mips=()) -> None:
        """Create the image, its memory and view from the attributes (format, width, height, layers, cube,
        aspect, layout, levels), upload `arr` and its `mips` (the texels already checked) and hand the image
        to its device; on any failure release what was made (destroy) and re-raise."""
        self.handle = self.memory = self.view = None
        try:
            self._create()
            self._upload_staged(arr, mips)
        except BaseException:
            self.destroy()
            raise
        self.device.own(self)

    def _create(self) -> None:
        """vkCreateImage (its levels, optimal tiling, SAMPLED | TRANSFER_DST; CUBE_COMPATIBLE for a cube),
        device-local memory and a 2D or CUBE view of the aspect; each handle is set as soon as it exists, so
        that destroy releases a partial creation."""
        vk, dev = self.device.vk, self.device.handle
        self.handle = vk.vkCreateImage(dev, vk.VkImageCreateInfo(
            flags=vk.VK_IMAGE_CREATE_CUBE_COMPATIBLE_BIT if self.cube else 0,
            imageType=vk.VK_IMAGE_TYPE_2D, format=self.format,
            extent=vk.VkExtent3D(width=self.width, height=self.height, depth=1),
            mipLevels=self.levels, arrayLayers=self.layers, samples=vk.VK_SAMPLE_COUNT_1_BIT,
            tiling=vk.VK_IMAGE_TILING_OPTIMAL,
            usage=vk.VK_IMAGE_USAGE_SAMPLED_BIT | vk.VK_IMAGE_USAGE_TRANSFER_DST_BIT,
            sharingMode=vk.VK_SHARING_MODE_EXCLUSIVE, initialLayout=vk.VK_IMAGE_LAYOUT_UNDEFINED), None)
        req = vk.vkGetImageMemoryRequirements(dev, self.handle)
        self.memory = vk.vkAllocateMemory(dev, vk.VkMemoryAllocateInfo(
            allocationSize=req.size, memoryTypeIndex=self.device.local_memory_type(req.memoryTypeBits)), None)
        vk.vkBindImageMemory(dev, self.handle, self.memory, 0)
        self.view = vk.vkCreateImageView(dev, vk.VkImageViewCreateInfo(
            image=self.handle, format=self.format,
            viewType=vk.VK_IMAGE_VIEW_TYPE_CUBE if self.cube else vk.VK_IMAGE_VIEW_TYPE_2D,
            components=vk.VkComponentMapping(**dict.fromkeys("rgba", vk.VK_COMPONENT_SWIZZLE_IDENTITY)),
            subresourceRange=self._range()), None)

    def _range(self):
        vk = self.device.vk
        return vk.VkImageSubresourceRange(aspectMask=getattr(vk, self.aspect), baseMipLevel=0, levelCount=self.levels,
                                          baseArrayLayer=0, layerCount=self.layers)

    def upload(self, data, mips=()) -> None:
        """Replace all texels (same shape and dtype; `mips`: every further level the image has) through a
        staging buffer; waits for the copy."""
        arr, _ = texels(data, self.cube)
        if arr.shape != (self.layers, self.height, self.width, 4) or arr.dtype != self.dtype:
            raise ValueError(f"upload of {arr.shape} {arr.dtype} into an image of "
                             f"{(self.layers, self.height, self.width, 4)} {self.dtype}")
        more = self._mip_levels(mips)
        if 1 + len(more) != self.levels:
            raise ValueError(f"upload of {1 + len(more)} levels into an image of {self.levels}")
        self._upload_staged(arr, more)

    def _upload_staged(self, arr: np.ndarray, mips=()) -> None:
        """Copy `arr` (level 0: the bytes of every layer, tightly packed, already checked) and `mips` (levels
        1, 2, …) into the image's aspect through one staging buffer, UNDEFINED → TRANSFER_DST_OPTIMAL →
        :attr:`layout`; waits for the copy."""
        vk, device = self.device.vk, self.device
        levels = [arr, *mips]
        # each level at a multiple of 16 bytes: a copy's bufferOffset must be a multiple of the texel size
        # (4, 8 or 16 here) and of 4
        offsets = np.cumsum([0] + [-(-a.nbytes // 16) * 16 for a in levels])
        staging = device.buffer(int(offsets[-1]), vk.VK_BUFFER_USAGE_TRANSFER_SRC_BIT)
        try:
            packed = np.zeros(int(offsets[-1]), np.uint8)
            for a, at in zip(levels, offsets):
                packed[at:at + a.nbytes] = np.frombuffer(np.ascontiguousarray(a).tobytes(), np.uint8)
            staging.write(packed)
            rng = self._range()
            # Earlier submissions were waited for (Device.submit), so the first barrier needs no source
            # scope; UNDEFINED discards the old texels, all of which the copy replaces.
            to_dst = vk.VkImageMemoryBarrier(
                srcAccessMask=0, dstAccessMask=vk.VK_ACCESS_TRANSFER_WRITE_BIT,
                oldLayout=vk.VK_IMAGE_LAYOUT_UNDEFINED, newLayout=vk.VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                srcQueueFamilyIndex=vk.VK_QUEUE_FAMILY_IGNORED, dstQueueFamilyIndex=vk.VK_QUEUE_FAMILY_IGNORED,
                image=self.handle, subresourceRange=rng)
            to_read = vk.VkImageMemoryBarrier(
                srcAccessMask=vk.VK_ACCESS_TRANSFER_WRITE_BIT, dstAccessMask=vk.VK_ACCESS_SHADER_READ_BIT,
                oldLayout=vk.VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, newLayout=self.layout,
                srcQueueFamilyIndex=vk.VK_QUEUE_FAMILY_IGNORED, dstQueueFamilyIndex=vk.VK_QUEUE_FAMILY_IGNORED,
                image=self.handle, subresourceRange=rng)
            # Per level, its tightly packed layers one after another: one region covers them all.
            regions = []
            for i, at in enumerate(offsets[:-1]):
                h, w = _level_shape(self.height, self.width, i)
                regions.append(vk.VkBufferImageCopy(
                    bufferOffset=int(at), bufferRowLength=0, bufferImageHeight=0,
                    imageSubresource=vk.VkImageSubresourceLayers(aspectMask=getattr(vk, self.aspect), mipLevel=i,
                                                                 baseArrayLayer=0, layerCount=self.layers),
                    imageOffset=vk.VkOffset3D(x=0, y=0, z=0), imageExtent=vk.VkExtent3D(width=w, height=h, depth=1)))

            def record(cmd):
                vk.vkCmdPipelineBarrier(cmd, vk.VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, vk.VK_PIPELINE_STAGE_TRANSFER_BIT,
                                        0, 0, None, 0, None, 1, [to_dst])
                vk.vkCmdCopyBufferToImage(cmd, staging.handle, self.handle, vk.VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                                          len(regions), regions)
                vk.vkCmdPipelineBarrier(cmd, vk.VK_PIPELINE_STAGE_TRANSFER_BIT,
                                        vk.VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | vk.VK_PIPELINE_STAGE_VERTEX_SHADER_BIT
                                        | vk.VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT, 0, 0, None, 0, None, 1, [to_read])

            device.submit(record)
        finally:
            staging.destroy()

    def destroy(self) -> None:
        dev = self.device.handle
        if dev is None or (self.handle is None and self.memory is None):
            return
        vk = self.device.vk
        if self in self.device._owned:
            self.device._owned.remove(self)
        if self.view is not None:
            vk.vkDestroyImageView(dev, self.view, None)
        if self.handle is not None:
            vk.vkDestroyImage(dev, self.handle, None)
        if self.memory is not None:
            vk.vkFreeMemory(dev, self.memory, None)
        self.view = self.handle = self.memory = None


# the keys of a sampler state in Vulkan's words (assemble/samplers.py spells them so), as VkSamplerCreateInfo has them
STATE_KEYS = ("magFilter", "minFilter", "mipmapMode", "addressModeU", "addressModeV", "addressModeW", "mipLodBias",
              "anisotropyEnable", "maxAnisotropy", "compareEnable", "compareOp", "minLod", "maxLod")


class Sampler:
    """A sampler: by default the project's one filter, exactly the one the NumPy target reproduces; or the
    `state` given in Vulkan's words.

    Default: VK_FILTER_LINEAR for min and mag (bilinear), mipmapMode NEAREST, minLod =
    maxLod = 0 (level 0 only), VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE on u, v and w,
    normalized coordinates (texel i's centre at (i + 0.5) / W), no anisotropy,
    no compare. generator/backends/numpy/resources.py computes the same bilinear
    clamp-to-edge fetch with exact float64 weights; a GPU rounds the weights to
    its sub-texel precision (see tests/runtime/test_runtime_images.py for lavapipe's).
    Cube views filter seamlessly across faces in Vulkan; the NumPy target clamps
    within a face, so they differ within half a texel of a face edge.

    `state`: {VkSamplerCreateInfo member: value} for every key of :data:`STATE_KEYS`, enums by their names
    (``"VK_SAMPLER_ADDRESS_MODE_REPEAT"``), as a manifest's ``samplers[i].platforms.vulkan`` spells them. What
    the device cannot do is clamped, each change said in :attr:`notes`: anisotropy where the device has no
    samplerAnisotropy feature (off: maxAnisotropy 1) or past its maxSamplerAnisotropy, a LOD bias past
    maxSamplerLodBias. :attr:`state` is the state created.
    Owned by its device: released by Device.close unless destroyed earlier.
    """

    # No depth comparison (ComparisonSampler sets one); the border colour is never read (clamp-to-edge).
    compare_op: str | None = None
    border_color = "VK_BORDER_COLOR_FLOAT_TRANSPARENT_BLACK"

    def __init__(self, device: "Device", state: dict | None = None):
        vk = device.vk
        self.device = device
        self.notes: list[str] = []
        self.state = self._clamped(dict(state)) if state is not None else self._default()
        st = self.state

        def enum(key):
            return getattr(vk, st[key])

        self.handle = vk.vkCreateSampler(device.handle, vk.VkSamplerCreateInfo(
            magFilter=enum("magFilter"), minFilter=enum("minFilter"), mipmapMode=enum("mipmapMode"),
            addressModeU=enum("addressModeU"), addressModeV=enum("addressModeV"), addressModeW=enum("addressModeW"),
            mipLodBias=float(st["mipLodBias"]),
            anisotropyEnable=vk.VK_TRUE if st["anisotropyEnable"] else vk.VK_FALSE,
            maxAnisotropy=float(st["maxAnisotropy"]),
            compareEnable=vk.VK_TRUE if st["compareEnable"] else vk.VK_FALSE, compareOp=enum("compareOp"),
            minLod=float(st["minLod"]), maxLod=float(st["maxLod"]),
            borderColor=getattr(vk, self.border_color), unnormalizedCoordinates=vk.VK_FALSE), None)
        device.own(self)

    def _default(self) -> dict:
        clamp = "VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE"
        return {"magFilter": "VK_FILTER_LINEAR", "minFilter": "VK_FILTER_LINEAR",
                "mipmapMode": "VK_SAMPLER_MIPMAP_MODE_NEAREST", "addressModeU": clamp, "addressModeV": clamp,
                "addressModeW": clamp, "mipLodBias": 0.0, "anisotropyEnable": False, "maxAnisotropy": 1.0,
                "compareEnable": self.compare_op is not None, "compareOp": self.compare_op or "VK_COMPARE_OP_ALWAYS",
                "minLod": 0.0, "maxLod": 0.0}

    def _clamped(self, st: dict) -> dict:
        """`st` checked for its keys and enum names, with what the device cannot do clamped (each change a note)."""
        vk, limits = self.device.vk, self.device.limits
        missing = [k for k in STATE_KEYS if k not in st]
        if missing:
            raise ValueError(f"a sampler state without {', '.join(missing)} (VkSamplerCreateInfo's members: "
                             f"{', '.join(STATE_KEYS)})")
        for k in ("magFilter", "minFilter", "mipmapMode", "addressModeU", "addressModeV", "addressModeW", "compareOp"):
            if not (isinstance(st[k], str) and st[k].startswith("VK_") and isinstance(getattr(vk, st[k], None), int)):
                raise ValueError(f"sampler {k} {st[k]!r} is not a Vulkan enum name")
        aniso = float(st["maxAnisotropy"]) if st["anisotropyEnable"] else 1.0
        if aniso > 1.0 and not getattr(self.device, "sampler_anisotropy", False):
            self.notes.append(f"anisotropy {aniso:g} clamped to 1: {self.device.name} has no samplerAnisotropy")
            aniso = 1.0
        elif aniso > float(limits.maxSamplerAnisotropy):
            self.notes.append(f"anisotropy {aniso:g} clamped to {limits.maxSamplerAnisotropy:g}, "
                              f"{self.device.name}'s maxSamplerAnisotropy")
            aniso = float(limits.maxSamplerAnisotropy)
        st["anisotropyEnable"], st["maxAnisotropy"] = aniso > 1.0, aniso
        bias, most = float(st["mipLodBias"]), float(limits.maxSamplerLodBias)
        if abs(bias) > most:
            st["mipLodBias"] = max(-most, min(most, bias))
            self.notes.append(f"LOD bias {bias:g} clamped to {st['mipLodBias']:g}, {self.device.name}'s "
                              "maxSamplerLodBias")
        return st

    def destroy(self) -> None:
        dev = self.device.handle
        if dev is None or self.handle is None:
            return
        if self in self.device._owned:
            self.device._owned.remove(self)
        self.device.vk.vkDestroySampler(dev, self.handle, None)
        self.handle = None
