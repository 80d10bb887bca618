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
