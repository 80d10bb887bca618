"""Sampled images for the texture tests: a float RGBA 2D or cube image, a sampler, a compute pipeline.

Test-only Vulkan on top of generator.runtime.device.Device (its handle, buffers and submit):
the project's ComputePipeline binds buffers only. The sampler is the one the NumPy target
reproduces: VK_FILTER_LINEAR, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE, one mip level.
"""
from __future__ import annotations

import numpy as np


_VIEWS = {"2d": "VK_IMAGE_VIEW_TYPE_2D", "cube": "VK_IMAGE_VIEW_TYPE_CUBE", "2d_array": "VK_IMAGE_VIEW_TYPE_2D_ARRAY",
          "cube_array": "VK_IMAGE_VIEW_TYPE_CUBE_ARRAY"}


class Image:
    """An R32G32B32A32_SFLOAT image (H, W, 4) or cube (6, H, W, 4), uploaded and ready to sample; with `view`
    "2d_array" (L, H, W, 4) or "cube_array" (L, 6, H, W, 4) layers; depth: a D32_SFLOAT image of (L, H, W)
    depths in [0, 1] (a 2d_array view) for a comparison sampler."""

    def __init__(self, device, texels: np.ndarray, cube: bool = False, view: str | None = None,
                 depth: bool = False):
        vk = self.vk = device.vk
        self.device, self.depth = device, depth
        view = view or ("cube" if cube else "2d")
        texels = np.ascontiguousarray(texels, np.float32)
        cube = view.startswith("cube")
        layers = {"2d": 1, "cube": 6}.get(view) or int(np.prod(texels.shape[:-2 if depth else -3]))
        h, w = (texels.shape[-2], texels.shape[-1]) if depth else (texels.shape[-3], texels.shape[-2])
        fmt = vk.VK_FORMAT_D32_SFLOAT if depth else vk.VK_FORMAT_R32G32B32A32_SFLOAT
        aspect = vk.VK_IMAGE_ASPECT_DEPTH_BIT if depth else vk.VK_IMAGE_ASPECT_COLOR_BIT
        dev = device.handle
        self.handle = self.memory = self.view = None
        staging = device.buffer(texels.nbytes, vk.VK_BUFFER_USAGE_TRANSFER_SRC_BIT)
        try:
            staging.write(texels)
            self.handle = vk.vkCreateImage(dev, vk.VkImageCreateInfo(
                flags=vk.VK_IMAGE_CREATE_CUBE_COMPATIBLE_BIT if cube else 0, imageType=vk.VK_IMAGE_TYPE_2D,
                format=fmt, extent=vk.VkExtent3D(width=w, height=h, depth=1),
                mipLevels=1, arrayLayers=layers, samples=vk.VK_SAMPLE_COUNT_1_BIT, tiling=vk.VK_IMAGE_TILING_OPTIMAL,
                usage=vk.VK_IMAGE_USAGE_SAMPLED_BIT | vk.VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                sharingMode=vk.VK_SHARING_MODE_EXCLUSIVE, initialLayout=vk.VK_IMAGE_LAYOUT_UNDEFINED), None)
            req = vk.vkGetImageMemoryRequirements(dev, self.handle)
            self.memory = vk.vkAllocateMemory(dev, vk.VkMemoryAllocateInfo(
                allocationSize=req.size, memoryTypeIndex=device.host_memory_type(req.memoryTypeBits)), None)
            vk.vkBindImageMemory(dev, self.handle, self.memory, 0)
            rng = vk.VkImageSubresourceRange(aspectMask=aspect, baseMipLevel=0, levelCount=1,
                                             baseArrayLayer=0, layerCount=layers)

            def barrier(old, new, src, dst):
                return vk.VkImageMemoryBarrier(srcAccessMask=src, dstAccessMask=dst, oldLayout=old, newLayout=new,
                                               srcQueueFamilyIndex=vk.VK_QUEUE_FAMILY_IGNORED,
                                               dstQueueFamilyIndex=vk.VK_QUEUE_FAMILY_IGNORED,
                                               image=self.handle, subresourceRange=rng)

            def record(cmd):
                vk.vkCmdPipelineBarrier(cmd, vk.VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, vk.VK_PIPELINE_STAGE_TRANSFER_BIT,
                                        0, 0, None, 0, None, 1, [barrier(
                                            vk.VK_IMAGE_LAYOUT_UNDEFINED, vk.VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                                            0, vk.VK_ACCESS_TRANSFER_WRITE_BIT)])
                region = vk.VkBufferImageCopy(
                    bufferOffset=0, bufferRowLength=0, bufferImageHeight=0,
                    imageSubresource=vk.VkImageSubresourceLayers(aspectMask=aspect, mipLevel=0,
                                                                 baseArrayLayer=0, layerCount=layers),
                    imageOffset=vk.VkOffset3D(x=0, y=0, z=0), imageExtent=vk.VkExtent3D(width=w, height=h, depth=1))
                vk.vkCmdCopyBufferToImage(cmd, staging.handle, self.handle, vk.VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                                          1, [region])
                vk.vkCmdPipelineBarrier(cmd, vk.VK_PIPELINE_STAGE_TRANSFER_BIT,
                                        vk.VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 0, None, 0, None, 1, [barrier(
                                            vk.VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                                            vk.VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                                            vk.VK_ACCESS_TRANSFER_WRITE_BIT, vk.VK_ACCESS_SHADER_READ_BIT)])

            device.submit(record)
            self.view = vk.vkCreateImageView(dev, vk.VkImageViewCreateInfo(
                image=self.handle, viewType=getattr(vk, _VIEWS[view]), format=fmt, subresourceRange=rng,
                components=vk.VkComponentMapping(r=vk.VK_COMPONENT_SWIZZLE_IDENTITY, g=vk.VK_COMPONENT_SWIZZLE_IDENTITY,
                                                 b=vk.VK_COMPONENT_SWIZZLE_IDENTITY,
                                                 a=vk.VK_COMPONENT_SWIZZLE_IDENTITY)), None)
        except BaseException:
            self.destroy()
            raise
        finally:
            staging.destroy()

    def destroy(self):
        vk, dev = self.vk, self.device.handle
        if self.view is not None:
            vk.vkDestroyImageView(dev, self.view, None)
        if self.handle is not None:
            vk.vkDestroyImage(dev, self.handle, None)
        if self.memory is not None:
            vk.vkFreeMemory(dev, self.memory, None)
        self.view = self.handle = self.memory = None


def linear_clamp_sampler(device, compare: bool = False):
    """The linear clamp-to-edge level-0 sampler (compare: with compareOp LESS_OR_EQUAL, for depth images)."""
    vk = device.vk
    clamp = vk.VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE
    return vk.vkCreateSampler(device.handle, vk.VkSamplerCreateInfo(
        magFilter=vk.VK_FILTER_LINEAR, minFilter=vk.VK_FILTER_LINEAR, mipmapMode=vk.VK_SAMPLER_MIPMAP_MODE_NEAREST,
        addressModeU=clamp, addressModeV=clamp, addressModeW=clamp, mipLodBias=0.0, anisotropyEnable=vk.VK_FALSE,
        maxAnisotropy=1.0, compareEnable=vk.VK_TRUE if compare else vk.VK_FALSE,
        compareOp=vk.VK_COMPARE_OP_LESS_OR_EQUAL if compare else vk.VK_COMPARE_OP_ALWAYS, minLod=0.0, maxLod=0.0,
        borderColor=vk.VK_BORDER_COLOR_FLOAT_TRANSPARENT_BLACK, unnormalizedCoordinates=vk.VK_FALSE), None)


def run_sampling_kernel(device, spirv: bytes, samples: np.ndarray, out_vec4s: int, images: list[Image]):
    """Run one invocation per sample (len(samples), any trailing shape): binding 0 the samples,
    1 out_vec4s result vec4s per sample, then an (image, sampler) binding pair per image."""
    vk, dev = device.vk, device.handle
    kinds = ([vk.VK_DESCRIPTOR_TYPE_STORAGE_BUFFER] * 2
             + [vk.VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, vk.VK_DESCRIPTOR_TYPE_SAMPLER] * len(images))
    usage = vk.VK_BUFFER_USAGE_STORAGE_BUFFER_BIT
    samples = np.ascontiguousarray(samples, np.float32)
    bufs = [device.buffer(samples.nbytes, usage), device.buffer(len(samples) * out_vec4s * 16, usage)]
    objs = {}
    try:
        bufs[0].write(samples)
        objs["sampler"] = linear_clamp_sampler(device)
        if any(getattr(i, "depth", False) for i in images):
            objs["compare_sampler"] = linear_clamp_sampler(device, compare=True)
        objs["module"] = vk.vkCreateShaderModule(dev, vk.VkShaderModuleCreateInfo(codeSize=len(spirv), pCode=spirv), None)
        objs["set_layout"] = vk.vkCreateDescriptorSetLayout(dev, vk.VkDescriptorSetLayoutCreateInfo(pBindings=[
            vk.VkDescriptorSetLayoutBinding(binding=i, descriptorType=t, descriptorCount=1,
                                            stageFlags=vk.VK_SHADER_STAGE_COMPUTE_BIT)
            for i, t in enumerate(kinds)]), None)
        objs["layout"] = vk.vkCreatePipelineLayout(dev, vk.VkPipelineLayoutCreateInfo(
            pSetLayouts=[objs["set_layout"]]), None)
        name = vk.ffi.new("char[]", b"main")
        stage = vk.VkPipelineShaderStageCreateInfo(stage=vk.VK_SHADER_STAGE_COMPUTE_BIT, module=objs["module"],
                                                   pName=name)
        objs["pipeline"] = vk.vkCreateComputePipelines(dev, None, 1, [vk.VkComputePipelineCreateInfo(
            stage=stage, layout=objs["layout"])], None)[0]
        counts = {}
        for t in kinds:
            counts[t] = counts.get(t, 0) + 1
        objs["pool"] = vk.vkCreateDescriptorPool(dev, vk.VkDescriptorPoolCreateInfo(maxSets=1, pPoolSizes=[
            vk.VkDescriptorPoolSize(type=t, descriptorCount=n) for t, n in counts.items()]), None)
        dset = vk.vkAllocateDescriptorSets(dev, vk.VkDescriptorSetAllocateInfo(
            descriptorPool=objs["pool"], pSetLayouts=[objs["set_layout"]]))[0]
        writes = [vk.VkWriteDescriptorSet(dstSet=dset, dstBinding=i, dstArrayElement=0, descriptorCount=1,
                                          descriptorType=kinds[i], pBufferInfo=[vk.VkDescriptorBufferInfo(
                                              buffer=b.handle, offset=0, range=b.size)])
                  for i, b in enumerate(bufs)]
        for j, img in enumerate(images):
            writes.append(vk.VkWriteDescriptorSet(
                dstSet=dset, dstBinding=2 + 2 * j, dstArrayElement=0, descriptorCount=1,
                descriptorType=vk.VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, pImageInfo=[vk.VkDescriptorImageInfo(
                    imageView=img.view, imageLayout=vk.VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL)]))
            writes.append(vk.VkWriteDescriptorSet(
                dstSet=dset, dstBinding=3 + 2 * j, dstArrayElement=0, descriptorCount=1,
                descriptorType=vk.VK_DESCRIPTOR_TYPE_SAMPLER, pImageInfo=[vk.VkDescriptorImageInfo(
                    sampler=objs["compare_sampler" if getattr(img, "depth", False) else "sampler"])]))
        vk.vkUpdateDescriptorSets(dev, len(writes), writes, 0, None)

        def record(cmd):
            vk.vkCmdBindPipeline(cmd, vk.VK_PIPELINE_BIND_POINT_COMPUTE, objs["pipeline"])
            vk.vkCmdBindDescriptorSets(cmd, vk.VK_PIPELINE_BIND_POINT_COMPUTE, objs["layout"], 0, 1, [dset], 0, None)
            vk.vkCmdDispatch(cmd, len(samples), 1, 1)

        device.submit(record)
        return bufs[1].array(np.float32)[: len(samples) * out_vec4s * 4].reshape(len(samples), out_vec4s, 4).copy()
    finally:
        for b in bufs:
            b.destroy()
        for key, destroy in (("pipeline", vk.vkDestroyPipeline), ("pool", vk.vkDestroyDescriptorPool),
                             ("layout", vk.vkDestroyPipelineLayout), ("set_layout", vk.vkDestroyDescriptorSetLayout),
                             ("module", vk.vkDestroyShaderModule), ("sampler", vk.vkDestroySampler),
                             ("compare_sampler", vk.vkDestroySampler)):
            if key in objs:
                destroy(dev, objs[key], None)
