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
  reads them off an Interface. Triangle lists, cull mode none, depth test LESS with writes,
  viewport and scissor = the target, no blending.
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

Descriptor sets are allocated per frame from a pool sized for that frame's items and freed after
it; every binding of every set a pipeline declares must be given a resource per item, keyed
(set, binding). Everything is owned by the device and released by Device.close unless destroyed
earlier. The binding's pitfalls (../shared/TOOLCHAIN.md) are handled as in compute.py: entry-point
names and nested structs are kept alive across the calls; buffer ranges are byte sizes.
"""
from __future__ import annotations

import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from .compute import SAMPLED_IMAGE, SAMPLER, STORAGE, UNIFORM
from .device import Buffer, Device, VulkanUnavailable
from .images import Image, Sampler

if TYPE_CHECKING:
    from ..link.interface import Interface
    from .meshes import Mesh

COLOR_FORMAT = "R8G8B8A8_UNORM"
DEPTH_FORMAT = "D32_SFLOAT"

# Bytes per vertex of the vertex formats the Interface names (link/interface.VERTEX_INPUTS).
VERTEX_FORMAT_BYTES = {"R32_SFLOAT": 4, "R32G32_SFLOAT": 8, "R32G32B32_SFLOAT": 12, "R32G32B32A32_SFLOAT": 16}
_RESOURCE = {STORAGE: Buffer, UNIFORM: Buffer, SAMPLED_IMAGE: Image, SAMPLER: Sampler}


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


def resource_keys(set_layouts: dict[int, dict[int, str]]) -> list[tuple[int, int]]:
    """The (set, binding) keys a draw item must give resources for."""
    return [(s, b) for s, bs in sorted(set_layouts.items()) for b in sorted(bs)]


# ------------------------------------------------------------------ camera and Frame block

def perspective(fovy_deg: float, aspect: float, near: float, far: float) -> np.ndarray:
    """A right-handed perspective projection (camera looks down −z) into Vulkan's clip space: x right,
    y down (world up is image up), depth 0 at `near` … 1 at `far`. Row-major math matrix (M @ v), float64."""
    f = 1.0 / np.tan(np.radians(fovy_deg) / 2.0)
    m = np.zeros((4, 4))
    m[0, 0] = f / aspect
    m[1, 1] = -f  # Vulkan's y points down
    m[2, 2] = far / (near - far)
    m[2, 3] = near * far / (near - far)
    m[3, 2] = -1.0
    return m


def look_at(eye, target, up=(0.0, 1.0, 0.0)) -> np.ndarray:
    """The view matrix of a camera at `eye` looking at `target` (right-handed, −z forward), row-major, float64."""
    eye, target, up = (np.asarray(x, np.float64) for x in (eye, target, up))
    f = target - eye
    f /= np.linalg.norm(f)
    s = np.cross(f, up)
    s /= np.linalg.norm(s)
    u = np.cross(s, f)
    m = np.eye(4)
    m[0, :3], m[1, :3], m[2, :3] = s, u, -f
    m[:3, 3] = -m[:3, :3] @ eye
    return m


def orthographic(left: float, right: float, bottom: float, top: float, near: float, far: float) -> np.ndarray:
    """An orthographic projection of view space (looking down −z) into Vulkan's clip space: x in [left, right]
    → [−1, 1], y in [bottom, top] → [−1, 1] (not flipped), depth: z = −near → 0, z = −far → 1. Row-major,
    float64; w stays 1."""
    m = np.eye(4)
    m[0, 0], m[0, 3] = 2.0 / (right - left), -(right + left) / (right - left)
    m[1, 1], m[1, 3] = 2.0 / (top - bottom), -(top + bottom) / (top - bottom)
    m[2, 2], m[2, 3] = -1.0 / (far - near), -near / (far - near)
    return m


def _light_up(d) -> np.ndarray:
    """An up vector for a light's view that is not parallel to its direction d."""
    return np.array([0.0, 1.0, 0.0]) if abs(d[1]) < 0.99 * np.linalg.norm(d) else np.array([0.0, 0.0, 1.0])


def directional_shadow_matrix(direction, points, margin: float = 0.02) -> np.ndarray:
    """World → light clip space for a directional light: an orthographic projection along the light.

    `direction` points from the surface toward the light (the directional brick's parameter); `points`
    ((n, 3) world positions, e.g. the corners of every object's bounds) are all mapped inside clip space:
    x, y in [−1, 1] (padded by `margin` of their extent on each side), depth in [0, 1], 0 nearest the light.
    The shadow brick reads uv = p.xy · 0.5 + 0.5, the texel the depth pass rasterized p to. Row-major, float64
    (:func:`column_major` gives the mat4 parameter's 16 numbers)."""
    d = np.asarray(direction, np.float64).reshape(3)
    if not np.linalg.norm(d) > 0:
        raise ValueError(f"a directional light needs a non-zero direction, got {list(d)}")
    d = d / np.linalg.norm(d)
    pts = np.asarray(points, np.float64).reshape(-1, 3)
    centre = 0.5 * (pts.min(0) + pts.max(0))
    view = look_at(centre + d, centre, _light_up(d))  # looks along −d: the way the light travels
    q = (view[:3, :3] @ pts.T).T + view[:3, 3]
    lo, hi = q.min(0), q.max(0)
    pad = margin * (hi - lo) + 1e-4
    lo, hi = lo - pad, hi + pad
    # view z is negative in front: near = −max z, far = −min z
    return orthographic(lo[0], hi[0], lo[1], hi[1], -hi[2], -lo[2]) @ view


def point_shadow_matrix(position, points, max_half_angle_deg: float = 75.0) -> np.ndarray:
    """World → light clip space for a point light: a perspective projection from `position` toward the centre of
    `points`, its field of view and depth range fitted to them (one map, not a cube: a light among the
    points sees at most ±`max_half_angle_deg`; what lies outside is not shadowed correctly). Row-major."""
    eye = np.asarray(position, np.float64).reshape(3)
    pts = np.asarray(points, np.float64).reshape(-1, 3)
    centre = 0.5 * (pts.min(0) + pts.max(0))
    d = centre - eye
    if not np.linalg.norm(d) > 1e-9:
        d = np.array([0.0, -1.0, 0.0])
    view = look_at(eye, eye + d, _light_up(d))
    q = (view[:3, :3] @ pts.T).T + view[:3, 3]
    depth = -q[:, 2]
    far = max(float(depth.max()), 1e-3) * 1.02 + 1e-3
    near = max(float(depth.min()) * 0.98, far * 1e-3)
    ahead = depth > near
    limit = np.tan(np.radians(max_half_angle_deg))
    tx = min(float(np.max(np.abs(q[ahead, 0]) / depth[ahead], initial=0.1)) * 1.02, limit)
    ty = min(float(np.max(np.abs(q[ahead, 1]) / depth[ahead], initial=0.1)) * 1.02, limit)
    return perspective(2.0 * np.degrees(np.arctan(ty)), tx / ty, near, far) @ view


def column_major(m) -> list[float]:
    """A 4×4 math matrix as the 16 numbers of a mat4 parameter (column-major, as every block reads it)."""
    return [float(x) for x in _columns(m)]


def _columns(m) -> np.ndarray:
    """A 4×4 math matrix as std140 reads a mat4: column-major (every target reads the same bytes)."""
    return np.asarray(m, np.float64).reshape(4, 4).T.reshape(-1)


def frame_bytes(view_proj, camera_pos) -> bytes:
    """The Frame block (link/interface.FRAME_BLOCK: view_proj mat4, camera_pos vec4; 80 bytes)."""
    cam = np.zeros(4)
    c = np.asarray(camera_pos, np.float64).reshape(-1)
    cam[:len(c)] = c
    if len(c) < 4:
        cam[3] = 1.0
    return np.concatenate([_columns(view_proj), cam]).astype("<f4").tobytes()


def object_bytes(model) -> bytes:
    """The per-draw Object block (link/interface.OBJECT_BLOCK: model, and its inverse transpose for normals)."""
    m = np.asarray(model, np.float64).reshape(4, 4)
    n = np.eye(4)
    n[:3, :3] = np.linalg.inv(m[:3, :3]).T
    return np.concatenate([_columns(m), _columns(n)]).astype("<f4").tobytes()


# ------------------------------------------------------------------ PNG

def save_png(array, path) -> Path:
    """Write an (H, W), (H, W, 3) or (H, W, 4) uint8 array as a PNG, atomically (a temporary file in the same
    directory, then os.replace): a reader never sees a half-written file. Returns the path."""
    from PIL import Image as PILImage

    a = np.asarray(array)
    if a.dtype != np.uint8:
        raise TypeError(f"save_png takes uint8 pixels, got {a.dtype}")
    if not (a.ndim == 2 or (a.ndim == 3 and a.shape[2] in (1, 3, 4))):
        raise ValueError(f"save_png takes (H, W), (H, W, 3) or (H, W, 4), got {a.shape}")
    if a.ndim == 3 and a.shape[2] == 1:
        a = a[..., 0]
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as fh:
            PILImage.fromarray(np.ascontiguousarray(a)).save(fh, format="PNG")
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
    return path


# ------------------------------------------------------------------ target

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
                        res = it.resources[(s, b)]
                        w = dict(dstSet=ds, dstBinding=b, dstArrayElement=0, descriptorCount=1,
                                 descriptorType=_TYPES[kind](vk))
                        if kind in (UNIFORM, STORAGE):
                            buf, off, size = res if isinstance(res, tuple) else (res, 0, res.size)
                            # range = the byte size: VK_WHOLE_SIZE overflows the binding (TOOLCHAIN.md)
                            info = vk.VkDescriptorBufferInfo(buffer=buf.handle, offset=int(off), range=int(size))
                            w["pBufferInfo"] = [info]
                        elif kind == SAMPLED_IMAGE:
                            info = vk.VkDescriptorImageInfo(sampler=None, imageView=res.view, imageLayout=res.layout)
                            w["pImageInfo"] = [info]
                        else:
                            info = vk.VkDescriptorImageInfo(sampler=res.handle, imageView=None,
                                                            imageLayout=vk.VK_IMAGE_LAYOUT_UNDEFINED)
                            w["pImageInfo"] = [info]
                        infos.append(info)
                        writes.append(vk.VkWriteDescriptorSet(**w))
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


class OffscreenTarget(_Target):
    """A W×H R8G8B8A8_UNORM colour image and D32_SFLOAT depth, their render pass and framebuffer, a readback
    buffer and two timestamp queries. Draw frames with :meth:`draw`, read the last one with :meth:`read`."""

    def _clear_values(self, clear):
        vk = self.vk
        return [vk.VkClearValue(color=vk.VkClearColorValue(float32=[float(x) for x in clear])),
                vk.VkClearValue(depthStencil=vk.VkClearDepthStencilValue(depth=1.0, stencil=0))]

    def _after_pass(self, cmd) -> None:
        pass

    def __init__(self, device: Device, width: int, height: int):
        vk = self.vk = device.vk
        self.device, self.width, self.height = device, int(width), int(height)
        if self.width < 1 or self.height < 1:
            raise ValueError(f"a target needs W, H ≥ 1, got {width}x{height}")
        self.color_format, self.depth_format = _format(vk, COLOR_FORMAT), _format(vk, DEPTH_FORMAT)
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
        vk = self.vk
        color = vk.VkAttachmentDescription(
            format=self.color_format, samples=vk.VK_SAMPLE_COUNT_1_BIT, loadOp=vk.VK_ATTACHMENT_LOAD_OP_CLEAR,
            storeOp=vk.VK_ATTACHMENT_STORE_OP_STORE, stencilLoadOp=vk.VK_ATTACHMENT_LOAD_OP_DONT_CARE,
            stencilStoreOp=vk.VK_ATTACHMENT_STORE_OP_DONT_CARE, initialLayout=vk.VK_IMAGE_LAYOUT_UNDEFINED,
            finalLayout=vk.VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL)
        depth = vk.VkAttachmentDescription(
            format=self.depth_format, samples=vk.VK_SAMPLE_COUNT_1_BIT, loadOp=vk.VK_ATTACHMENT_LOAD_OP_CLEAR,
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
        self.render_pass = vk.vkCreateRenderPass(self.device.handle, vk.VkRenderPassCreateInfo(
            pAttachments=attachments, pSubpasses=[subpass], pDependencies=deps), None)

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
        for a in (self.depth, self.color):
            if a is not None:
                a.destroy()
        self.queries = self.readback = self.framebuffer = self.render_pass = self.depth = self.color = None


class DepthTarget(_Target):
    """A W×H D32_SFLOAT depth image drawn by a depth-only render pass (no colour attachment; pipelines made for
    it have a vertex stage only), then sampled as a shadow map: pass the target itself as a SAMPLED_IMAGE
    resource of a later draw (:attr:`view` and :attr:`layout` are what the descriptor reads).

    After every :meth:`draw` the depth image (left in TRANSFER_SRC_OPTIMAL by the pass) is copied to a
    host-visible buffer (:meth:`read` returns it as (H, W) float32, row 0 = clip y −1) and then made
    sampleable in SHADER_READ_ONLY_OPTIMAL, one of two ways (:attr:`sampled`):

    - ``"depth"``: the depth image itself, when the device can sample D32_SFLOAT with linear filtering
      (the project's one sampler is bilinear, no compare): sampling returns depth in .x;
    - ``"r32_copy"``: otherwise (Mesa 22.3 lavapipe: D32_SFLOAT is sampleable but not linearly filterable),
      the buffer is copied into an R32_SFLOAT colour image of the same size, which is sampled instead:
      depth in .x (g, b = 0, a = 1 as Vulkan expands R32).

    Depth is cleared to 1.0 (the far plane: lit everywhere nothing was drawn).
    """

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
                                        vk.VK_IMAGE_USAGE_SAMPLED_BIT | vk.VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                                        vk.VK_IMAGE_ASPECT_COLOR_BIT)
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
        for a in (self.copy, self.depth):
            if a is not None:
                a.destroy()
        self.queries = self.readback = self.framebuffer = self.render_pass = self.copy = self.depth = None


_RESOURCE[SAMPLED_IMAGE] = (Image, DepthTarget)


_TYPES = {UNIFORM: lambda vk: vk.VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER,
          STORAGE: lambda vk: vk.VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
          SAMPLED_IMAGE: lambda vk: vk.VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE,
          SAMPLER: lambda vk: vk.VK_DESCRIPTOR_TYPE_SAMPLER}


# ------------------------------------------------------------------ pipeline

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
                 vert_entry: str = "main", frag_entry: str = "main", cache=None):
        vk = self.vk = device.vk
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
            cullMode=vk.VK_CULL_MODE_NONE, frontFace=vk.VK_FRONT_FACE_COUNTER_CLOCKWISE, depthBiasEnable=vk.VK_FALSE,
            depthBiasConstantFactor=0.0, depthBiasClamp=0.0, depthBiasSlopeFactor=0.0, lineWidth=1.0)
        multisample = vk.VkPipelineMultisampleStateCreateInfo(
            rasterizationSamples=vk.VK_SAMPLE_COUNT_1_BIT, sampleShadingEnable=vk.VK_FALSE, minSampleShading=0.0,
            alphaToCoverageEnable=vk.VK_FALSE, alphaToOneEnable=vk.VK_FALSE)
        stencil = vk.VkStencilOpState(failOp=vk.VK_STENCIL_OP_KEEP, passOp=vk.VK_STENCIL_OP_KEEP,
                                      depthFailOp=vk.VK_STENCIL_OP_KEEP, compareOp=vk.VK_COMPARE_OP_ALWAYS,
                                      compareMask=0, writeMask=0, reference=0)
        depth = vk.VkPipelineDepthStencilStateCreateInfo(
            depthTestEnable=vk.VK_TRUE, depthWriteEnable=vk.VK_TRUE, depthCompareOp=vk.VK_COMPARE_OP_LESS,
            depthBoundsTestEnable=vk.VK_FALSE, stencilTestEnable=vk.VK_FALSE, front=stencil, back=stencil,
            minDepthBounds=0.0, maxDepthBounds=1.0)
        mask = (vk.VK_COLOR_COMPONENT_R_BIT | vk.VK_COLOR_COMPONENT_G_BIT | vk.VK_COLOR_COMPONENT_B_BIT
                | vk.VK_COLOR_COMPONENT_A_BIT)
        blend_attachment = vk.VkPipelineColorBlendAttachmentState(
            blendEnable=vk.VK_FALSE, srcColorBlendFactor=vk.VK_BLEND_FACTOR_ONE,
            dstColorBlendFactor=vk.VK_BLEND_FACTOR_ZERO, colorBlendOp=vk.VK_BLEND_OP_ADD,
            srcAlphaBlendFactor=vk.VK_BLEND_FACTOR_ONE, dstAlphaBlendFactor=vk.VK_BLEND_FACTOR_ZERO,
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
            pNext=feedback_info, pStages=stages, pVertexInputState=vertex_input, pInputAssemblyState=assembly,
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
    name: a_position, a_normal, a_tangent, a_uv) and a uint32 index buffer."""

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
