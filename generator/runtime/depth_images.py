"""Depth images read through a comparison sampler: hardware percentage-closer filtering.

A brick's `texture2d_shadow` is a depth image and a comparison sampler (generator/lang/types.py): its
`sample_compare(t, uv, ref)` asks the sampler to compare `ref` with each texel of the bilinear 2×2
footprint (compareOp LESS_OR_EQUAL: 1 where ref <= stored depth) and to filter the four results with the
bilinear weights (Vulkan, "Depth Compare Operation", then "Texel Filtering"). That is Reeves, Salesin &
Cook 1987's percentage-closer filter over 2 × 2 texels, done by the texture unit; the NumPy target
reproduces it (generator/backends/numpy/resources.py, _tex2d_compare).

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
from .images import FORMAT_FEATURE_TRANSFER_DST, Image, Sampler

if TYPE_CHECKING:
    from .device import Device

DEPTH_FORMAT = "VK_FORMAT_D32_SFLOAT"


def depth_compare_filterable(device: "Device") -> bool:
    """Whether the device samples D32_SFLOAT with linear filtering (what a linear comparison sampler needs)."""
    vk = device.vk
    feats = vk.vkGetPhysicalDeviceFormatProperties(device.physical, getattr(vk, DEPTH_FORMAT)).optimalTilingFeatures
    need = vk.VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT | vk.VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT
    return feats & need == need


class DepthImage(Image):
    """A sampled D32_SFLOAT image of level 0 from (H, W) depths in [0, 1] (the depth aspect, SHADER_READ_ONLY).

    Depths outside [0, 1] are refused: a copy into a D32_SFLOAT depth aspect must stay in [0, 1] without
    VK_EXT_depth_range_unrestricted. Created and uploaded as an :class:`~.images.Image` is (its _create and
    _upload_staged, on the depth aspect). Owned by its device: released by Device.close unless destroyed earlier.
    """

    aspect = "VK_IMAGE_ASPECT_DEPTH_BIT"

    def __init__(self, device: "Device", depth):  # no super().__init__: (H, W) depths, not colour texels
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
        if not depth_compare_filterable(device) or not feats & FORMAT_FEATURE_TRANSFER_DST:
            raise VulkanUnavailable(f"{device.name} cannot upload and linearly filter {DEPTH_FORMAT}: no "
                                    "comparison sampling of a depth image")
        self._realize(d)

    def upload(self, depth) -> None:
        """Replace all depths ((H, W) float32 in [0, 1]) through a staging buffer; waits for the copy."""
        d = np.ascontiguousarray(np.asarray(depth, np.float32))
        if d.shape != (self.height, self.width):
            raise ValueError(f"upload of {d.shape} depths into a {self.height}x{self.width} depth image")
        self._upload_staged(d)


class ComparisonSampler(Sampler):
    """The sampler of every texture2d_shadow: the project's sampler (bilinear, clamp-to-edge, level 0) with
    compareEnable and VK_COMPARE_OP_LESS_OR_EQUAL (lit where ref <= stored depth, the shadow bricks' test).

    Bound with a depth-format image only (a comparison on a colour format is undefined in Vulkan).
    """

    compare_op = "VK_COMPARE_OP_LESS_OR_EQUAL"
    border_color = "VK_BORDER_COLOR_FLOAT_OPAQUE_WHITE"


class LayeredImage(Image):
    """One 2D array image whose layer k is a copy of `sources[k]`: drawn depth targets (their sampled image,
    depth or the R32 copy) or moments targets (their blurred colour), all of one format and size — a point
    light's six faces (runtime/shadow_pass.py). Each face is drawn by the depth pass as a light's one map is,
    then copied into its layer on the device (vkCmdCopyImage: nothing goes through the host), so the pass and its
    blur stay those of one map; the view is VK_IMAGE_VIEW_TYPE_2D_ARRAY over every layer, SHADER_READ_ONLY.
    With `clear`, every layer is cleared to that value instead (sources give the format and size only: a lit
    stand-in where no light's map is bound). Owned by its device: released by Device.close unless destroyed
    earlier."""

    def __init__(self, device: "Device", sources: list, clear: float | None = None):  # no super().__init__
        vk = device.vk
        first = [_attachment_of(s) for s in sources]
        att = first[0]
        self.device, self.srgb, self.cube, self.levels = device, False, False, 1
        self.layers, self.width, self.height = len(sources), sources[0].width, sources[0].height
        self.format, self.dtype = att.format, np.float32
        self.depth_format, self.sampled = att.format, getattr(sources[0], "sampled", "depth")
        texel = 16 if att.format == vk.VK_FORMAT_R32G32B32A32_SFLOAT else 4  # moments, or one depth
        self.nbytes = texel * self.width * self.height * self.layers
        self.layout = vk.VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL
        self.handle = self.memory = self.view = None
        depth = att.format == getattr(vk, DEPTH_FORMAT)
        aspect = vk.VK_IMAGE_ASPECT_DEPTH_BIT if depth else vk.VK_IMAGE_ASPECT_COLOR_BIT
        dev = device.handle
        try:
            self.handle = vk.vkCreateImage(dev, vk.VkImageCreateInfo(
                imageType=vk.VK_IMAGE_TYPE_2D, format=self.format,
                extent=vk.VkExtent3D(width=self.width, height=self.height, depth=1), mipLevels=1,
                arrayLayers=self.layers, samples=vk.VK_SAMPLE_COUNT_1_BIT, tiling=vk.VK_IMAGE_TILING_OPTIMAL,
                usage=vk.VK_IMAGE_USAGE_SAMPLED_BIT | vk.VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                sharingMode=vk.VK_SHARING_MODE_EXCLUSIVE, initialLayout=vk.VK_IMAGE_LAYOUT_UNDEFINED), None)
            req = vk.vkGetImageMemoryRequirements(dev, self.handle)
            self.memory = vk.vkAllocateMemory(dev, vk.VkMemoryAllocateInfo(
                allocationSize=req.size, memoryTypeIndex=device.local_memory_type(req.memoryTypeBits)), None)
            vk.vkBindImageMemory(dev, self.handle, self.memory, 0)
            self.view = vk.vkCreateImageView(dev, vk.VkImageViewCreateInfo(
                image=self.handle, viewType=vk.VK_IMAGE_VIEW_TYPE_2D_ARRAY, format=self.format,
                components=vk.VkComponentMapping(**dict.fromkeys("rgba", vk.VK_COMPONENT_SWIZZLE_IDENTITY)),
                subresourceRange=vk.VkImageSubresourceRange(aspectMask=aspect, baseMipLevel=0, levelCount=1,
                                                            baseArrayLayer=0, layerCount=self.layers)), None)
            device.submit(lambda cmd: self._copy(cmd, first, aspect) if clear is None
                          else self._clear(cmd, float(clear), aspect))
        except BaseException:
            self.destroy()
            raise
        device.own(self)

    def _clear(self, cmd, value: float, aspect) -> None:
        vk = self.device.vk
        ignored, dst = vk.VK_QUEUE_FAMILY_IGNORED, vk.VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL
        rng = vk.VkImageSubresourceRange(aspectMask=aspect, baseMipLevel=0, levelCount=1, baseArrayLayer=0,
                                         layerCount=self.layers)

        def barrier(old, new, src, dst_access):
            return vk.VkImageMemoryBarrier(srcAccessMask=src, dstAccessMask=dst_access, oldLayout=old, newLayout=new,
                                           srcQueueFamilyIndex=ignored, dstQueueFamilyIndex=ignored,
                                           image=self.handle, subresourceRange=rng)
        vk.vkCmdPipelineBarrier(cmd, vk.VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, vk.VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0,
                                None, 0, None, 1, [barrier(vk.VK_IMAGE_LAYOUT_UNDEFINED, dst, 0,
                                                           vk.VK_ACCESS_TRANSFER_WRITE_BIT)])
        if aspect == vk.VK_IMAGE_ASPECT_DEPTH_BIT:
            vk.vkCmdClearDepthStencilImage(cmd, self.handle, dst, vk.VkClearDepthStencilValue(depth=value, stencil=0),
                                           1, [rng])
        else:
            vk.vkCmdClearColorImage(cmd, self.handle, dst, vk.VkClearColorValue(float32=[value] * 4), 1, [rng])
        vk.vkCmdPipelineBarrier(cmd, vk.VK_PIPELINE_STAGE_TRANSFER_BIT, vk.VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT, 0,
                                0, None, 0, None, 1, [barrier(dst, self.layout, vk.VK_ACCESS_TRANSFER_WRITE_BIT,
                                                              vk.VK_ACCESS_SHADER_READ_BIT)])

    def _copy(self, cmd, sources, aspect) -> None:
        vk = self.device.vk
        ignored, read = vk.VK_QUEUE_FAMILY_IGNORED, vk.VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL
        src_layout, dst_layout = vk.VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, vk.VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL
        shaders = vk.VK_PIPELINE_STAGE_VERTEX_SHADER_BIT | vk.VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT
        late = vk.VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT | vk.VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT

        def rng(first, n):
            return vk.VkImageSubresourceRange(aspectMask=aspect, baseMipLevel=0, levelCount=1, baseArrayLayer=first,
                                              layerCount=n)

        def barrier(image, old, new, src, dst, first=0, n=1):
            return vk.VkImageMemoryBarrier(srcAccessMask=src, dstAccessMask=dst, oldLayout=old, newLayout=new,
                                           srcQueueFamilyIndex=ignored, dstQueueFamilyIndex=ignored, image=image,
                                           subresourceRange=rng(first, n))
        pre = [barrier(s.handle, read, src_layout, vk.VK_ACCESS_SHADER_READ_BIT | vk.VK_ACCESS_TRANSFER_WRITE_BIT
                       | vk.VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT, vk.VK_ACCESS_TRANSFER_READ_BIT) for s in sources]
        pre.append(barrier(self.handle, vk.VK_IMAGE_LAYOUT_UNDEFINED, dst_layout, 0, vk.VK_ACCESS_TRANSFER_WRITE_BIT,
                           0, self.layers))
        vk.vkCmdPipelineBarrier(cmd, vk.VK_PIPELINE_STAGE_TRANSFER_BIT | shaders | late,
                                vk.VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, None, 0, None, len(pre), pre)
        for k, s in enumerate(sources):
            layers = [vk.VkImageSubresourceLayers(aspectMask=aspect, mipLevel=0, baseArrayLayer=x, layerCount=1)
                      for x in (0, k)]
            region = vk.VkImageCopy(srcSubresource=layers[0], srcOffset=vk.VkOffset3D(x=0, y=0, z=0),
                                    dstSubresource=layers[1], dstOffset=vk.VkOffset3D(x=0, y=0, z=0),
                                    extent=vk.VkExtent3D(width=self.width, height=self.height, depth=1))
            vk.vkCmdCopyImage(cmd, s.handle, src_layout, self.handle, dst_layout, 1, [region])
        post = [barrier(s.handle, src_layout, read, vk.VK_ACCESS_TRANSFER_READ_BIT, vk.VK_ACCESS_SHADER_READ_BIT)
                for s in sources]
        post.append(barrier(self.handle, dst_layout, read, vk.VK_ACCESS_TRANSFER_WRITE_BIT,
                            vk.VK_ACCESS_SHADER_READ_BIT, 0, self.layers))
        vk.vkCmdPipelineBarrier(cmd, vk.VK_PIPELINE_STAGE_TRANSFER_BIT, shaders, 0, 0, None, 0, None,
                                len(post), post)


def _attachment_of(source):
    """The image a drawn target (or an Image) is sampled through: .handle and .format."""
    if hasattr(source, "_image"):  # a DepthTarget
        return source._image
    return getattr(source, "attachment", source)  # a target's colour view, or an Image itself

