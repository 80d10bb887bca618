/* Pipelines, their layouts and samplers, made from the manifest's words alone.
 *
 * A program's descriptor set layouts come from its interface (scene.h program): one uniform-buffer binding per
 * block, and per texture a sampled image at `binding` and a sampler at `sampler_binding`, each visible to the
 * stages whose interface lists it; every set from 0 to the highest used exists (an empty layout where nothing
 * is bound), as a pipeline layout needs. The pipeline's fixed-function state is a pipeline_state filled from
 * render_state / a depth pass description and the conventions (render.c). */
#ifndef ENGINE_VK_PIPELINE_H
#define ENGINE_VK_PIPELINE_H

#include <shadermatrix/pack.h>

#include "scene.h"
#include "vk_device.h"

#define MAX_SETS 8
#define MAX_SET_BINDINGS 64

typedef enum binding_kind { BIND_BLOCK, BIND_IMAGE, BIND_SAMPLER, BIND_STORAGE } binding_kind;

typedef struct set_binding {
    uint32_t binding;
    binding_kind kind;
    int ref;                   /* index into the program's blocks (BIND_BLOCK) or textures */
    VkShaderStageFlags stages;
} set_binding;

typedef struct program_layout {
    int nsets;
    VkDescriptorSetLayout sets[MAX_SETS];
    set_binding bindings[MAX_SETS][MAX_SET_BINDINGS];
    int nbindings[MAX_SETS];
    VkPipelineLayout layout;
} program_layout;

typedef struct pipeline_state {
    VkRenderPass render_pass;
    uint32_t width, height;
    bool color;                /* the render pass has a colour attachment (else depth only) */
    VkCullModeFlags cull;
    VkFrontFace front_face;
    bool blend;
    VkBlendFactor src_color, dst_color, src_alpha, dst_alpha;
    VkBlendOp color_op, alpha_op;
    bool depth_test, depth_write;
    VkCompareOp depth_compare;
    float bias_constant, bias_slope, bias_clamp;
} pipeline_state;

bool layout_create(gpu *g, const program *p, program_layout *out);
/* Loads p's stages from the pack (checking each entry's input key against the manifest's) and creates the
 * pipeline; vertex input k is binding k, tightly packed, fed by the mesh attribute named like it. */
bool pipeline_create(gpu *g, const smpack *pack, const program *p, const program_layout *layout,
                     const pipeline_state *state, VkPipeline *out);
/* The sampler of a manifest row's `platforms.vulkan` (VkSamplerCreateInfo's members by name); what the device
 * cannot do (anisotropy without the feature or past its limit, a LOD bias past maxSamplerLodBias) is clamped
 * and said in a note, as the renderer does. */
bool sampler_create(gpu *g, const json_src *src, const cJSON *row, const char *where, VkSampler *out);

#endif
