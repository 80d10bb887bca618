"""The renderer's depth passes, drawn with the generated depth shaders (compose/depth.py) by the description the
build writes into the manifest (runtime/shadow_pass.py, depth_pass): what an engine reads is what this reads.

For a light of kind "depth" (shadow_map, pcf, pcf_hardware) every caster is drawn into a
:class:`~.rendertarget.DepthTarget` (D32_SFLOAT, cleared to 1): an opaque or blended caster by the `depth`
unit's vertex stage alone, a masked one by its `<hash>.mask` unit (which discards what its coverage cuts).
For a light of kind "moments" (vsm) every caster is drawn into a :class:`FloatTarget` with a depth attachment,
its fragment stage writing (d, d², 0, 1) (the `depth` unit's moments stage, or `<hash>.mask_moments`), cleared
to the moments of the far plane; then the `blur` unit's fullscreen pass averages 2r + 1 texels along y into a
scratch target and along x into the result, edges clamped: the box filter of shadow_pass.moments_map, on the
GPU. Nothing is read back to the host.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from .device import Buffer, Device, VulkanUnavailable
from .images import Image, Sampler
from .rendertarget import DEPTH_FORMAT, DepthTarget, DrawItem, _Attachment, _format, _Target

FULLSCREEN = np.array([[-1.0, -1.0, 0.0], [3.0, -1.0, 0.0], [-1.0, 3.0, 0.0]], np.float32)


class _View(Image):
    """A target's colour image as a sampled-image resource (its view and layout); owned by the target."""

    def __init__(self, attachment: _Attachment, layout: int, width: int, height: int):  # no upload: drawn
        self.attachment, self.layout, self.width, self.height = attachment, layout, width, height

    @property
    def handle(self):
        return self.attachment.handle

    @property
    def view(self):
        return self.attachment.view

    def destroy(self) -> None:  # the target destroys its attachments
        pass


class FloatTarget(_Target):
    """A W×H R32G32B32A32_SFLOAT colour image (and, with `depth`, a D32_SFLOAT depth image, cleared and not
    kept) drawn by one render pass that leaves the colour in SHADER_READ_ONLY_OPTIMAL, sampled by later passes
    through :attr:`image`; :meth:`read` copies it out as (H, W, 4) float32, row 0 first."""

    ATTACHMENTS = ("color", "depth")

    def __init__(self, device: Device, width: int, height: int, depth: bool = False):
        vk = self.vk = device.vk
        self.device, self.width, self.height = device, int(width), int(height)
        self.color = self.depth = self.render_pass = self.framebuffer = self.readback = self.queries = None
        self.gpu_ms: float | None = None
        self._drawn = False
        self.color_format = _format(vk, "R32G32B32A32_SFLOAT")
        self.depth_format = _format(vk, DEPTH_FORMAT) if depth else None
        try:
            feats = vk.vkGetPhysicalDeviceFormatProperties(device.physical, self.color_format).optimalTilingFeatures
            need = (vk.VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT | vk.VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT
                    | vk.VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT)
            if feats & need != need:
                raise VulkanUnavailable(f"{device.name} cannot render to and linearly filter R32G32B32A32_SFLOAT: "
                                        "no variance shadow map")
            self.color = _Attachment(device, self.color_format, self.width, self.height,
                                     vk.VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | vk.VK_IMAGE_USAGE_SAMPLED_BIT
                                     | vk.VK_IMAGE_USAGE_TRANSFER_SRC_BIT, vk.VK_IMAGE_ASPECT_COLOR_BIT)
            if depth:
                self.depth = _Attachment(device, self.depth_format, self.width, self.height,
                                         vk.VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT, vk.VK_IMAGE_ASPECT_DEPTH_BIT)
            self._create_render_pass()
            views = [self.color.view] + ([self.depth.view] if depth else [])
            self.framebuffer = vk.vkCreateFramebuffer(device.handle, vk.VkFramebufferCreateInfo(
                renderPass=self.render_pass, pAttachments=views, width=self.width, height=self.height,
                layers=1), None)
            if device.timestamp_bits:
                self.queries = vk.vkCreateQueryPool(device.handle, vk.VkQueryPoolCreateInfo(
                    queryType=vk.VK_QUERY_TYPE_TIMESTAMP, queryCount=2), None)
        except BaseException:
            self.destroy()
            raise
        self.image = _View(self.color, vk.VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, self.width, self.height)
        device.own(self)

    def _create_render_pass(self) -> None:
        vk = self.vk
        color = vk.VkAttachmentDescription(
            format=self.color_format, samples=vk.VK_SAMPLE_COUNT_1_BIT, loadOp=vk.VK_ATTACHMENT_LOAD_OP_CLEAR,
            storeOp=vk.VK_ATTACHMENT_STORE_OP_STORE, stencilLoadOp=vk.VK_ATTACHMENT_LOAD_OP_DONT_CARE,
            stencilStoreOp=vk.VK_ATTACHMENT_STORE_OP_DONT_CARE, initialLayout=vk.VK_IMAGE_LAYOUT_UNDEFINED,
            finalLayout=vk.VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL)
        attachments = [color]
        color_ref = vk.VkAttachmentReference(attachment=0, layout=vk.VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL)
        depth_ref = None
        if self.depth_format is not None:
            attachments.append(vk.VkAttachmentDescription(
                format=self.depth_format, samples=vk.VK_SAMPLE_COUNT_1_BIT, loadOp=vk.VK_ATTACHMENT_LOAD_OP_CLEAR,
                storeOp=vk.VK_ATTACHMENT_STORE_OP_DONT_CARE, stencilLoadOp=vk.VK_ATTACHMENT_LOAD_OP_DONT_CARE,
                stencilStoreOp=vk.VK_ATTACHMENT_STORE_OP_DONT_CARE, initialLayout=vk.VK_IMAGE_LAYOUT_UNDEFINED,
                finalLayout=vk.VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL))
            depth_ref = vk.VkAttachmentReference(attachment=1,
                                                 layout=vk.VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL)
        subpass = vk.VkSubpassDescription(pipelineBindPoint=vk.VK_PIPELINE_BIND_POINT_GRAPHICS,
                                          pColorAttachments=[color_ref], pDepthStencilAttachment=depth_ref)
        out = vk.VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | vk.VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT \
            | vk.VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT
        writes = vk.VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | vk.VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT \
            | vk.VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT
        deps = [
            # a later pass's reads of the last frame (or a readback's copy) before this frame's clear
            vk.VkSubpassDependency(srcSubpass=vk.VK_SUBPASS_EXTERNAL, dstSubpass=0,
                                   srcStageMask=vk.VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT
                                   | vk.VK_PIPELINE_STAGE_TRANSFER_BIT, dstStageMask=out,
                                   srcAccessMask=0, dstAccessMask=writes),
            # the colour writes before the next pass samples them
            vk.VkSubpassDependency(srcSubpass=0, dstSubpass=vk.VK_SUBPASS_EXTERNAL,
                                   srcStageMask=vk.VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                                   dstStageMask=vk.VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT
                                   | vk.VK_PIPELINE_STAGE_TRANSFER_BIT,
                                   srcAccessMask=vk.VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
                                   dstAccessMask=vk.VK_ACCESS_SHADER_READ_BIT | vk.VK_ACCESS_TRANSFER_READ_BIT)]
        self.render_pass = vk.vkCreateRenderPass(self.device.handle, vk.VkRenderPassCreateInfo(
            pAttachments=attachments, pSubpasses=[subpass], pDependencies=deps), None)

    def _clear_values(self, clear):
        vk = self.vk
        out = [vk.VkClearValue(color=vk.VkClearColorValue(float32=[float(x) for x in clear]))]
        if self.depth_format is not None:
            out.append(vk.VkClearValue(depthStencil=vk.VkClearDepthStencilValue(depth=1.0, stencil=0)))
        return out

    def _after_pass(self, cmd) -> None:  # the render pass leaves the colour sampleable
        pass

    def read(self) -> np.ndarray:
        """The last draw's colour, (H, W, 4) float32 (a copy), row 0 the framebuffer's first row."""
        if not self._drawn:
            raise RuntimeError("read() before any draw(): the target holds no image")
        vk, dev = self.vk, self.device
        n = 16 * self.width * self.height
        buf = Buffer(dev, n, vk.VK_BUFFER_USAGE_TRANSFER_DST_BIT)
        rng = vk.VkImageSubresourceRange(aspectMask=vk.VK_IMAGE_ASPECT_COLOR_BIT, baseMipLevel=0, levelCount=1,
                                         baseArrayLayer=0, layerCount=1)
        ignored = vk.VK_QUEUE_FAMILY_IGNORED

        def barrier(old, new, src, dst):
            return vk.VkImageMemoryBarrier(srcAccessMask=src, dstAccessMask=dst, oldLayout=old, newLayout=new,
                                           srcQueueFamilyIndex=ignored, dstQueueFamilyIndex=ignored,
                                           image=self.color.handle, subresourceRange=rng)
        region = vk.VkBufferImageCopy(
            bufferOffset=0, bufferRowLength=0, bufferImageHeight=0,
            imageSubresource=vk.VkImageSubresourceLayers(aspectMask=vk.VK_IMAGE_ASPECT_COLOR_BIT, mipLevel=0,
                                                         baseArrayLayer=0, layerCount=1),
            imageOffset=vk.VkOffset3D(x=0, y=0, z=0), imageExtent=vk.VkExtent3D(width=self.width, height=self.height,
                                                                                depth=1))
        shader, src_layout = vk.VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, vk.VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL
        all_shaders = vk.VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT | vk.VK_PIPELINE_STAGE_TRANSFER_BIT

        def record(cmd):
            vk.vkCmdPipelineBarrier(cmd, all_shaders, vk.VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, None, 0, None, 1,
                                    [barrier(shader, src_layout, 0, vk.VK_ACCESS_TRANSFER_READ_BIT)])
            vk.vkCmdCopyImageToBuffer(cmd, self.color.handle, src_layout, buf.handle, 1, [region])
            vk.vkCmdPipelineBarrier(cmd, vk.VK_PIPELINE_STAGE_TRANSFER_BIT, all_shaders | vk.VK_PIPELINE_STAGE_HOST_BIT,
                                    0, 0, None, 0, None, 1,
                                    [barrier(src_layout, shader, 0, vk.VK_ACCESS_SHADER_READ_BIT)])
        try:
            dev.submit(record)
            return buf.array(np.float32)[:n // 4].reshape(self.height, self.width, 4).copy()
        finally:
            buf.destroy()


@dataclass
class Caster:
    """One object drawn into a light's map: its mesh, Object block, the unit drawing it (the light's
    description's ``casters``) and, for a masked one, its material's resources ({(set, binding): resource}:
    the Material block, the coverage texture and its sampler, as its colour pass binds them)."""

    mesh: object
    object_block: Buffer
    permutation: str = ""
    material: dict = field(default_factory=dict)


def mask_interface(units: dict, h: str):
    """The interface of permutation h's mask unit (either kind: both read the same block and textures)."""
    from ..link.depth import mask_unit

    return next(units[n].interface for n in (mask_unit(h, False), mask_unit(h, True)) if n in units)


def mask_resources(iface, material: Buffer, textures, sampler) -> dict:
    """A masked caster's material resources for a mask unit's interface: the Material block `material`, and each
    coverage texture (textures[its brick name]) with `sampler`, at the bindings the unit declares."""
    mb = iface.block("Material")
    res = {(mb.set, mb.binding): material}
    for t in iface.textures:
        res[(t.set, t.binding)], res[(t.set, t.binding + 1)] = textures[t.param], sampler
    return res


@dataclass
class Drawn:
    """A light's drawn pass: what its brick samples (the DepthTarget, or the blurred moments' target), the
    moments before the blur, the device and pipeline-creation times, the units it drew with."""

    depth: DepthTarget | None = None
    blurred: FloatTarget | None = None
    unblurred: FloatTarget | None = None
    gpu_ms: float = 0.0
    pipeline_ms: float = 0.0
    units: list = field(default_factory=list)
    layered: Image | None = None  # a point light's faces, copied into the layers of one array (what is sampled)
    faces: list = field(default_factory=list)  # and each face's own Drawn

    @property
    def moments(self) -> Image | None:
        """The blurred moments as a sampled-image resource."""
        if self.faces:
            return self.layered if self.faces[0].blurred is not None else None
        return self.blurred.image if self.blurred is not None else None


class DepthPasses:
    """Draws shadowed lights' depth passes on `device` from compiled units: spirv {(unit, "vert"|"frag"): bytes},
    interfaces {unit: its DepthInterface} (compose/depth.py). Everything it makes goes into `owned`, released
    by the caller in reverse order."""

    def __init__(self, device: Device, spirv: dict, interfaces: dict, owned: list, cache=None):
        self.device, self.spirv, self.interfaces, self.owned, self.cache = device, spirv, interfaces, owned, cache
        self._fullscreen = None

    def _own(self, x):
        self.owned.append(x)
        return x

    def _buffer(self, data: bytes) -> Buffer:
        vk = self.device.vk
        b = self._own(Buffer(self.device, len(data), vk.VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT))
        b.write(np.frombuffer(data, np.uint8))
        return b

    def _pipeline(self, target, unit: str, stages) -> tuple[object, float]:
        from .graphics import GraphicsPipeline, layouts_from_interface

        iface = self.interfaces[unit]
        t0 = time.perf_counter()
        frag = self.spirv[(unit, "frag")] if "frag" in stages else None
        p = self._own(GraphicsPipeline(self.device, target, self.spirv[(unit, "vert")], frag, iface.vertex_inputs,
                                       layouts_from_interface(iface), cache=self.cache))
        return p, (time.perf_counter() - t0) * 1e3

    def draw_layers(self, desc: dict, matrices: list, eye, casters: list[Caster]) -> Drawn:
        """Draw a light's pass once per matrix of `matrices` (column-major: its one shadow_matrix, or a point light's
        six faces, desc["faces"]), each premultiplied for Vulkan as desc["matrix"] says; six faces are then
        copied into the layers of one 2D array (depth_images.LayeredImage), which the returned Drawn's `depth`
        (or `moments`) is."""
        from .depth_images import LayeredImage

        pre = np.asarray(desc["matrix"]["premultiply"]["vulkan"], np.float64)
        drawn = [self.draw(desc, pre @ np.asarray(m, np.float64).reshape(4, 4).T, eye, casters) for m in matrices]
        if "faces" not in desc:
            return drawn[0]
        moments = desc["kind"] == "moments"
        sources = [d.blurred.image if moments else d.depth for d in drawn]
        layered = self._own(LayeredImage(self.device, sources))
        layered.sampled = "moments" if moments else drawn[0].depth.sampled
        out = Drawn(depth=None if moments else layered, layered=layered, faces=drawn,
                    gpu_ms=sum(d.gpu_ms for d in drawn), pipeline_ms=sum(d.pipeline_ms for d in drawn),
                    units=list(dict.fromkeys(u for d in drawn for u in d.units)))
        return out

    def draw(self, desc: dict, view_proj, eye, casters: list[Caster]) -> Drawn:
        """Draw one light's pass as `desc` (shadow_pass.depth_pass) says, every caster with Frame.view_proj =
        `view_proj` (row-major: the light's matrix premultiplied for Vulkan, the identity). A device that cannot draw
        the description's kind is a shadow_pass.ShadowProblem (the renderer locates it at the light's line)."""
        from .graphics import frame_bytes

        size, dep = desc["size"], desc["depth"]
        if dep["format"] != DEPTH_FORMAT or dep["clear"] != 1.0 or any(dep["bias"].values()) or dep["cull"] != "none":
            raise ValueError(f"this renderer draws a {DEPTH_FORMAT} map cleared to 1, no rasterizer bias, no culling; "
                             f"the description asks for {dep}")
        moments = desc["kind"] == "moments"
        if moments:
            try:
                target = self._own(FloatTarget(self.device, size[0], size[1], depth=True))
            except VulkanUnavailable as e:  # the device, for this light's filter: the caller locates it at the light
                from .shadow_pass import ShadowProblem
                raise ShadowProblem(None, str(e), 'use shadow = "pcf"') from None
        else:
            target = self._own(DepthTarget(self.device, size[0], size[1]))
        frame = self._buffer(frame_bytes(view_proj, eye))
        out, items, pipes = Drawn(), [], {}
        for c in casters:
            spec = desc["casters"]["masked"].get(c.permutation) or desc["casters"]["opaque"]
            unit = spec["unit"]
            if unit not in pipes:
                pipes[unit], ms = self._pipeline(target, unit, spec["stages"])
                out.pipeline_ms += ms
                out.units.append(unit)
            iface = self.interfaces[unit]
            fb, ob = iface.block("Frame"), iface.block("Object")
            res = {(fb.set, fb.binding): frame, (ob.set, ob.binding): c.object_block}
            if c.permutation in desc["casters"]["masked"]:  # its material's block and coverage texture
                res.update(c.material)
            items.append(DrawItem(pipes[unit], c.mesh, res))
        out.gpu_ms = target.draw(items, clear=desc.get("moments", {}).get("clear", (0.0, 0.0, 0.0, 1.0))) or 0.0
        if not moments:
            out.depth = target
            return out
        out.unblurred = target
        out.blurred, ms = self._blur(target, desc["moments"])
        out.gpu_ms += ms
        out.units.append(desc["moments"]["blur"]["unit"])
        return out

    def _blur(self, source: FloatTarget, m: dict) -> tuple[FloatTarget, float]:
        """The moments' box filter: one fullscreen pass per axis of m["blur"]["passes"], into fresh targets."""
        from .graphics import GpuMesh
        from .meshes import Mesh

        blur = m["blur"]
        unit, radius = blur["unit"], int(blur["radius"])
        if blur["filter"] != "box" or blur["edges"] != "clamp" or blur["size"] != 2 * radius + 1:
            raise ValueError(f"this renderer blurs with a clamped box of 2r + 1 texels; the description asks for {blur}")
        if self._fullscreen is None:
            zeros = np.zeros((3, 4), np.float32)
            self._fullscreen = self._own(GpuMesh(self.device, Mesh(FULLSCREEN, zeros[:, :3], zeros, zeros[:, :2],
                                                                   np.arange(3, dtype=np.uint32))))
        sampler = self._own(Sampler(self.device))
        iface = self.interfaces[unit]
        tex, block = iface.textures[0], iface.block("Blur")
        src, ms = source, 0.0
        for step in blur["passes"]:
            dst = self._own(FloatTarget(self.device, source.width, source.height))
            pipe, _ = self._pipeline(dst, unit, ("vert", "frag"))
            params = self._buffer(np.array([*step["axis"], radius, 0], np.int32).tobytes())
            res = {(tex.set, tex.binding): src.image, (tex.set, tex.binding + 1): sampler,
                   (block.set, block.binding): params}
            ms += dst.draw([DrawItem(pipe, self._fullscreen, res)], clear=m["clear"]) or 0.0
            src = dst
        return src, ms
