"""An offscreen graphics renderer on a :class:`~.device.Device`: target, pipelines, meshes, frames, PNGs.

- :class:`OffscreenTarget`: a W×H colour image (R8G8B8A8_UNORM) and a D32_SFLOAT depth image,
  one render pass (clear both, store colour, colour left in TRANSFER_SRC_OPTIMAL) and its
  framebuffer. :meth:`OffscreenTarget.draw` records one frame of :class:`DrawItem` s in one render
  pass, submits and waits (device time between timestamps around the pass in
  :attr:`OffscreenTarget.gpu_ms`); :meth:`OffscreenTarget.read` copies the colour image to a host
  buffer and returns an (H, W, 4) uint8 array, row 0 the top of the image.
- :class:`GraphicsPipeline`: a vertex and a fragment SPIR-V module for a target's render pass, one
  vertex buffer binding per vertex input (the Interface's ``vertex_inputs``: location, name, Vulkan
  format), descriptor sets described by ``set_layouts`` ({set: {binding: kind}}, kinds of
  :mod:`.compute`: UNIFORM, STORAGE, SAMPLED_IMAGE, SAMPLER), as :func:`layouts_from_interface`
  reads them off an Interface. Triangle lists, front faces counter-clockwise, viewport and scissor = the
  target; cull, blend and depth write from a ``render_state`` (the manifest's: runtime/pipeline_state.py
  render_state), or without one cull mode none (back with ``cull_back``), depth test LESS with writes and no
  blending (source-over with ``blend``: src·a + dst·(1 − a)).
- :class:`GpuMesh`: a :class:`~.meshes.Mesh` uploaded, one vertex buffer per attribute, and its
  uint32 index buffer.
- :class:`DepthTarget`: a D32_SFLOAT image drawn by a depth-only render pass (vertex-only pipelines), then
  sampled as a shadow map (the depth image itself, or an R32_SFLOAT copy where the device cannot filter
  D32_SFLOAT linearly, as lavapipe cannot); :meth:`DepthTarget.read` gives the depth as (H, W) float32.
- :func:`perspective`, :func:`look_at`, :func:`frame_bytes`, :func:`object_bytes`: a camera in Vulkan's clip
  space (y down, depth 0 … 1), the Frame block's and the per-draw Object block's bytes (column-major).
- :func:`orthographic`, :func:`directional_shadow_matrix`, :func:`point_shadow_matrix`, :func:`column_major`:
  a light's world → clip matrix fitted to a set of points, and a matrix as a mat4 parameter's 16 numbers.
- :func:`save_png`: an (H, W, 3|4) uint8 array to a PNG file, written atomically.

The targets live in runtime/rendertarget.py and the camera math in runtime/camera.py; their names are
imported here so that this module stays the renderer's one entry.

Descriptor sets are allocated per frame from a pool sized for that frame's items and freed after
it; every binding of every set a pipeline declares must be given a resource per item, keyed
(set, binding). Everything is owned by the device and released by Device.close unless destroyed
earlier. The binding's pitfalls (../shared/TOOLCHAIN.md) are handled as in compute.py: entry-point
names and nested structs are kept alive across the calls; buffer ranges are byte sizes.
"""
from __future__ import annotations

import io
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..io import atomic_write
from .camera import (column_major, directional_shadow_matrix, frame_bytes, look_at, object_bytes,  # noqa: F401
                     orthographic, perspective, point_shadow_matrix)
from .compute import SAMPLED_IMAGE, SAMPLER, STORAGE, UNIFORM
from .device import Buffer, Device
from .rendertarget import _TYPES, DepthTarget, DrawItem, OffscreenTarget, _format, resource_keys  # noqa: F401

if TYPE_CHECKING:
    from ..link.interface import Interface
    from .meshes import Mesh

# Bytes per vertex of the vertex formats the Interface names (link/interface.VERTEX_INPUTS).
VERTEX_FORMAT_BYTES = {"R32_SFLOAT": 4, "R32G32_SFLOAT": 8, "R32G32B32_SFLOAT": 12, "R32G32B32A32_SFLOAT": 16}


# ------------------------------------------------------------------ set layouts

def layouts_from_interface(iface: "Interface", sets: tuple[int, ...] = (0, 1)) -> dict[int, dict[int, str]]:
    """{set: {binding: kind}} of an Interface: its blocks (uniform / storage at their set and binding) and its
    textures (SAMPLED_IMAGE at the texture's binding, SAMPLER at binding + 1). Sets 0 and 1 are always present
    (empty when nothing lives there); a binding claimed twice is an error."""
    out: dict[int, dict[int, str]] = {s: {} for s in sets}
    owner: dict[tuple[int, int], str] = {}

    def put(s, b, kind, what):
        if (s, b) in owner:
            raise ValueError(f"set {s} binding {b} is both {owner[(s, b)]} and {what}")
        owner[(s, b)] = what
        out.setdefault(s, {})[b] = kind

    for blk in iface.blocks:
        if blk.kind not in (UNIFORM, STORAGE):
            raise ValueError(f"block {blk.name} has kind {blk.kind!r}: expected 'uniform' or 'storage'")
        put(blk.set, blk.binding, blk.kind, f"block {blk.name}")
    for t in iface.textures:
        put(t.set, t.binding, SAMPLED_IMAGE, f"texture {t.name}")
        put(t.set, t.binding + 1, SAMPLER, f"the sampler of {t.name}")
    return {s: dict(sorted(b.items())) for s, b in sorted(out.items())}


# ------------------------------------------------------------------ PNG

def save_png(array, path) -> Path:
    """Write an (H, W), (H, W, 3) or (H, W, 4) uint8 array as a PNG, atomically (a temporary file in the same
    directory, then renamed: io.atomic_write): a reader never sees a half-written file. Returns the path."""
    from PIL import Image as PILImage

    a = np.asarray(array)
    if a.dtype != np.uint8:
        raise TypeError(f"save_png takes uint8 pixels, got {a.dtype}")
    if not (a.ndim == 2 or (a.ndim == 3 and a.shape[2] in (1, 3, 4))):
        raise ValueError(f"save_png takes (H, W), (H, W, 3) or (H, W, 4), got {a.shape}")
    if a.ndim == 3 and a.shape[2] == 1:
        a = a[..., 0]
    path = Path(path)
    png = io.BytesIO()
    PILImage.fromarray(np.ascontiguousarray(a)).save(png, format="PNG")
    atomic_write(path, png.getvalue())
    return path


# ------------------------------------------------------------------ pipeline

def _from_render_state(state: dict) -> tuple[bool, bool, bool]:
    """(cull back, blend source-over, write depth) of a manifest render_state; ValueError for a state this
    pipeline cannot draw (another blend equation or depth test than the manifest's format 1 states)."""
    from .pipeline_state import SOURCE_OVER
    depth = state["depth"]
    if state["blend"] not in (None, SOURCE_OVER) or not depth["test"] or depth["compare"] != "less" \
            or state["cull"] not in ("back", "none"):
        raise ValueError(f"this renderer draws source-over or no blending, cull back or none, depth test less; not "
                         f"{state}")
    return state["cull"] == "back", state["blend"] is not None, bool(depth["write"])


class GraphicsPipeline:
    """A vertex + fragment pipeline for `target`'s render pass, or a vertex-only one (``frag_spirv=None``) for a
    :class:`DepthTarget` (depth-only: no colour attachment, so no blend state and no fragment stage).

    vertex_inputs: Location-like objects (location, name, format: "R32G32B32_SFLOAT" …), one vertex buffer
    binding each (binding k = the k-th input, tightly packed, per vertex). set_layouts: {set: {binding: kind}}
    (:func:`layouts_from_interface`); the pipeline layout has a set layout for every set 0 … max (empty ones
    where nothing lives), every binding visible to both stages. specialization: {SpecId: int32 value}, given
    to both stages (an id a stage does not declare is ignored, as Vulkan specifies).
    """

    def __init__(self, device: Device, target: "OffscreenTarget | DepthTarget", vert_spirv: bytes,
                 frag_spirv: bytes | None,
                 vertex_inputs, set_layouts: dict[int, dict[int, str]], specialization: dict[int, int] | None = None,
                 vert_entry: str = "main", frag_entry: str = "main", cache=None, flags: int = 0,
                 cull_back: bool = False, blend: bool = False, render_state: dict | None = None):
        vk = self.vk = device.vk
        self.cull_back, self.blend, self.depth_write = cull_back, blend, True
        if render_state is not None:  # the surface's pipeline state as the manifest states it
            self.cull_back, self.blend, self.depth_write = _from_render_state(render_state)
        self.flags = flags  # VkPipelineCreateFlags (e.g. capture statistics: runtime/gpu_stats.py)
        self.cache = cache  # a runtime.pipeline_cache.PipelineCacheFile, or None
        self.device, self.target = device, target
        self.vertex_inputs = tuple(vertex_inputs)
        self.attribute_names = tuple(x.name for x in self.vertex_inputs)
        self.set_layouts = {int(s): {int(b): k for b, k in sorted(bs.items())} for s, bs in sorted(set_layouts.items())}
        self.handle = self.layout = self.vert = self.frag = None
        self.set_layout_handles: dict[int, object] = {}
        dev = device.handle
        if frag_spirv is None and target.has_color:
            raise ValueError("a pipeline for a colour target needs a fragment shader; frag_spirv=None is for a "
                             "DepthTarget")
        try:
            for s, bs in self.set_layouts.items():
                bad = [k for k in bs.values() if k not in _TYPES]
                if bad or s < 0:
                    raise ValueError(f"set {s}: unknown binding kinds {bad}: use {', '.join(_TYPES)}")
            formats = {}
            for x in self.vertex_inputs:
                if x.format not in VERTEX_FORMAT_BYTES:
                    raise ValueError(f"vertex input {x.name}: format {x.format!r} is not one of "
                                     f"{', '.join(VERTEX_FORMAT_BYTES)}")
                formats[x.name] = _format(vk, x.format)
            stages_flags = vk.VK_SHADER_STAGE_VERTEX_BIT | vk.VK_SHADER_STAGE_FRAGMENT_BIT
            top = max(self.set_layouts, default=-1)
            for s in range(top + 1):
                bs = self.set_layouts.get(s, {})
                bindings = [vk.VkDescriptorSetLayoutBinding(binding=b, descriptorType=_TYPES[k](vk), descriptorCount=1,
                                                            stageFlags=stages_flags) for b, k in bs.items()]
                self.set_layout_handles[s] = vk.vkCreateDescriptorSetLayout(dev, vk.VkDescriptorSetLayoutCreateInfo(
                    pBindings=bindings), None)
            handles = [self.set_layout_handles[s] for s in range(top + 1)]
            self.layout = vk.vkCreatePipelineLayout(dev, vk.VkPipelineLayoutCreateInfo(pSetLayouts=handles), None)
            vert_spirv = device.fit_spirv(vert_spirv)  # fp16: naga's unused StorageInputOutput16 (device.py)
            frag_spirv = device.fit_spirv(frag_spirv) if frag_spirv is not None else None
            self.vert = vk.vkCreateShaderModule(dev, vk.VkShaderModuleCreateInfo(codeSize=len(vert_spirv),
                                                                                 pCode=vert_spirv), None)
            if frag_spirv is not None:
                self.frag = vk.vkCreateShaderModule(dev, vk.VkShaderModuleCreateInfo(codeSize=len(frag_spirv),
                                                                                     pCode=frag_spirv), None)
            self._create(vert_entry, frag_entry, formats, specialization)
        except BaseException:
            self.destroy()
            raise
        device.own(self)

    def _create(self, vert_entry, frag_entry, formats, specialization) -> None:
        vk, t = self.vk, self.target
        # Every nested struct and string lives in a local across the call (TOOLCHAIN.md).
        vname, fname = vk.ffi.new("char[]", vert_entry.encode()), vk.ffi.new("char[]", frag_entry.encode())
        spec = spec_data = spec_entries = None
        if specialization:
            ids = sorted(specialization)
            spec_data = vk.ffi.new("int32_t[]", [int(specialization[i]) for i in ids])
            spec_entries = [vk.VkSpecializationMapEntry(constantID=i, offset=4 * k, size=4) for k, i in enumerate(ids)]
            spec = vk.VkSpecializationInfo(pMapEntries=spec_entries, dataSize=4 * len(ids), pData=spec_data)
        stages = [vk.VkPipelineShaderStageCreateInfo(stage=vk.VK_SHADER_STAGE_VERTEX_BIT, module=self.vert,
                                                     pName=vname, pSpecializationInfo=spec)]
        if self.frag is not None:
            stages.append(vk.VkPipelineShaderStageCreateInfo(stage=vk.VK_SHADER_STAGE_FRAGMENT_BIT, module=self.frag,
                                                             pName=fname, pSpecializationInfo=spec))
        vbind = [vk.VkVertexInputBindingDescription(binding=k, stride=VERTEX_FORMAT_BYTES[x.format],
                                                    inputRate=vk.VK_VERTEX_INPUT_RATE_VERTEX)
                 for k, x in enumerate(self.vertex_inputs)]
        vattr = [vk.VkVertexInputAttributeDescription(location=int(x.location), binding=k, format=formats[x.name],
                                                      offset=0) for k, x in enumerate(self.vertex_inputs)]
        vertex_input = vk.VkPipelineVertexInputStateCreateInfo(pVertexBindingDescriptions=vbind,
                                                               pVertexAttributeDescriptions=vattr)
        assembly = vk.VkPipelineInputAssemblyStateCreateInfo(topology=vk.VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST,
                                                             primitiveRestartEnable=vk.VK_FALSE)
        viewport = vk.VkViewport(x=0.0, y=0.0, width=float(t.width), height=float(t.height), minDepth=0.0,
                                 maxDepth=1.0)
        scissor = vk.VkRect2D(offset=vk.VkOffset2D(x=0, y=0), extent=vk.VkExtent2D(width=t.width, height=t.height))
        viewport_state = vk.VkPipelineViewportStateCreateInfo(pViewports=[viewport], pScissors=[scissor])
        raster = vk.VkPipelineRasterizationStateCreateInfo(
            depthClampEnable=vk.VK_FALSE, rasterizerDiscardEnable=vk.VK_FALSE, polygonMode=vk.VK_POLYGON_MODE_FILL,
            cullMode=vk.VK_CULL_MODE_BACK_BIT if self.cull_back else vk.VK_CULL_MODE_NONE, frontFace=vk.VK_FRONT_FACE_COUNTER_CLOCKWISE, depthBiasEnable=vk.VK_FALSE,
            depthBiasConstantFactor=0.0, depthBiasClamp=0.0, depthBiasSlopeFactor=0.0, lineWidth=1.0)
        multisample = vk.VkPipelineMultisampleStateCreateInfo(
            rasterizationSamples=vk.VK_SAMPLE_COUNT_1_BIT, sampleShadingEnable=vk.VK_FALSE, minSampleShading=0.0,
            alphaToCoverageEnable=vk.VK_FALSE, alphaToOneEnable=vk.VK_FALSE)
        stencil = vk.VkStencilOpState(failOp=vk.VK_STENCIL_OP_KEEP, passOp=vk.VK_STENCIL_OP_KEEP,
                                      depthFailOp=vk.VK_STENCIL_OP_KEEP, compareOp=vk.VK_COMPARE_OP_ALWAYS,
                                      compareMask=0, writeMask=0, reference=0)
        depth = vk.VkPipelineDepthStencilStateCreateInfo(
            depthTestEnable=vk.VK_TRUE, depthWriteEnable=vk.VK_TRUE if self.depth_write else vk.VK_FALSE,
            depthCompareOp=vk.VK_COMPARE_OP_LESS,
            depthBoundsTestEnable=vk.VK_FALSE, stencilTestEnable=vk.VK_FALSE, front=stencil, back=stencil,
            minDepthBounds=0.0, maxDepthBounds=1.0)
        mask = (vk.VK_COLOR_COMPONENT_R_BIT | vk.VK_COLOR_COMPONENT_G_BIT | vk.VK_COLOR_COMPONENT_B_BIT
                | vk.VK_COLOR_COMPONENT_A_BIT)
        over = self.blend  # source-over for colour; alpha keeps the destination's coverage summed (a + d(1 − a))
        blend_attachment = vk.VkPipelineColorBlendAttachmentState(
            blendEnable=vk.VK_TRUE if over else vk.VK_FALSE,
            srcColorBlendFactor=vk.VK_BLEND_FACTOR_SRC_ALPHA if over else vk.VK_BLEND_FACTOR_ONE,
            dstColorBlendFactor=vk.VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA if over else vk.VK_BLEND_FACTOR_ZERO,
            colorBlendOp=vk.VK_BLEND_OP_ADD,
            srcAlphaBlendFactor=vk.VK_BLEND_FACTOR_ONE,
            dstAlphaBlendFactor=vk.VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA if over else vk.VK_BLEND_FACTOR_ZERO,
            alphaBlendOp=vk.VK_BLEND_OP_ADD, colorWriteMask=mask)
        blend = vk.VkPipelineColorBlendStateCreateInfo(logicOpEnable=vk.VK_FALSE, logicOp=vk.VK_LOGIC_OP_COPY,
                                                       pAttachments=[blend_attachment],
                                                       blendConstants=[0.0, 0.0, 0.0, 0.0]) if t.has_color else None
        # Creation feedback (core in Vulkan 1.3): whether the pipeline cache supplied the pipeline.
        feedback = vk.ffi.new("VkPipelineCreationFeedback*")
        feedback_info = None
        if "VK_EXT_pipeline_creation_feedback" in getattr(self.device, "extensions", ()):
            feedback_info = vk.VkPipelineCreationFeedbackCreateInfo(pPipelineCreationFeedback=feedback,
                                                                    pipelineStageCreationFeedbackCount=0)
        info = vk.VkGraphicsPipelineCreateInfo(
            pNext=feedback_info, flags=self.flags, pStages=stages, pVertexInputState=vertex_input, pInputAssemblyState=assembly,
            pViewportState=viewport_state, pRasterizationState=raster, pMultisampleState=multisample,
            pDepthStencilState=depth, pColorBlendState=blend, layout=self.layout, renderPass=t.render_pass,
            subpass=0, basePipelineIndex=-1)
        cache = self.cache.handle if self.cache is not None else None
        self.handle = vk.vkCreateGraphicsPipelines(self.device.handle, cache, 1, [info], None)[0]
        HIT = 0x2  # VK_PIPELINE_CREATION_FEEDBACK_APPLICATION_PIPELINE_CACHE_HIT_BIT
        self.cache_hit = bool(feedback.flags & HIT) and cache is not None
        del vname, fname, spec_data, spec_entries, feedback_info  # alive until here

    def destroy(self) -> None:
        vk, dev = self.vk, self.device.handle
        if dev is None:
            return
        if self in self.device._owned:
            self.device._owned.remove(self)
        for attr, fn in (("handle", vk.vkDestroyPipeline), ("layout", vk.vkDestroyPipelineLayout),
                         ("frag", vk.vkDestroyShaderModule), ("vert", vk.vkDestroyShaderModule)):
            obj = getattr(self, attr)
            if obj is not None:
                fn(dev, obj, None)
                setattr(self, attr, None)
        for h in self.set_layout_handles.values():
            vk.vkDestroyDescriptorSetLayout(dev, h, None)
        self.set_layout_handles = {}


# ------------------------------------------------------------------ meshes on the device

class GpuMesh:
    """A :class:`~.meshes.Mesh` on the device: one vertex buffer per attribute (:attr:`buffers`, by vertex-input
    name: a_position, a_normal, a_tangent, a_uv, a_color) and a uint32 index buffer."""

    def __init__(self, device: Device, mesh: "Mesh"):
        vk = device.vk
        self.device = device
        self.buffers: dict[str, Buffer] = {}
        self.index_buffer = None
        self.vertex_count, self.index_count = mesh.vertex_count, mesh.index_count
        try:
            for name, arr in mesh.attributes().items():
                a = np.ascontiguousarray(arr, np.float32)
                b = self.buffers[name] = Buffer(device, max(a.nbytes, 16), vk.VK_BUFFER_USAGE_VERTEX_BUFFER_BIT)
                b.write(a)
            idx = np.ascontiguousarray(mesh.indices, np.uint32)
            if idx.size and int(idx.max()) >= self.vertex_count:
                raise ValueError(f"index {int(idx.max())} outside the mesh's {self.vertex_count} vertices")
            self.index_buffer = Buffer(device, max(idx.nbytes, 16), vk.VK_BUFFER_USAGE_INDEX_BUFFER_BIT)
            self.index_buffer.write(idx)
        except BaseException:
            self.destroy()
            raise
        device.own(self)

    def destroy(self) -> None:
        if self.device.handle is None:
            return
        if self in self.device._owned:
            self.device._owned.remove(self)
        for b in self.buffers.values():
            b.destroy()
        self.buffers = {}
        if self.index_buffer is not None:
            self.index_buffer.destroy()
            self.index_buffer = None
