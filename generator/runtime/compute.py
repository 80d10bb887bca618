"""Compute pipelines from SPIR-V: descriptor set 0 of buffers, images and samplers, dispatch, timestamps.

One :class:`ComputePipeline` holds its shader module, set layout, pipeline
layout, pipeline, a descriptor pool with one set, and a timestamp query pool.
Binding i of set 0 has the i-th kind of `bindings`: STORAGE or UNIFORM (a
:class:`~.device.Buffer`), SAMPLED_IMAGE (an :class:`~.device.Image`: GLSL
``texture2D`` / ``textureCube``, HLSL ``Texture2D`` / ``TextureCube``, WGSL
``texture_2d<f32>`` / ``texture_cube<f32>``) or SAMPLER (a
:class:`~.device.Sampler`: GLSL ``sampler``, HLSL ``SamplerState``, WGSL
``sampler``), separate image and sampler as every target declares them.
``bind`` points the set at those resources; ``dispatch`` records, submits and
waits, and with ``timed=True`` returns the device time between a timestamp
written before the dispatch (top of pipe) and one after it (bottom of pipe).
"""
from __future__ import annotations

from .device import Buffer, Device
from .images import Image, Sampler

STORAGE = "storage"
UNIFORM = "uniform"
SAMPLED_IMAGE = "sampled_image"
SAMPLER = "sampler"

_RESOURCE = {STORAGE: Buffer, UNIFORM: Buffer, SAMPLED_IMAGE: Image, SAMPLER: Sampler}


def descriptor_write(vk, dst_set, binding: int, kind: str, descriptor_type, res):
    """(info, VkWriteDescriptorSet) pointing `binding` of `dst_set` at `res`: a Buffer (or (buffer, offset,
    size)), an image with .view and .layout, or a Sampler. Keep `info` alive until vkUpdateDescriptorSets."""
    write = dict(dstSet=dst_set, dstBinding=binding, dstArrayElement=0, descriptorCount=1,
                 descriptorType=descriptor_type)
    if kind in (STORAGE, UNIFORM):
        buf, off, size = res if isinstance(res, tuple) else (res, 0, res.size)
        # range = the byte size: VK_WHOLE_SIZE overflows the binding's conversion (TOOLCHAIN.md).
        info = vk.VkDescriptorBufferInfo(buffer=buf.handle, offset=int(off), range=int(size))
        write["pBufferInfo"] = [info]
    elif kind == SAMPLED_IMAGE:
        info = vk.VkDescriptorImageInfo(sampler=None, imageView=res.view, imageLayout=res.layout)
        write["pImageInfo"] = [info]
    else:
        info = vk.VkDescriptorImageInfo(sampler=res.handle, imageView=None, imageLayout=vk.VK_IMAGE_LAYOUT_UNDEFINED)
        write["pImageInfo"] = [info]
    return info, vk.VkWriteDescriptorSet(**write)


class ComputePipeline:
    """A compute pipeline whose set 0 holds `bindings` (STORAGE / UNIFORM / SAMPLED_IMAGE / SAMPLER at 0, 1, ...)."""

    def __init__(self, device: Device, spirv: bytes, bindings: tuple[str, ...], entry: str = "main",
                 specialization: dict[int, int] | None = None, cache=None, flags: int = 0):
        vk = self.vk = device.vk
        self.device, self.bindings = device, tuple(bindings)  # flags: VkPipelineCreateFlags
        self.handle = self.module = self.layout = self.set_layout = self.pool = self.queries = None
        dev = device.handle
        try:
            kinds = {STORAGE: vk.VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, UNIFORM: vk.VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER,
                     SAMPLED_IMAGE: vk.VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, SAMPLER: vk.VK_DESCRIPTOR_TYPE_SAMPLER}
            unknown = [b for b in self.bindings if b not in kinds]
            if unknown:
                raise ValueError(f"unknown binding kinds {unknown}: use {', '.join(kinds)}")
            self._types = [kinds[b] for b in self.bindings]
            spirv = device.fit_spirv(spirv)  # fp16: drop naga's unused StorageInputOutput16 where unsupported
            self.module = vk.vkCreateShaderModule(dev, vk.VkShaderModuleCreateInfo(
                codeSize=len(spirv), pCode=spirv), None)
            self.set_layout = vk.vkCreateDescriptorSetLayout(dev, vk.VkDescriptorSetLayoutCreateInfo(
                pBindings=[vk.VkDescriptorSetLayoutBinding(
                    binding=i, descriptorType=t, descriptorCount=1, stageFlags=vk.VK_SHADER_STAGE_COMPUTE_BIT)
                    for i, t in enumerate(self._types)]), None)
            self.layout = vk.vkCreatePipelineLayout(dev, vk.VkPipelineLayoutCreateInfo(
                pSetLayouts=[self.set_layout]), None)
            # The entry-point name must outlive the call (TOOLCHAIN.md: the binding frees nested
            # strings early, and vkCreateComputePipelines then finds no entry point named "").
            name = vk.ffi.new("char[]", entry.encode())
            spec = None
            if specialization:  # int32 values by SpecId; the data and entries must outlive the call
                ids = sorted(specialization)
                data = vk.ffi.new("int32_t[]", [int(specialization[i]) for i in ids])
                entries = [vk.VkSpecializationMapEntry(constantID=i, offset=4 * k, size=4) for k, i in enumerate(ids)]
                spec = vk.VkSpecializationInfo(pMapEntries=entries, dataSize=4 * len(ids), pData=data)
            stage = vk.VkPipelineShaderStageCreateInfo(stage=vk.VK_SHADER_STAGE_COMPUTE_BIT,
                                                       module=self.module, pName=name, pSpecializationInfo=spec)
            info = vk.VkComputePipelineCreateInfo(flags=flags, stage=stage, layout=self.layout)
            # cache: a runtime.pipeline_cache.PipelineCacheFile (its VkPipelineCache), or None
            self.handle = vk.vkCreateComputePipelines(dev, cache.handle if cache else None, 1, [info], None)[0]
            counts = {}
            for t in self._types:
                counts[t] = counts.get(t, 0) + 1
            self.pool = vk.vkCreateDescriptorPool(dev, vk.VkDescriptorPoolCreateInfo(
                maxSets=1, pPoolSizes=[vk.VkDescriptorPoolSize(type=t, descriptorCount=n)
                                       for t, n in counts.items()]), None)
            self.set = vk.vkAllocateDescriptorSets(dev, vk.VkDescriptorSetAllocateInfo(
                descriptorPool=self.pool, pSetLayouts=[self.set_layout]))[0]
            self.queries = vk.vkCreateQueryPool(dev, vk.VkQueryPoolCreateInfo(
                queryType=vk.VK_QUERY_TYPE_TIMESTAMP, queryCount=2), None)
        except BaseException:
            self.destroy()
            raise
        device.own(self)

    def bind(self, resources) -> None:
        """Point set 0 at resources: a list for every binding (resources[i] at binding i), or a dict
        {binding: resource} that updates only those bindings.

        Buffers are bound whole; an Image as its view in SHADER_READ_ONLY_OPTIMAL; a Sampler alone.
        Every binding must have been written before :meth:`dispatch`.
        """
        vk = self.vk
        if isinstance(resources, dict):
            items = sorted(resources.items())
        else:
            resources = list(resources)
            if len(resources) != len(self.bindings):
                raise ValueError(f"pipeline has {len(self.bindings)} bindings, got {len(resources)} resources")
            items = list(enumerate(resources))
        infos, writes = [], []  # the infos must outlive vkUpdateDescriptorSets (cffi frees nested data)
        for i, res in items:
            if not 0 <= i < len(self.bindings):
                raise ValueError(f"binding {i} is not one of the pipeline's 0..{len(self.bindings) - 1}")
            kind = self.bindings[i]
            if not isinstance(res, _RESOURCE[kind]) or res.handle is None:
                dead = " (destroyed)" if getattr(res, "handle", 0) is None else ""
                raise TypeError(f"binding {i} is {kind}: it takes a live {_RESOURCE[kind].__name__}, "
                                f"got {type(res).__name__}{dead}")
            info, write = descriptor_write(vk, self.set, i, kind, self._types[i], res)
            infos.append(info)
            writes.append(write)
        if writes:
            vk.vkUpdateDescriptorSets(self.device.handle, len(writes), writes, 0, None)

    def dispatch(self, groups_x: int, groups_y: int = 1, groups_z: int = 1, timed: bool = False) -> float | None:
        """Run the pipeline over the given workgroup counts and wait; seconds of device time if `timed`."""
        vk, dev = self.vk, self.device

        def record(cmd):
            if timed:
                vk.vkCmdResetQueryPool(cmd, self.queries, 0, 2)
                vk.vkCmdWriteTimestamp(cmd, vk.VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, self.queries, 0)
            vk.vkCmdBindPipeline(cmd, vk.VK_PIPELINE_BIND_POINT_COMPUTE, self.handle)
            vk.vkCmdBindDescriptorSets(cmd, vk.VK_PIPELINE_BIND_POINT_COMPUTE, self.layout, 0, 1, [self.set], 0, None)
            vk.vkCmdDispatch(cmd, groups_x, groups_y, groups_z)
            if timed:
                vk.vkCmdWriteTimestamp(cmd, vk.VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, self.queries, 1)

        dev.submit(record)
        if not timed:
            return None
        data = vk.ffi.new("uint64_t[2]")
        vk.vkGetQueryPoolResults(dev.handle, self.queries, 0, 2, vk.ffi.sizeof(data), data, 8,
                                 vk.VK_QUERY_RESULT_64_BIT | vk.VK_QUERY_RESULT_WAIT_BIT)
        mask = (1 << dev.timestamp_bits) - 1 if dev.timestamp_bits < 64 else (1 << 64) - 1
        ticks = (int(data[1]) - int(data[0])) & mask
        return ticks * dev.timestamp_period_ns * 1e-9

    def destroy(self) -> None:
        vk, dev = self.vk, self.device.handle
        if dev is None:
            return
        for attr, fn in (("queries", vk.vkDestroyQueryPool), ("pool", vk.vkDestroyDescriptorPool),
                         ("handle", vk.vkDestroyPipeline), ("layout", vk.vkDestroyPipelineLayout),
                         ("set_layout", vk.vkDestroyDescriptorSetLayout), ("module", vk.vkDestroyShaderModule)):
            obj = getattr(self, attr)
            if obj is not None:
                fn(dev, obj, None)
                setattr(self, attr, None)
