"""Offscreen render targets: a colour + depth target with one render pass, and a depth-only target for shadow maps.

See runtime/graphics.py for the overview; DrawItem is one draw of a frame (pipeline, mesh, resources).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from .compute import SAMPLED_IMAGE, SAMPLER, STORAGE, UNIFORM, descriptor_write
from .device import Buffer, Device, VulkanUnavailable
from .images import Image, Sampler

if TYPE_CHECKING:
    from .graphics import GpuMesh, GraphicsPipeline

COLOR_FORMAT = "R8G8B8A8_UNORM"
DEPTH_FORMAT = "D32_SFLOAT"
_RESOURCE = {STORAGE: Buffer, UNIFORM: Buffer, SAMPLED_IMAGE: Image, SAMPLER: Sampler}


def resource_keys(set_layouts: dict[int, dict[int, str]]) -> list[tuple[int, int]]:
    """The (set, binding) keys a draw item must give resources for."""
    return [(s, b) for s, bs in sorted(set_layouts.items()) for b in sorted(bs)]


def _format(vk, name: str) -> int:
    v = getattr(vk, "VK_FORMAT_" + name, None)
    if v is None:
        raise ValueError(f"unknown Vulkan format {name!r}")
    return v


class _Attachment:
    """A device-local 2D image of level 0 with a view, for a framebuffer."""

    def __init__(self, device: Device, fmt: int, width: int, height: int, usage: int, aspect: int):
        vk = device.vk
        dev = device.handle
        self.handle = self.memory = self.view = None
        self.device, self.format = device, fmt
        self.handle = vk.vkCreateImage(dev, vk.VkImageCreateInfo(
            imageType=vk.VK_IMAGE_TYPE_2D, format=fmt, extent=vk.VkExtent3D(width=width, height=height, depth=1),
            mipLevels=1, arrayLayers=1, samples=vk.VK_SAMPLE_COUNT_1_BIT, tiling=vk.VK_IMAGE_TILING_OPTIMAL,
            usage=usage, sharingMode=vk.VK_SHARING_MODE_EXCLUSIVE, initialLayout=vk.VK_IMAGE_LAYOUT_UNDEFINED), None)
        req = vk.vkGetImageMemoryRequirements(dev, self.handle)
        self.memory = vk.vkAllocateMemory(dev, vk.VkMemoryAllocateInfo(
            allocationSize=req.size, memoryTypeIndex=device.local_memory_type(req.memoryTypeBits)), None)
        vk.vkBindImageMemory(dev, self.handle, self.memory, 0)
        self.view = vk.vkCreateImageView(dev, vk.VkImageViewCreateInfo(
            image=self.handle, viewType=vk.VK_IMAGE_VIEW_TYPE_2D, format=fmt,
            components=vk.VkComponentMapping(**dict.fromkeys("rgba", vk.VK_COMPONENT_SWIZZLE_IDENTITY)),
            subresourceRange=vk.VkImageSubresourceRange(aspectMask=aspect, baseMipLevel=0, levelCount=1,
                                                        baseArrayLayer=0, layerCount=1)), None)

    def destroy(self) -> None:
        vk, dev = self.device.vk, self.device.handle
        if dev is None:
            return
        if self.view is not None:
            vk.vkDestroyImageView(dev, self.view, None)
        if self.handle is not None:
            vk.vkDestroyImage(dev, self.handle, None)
        if self.memory is not None:
            vk.vkFreeMemory(dev, self.memory, None)
        self.view = self.handle = self.memory = None


@dataclass
class DrawItem:
    """One indexed draw: a pipeline, a mesh, and a resource for every (set, binding) the pipeline declares.

    A resource is a :class:`~.device.Buffer` (bound whole), ``(Buffer, offset, size)`` (a range of it: a
    storage buffer's runtime array then has size / stride elements), an :class:`~.images.Image` or a
    :class:`~.images.Sampler`. ``index_count`` None draws the whole mesh.
    """

    pipeline: "GraphicsPipeline"
    mesh: "GpuMesh"
    resources: dict = field(default_factory=dict)
    index_count: int | None = None
    first_index: int = 0


class _Target:
    """What a colour target and a depth-only target share: frames of DrawItems in one render pass, descriptor
    sets per frame, timestamps. Subclasses set render_pass, framebuffer, width, height, queries and implement
    _clear_values(clear) and _after_pass(cmd) (commands recorded after the pass, before the end timestamp)."""

    has_color = True

    # ------------------------------------------------------------ frames
    def draw(self, items, clear=(0.0, 0.0, 0.0, 1.0), timed: bool = True) -> float | None:
        """Render one frame: clear colour to `clear` (RGBA, 0 … 1; a depth-only target has none) and depth to 1.0,
        then every item in order, in one render pass; submit and wait. Returns (and keeps in :attr:`gpu_ms`) the
        device milliseconds between timestamps written before and after the pass (and, on a depth-only target,
        its copies), when `timed` and the queue has timestamps."""
        vk, device = self.vk, self.device
        items = list(items)
        for k, it in enumerate(items):
            self._check(k, it)
        timed = bool(timed and self.queries is not None)
        pool, sets = self._descriptor_sets(items)
        try:
            clears = self._clear_values(clear)
            area = vk.VkRect2D(offset=vk.VkOffset2D(x=0, y=0),
                               extent=vk.VkExtent2D(width=self.width, height=self.height))
            begin = vk.VkRenderPassBeginInfo(renderPass=self.render_pass, framebuffer=self.framebuffer,
                                             renderArea=area, pClearValues=clears)

            # Texel uploads (images.py ends them with a barrier for compute shaders only) and any other
            # transfer writes of earlier submissions, before the vertex and fragment shaders read them.
            uploads = vk.VkMemoryBarrier(srcAccessMask=vk.VK_ACCESS_TRANSFER_WRITE_BIT,
                                         dstAccessMask=vk.VK_ACCESS_SHADER_READ_BIT | vk.VK_ACCESS_UNIFORM_READ_BIT)
            shaders = vk.VK_PIPELINE_STAGE_VERTEX_SHADER_BIT | vk.VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT

            def record(cmd):
                vk.vkCmdPipelineBarrier(cmd, vk.VK_PIPELINE_STAGE_TRANSFER_BIT, shaders, 0, 1, [uploads], 0, None,
                                        0, None)
                if timed:
                    vk.vkCmdResetQueryPool(cmd, self.queries, 0, 2)
                    vk.vkCmdWriteTimestamp(cmd, vk.VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, self.queries, 0)
                vk.vkCmdBeginRenderPass(cmd, begin, vk.VK_SUBPASS_CONTENTS_INLINE)
                for it, its_sets in zip(items, sets):
                    p = it.pipeline
                    vk.vkCmdBindPipeline(cmd, vk.VK_PIPELINE_BIND_POINT_GRAPHICS, p.handle)
                    for s, ds in its_sets:
                        vk.vkCmdBindDescriptorSets(cmd, vk.VK_PIPELINE_BIND_POINT_GRAPHICS, p.layout, s, 1, [ds],
                                                   0, None)
                    bufs = [it.mesh.buffers[name].handle for name in p.attribute_names]
                    vk.vkCmdBindVertexBuffers(cmd, 0, len(bufs), bufs, [0] * len(bufs))
                    vk.vkCmdBindIndexBuffer(cmd, it.mesh.index_buffer.handle, 0, vk.VK_INDEX_TYPE_UINT32)
                    n = it.mesh.index_count - it.first_index if it.index_count is None else it.index_count
                    vk.vkCmdDrawIndexed(cmd, n, 1, it.first_index, 0, 0)
                vk.vkCmdEndRenderPass(cmd)
                self._after_pass(cmd)
                if timed:
                    vk.vkCmdWriteTimestamp(cmd, vk.VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, self.queries, 1)

            device.submit(record)
        finally:
            if pool is not None:
                vk.vkDestroyDescriptorPool(device.handle, pool, None)
        self._drawn = True
        self.gpu_ms = self._elapsed_ms() if timed else None
        return self.gpu_ms

    def _check(self, k: int, it: DrawItem) -> None:
        from .graphics import GpuMesh, GraphicsPipeline  # graphics.py builds on this module

        p = it.pipeline
        if not isinstance(p, GraphicsPipeline) or p.handle is None:
            raise TypeError(f"item {k}: a live GraphicsPipeline is needed, got {type(p).__name__}")
        if p.target is not self:
            raise ValueError(f"item {k}: its pipeline was made for another target")
        if not isinstance(it.mesh, GpuMesh) or it.mesh.index_buffer is None:
            raise TypeError(f"item {k}: a live GpuMesh is needed, got {type(it.mesh).__name__}")
        missing = [n for n in p.attribute_names if n not in it.mesh.buffers]
        if missing:
            raise ValueError(f"item {k}: the mesh has no {', '.join(missing)}")
        n = it.mesh.index_count - it.first_index if it.index_count is None else it.index_count
        if it.first_index < 0 or n < 0 or it.first_index + n > it.mesh.index_count:
            raise ValueError(f"item {k}: indices {it.first_index} … {it.first_index + n} outside the mesh's "
                             f"{it.mesh.index_count}")
        want = set(resource_keys(p.set_layouts))
        got = set(it.resources)
        if want - got:
            raise ValueError(f"item {k}: no resource for (set, binding) {sorted(want - got)}")
        if got - want:
            raise ValueError(f"item {k}: the pipeline declares no (set, binding) {sorted(got - want)}")
        for (s, b), res in it.resources.items():
            kind = p.set_layouts[s][b]
            obj = res[0] if isinstance(res, tuple) else res
            types = _RESOURCE[kind] if isinstance(_RESOURCE[kind], tuple) else (_RESOURCE[kind],)
            if not isinstance(obj, types) or obj.handle is None:
                dead = " (destroyed)" if getattr(obj, "handle", 0) is None else ""
                raise TypeError(f"item {k}: set {s} binding {b} is {kind}: it takes a live "
                                f"{' or '.join(t.__name__ for t in types)}, got {type(obj).__name__}{dead}")
            if isinstance(obj, DepthTarget):
                if obj is self:
                    raise ValueError(f"item {k}: set {s} binding {b} samples the depth target being drawn")
                if not obj._drawn:
                    raise ValueError(f"item {k}: set {s} binding {b} samples a depth target before its first "
                                     "draw(): it holds no depth yet")
            if isinstance(res, tuple) and (kind not in (UNIFORM, STORAGE) or len(res) != 3):
                raise TypeError(f"item {k}: set {s} binding {b}: a range is (Buffer, offset, size)")

    def _descriptor_sets(self, items):
        """A pool for this frame and, per item, [(set index, descriptor set)] written with its resources."""
        vk, dev = self.vk, self.device.handle
        counts: dict[int, int] = {}
        nsets = 0
        for it in items:
            for s, bs in it.pipeline.set_layouts.items():
                if bs:
                    nsets += 1
                for kind in bs.values():
                    t = _TYPES[kind](vk)
                    counts[t] = counts.get(t, 0) + 1
        if not nsets:
            return None, [[] for _ in items]
        pool = vk.vkCreateDescriptorPool(dev, vk.VkDescriptorPoolCreateInfo(
            maxSets=nsets, pPoolSizes=[vk.VkDescriptorPoolSize(type=t, descriptorCount=n)
                                       for t, n in counts.items()]), None)
        try:
            out = []
            for it in items:
                p = it.pipeline
                used = [s for s, bs in p.set_layouts.items() if bs]
                handles = vk.vkAllocateDescriptorSets(dev, vk.VkDescriptorSetAllocateInfo(
                    descriptorPool=pool, pSetLayouts=[p.set_layout_handles[s] for s in used])) if used else []
                mine = list(zip(used, handles))
                infos, writes = [], []  # the infos must outlive vkUpdateDescriptorSets
                for s, ds in mine:
                    for b, kind in p.set_layouts[s].items():
                        info, write = descriptor_write(vk, ds, b, kind, _TYPES[kind](vk), it.resources[(s, b)])
                        infos.append(info)
                        writes.append(write)
                if writes:
                    vk.vkUpdateDescriptorSets(dev, len(writes), writes, 0, None)
                out.append(mine)
            return pool, out
        except BaseException:
            vk.vkDestroyDescriptorPool(dev, pool, None)
            raise

    def _elapsed_ms(self) -> float:
        vk, dev = self.vk, self.device
        data = vk.ffi.new("uint64_t[2]")
        vk.vkGetQueryPoolResults(dev.handle, self.queries, 0, 2, vk.ffi.sizeof(data), data, 8,
                                 vk.VK_QUERY_RESULT_64_BIT | vk.VK_QUERY_RESULT_WAIT_BIT)
        mask = (1 << dev.timestamp_bits) - 1 if dev.timestamp_bits < 64 else (1 << 64) - 1
        return ((int(data[1]) - int(data[0])) & mask) * dev.timestamp_period_ns * 1e-6

    ATTACHMENTS: tuple[str, ...] = ()  # the images a subclass owns, destroyed in this order

    def destroy(self) -> None:
        vk, dev = self.vk, self.device.handle
        if dev is None:
            return
        if self in self.device._owned:
            self.device._owned.remove(self)
        if self.queries is not None:
            vk.vkDestroyQueryPool(dev, self.queries, None)
        if self.readback is not None:
            self.readback.destroy()
        if self.framebuffer is not None:
            vk.vkDestroyFramebuffer(dev, self.framebuffer, None)
        if self.render_pass is not None:
            vk.vkDestroyRenderPass(dev, self.render_pass, None)
        for name in self.ATTACHMENTS:
            a = getattr(self, name)
            if a is not None:
                a.destroy()
            setattr(self, name, None)
        self.queries = self.readback = self.framebuffer = self.render_pass = None


def color_depth_render_pass(vk, dev, color_format, depth_format):
    """The render pass of an :class:`OffscreenTarget`: colour (cleared, stored, left TRANSFER_SRC for the
    readback) and depth (cleared, not stored), one subpass, the dependencies between frames."""
    color = vk.VkAttachmentDescription(
        format=color_format, samples=vk.VK_SAMPLE_COUNT_1_BIT, loadOp=vk.VK_ATTACHMENT_LOAD_OP_CLEAR,
        storeOp=vk.VK_ATTACHMENT_STORE_OP_STORE, stencilLoadOp=vk.VK_ATTACHMENT_LOAD_OP_DONT_CARE,
        stencilStoreOp=vk.VK_ATTACHMENT_STORE_OP_DONT_CARE, initialLayout=vk.VK_IMAGE_LAYOUT_UNDEFINED,
        finalLayout=vk.VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL)
    depth = vk.VkAttachmentDescription(
        format=depth_format, samples=vk.VK_SAMPLE_COUNT_1_BIT, loadOp=vk.VK_ATTACHMENT_LOAD_OP_CLEAR,
        storeOp=vk.VK_ATTACHMENT_STORE_OP_DONT_CARE, stencilLoadOp=vk.VK_ATTACHMENT_LOAD_OP_DONT_CARE,
        stencilStoreOp=vk.VK_ATTACHMENT_STORE_OP_DONT_CARE, initialLayout=vk.VK_IMAGE_LAYOUT_UNDEFINED,
        finalLayout=vk.VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL)
    color_ref = vk.VkAttachmentReference(attachment=0, layout=vk.VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL)
    depth_ref = vk.VkAttachmentReference(attachment=1, layout=vk.VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL)
    subpass = vk.VkSubpassDescription(pipelineBindPoint=vk.VK_PIPELINE_BIND_POINT_GRAPHICS,
                                      pColorAttachments=[color_ref], pDepthStencilAttachment=depth_ref)
    frag_tests = vk.VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT | vk.VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT
    attach_stages = vk.VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | frag_tests
    attach_access = (vk.VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | vk.VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT
                     | vk.VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT)
    deps = [
        # The previous frame's attachment writes and readback copy before this frame's clears.
        vk.VkSubpassDependency(
            srcSubpass=vk.VK_SUBPASS_EXTERNAL, dstSubpass=0,
            srcStageMask=attach_stages | vk.VK_PIPELINE_STAGE_TRANSFER_BIT, dstStageMask=attach_stages,
            srcAccessMask=vk.VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | vk.VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
            dstAccessMask=attach_access),
        # The colour writes before the readback copy (read(), a later submission).
        vk.VkSubpassDependency(
            srcSubpass=0, dstSubpass=vk.VK_SUBPASS_EXTERNAL,
            srcStageMask=vk.VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
            dstStageMask=vk.VK_PIPELINE_STAGE_TRANSFER_BIT,
            srcAccessMask=vk.VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT, dstAccessMask=vk.VK_ACCESS_TRANSFER_READ_BIT)]
    attachments = [color, depth]
    return vk.vkCreateRenderPass(dev, vk.VkRenderPassCreateInfo(
        pAttachments=attachments, pSubpasses=[subpass], pDependencies=deps), None)


class RenderPassOnly:
    """An :class:`OffscreenTarget`'s render pass without its images: what a graphics pipeline is created
    against on a compile-only device (runtime/gpu_stats.py: RADV's null device creates pipelines, not images).
    Draws nothing; `width` × `height` is the pipeline's viewport."""

    has_color = True

    def __init__(self, device: Device, width: int = 256, height: int = 256):
        self.vk, self.device, self.width, self.height = device.vk, device, int(width), int(height)
        self.render_pass = color_depth_render_pass(self.vk, device.handle, _format(self.vk, COLOR_FORMAT),
                                                   _format(self.vk, DEPTH_FORMAT))
        device.own(self)

    def destroy(self) -> None:
        if self.render_pass is not None and self.device.handle is not None:
            if self in self.device._owned:
                self.device._owned.remove(self)
            self.vk.vkDestroyRenderPass(self.device.handle, self.render_pass, None)
        self.render_pass = None


class OffscreenTarget(_Target):
    """A W×H R8G8B8A8_UNORM colour image and D32_SFLOAT depth, their render pass and framebuffer, a readback
    buffer and two timestamp queries. Draw frames with :meth:`draw`, read the last one with :meth:`read`.
    `color_format` R8G8B8A8_SRGB makes the colour attachment encode what is written (the manifest's attachment
    for a linear output); the renderer's default stores the shader's values as they are."""

    ATTACHMENTS = ("depth", "color")

    def _clear_values(self, clear):
        vk = self.vk
        return [vk.VkClearValue(color=vk.VkClearColorValue(float32=[float(x) for x in clear])),
                vk.VkClearValue(depthStencil=vk.VkClearDepthStencilValue(depth=1.0, stencil=0))]

    def _after_pass(self, cmd) -> None:
        pass

    def __init__(self, device: Device, width: int, height: int, color_format: str = COLOR_FORMAT):
        vk = self.vk = device.vk
        self.device, self.width, self.height = device, int(width), int(height)
        if self.width < 1 or self.height < 1:
            raise ValueError(f"a target needs W, H ≥ 1, got {width}x{height}")
        if color_format not in ("R8G8B8A8_UNORM", "R8G8B8A8_SRGB"):  # read() reads 4 bytes a pixel
            raise ValueError(f"an offscreen target's colour is R8G8B8A8_UNORM or R8G8B8A8_SRGB, not {color_format!r}")
        self.color_format, self.depth_format = _format(vk, color_format), _format(vk, DEPTH_FORMAT)
        self.color = self.depth = self.render_pass = self.framebuffer = self.readback = self.queries = None
        self.gpu_ms: float | None = None
        self._drawn = False
        dev = device.handle
        try:
            flags = vk.vkGetPhysicalDeviceQueueFamilyProperties(device.physical)[device.queue_family].queueFlags
            if not flags & vk.VK_QUEUE_GRAPHICS_BIT:
                raise VulkanUnavailable(f"{device.name}: queue family {device.queue_family} has no graphics")
            for fmt, need, what in ((self.color_format, vk.VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT, "colour"),
                                    (self.depth_format, vk.VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT, "depth")):
                feats = vk.vkGetPhysicalDeviceFormatProperties(device.physical, fmt).optimalTilingFeatures
                if not feats & need:
                    raise VulkanUnavailable(f"{device.name} cannot render {what} to format {fmt}")
            self.color = _Attachment(device, self.color_format, self.width, self.height,
                                     vk.VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | vk.VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                                     vk.VK_IMAGE_ASPECT_COLOR_BIT)
            self.depth = _Attachment(device, self.depth_format, self.width, self.height,
                                     vk.VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT, vk.VK_IMAGE_ASPECT_DEPTH_BIT)
            self._create_render_pass()
            views = [self.color.view, self.depth.view]
            self.framebuffer = vk.vkCreateFramebuffer(dev, vk.VkFramebufferCreateInfo(
                renderPass=self.render_pass, pAttachments=views, width=self.width, height=self.height,
                layers=1), None)
            self.readback = Buffer(device, 4 * self.width * self.height, vk.VK_BUFFER_USAGE_TRANSFER_DST_BIT)
            if device.timestamp_bits:
                self.queries = vk.vkCreateQueryPool(dev, vk.VkQueryPoolCreateInfo(
                    queryType=vk.VK_QUERY_TYPE_TIMESTAMP, queryCount=2), None)
        except BaseException:
            self.destroy()
            raise
        device.own(self)

    def _create_render_pass(self) -> None:
        self.render_pass = color_depth_render_pass(self.vk, self.device.handle, self.color_format, self.depth_format)

    def read(self) -> np.ndarray:
        """The last frame's colour image, (H, W, 4) uint8 RGBA (a copy), row 0 at the top."""
        if not self._drawn:
            raise RuntimeError("read() before any draw(): the colour image holds no frame")
        vk = self.vk
        region = vk.VkBufferImageCopy(
            bufferOffset=0, bufferRowLength=0, bufferImageHeight=0,
            imageSubresource=vk.VkImageSubresourceLayers(aspectMask=vk.VK_IMAGE_ASPECT_COLOR_BIT, mipLevel=0,
                                                         baseArrayLayer=0, layerCount=1),
            imageOffset=vk.VkOffset3D(x=0, y=0, z=0),
            imageExtent=vk.VkExtent3D(width=self.width, height=self.height, depth=1))
        to_host = vk.VkBufferMemoryBarrier(
            srcAccessMask=vk.VK_ACCESS_TRANSFER_WRITE_BIT, dstAccessMask=vk.VK_ACCESS_HOST_READ_BIT,
            srcQueueFamilyIndex=vk.VK_QUEUE_FAMILY_IGNORED, dstQueueFamilyIndex=vk.VK_QUEUE_FAMILY_IGNORED,
            buffer=self.readback.handle, offset=0, size=self.readback.size)

        def record(cmd):
            vk.vkCmdCopyImageToBuffer(cmd, self.color.handle, vk.VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                                      self.readback.handle, 1, [region])
            vk.vkCmdPipelineBarrier(cmd, vk.VK_PIPELINE_STAGE_TRANSFER_BIT, vk.VK_PIPELINE_STAGE_HOST_BIT, 0,
                                    0, None, 1, [to_host], 0, None)

        self.device.submit(record)
        n = 4 * self.width * self.height
        return self.readback.array(np.uint8)[:n].reshape(self.height, self.width, 4).copy()



class DepthTarget(_Target):
    """A W×H D32_SFLOAT depth image drawn by a depth-only render pass (no colour attachment; pipelines made for
    it have a vertex stage only), then sampled as a shadow map: pass the target itself as a SAMPLED_IMAGE
    resource of a later draw (:attr:`view` and :attr:`layout` are what the descriptor reads).

    After every :meth:`draw` the depth image (left in TRANSFER_SRC_OPTIMAL by the pass) is copied to a
    host-visible buffer (:meth:`read` returns it as (H, W) float32, row 0 = clip y −1) and then made
    sampleable in SHADER_READ_ONLY_OPTIMAL, one of two ways (:attr:`sampled`):

    - ``"depth"``: the depth image itself, when the device can sample D32_SFLOAT with linear filtering
      (the project's one sampler is bilinear, no compare): sampling returns depth in .x (lavapipe, Mesa 25.0);
    - ``"r32_copy"``: otherwise (lavapipe in Mesa 22.3: D32_SFLOAT is sampleable but not linearly filterable),
      the buffer is copied into an R32_SFLOAT colour image of the same size, which is sampled instead:
      depth in .x (g, b = 0, a = 1 as Vulkan expands R32).

    Depth is cleared to 1.0 (the far plane: lit everywhere nothing was drawn).
    """

    ATTACHMENTS = ("copy", "depth")

    has_color = False

    def __init__(self, device: Device, width: int, height: int):
        vk = self.vk = device.vk
        self.device, self.width, self.height = device, int(width), int(height)
        if self.width < 1 or self.height < 1:
            raise ValueError(f"a depth target needs W, H ≥ 1, got {width}x{height}")
        self.depth_format = _format(vk, DEPTH_FORMAT)
        self.depth = self.copy = self.render_pass = self.framebuffer = self.readback = self.queries = None
        self.gpu_ms: float | None = None
        self.layout = vk.VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL
        self._drawn = False
        dev = device.handle
        try:
            feats = vk.vkGetPhysicalDeviceFormatProperties(device.physical, self.depth_format).optimalTilingFeatures
            if not feats & vk.VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT:
                raise VulkanUnavailable(f"{device.name} cannot render depth to {DEPTH_FORMAT}")
            sample = vk.VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT | vk.VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT
            self.sampled = "depth" if feats & sample == sample else "r32_copy"
            usage = vk.VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | vk.VK_IMAGE_USAGE_TRANSFER_SRC_BIT
            if self.sampled == "depth":
                usage |= vk.VK_IMAGE_USAGE_SAMPLED_BIT
            self.depth = _Attachment(device, self.depth_format, self.width, self.height, usage,
                                     vk.VK_IMAGE_ASPECT_DEPTH_BIT)
            if self.sampled == "r32_copy":
                r32 = _format(vk, "R32_SFLOAT")
                feats = vk.vkGetPhysicalDeviceFormatProperties(device.physical, r32).optimalTilingFeatures
                if feats & sample != sample:
                    raise VulkanUnavailable(f"{device.name} can linearly filter neither {DEPTH_FORMAT} nor "
                                            "R32_SFLOAT: no shadow map to sample")
                self.copy = _Attachment(device, r32, self.width, self.height,
                                        vk.VK_IMAGE_USAGE_SAMPLED_BIT | vk.VK_IMAGE_USAGE_TRANSFER_DST_BIT
                                        | vk.VK_IMAGE_USAGE_TRANSFER_SRC_BIT, vk.VK_IMAGE_ASPECT_COLOR_BIT)
            self._create_render_pass()
            self.framebuffer = vk.vkCreateFramebuffer(dev, vk.VkFramebufferCreateInfo(
                renderPass=self.render_pass, pAttachments=[self.depth.view], width=self.width, height=self.height,
                layers=1), None)
            self.readback = Buffer(device, 4 * self.width * self.height,
                                   vk.VK_BUFFER_USAGE_TRANSFER_DST_BIT | vk.VK_BUFFER_USAGE_TRANSFER_SRC_BIT)
            if device.timestamp_bits:
                self.queries = vk.vkCreateQueryPool(dev, vk.VkQueryPoolCreateInfo(
                    queryType=vk.VK_QUERY_TYPE_TIMESTAMP, queryCount=2), None)
        except BaseException:
            self.destroy()
            raise
        device.own(self)

    # What a SAMPLED_IMAGE descriptor reads (DrawItem resources).
    @property
    def _image(self):
        return self.depth if self.sampled == "depth" else self.copy

    @property
    def handle(self):
        img = self._image
        return None if img is None else img.handle

    @property
    def view(self):
        return self._image.view

    def _create_render_pass(self) -> None:
        vk = self.vk
        depth = vk.VkAttachmentDescription(
            format=self.depth_format, samples=vk.VK_SAMPLE_COUNT_1_BIT, loadOp=vk.VK_ATTACHMENT_LOAD_OP_CLEAR,
            storeOp=vk.VK_ATTACHMENT_STORE_OP_STORE, stencilLoadOp=vk.VK_ATTACHMENT_LOAD_OP_DONT_CARE,
            stencilStoreOp=vk.VK_ATTACHMENT_STORE_OP_DONT_CARE, initialLayout=vk.VK_IMAGE_LAYOUT_UNDEFINED,
            finalLayout=vk.VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL)
        depth_ref = vk.VkAttachmentReference(attachment=0, layout=vk.VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL)
        subpass = vk.VkSubpassDescription(pipelineBindPoint=vk.VK_PIPELINE_BIND_POINT_GRAPHICS,
                                          colorAttachmentCount=0, pDepthStencilAttachment=depth_ref)
        tests = vk.VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT | vk.VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT
        deps = [
            # The previous frame's copy (and, sampled directly, the shaders' reads) before this frame's clear.
            vk.VkSubpassDependency(
                srcSubpass=vk.VK_SUBPASS_EXTERNAL, dstSubpass=0,
                srcStageMask=vk.VK_PIPELINE_STAGE_TRANSFER_BIT | vk.VK_PIPELINE_STAGE_VERTEX_SHADER_BIT
                | vk.VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT, dstStageMask=tests, srcAccessMask=0,
                dstAccessMask=vk.VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT
                | vk.VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT),
            # The depth writes before the copy out of the image (_after_pass).
            vk.VkSubpassDependency(
                srcSubpass=0, dstSubpass=vk.VK_SUBPASS_EXTERNAL, srcStageMask=tests,
                dstStageMask=vk.VK_PIPELINE_STAGE_TRANSFER_BIT,
                srcAccessMask=vk.VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                dstAccessMask=vk.VK_ACCESS_TRANSFER_READ_BIT)]
        self.render_pass = vk.vkCreateRenderPass(self.device.handle, vk.VkRenderPassCreateInfo(
            pAttachments=[depth], pSubpasses=[subpass], pDependencies=deps), None)

    def _clear_values(self, clear):
        vk = self.vk
        return [vk.VkClearValue(depthStencil=vk.VkClearDepthStencilValue(depth=1.0, stencil=0))]

    def _after_pass(self, cmd) -> None:
        """Depth → readback buffer; then the sampled image into SHADER_READ_ONLY_OPTIMAL (the depth image by a
        layout transition, or the R32_SFLOAT copy filled from the buffer)."""
        vk = self.vk
        ignored = vk.VK_QUEUE_FAMILY_IGNORED
        shaders = (vk.VK_PIPELINE_STAGE_VERTEX_SHADER_BIT | vk.VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT
                   | vk.VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT)

        def whole(aspect):
            return vk.VkImageSubresourceRange(aspectMask=aspect, baseMipLevel=0, levelCount=1, baseArrayLayer=0,
                                              layerCount=1)

        def region(aspect):
            return vk.VkBufferImageCopy(
                bufferOffset=0, bufferRowLength=0, bufferImageHeight=0,
                imageSubresource=vk.VkImageSubresourceLayers(aspectMask=aspect, mipLevel=0, baseArrayLayer=0,
                                                             layerCount=1),
                imageOffset=vk.VkOffset3D(x=0, y=0, z=0),
                imageExtent=vk.VkExtent3D(width=self.width, height=self.height, depth=1))

        out = region(vk.VK_IMAGE_ASPECT_DEPTH_BIT)
        vk.vkCmdCopyImageToBuffer(cmd, self.depth.handle, vk.VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                                  self.readback.handle, 1, [out])
        written = vk.VkBufferMemoryBarrier(
            srcAccessMask=vk.VK_ACCESS_TRANSFER_WRITE_BIT,
            dstAccessMask=vk.VK_ACCESS_TRANSFER_READ_BIT | vk.VK_ACCESS_HOST_READ_BIT,
            srcQueueFamilyIndex=ignored, dstQueueFamilyIndex=ignored, buffer=self.readback.handle, offset=0,
            size=self.readback.size)
        if self.sampled == "depth":
            written.dstAccessMask = vk.VK_ACCESS_HOST_READ_BIT  # only the host reads the buffer on this path
            to_read = vk.VkImageMemoryBarrier(
                srcAccessMask=0, dstAccessMask=vk.VK_ACCESS_SHADER_READ_BIT,
                oldLayout=vk.VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, newLayout=self.layout,
                srcQueueFamilyIndex=ignored, dstQueueFamilyIndex=ignored, image=self.depth.handle,
                subresourceRange=whole(vk.VK_IMAGE_ASPECT_DEPTH_BIT))
            vk.vkCmdPipelineBarrier(cmd, vk.VK_PIPELINE_STAGE_TRANSFER_BIT,
                                    shaders | vk.VK_PIPELINE_STAGE_HOST_BIT, 0, 0, None, 1, [written], 1, [to_read])
            return
        color = whole(vk.VK_IMAGE_ASPECT_COLOR_BIT)
        # Earlier reads of the copy (a previous frame's shaders) before it is overwritten; UNDEFINED: all replaced.
        to_dst = vk.VkImageMemoryBarrier(
            srcAccessMask=0, dstAccessMask=vk.VK_ACCESS_TRANSFER_WRITE_BIT,
            oldLayout=vk.VK_IMAGE_LAYOUT_UNDEFINED, newLayout=vk.VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
            srcQueueFamilyIndex=ignored, dstQueueFamilyIndex=ignored, image=self.copy.handle, subresourceRange=color)
        vk.vkCmdPipelineBarrier(cmd, vk.VK_PIPELINE_STAGE_TRANSFER_BIT | shaders,
                                vk.VK_PIPELINE_STAGE_TRANSFER_BIT | vk.VK_PIPELINE_STAGE_HOST_BIT, 0, 0, None,
                                1, [written], 1, [to_dst])
        into = region(vk.VK_IMAGE_ASPECT_COLOR_BIT)
        vk.vkCmdCopyBufferToImage(cmd, self.readback.handle, self.copy.handle,
                                  vk.VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, [into])
        to_read = vk.VkImageMemoryBarrier(
            srcAccessMask=vk.VK_ACCESS_TRANSFER_WRITE_BIT, dstAccessMask=vk.VK_ACCESS_SHADER_READ_BIT,
            oldLayout=vk.VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, newLayout=self.layout,
            srcQueueFamilyIndex=ignored, dstQueueFamilyIndex=ignored, image=self.copy.handle, subresourceRange=color)
        vk.vkCmdPipelineBarrier(cmd, vk.VK_PIPELINE_STAGE_TRANSFER_BIT, shaders, 0, 0, None, 0, None, 1, [to_read])

    def read(self) -> np.ndarray:
        """The last draw's depth, (H, W) float32 (a copy; 1.0 where nothing was drawn), row 0 at clip y = −1."""
        if not self._drawn:
            raise RuntimeError("read() before any draw(): the depth image holds no frame")
        n = self.width * self.height
        return self.readback.array(np.float32)[:n].reshape(self.height, self.width).copy()



_RESOURCE[SAMPLED_IMAGE] = (Image, DepthTarget)


_TYPES = {UNIFORM: lambda vk: vk.VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER,
          STORAGE: lambda vk: vk.VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
          SAMPLED_IMAGE: lambda vk: vk.VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE,
          SAMPLER: lambda vk: vk.VK_DESCRIPTOR_TYPE_SAMPLER}
