"""Sampled images and the one sampler of the project, on a :class:`~.device.Device`.

:class:`Image` is a sampled 2D or cube image (level 0 only) uploaded from a NumPy array
through a staging buffer; :class:`Sampler` is the one filter the project uses, exactly the
one the NumPy target reproduces (generator/backends/numpy/resources.py): bilinear,
clamp-to-edge, texel centres at (i + 0.5) / W, level 0.
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


class Image:
    """A sampled image of level 0 only: 2D, or cube (6 layers, CUBE_COMPATIBLE, a CUBE view).

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

    def __init__(self, device: "Device", data, srgb: bool = False, cube: bool | None = None):
        vk = device.vk
        arr, self.cube = texels(data, cube)
        self.device, self.srgb = device, bool(srgb)
        self.layers, self.height, self.width = arr.shape[:3]
        self.dtype = arr.dtype
        self.format = _image_format(vk, arr.dtype, self.srgb)
        self.layout = vk.VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL
        self.nbytes = arr.nbytes
        feats = vk.vkGetPhysicalDeviceFormatProperties(device.physical, self.format).optimalTilingFeatures
        need = (vk.VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT | vk.VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT
                | FORMAT_FEATURE_TRANSFER_DST)
        if feats & need != need:
            raise VulkanUnavailable(f"{device.name} cannot sample format {self.format} with linear filtering "
                                    "from optimal tiling")
        self._realize(arr)

    def _realize(self, arr: np.ndarray) -> None:
        """Create the image, its memory and view from the attributes (format, width, height, layers, cube,
        aspect, layout), upload `arr` (its texels already checked) and hand the image to its device; on
        any failure release what was made (destroy) and re-raise."""
        self.handle = self.memory = self.view = None
        try:
            self._create()
            self._upload_staged(arr)
        except BaseException:
            self.destroy()
            raise
        self.device.own(self)

    def _create(self) -> None:
        """vkCreateImage (level 0, optimal tiling, SAMPLED | TRANSFER_DST; CUBE_COMPATIBLE for a cube),
        device-local memory and a 2D or CUBE view of the aspect; each handle is set as soon as it exists, so
        that destroy releases a partial creation."""
        vk, dev = self.device.vk, self.device.handle
        self.handle = vk.vkCreateImage(dev, vk.VkImageCreateInfo(
            flags=vk.VK_IMAGE_CREATE_CUBE_COMPATIBLE_BIT if self.cube else 0,
            imageType=vk.VK_IMAGE_TYPE_2D, format=self.format,
            extent=vk.VkExtent3D(width=self.width, height=self.height, depth=1),
            mipLevels=1, arrayLayers=self.layers, samples=vk.VK_SAMPLE_COUNT_1_BIT,
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
        return vk.VkImageSubresourceRange(aspectMask=getattr(vk, self.aspect), baseMipLevel=0, levelCount=1,
                                          baseArrayLayer=0, layerCount=self.layers)

    def upload(self, data) -> None:
        """Replace all texels (same shape and dtype) through a staging buffer; waits for the copy."""
        arr, _ = texels(data, self.cube)
        if arr.shape != (self.layers, self.height, self.width, 4) or arr.dtype != self.dtype:
            raise ValueError(f"upload of {arr.shape} {arr.dtype} into an image of "
                             f"{(self.layers, self.height, self.width, 4)} {self.dtype}")
        self._upload_staged(arr)

    def _upload_staged(self, arr: np.ndarray) -> None:
        """Copy `arr` (the bytes of every layer, tightly packed, already checked) into the image's aspect
        through a staging buffer, UNDEFINED → TRANSFER_DST_OPTIMAL → :attr:`layout`; waits for the copy."""
        vk, device = self.device.vk, self.device
        staging = device.buffer(arr.nbytes, vk.VK_BUFFER_USAGE_TRANSFER_SRC_BIT)
        try:
            staging.write(arr)
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
            # Tightly packed layers one after another: one region covers them all.
            region = vk.VkBufferImageCopy(
                bufferOffset=0, bufferRowLength=0, bufferImageHeight=0,
                imageSubresource=vk.VkImageSubresourceLayers(aspectMask=getattr(vk, self.aspect), mipLevel=0,
                                                             baseArrayLayer=0, layerCount=self.layers),
                imageOffset=vk.VkOffset3D(x=0, y=0, z=0),
                imageExtent=vk.VkExtent3D(width=self.width, height=self.height, depth=1))

            def record(cmd):
                vk.vkCmdPipelineBarrier(cmd, vk.VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, vk.VK_PIPELINE_STAGE_TRANSFER_BIT,
                                        0, 0, None, 0, None, 1, [to_dst])
                vk.vkCmdCopyBufferToImage(cmd, staging.handle, self.handle, vk.VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                                          1, [region])
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


class Sampler:
    """The project's one sampler: exactly the filter the NumPy target reproduces.

    VK_FILTER_LINEAR for min and mag (bilinear), mipmapMode NEAREST, minLod =
    maxLod = 0 (level 0 only), VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE on u, v and w,
    normalized coordinates (texel i's centre at (i + 0.5) / W), no anisotropy,
    no compare. generator/backends/numpy/resources.py computes the same bilinear
    clamp-to-edge fetch with exact float64 weights; a GPU rounds the weights to
    its sub-texel precision (see tests/runtime/test_runtime_images.py for lavapipe's).
    Cube views filter seamlessly across faces in Vulkan; the NumPy target clamps
    within a face, so they differ within half a texel of a face edge.
    Owned by its device: released by Device.close unless destroyed earlier.
    """

    # No depth comparison (ComparisonSampler sets one); the border colour is never read (clamp-to-edge).
    compare_op: str | None = None
    border_color = "VK_BORDER_COLOR_FLOAT_TRANSPARENT_BLACK"

    def __init__(self, device: "Device"):
        vk = device.vk
        self.device = device
        clamp = vk.VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE
        self.handle = vk.vkCreateSampler(device.handle, vk.VkSamplerCreateInfo(
            magFilter=vk.VK_FILTER_LINEAR, minFilter=vk.VK_FILTER_LINEAR,
            mipmapMode=vk.VK_SAMPLER_MIPMAP_MODE_NEAREST,
            addressModeU=clamp, addressModeV=clamp, addressModeW=clamp, mipLodBias=0.0,
            anisotropyEnable=vk.VK_FALSE, maxAnisotropy=1.0,
            compareEnable=vk.VK_FALSE if self.compare_op is None else vk.VK_TRUE,
            compareOp=getattr(vk, self.compare_op or "VK_COMPARE_OP_ALWAYS"), minLod=0.0, maxLod=0.0,
            borderColor=getattr(vk, self.border_color), unnormalizedCoordinates=vk.VK_FALSE), None)
        device.own(self)

    def destroy(self) -> None:
        dev = self.device.handle
        if dev is None or self.handle is None:
            return
        if self in self.device._owned:
            self.device._owned.remove(self)
        self.device.vk.vkDestroySampler(dev, self.handle, None)
        self.handle = None
