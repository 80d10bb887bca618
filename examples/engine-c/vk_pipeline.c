/* See vk_pipeline.h. */
#include "vk_pipeline.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vk_enums.h"

static bool put_binding(program_layout *l, const program *p, int set, int binding, binding_kind kind, int ref,
                        VkShaderStageFlags stages)
{
    if (set >= MAX_SETS)
        return fail("%s: set %d; this engine binds sets 0 to %d", p->name, set, MAX_SETS - 1);
    for (int i = 0; i < l->nbindings[set]; i++)
        if (l->bindings[set][i].binding == (uint32_t)binding)
            return fail("%s: set %d binding %d is claimed twice in its interface", p->name, set, binding);
    if (l->nbindings[set] == MAX_SET_BINDINGS)
        return fail("%s: more than %d bindings in set %d", p->name, MAX_SET_BINDINGS, set);
    l->bindings[set][l->nbindings[set]++] = (set_binding){(uint32_t)binding, kind, ref, stages};
    if (set + 1 > l->nsets)
        l->nsets = set + 1;
    return true;
}

static const VkDescriptorType TYPES[] = {
    [BIND_BLOCK] = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER,
    [BIND_IMAGE] = VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE,
    [BIND_SAMPLER] = VK_DESCRIPTOR_TYPE_SAMPLER,
    [BIND_STORAGE] = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
};

bool layout_create(gpu *g, const program *p, program_layout *l)
{
    memset(l, 0, sizeof *l);
    for (int i = 0; i < p->nblocks; i++)
        if (!put_binding(l, p, p->blocks[i].set, p->blocks[i].binding,
                         p->blocks[i].storage ? BIND_STORAGE : BIND_BLOCK, i, p->blocks[i].stages))
            return false;
    for (int i = 0; i < p->ntextures; i++) {
        const texture_ref *t = &p->textures[i];
        if (!put_binding(l, p, t->set, t->binding, BIND_IMAGE, i, t->stages)
            || !put_binding(l, p, t->set, t->sampler_binding, BIND_SAMPLER, i, t->stages))
            return false;
    }
    for (int s = 0; s < l->nsets; s++) {
        VkDescriptorSetLayoutBinding b[MAX_SET_BINDINGS];
        for (int i = 0; i < l->nbindings[s]; i++) {
            const set_binding *x = &l->bindings[s][i];
            b[i] = (VkDescriptorSetLayoutBinding){x->binding, TYPES[x->kind], 1, x->stages, NULL};
        }
        VkDescriptorSetLayoutCreateInfo info = {.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
        info.bindingCount = (uint32_t)l->nbindings[s];
        info.pBindings = b;
        VkResult r = vkCreateDescriptorSetLayout(g->device, &info, NULL, &l->sets[s]);
        if (r != VK_SUCCESS)
            return vk_failed("vkCreateDescriptorSetLayout", r);
        if (!gpu_own(g, (owned){.kind = OWN_SET_LAYOUT, .u.set_layout = l->sets[s]}))
            return false;
    }
    VkPipelineLayoutCreateInfo info = {.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    info.setLayoutCount = (uint32_t)l->nsets;
    info.pSetLayouts = l->sets;
    VkResult r = vkCreatePipelineLayout(g->device, &info, NULL, &l->layout);
    if (r != VK_SUCCESS)
        return vk_failed("vkCreatePipelineLayout", r);
    return gpu_own(g, (owned){.kind = OWN_PIPELINE_LAYOUT, .u.pipeline_layout = l->layout});
}

static void hex32(const unsigned char *raw, char out[65])
{
    for (int i = 0; i < 32; i++)
        snprintf(out + 2 * i, 3, "%02x", raw[i]);
}

/* The stage's SPIR-V from the pack, in a shader module. The blob is copied: the pack's bytes are not
 * guaranteed 4-byte aligned, and vkCreateShaderModule reads uint32_t words. */
static bool shader_module(gpu *g, const smpack *pack, const program *p, const char *stage, VkShaderModule *out)
{
    smpack_entry e;
    smpack_status s = smpack_find(pack, p->hash, stage, &e);
    if (s != SMPACK_OK)
        return fail("the vulkan pack has no %s stage of %s (%s) — build again with `--pack`: the pack and the "
                    "manifest are from different builds", stage, p->name, smpack_status_name(s));
    char key[65];
    hex32(e.input_key, key);
    if (strcmp(key, p->input_key) != 0)
        return fail("the vulkan pack's %s.%s was built from other inputs (input key %.12s…, the manifest's "
                    "%.12s…) — build again: the pack and the manifest are from different builds", p->hash, stage,
                    key, p->input_key);
    if (e.length == 0 || e.length % 4 || e.length > 64u << 20)
        return fail("the vulkan pack's %s.%s is %llu bytes: not SPIR-V words", p->hash, stage,
                    (unsigned long long)e.length);
    uint32_t *words = malloc((size_t)e.length);
    if (!words)
        return fail("out of memory");
    memcpy(words, e.data, (size_t)e.length);
    VkShaderModuleCreateInfo info = {.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    info.codeSize = (size_t)e.length;
    info.pCode = words;
    VkResult r = vkCreateShaderModule(g->device, &info, NULL, out);
    free(words);
    return r == VK_SUCCESS || vk_failed("vkCreateShaderModule", r);
}

/* The fixed-function state of a pipeline, filled from a pipeline_state; the create infos point into it. */
typedef struct fixed_states {
    VkVertexInputBindingDescription vb[MAX_INPUTS];
    VkVertexInputAttributeDescription va[MAX_INPUTS];
    VkPipelineVertexInputStateCreateInfo vertex;
    VkPipelineInputAssemblyStateCreateInfo assembly;
    VkViewport viewport;
    VkRect2D scissor;
    VkPipelineViewportStateCreateInfo viewports;
    VkPipelineRasterizationStateCreateInfo raster;
    VkPipelineMultisampleStateCreateInfo multisample;
    VkPipelineDepthStencilStateCreateInfo depth;
    VkPipelineColorBlendAttachmentState attachment;
    VkPipelineColorBlendStateCreateInfo blend;
} fixed_states;

static void fixed_function(const program *p, const pipeline_state *st, fixed_states *f)
{
    memset(f, 0, sizeof *f);
    for (int i = 0; i < p->ninputs; i++) {  /* input k: binding k, tightly packed, per vertex */
        f->vb[i] = (VkVertexInputBindingDescription){(uint32_t)i, p->inputs[i].bytes, VK_VERTEX_INPUT_RATE_VERTEX};
        f->va[i] = (VkVertexInputAttributeDescription){(uint32_t)p->inputs[i].location, (uint32_t)i,
                                                       p->inputs[i].format, 0};
    }
    f->vertex = (VkPipelineVertexInputStateCreateInfo){.sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
    f->vertex.vertexBindingDescriptionCount = f->vertex.vertexAttributeDescriptionCount = (uint32_t)p->ninputs;
    f->vertex.pVertexBindingDescriptions = f->vb;
    f->vertex.pVertexAttributeDescriptions = f->va;
    f->assembly = (VkPipelineInputAssemblyStateCreateInfo){
        .sType = VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO,
        .topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST};
    /* Vulkan's own clip space (conventions.platforms.vulkan.clip): no y flip in the viewport, depth 0..1 */
    f->viewport = (VkViewport){0.0f, 0.0f, (float)st->width, (float)st->height, 0.0f, 1.0f};
    f->scissor = (VkRect2D){{0, 0}, {st->width, st->height}};
    f->viewports = (VkPipelineViewportStateCreateInfo){.sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO,
        .viewportCount = 1, .pViewports = &f->viewport, .scissorCount = 1, .pScissors = &f->scissor};
    f->raster = (VkPipelineRasterizationStateCreateInfo){
        .sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO, .polygonMode = VK_POLYGON_MODE_FILL,
        .cullMode = st->cull, .frontFace = st->front_face,
        .depthBiasEnable = st->bias_constant != 0.0f || st->bias_slope != 0.0f,
        .depthBiasConstantFactor = st->bias_constant, .depthBiasSlopeFactor = st->bias_slope,
        .depthBiasClamp = st->bias_clamp, .lineWidth = 1.0f};
    f->multisample = (VkPipelineMultisampleStateCreateInfo){
        .sType = VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO,
        .rasterizationSamples = VK_SAMPLE_COUNT_1_BIT};
    f->depth = (VkPipelineDepthStencilStateCreateInfo){.sType = VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO,
        .depthTestEnable = st->depth_test, .depthWriteEnable = st->depth_write, .depthCompareOp = st->depth_compare,
        .maxDepthBounds = 1.0f};
    bool b = st->blend;  /* without blending the attachment stores what the shader writes */
    f->attachment = (VkPipelineColorBlendAttachmentState){
        .blendEnable = b, .srcColorBlendFactor = b ? st->src_color : VK_BLEND_FACTOR_ONE,
        .dstColorBlendFactor = b ? st->dst_color : VK_BLEND_FACTOR_ZERO, .colorBlendOp = b ? st->color_op : VK_BLEND_OP_ADD,
        .srcAlphaBlendFactor = b ? st->src_alpha : VK_BLEND_FACTOR_ONE,
        .dstAlphaBlendFactor = b ? st->dst_alpha : VK_BLEND_FACTOR_ZERO, .alphaBlendOp = b ? st->alpha_op : VK_BLEND_OP_ADD,
        .colorWriteMask = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT
                        | VK_COLOR_COMPONENT_A_BIT};
    f->blend = (VkPipelineColorBlendStateCreateInfo){.sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO,
        .attachmentCount = 1, .pAttachments = &f->attachment};
}

bool pipeline_create(gpu *g, const smpack *pack, const program *p, const program_layout *layout,
                     const pipeline_state *st, VkPipeline *out)
{
    VkShaderModule modules[2] = {VK_NULL_HANDLE, VK_NULL_HANDLE};
    VkPipelineShaderStageCreateInfo stages[2];
    int nstages = p->has_frag ? 2 : 1;  /* a depth pass's caster may be vertex-only */
    const char *names[2] = {"vert", "frag"};
    const VkShaderStageFlagBits bits[2] = {VK_SHADER_STAGE_VERTEX_BIT, VK_SHADER_STAGE_FRAGMENT_BIT};
    bool ok = true;
    for (int i = 0; i < nstages && ok; i++) {
        ok = shader_module(g, pack, p, names[i], &modules[i]);
        stages[i] = (VkPipelineShaderStageCreateInfo){.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO,
                                                      .stage = bits[i], .module = modules[i], .pName = p->entry[i]};
    }
    fixed_states f;
    fixed_function(p, st, &f);
    VkGraphicsPipelineCreateInfo info = {.sType = VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
    info.stageCount = (uint32_t)nstages;
    info.pStages = stages;
    info.pVertexInputState = &f.vertex;
    info.pInputAssemblyState = &f.assembly;
    info.pViewportState = &f.viewports;
    info.pRasterizationState = &f.raster;
    info.pMultisampleState = &f.multisample;
    info.pDepthStencilState = &f.depth;
    info.pColorBlendState = st->color ? &f.blend : NULL;  /* a depth-only pass has no colour attachment */
    info.layout = layout->layout;
    info.renderPass = st->render_pass;
    info.basePipelineIndex = -1;
    if (ok) {
        VkResult r = vkCreateGraphicsPipelines(g->device, VK_NULL_HANDLE, 1, &info, NULL, out);
        ok = r == VK_SUCCESS ? gpu_own(g, (owned){.kind = OWN_PIPELINE, .u.pipeline = *out})
                             : vk_failed("vkCreateGraphicsPipelines", r);
    }
    for (int i = 0; i < 2; i++)  /* a pipeline keeps what it needs of its modules */
        if (modules[i])
            vkDestroyShaderModule(g->device, modules[i], NULL);
    return ok;
}

/* One enum member of a sampler row: `row[key]` must be a name of `family`. */
static bool row_enum(const json_src *src, const cJSON *row, const char *key, const char *family, const char *where,
                     int32_t *out)
{
    const char *name = j_str(src, row, key, where);
    if (!name)
        return false;
    if (!vk_enum(family, name, out))
        return j_fail(src, where, "%s %s is not a %s… name this engine knows", key, name, family);
    return true;
}

bool sampler_create(gpu *g, const json_src *src, const cJSON *row, const char *where, VkSampler *out)
{
    VkSamplerCreateInfo info = {.sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
    int32_t mag, min, mip, u, v, w, cmp;
    double bias, max_aniso, min_lod, max_lod;
    bool aniso, compare;
    if (!row_enum(src, row, "magFilter", "VK_FILTER_", where, &mag)
        || !row_enum(src, row, "minFilter", "VK_FILTER_", where, &min)
        || !row_enum(src, row, "mipmapMode", "VK_SAMPLER_MIPMAP_MODE_", where, &mip)
        || !row_enum(src, row, "addressModeU", "VK_SAMPLER_ADDRESS_MODE_", where, &u)
        || !row_enum(src, row, "addressModeV", "VK_SAMPLER_ADDRESS_MODE_", where, &v)
        || !row_enum(src, row, "addressModeW", "VK_SAMPLER_ADDRESS_MODE_", where, &w)
        || !row_enum(src, row, "compareOp", "VK_COMPARE_OP_", where, &cmp)
        || !j_num(src, row, "mipLodBias", where, &bias) || !j_bool(src, row, "anisotropyEnable", where, &aniso)
        || !j_num(src, row, "maxAnisotropy", where, &max_aniso) || !j_bool(src, row, "compareEnable", where, &compare)
        || !j_num(src, row, "minLod", where, &min_lod) || !j_num(src, row, "maxLod", where, &max_lod))
        return false;
    double a = aniso ? max_aniso : 1.0, limit = g->props.limits.maxSamplerAnisotropy;
    if (a > 1.0 && !g->anisotropy) {
        note("%s: anisotropy %g clamped to 1: %s has no samplerAnisotropy", where, a, g->props.deviceName);
        a = 1.0;
    } else if (a > limit) {
        note("%s: anisotropy %g clamped to %g, %s's maxSamplerAnisotropy", where, a, limit, g->props.deviceName);
        a = limit;
    }
    double most = g->props.limits.maxSamplerLodBias;
    if (bias > most || bias < -most) {
        double b = bias > most ? most : -most;
        note("%s: LOD bias %g clamped to %g, %s's maxSamplerLodBias", where, bias, b, g->props.deviceName);
        bias = b;
    }
    info.magFilter = (VkFilter)mag;
    info.minFilter = (VkFilter)min;
    info.mipmapMode = (VkSamplerMipmapMode)mip;
    info.addressModeU = (VkSamplerAddressMode)u;
    info.addressModeV = (VkSamplerAddressMode)v;
    info.addressModeW = (VkSamplerAddressMode)w;
    info.mipLodBias = (float)bias;
    info.anisotropyEnable = a > 1.0;
    info.maxAnisotropy = (float)a;
    info.compareEnable = compare;
    info.compareOp = (VkCompareOp)cmp;
    info.minLod = (float)min_lod;
    info.maxLod = (float)max_lod;
    info.borderColor = VK_BORDER_COLOR_FLOAT_TRANSPARENT_BLACK;  /* the rows clamp to the edge; never read */
    VkResult r = vkCreateSampler(g->device, &info, NULL, out);
    if (r != VK_SUCCESS)
        return vk_failed("vkCreateSampler", r);
    return gpu_own(g, (owned){.kind = OWN_SAMPLER, .u.sampler = *out});
}
