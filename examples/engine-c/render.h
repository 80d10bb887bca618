/* The frame: everything the engine creates from the manifest and the frame export, and the one command
 * buffer that draws it (the depth passes, then the colour pass, then the readback).
 *
 * resources.c makes what draws read: textures (KTX2), samplers (rows), meshes, the uniform blocks (Frame,
 * Object from the export; Material, Lights from the manifest's uploads, with the export's shadow matrices
 * written in). color.c makes the colour pass's target and states, passes.c the depth passes; draw.c the
 * pipelines and the draws, and records the frame; bindings.c writes the draws' descriptor sets. */
#ifndef ENGINE_RENDER_H
#define ENGINE_RENDER_H

#include <shadermatrix/pack.h>

#include "ktx2.h"
#include "scene.h"
#include "vk_device.h"
#include "vk_pipeline.h"

#define MAX_BLUR 8

typedef struct texture_entry {
    const char *path;          /* the manifest's path, relative to the build */
    gpu_image image;
    gpu_buffer staging;        /* its levels, copied in at the start of the frame */
    VkDeviceSize level_offset[KTX2_MAX_LEVELS];
} texture_entry;

typedef struct light_pass {
    const char *name;
    const cJSON *desc;         /* lights.<name>.depth_pass */
    const flight *fl;
    bool moments;              /* kind "moments": a colour target of moments beside the depth, then the blur */
    uint32_t width, height;
    gpu_image depth;
    VkRenderPass render_pass;
    VkFramebuffer framebuffer;
    VkClearValue clears[2];
    double view_proj[16];      /* premultiply.vulkan × shadow_matrix (or its face's), column-major */
    int face;                  /* a point light's face this pass draws (one pass per face), or -1 */
    gpu_image array;           /* on face 0's pass: the six faces' layers, copied in after the passes (what binds) */
    pipeline_state state;      /* the casters' fixed-function state */
    /* kind moments: the moments target, then one target per blur pass; the last is what binds */
    gpu_image targets[1 + MAX_BLUR];
    VkFramebuffer blur_framebuffers[MAX_BLUR];
    VkRenderPass blur_pass;
    int nblur;
    const cJSON *blur;         /* moments.blur */
} light_pass;

typedef struct pipe_entry {
    const program *prog;
    int pass;                  /* -1: the colour pass; else the light pass; blur pipelines: pass + 1000 */
    program_layout layout;
    VkPipeline pipeline;
} pipe_entry;

typedef struct draw_item {
    pipe_entry *pipe;
    int object;                /* index into the objects; -1 for a blur pass */
    int pass;                  /* -1 colour, else the light pass */
    int blur;                  /* the blur pass's index, or -1 */
    VkDescriptorSet sets[MAX_SETS];
    VkBuffer vertex_buffers[MAX_INPUTS];
    VkDeviceSize vertex_offsets[MAX_INPUTS];
    VkBuffer index_buffer;
    VkDeviceSize index_offset;
    uint32_t index_count;
} draw_item;

typedef struct block_entry {
    const char *name;
    const void *key;           /* what it is per: an object, an upload, a pass */
    gpu_buffer buffer;
    const cJSON *layout;       /* the block description it was written by */
} block_entry;

/* A dynamic set's shadowed pair: its lights' maps (one each, a point light's six faces) in the layers of one 2D
 * array, copied in after the passes (what its permutations bind). */
typedef struct pair_array {
    const cJSON *pair;         /* dynamic_light_sets.<set>.pairs[i] */
    gpu_image image;
    int nsources;
    const gpu_image **sources; /* layer k's pass result */
} pair_array;

typedef struct engine {
    gpu *g;
    const manifest *m;
    const frame *f;
    const smpack *pack;
    texture_entry *textures;
    int ntextures, captextures;
    VkSampler *samplers;       /* per row of the manifest's samplers, made on first use */
    int nsamplers;
    gpu_buffer *meshes;        /* per mesh: its .bin, vertex and index buffer at once */
    block_entry *blocks;
    int nblocks, capblocks;
    light_pass *passes;
    int npasses;
    pair_array *pairs;         /* made as the draws that read them are bound */
    int npairs, cappairs;
    program *units;
    int nunits, capunits;
    pipe_entry *pipes;
    int npipes, cappipes;
    draw_item *draws;
    int ndraws, capdraws;
    gpu_buffer fullscreen;     /* the blur passes' triangle */
    VkFormat color_format;
    gpu_image color, depth;
    VkRenderPass render_pass;
    VkFramebuffer framebuffer;
    gpu_buffer readback;
    VkDescriptorPool pool;
} engine;

/* Renders the frame into rgba (width × height × 4 bytes, row 0 at the top). */
bool engine_render(engine *e, unsigned char *rgba);
void engine_free(engine *e);

/* resources.c */
bool upload_meshes(engine *e);
bool texture_of_row(engine *e, const cJSON *row, const char *where, VkImageView *view);
bool sampler_of_row(engine *e, int index, const char *where, VkSampler *out);
bool block_buffer(engine *e, const draw_item *it, const block_ref *b, VkBuffer *out);
void record_texture_uploads(engine *e, VkCommandBuffer cmd);

/* bindings.c */
bool write_sets(engine *e);

/* color.c */
bool color_target(engine *e);
bool color_state(const engine *e, const program *p, pipeline_state *st);

/* passes.c: the light passes, and helpers every pass uses */
bool light_passes(engine *e);
bool face_array(engine *e, light_pass *first);
void record_face_copies(const engine *e, VkCommandBuffer cmd);
const gpu_image *pass_result(const light_pass *lp);
bool pair_array_of(engine *e, const cJSON *pair, const char *where, VkImageView *view);
bool make_render_pass(gpu *g, VkFormat color, VkImageLayout color_final, VkFormat depth, bool keep_depth,
                      VkImageLayout depth_final, VkRenderPass *out);
bool make_framebuffer(gpu *g, VkRenderPass pass, const VkImageView *views, uint32_t n, uint32_t w, uint32_t h,
                      VkFramebuffer *out);
/* conventions.platforms.vulkan.<group>.<key>[.<member>]: an enum name of `family` */
bool convention_enum(const engine *e, const char *group, const char *key, const char *member, const char *family,
                     int32_t *out);
bool cull_mode(const engine *e, const char *cull, VkCullModeFlags *out);
bool front_face(const engine *e, VkFrontFace *out);
/* obj[key], a lower-case name of `family` ("less" of VK_COMPARE_OP_) */
bool lower_enum(const engine *e, const cJSON *obj, const char *key, const char *family, const char *where,
                int32_t *out);
bool light_pass_of(const engine *e, const char *light, const light_pass **out);

#endif
