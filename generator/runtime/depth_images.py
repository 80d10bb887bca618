"""Depth images read through a comparison sampler: hardware percentage-closer filtering.

A brick's `texture2d_shadow` is a depth image and a comparison sampler (generator/lang/types.py): its
`sample_compare(t, uv, ref)` asks the sampler to compare `ref` with each texel of the bilinear 2×2
footprint (compareOp LESS_OR_EQUAL: 1 where ref <= stored depth) and to filter the four results with the
bilinear weights (Vulkan, "Depth Compare Operation", then "Texel Filtering"). That is Reeves, Salesin &
Cook 1987's percentage-closer filter over 2 × 2 texels, done by the texture unit; the NumPy target
reproduces it (generator/targets/numpy_resources.py, _tex2d_compare).

:class:`DepthImage` is a D32_SFLOAT image uploaded from (H, W) depths (the renderer's depth pass draws
into a :class:`~.rendertarget.DepthTarget` instead; this one serves stand-ins and tests);
:class:`ComparisonSampler` is the sampler both are read through. Both subclass the project's
:class:`~.images.Image` and :class:`~.images.Sampler`, so every descriptor path that binds those binds
these (SAMPLED_IMAGE and SAMPLER bindings: the comparison is the sampler's, not the descriptor type's).
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .device import VulkanUnavailable
from .images import Image, Sampler

if TYPE_CHECKING:
    from .device import Device

DEPTH_FORMAT = "VK_FORMAT_D32_SFLOAT"
_FORMAT_FEATURE_TRANSFER_DST = 0x00008000  # core in Vulkan 1.1; the binding has only a _KHR alias


def depth_compare_filterable(device: "Device") -> bool:
    """Whether the device samples D32_SFLOAT with linear filtering (what a linear comparison sampler needs)."""
    vk = device.vk
    feats = vk.vkGetPhysicalDeviceFormatProperties(device.physical, getattr(vk, DEPTH_FORMAT)).optimalTilingFeatures
    need = vk.VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT | vk.VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT
    return feats & need == need


class DepthImage(Image):
    """A sampled D32_SFLOAT image of level 0 from (H, W) depths in [0, 1] (the depth aspect, SHADER_READ_ONLY).

    Depths outside [0, 1] are refused: a copy into a D32_SFLOAT depth aspect must stay in [0, 1] without
    VK_EXT_depth_range_unrestricted. Owned by its device: released by Device.close unless destroyed earlier.
    """

    def __init__(self, device: "Device", depth):  # no super().__init__: a depth upload, not a colour one
        vk = device.vk
        d = np.ascontiguousarray(np.asarray(depth, np.float32))
        if d.ndim != 2 or d.shape[0] < 1 or d.shape[1] < 1:
            raise ValueError(f"a depth image is (H, W) with H, W ≥ 1, got shape {d.shape}")
        if not (np.isfinite(d).all() and d.min() >= 0.0 and d.max() <= 1.0):
            raise ValueError("depths must lie in [0, 1] (a D32_SFLOAT depth aspect without "
                             "VK_EXT_depth_range_unrestricted)")
        self.device, self.srgb, self.cube = device, False, False
        self.layers, (self.height, self.width) = 1, d.shape
        self.dtype = d.dtype
        self.format = getattr(vk, DEPTH_FORMAT)
        self.layout = vk.VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL
        self.nbytes = d.nbytes
        feats = vk.vkGetPhysicalDeviceFormatProperties(device.physical, self.format).optimalTilingFeatures
        if not depth_compare_filterable(device) or not feats & _FORMAT_FEATURE_TRANSFER_DST:
            raise VulkanUnavailable(f"{device.name} cannot upload and linearly filter {DEPTH_FORMAT}: no "
                                    "comparison sampling of a depth image")
        self.handle = self.memory = self.view = None
        dev = device.handle
        try:
            self.handle = vk.vkCreateImage(dev, vk.VkImageCreateInfo(
                imageType=vk.VK_IMAGE_TYPE_2D, format=self.format,
                extent=vk.VkExtent3D(width=self.width, height=self.height, depth=1), mipLevels=1, arrayLayers=1,
                samples=vk.VK_SAMPLE_COUNT_1_BIT, tiling=vk.VK_IMAGE_TILING_OPTIMAL,
                usage=vk.VK_IMAGE_USAGE_SAMPLED_BIT | vk.VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                sharingMode=vk.VK_SHARING_MODE_EXCLUSIVE, initialLayout=vk.VK_IMAGE_LAYOUT_UNDEFINED), None)
            req = vk.vkGetImageMemoryRequirements(dev, self.handle)
            self.memory = vk.vkAllocateMemory(dev, vk.VkMemoryAllocateInfo(
                allocationSize=req.size, memoryTypeIndex=device.local_memory_type(req.memoryTypeBits)), None)
            vk.vkBindImageMemory(dev, self.handle, self.memory, 0)
            self.view = vk.vkCreateImageView(dev, vk.VkImageViewCreateInfo(
                image=self.handle, format=self.format, viewType=vk.VK_IMAGE_VIEW_TYPE_2D,
                components=vk.VkComponentMapping(**dict.fromkeys("rgba", vk.VK_COMPONENT_SWIZZLE_IDENTITY)),
                subresourceRange=self._range()), None)
            self.upload(d)
        except BaseException:
            self.destroy()
            raise
        device.own(self)

    def _range(self):
        vk = self.device.vk
        return vk.VkImageSubresourceRange(aspectMask=vk.VK_IMAGE_ASPECT_DEPTH_BIT, baseMipLevel=0, levelCount=1,
                                          baseArrayLayer=0, layerCount=1)

    def upload(self, depth) -> None:
        """Replace all depths ((H, W) float32 in [0, 1]) through a staging buffer; waits for the copy."""
        vk, device = self.device.vk, self.device
        d = np.ascontiguousarray(np.asarray(depth, np.float32))
        if d.shape != (self.height, self.width):
            raise ValueError(f"upload of {d.shape} depths into a {self.height}x{self.width} depth image")
        staging = device.buffer(d.nbytes, vk.VK_BUFFER_USAGE_TRANSFER_SRC_BIT)
        ignored = vk.VK_QUEUE_FAMILY_IGNORED
        try:
            staging.write(d)
            rng = self._range()
            to_dst = vk.VkImageMemoryBarrier(
                srcAccessMask=0, dstAccessMask=vk.VK_ACCESS_TRANSFER_WRITE_BIT,
                oldLayout=vk.VK_IMAGE_LAYOUT_UNDEFINED, newLayout=vk.VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                srcQueueFamilyIndex=ignored, dstQueueFamilyIndex=ignored, image=self.handle, subresourceRange=rng)
            to_read = vk.VkImageMemoryBarrier(
                srcAccessMask=vk.VK_ACCESS_TRANSFER_WRITE_BIT, dstAccessMask=vk.VK_ACCESS_SHADER_READ_BIT,
                oldLayout=vk.VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, newLayout=self.layout,
                srcQueueFamilyIndex=ignored, dstQueueFamilyIndex=ignored, image=self.handle, subresourceRange=rng)
            region = vk.VkBufferImageCopy(
                bufferOffset=0, bufferRowLength=0, bufferImageHeight=0,
                imageSubresource=vk.VkImageSubresourceLayers(aspectMask=vk.VK_IMAGE_ASPECT_DEPTH_BIT, mipLevel=0,
                                                             baseArrayLayer=0, layerCount=1),
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


class ComparisonSampler(Sampler):
    """The sampler of every texture2d_shadow: the project's sampler (bilinear, clamp-to-edge, level 0) with
    compareEnable and VK_COMPARE_OP_LESS_OR_EQUAL (lit where ref <= stored depth, the shadow bricks' test).

    Bound with a depth-format image only (a comparison on a colour format is undefined in Vulkan).
    """

    def __init__(self, device: "Device"):  # no super().__init__: another VkSamplerCreateInfo
        vk = device.vk
        self.device = device
        clamp = vk.VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE
        self.handle = vk.vkCreateSampler(device.handle, vk.VkSamplerCreateInfo(
            magFilter=vk.VK_FILTER_LINEAR, minFilter=vk.VK_FILTER_LINEAR,
            mipmapMode=vk.VK_SAMPLER_MIPMAP_MODE_NEAREST,
            addressModeU=clamp, addressModeV=clamp, addressModeW=clamp, mipLodBias=0.0,
            anisotropyEnable=vk.VK_FALSE, maxAnisotropy=1.0, compareEnable=vk.VK_TRUE,
            compareOp=vk.VK_COMPARE_OP_LESS_OR_EQUAL, minLod=0.0, maxLod=0.0,
            borderColor=vk.VK_BORDER_COLOR_FLOAT_OPAQUE_WHITE, unnormalizedCoordinates=vk.VK_FALSE), None)
        device.own(self)
