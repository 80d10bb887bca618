/* The render passes: shared helpers (render passes, framebuffers, the conventions' and render state's enum
 * names), and each shadowed light's depth pass (lights.<name>.depth_pass:
 * its map, clear, depth test and bias, cull; for kind moments a moments target and the blur's targets), with
 * the fixed-function state their pipelines are made with. As the renderer: clears from the export and the
 * description, a viewport of the whole target with Vulkan's orientation, the colour left for the readback. */
#include "render.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vk_enums.h"

/* A render pass of an optional colour attachment (cleared, stored, left in `color_final`) and an optional depth
 * attachment (cleared; stored and left in `depth_final` when `keep_depth`, as a shadow map is). The two
 * dependencies order it after earlier passes' reads and writes and before later shaders' and copies' reads. */
bool make_render_pass(gpu *g, VkFormat color, VkImageLayout color_final, VkFormat depth, bool keep_depth,
                             VkImageLayout depth_final, VkRenderPass *out)
{
    VkAttachmentDescription att[2];
    VkAttachmentReference color_ref = {0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
    VkAttachmentReference depth_ref = {0, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
    uint32_t n = 0;
    if (color != VK_FORMAT_UNDEFINED)
        att[n++] = (VkAttachmentDescription){0, color, VK_SAMPLE_COUNT_1_BIT, VK_ATTACHMENT_LOAD_OP_CLEAR,
                                             VK_ATTACHMENT_STORE_OP_STORE, VK_ATTACHMENT_LOAD_OP_DONT_CARE,
                                             VK_ATTACHMENT_STORE_OP_DONT_CARE, VK_IMAGE_LAYOUT_UNDEFINED, color_final};
    if (depth != VK_FORMAT_UNDEFINED) {
        depth_ref.attachment = n;
        att[n++] = (VkAttachmentDescription){0, depth, VK_SAMPLE_COUNT_1_BIT, VK_ATTACHMENT_LOAD_OP_CLEAR,
                                             keep_depth ? VK_ATTACHMENT_STORE_OP_STORE : VK_ATTACHMENT_STORE_OP_DONT_CARE,
                                             VK_ATTACHMENT_LOAD_OP_DONT_CARE, VK_ATTACHMENT_STORE_OP_DONT_CARE,
                                             VK_IMAGE_LAYOUT_UNDEFINED,
                                             keep_depth ? depth_final : VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
    }
    VkSubpassDescription sub = {0};
    sub.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
    sub.colorAttachmentCount = color != VK_FORMAT_UNDEFINED;
    sub.pColorAttachments = color != VK_FORMAT_UNDEFINED ? &color_ref : NULL;
    sub.pDepthStencilAttachment = depth != VK_FORMAT_UNDEFINED ? &depth_ref : NULL;
    VkPipelineStageFlags outputs = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT
                                 | VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
    VkAccessFlags writes = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
    VkPipelineStageFlags readers = VK_PIPELINE_STAGE_VERTEX_SHADER_BIT | VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT
                                 | VK_PIPELINE_STAGE_TRANSFER_BIT;
    VkSubpassDependency deps[2] = {
        {VK_SUBPASS_EXTERNAL, 0, readers | outputs, outputs, 0,
         writes | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT, 0},
        {0, VK_SUBPASS_EXTERNAL, outputs, readers, writes, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_TRANSFER_READ_BIT, 0},
    };
    VkRenderPassCreateInfo info = {.sType = VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
    info.attachmentCount = n;
    info.pAttachments = att;
    info.subpassCount = 1;
    info.pSubpasses = &sub;
    info.dependencyCount = 2;
    info.pDependencies = deps;
    VkResult r = vkCreateRenderPass(g->device, &info, NULL, out);
    if (r != VK_SUCCESS)
        return vk_failed("vkCreateRenderPass", r);
    return gpu_own(g, (owned){.kind = OWN_RENDER_PASS, .u.render_pass = *out});
}

bool make_framebuffer(gpu *g, VkRenderPass pass, const VkImageView *views, uint32_t n, uint32_t w, uint32_t h,
                             VkFramebuffer *out)
{
    VkFramebufferCreateInfo info = {.sType = VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
    info.renderPass = pass;
    info.attachmentCount = n;
    info.pAttachments = views;
    info.width = w;
    info.height = h;
    info.layers = 1;
    VkResult r = vkCreateFramebuffer(g->device, &info, NULL, out);
    if (r != VK_SUCCESS)
        return vk_failed("vkCreateFramebuffer", r);
    return gpu_own(g, (owned){.kind = OWN_FRAMEBUFFER, .u.framebuffer = *out});
}

/* conventions.platforms.vulkan.<group>.<key>.<member> (or .<group>.<key> when member is NULL), an enum name of
 * `family`. */
bool convention_enum(const engine *e, const char *group, const char *key, const char *member,
                            const char *family, int32_t *out)
{
    const json_src *src = &e->m->src;
    char where[160];
    snprintf(where, sizeof where, "conventions.platforms.vulkan.%s", group);
    const cJSON *gj = j_opt(e->m->conv, group);
    const cJSON *v = member ? j_opt(j_opt(gj, key), member) : j_opt(gj, key);
    if (!cJSON_IsString(v))
        return j_fail(src, where, "no %s%s%s", key, member ? "." : "", member ? member : "");
    if (!vk_enum(family, v->valuestring, out))
        return j_fail(src, where, "%s is not a %s… name this engine knows", v->valuestring, family);
    return true;
}

bool cull_mode(const engine *e, const char *cull, VkCullModeFlags *out)
{
    int32_t v;
    if (!convention_enum(e, "cull", cull, "cullMode", "VK_CULL_MODE_", &v))
        return false;
    *out = (VkCullModeFlags)v;
    return true;
}

bool front_face(const engine *e, VkFrontFace *out)
{
    const cJSON *ff = j_opt(e->m->conv, "front_face");
    int32_t v;
    if (!cJSON_IsObject(ff))
        return j_fail(&e->m->src, "conventions.platforms.vulkan", "no front_face");
    const cJSON *state = j_opt(ff, "state");
    const cJSON *name = j_opt(state, "frontFace");
    if (!cJSON_IsString(name) || !vk_enum("VK_FRONT_FACE_", name->valuestring, &v))
        return j_fail(&e->m->src, "conventions.platforms.vulkan.front_face.state", "frontFace is not a "
                      "VK_FRONT_FACE_… name");
    *out = (VkFrontFace)v;
    return true;
}

bool lower_enum(const engine *e, const cJSON *obj, const char *key, const char *family, const char *where,
                       int32_t *out)
{
    const char *v = j_str(&e->m->src, obj, key, where);
    if (!v)
        return false;
    if (!vk_enum_lower(family, v, out))
        return j_fail(&e->m->src, where, "%s %s is not a %s… this engine knows", key, v, family);
    return true;
}

/* premultiply.vulkan × S, S the export's shadow_matrix (column-major: S[r][c] = s[4c + r]); column-major out. */
static bool light_view_proj(engine *e, const char *where, const cJSON *matrix, light_pass *lp)
{
    const json_src *src = &e->m->src;
    const cJSON *pre = j_opt(j_opt(matrix, "premultiply"), "vulkan");
    double p[4][4];
    if (cJSON_GetArraySize(pre) != 4)
        return j_fail(src, where, "matrix.premultiply.vulkan is not four rows");
    for (int r = 0; r < 4; r++) {
        const cJSON *row = cJSON_GetArrayItem(pre, r);
        if (cJSON_GetArraySize(row) != 4)
            return j_fail(src, where, "matrix.premultiply.vulkan row %d is not four numbers", r);
        for (int c = 0; c < 4; c++) {
            const cJSON *x = cJSON_GetArrayItem(row, c);
            if (!cJSON_IsNumber(x))
                return j_fail(src, where, "matrix.premultiply.vulkan[%d][%d] is not a number", r, c);
            p[r][c] = x->valuedouble;
        }
    }
    const double *s = lp->face >= 0 ? lp->fl->faces[lp->face] : lp->fl->shadow_matrix;
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++) {
            double v = 0.0;
            for (int k = 0; k < 4; k++)
                v += p[r][k] * s[4 * c + k];
            lp->view_proj[4 * c + r] = v;
        }
    return true;
}

/* The blur of kind moments: a fresh target per pass, of the moments' format, colour only. */
static bool blur_targets(engine *e, light_pass *lp, VkFormat format, const cJSON *moments, const char *where)
{
    const json_src *src = &e->m->src;
    lp->blur = j_obj(src, moments, "blur", where);
    const cJSON *passes = lp->blur ? j_arr(src, lp->blur, "passes", where) : NULL;
    const char *filter = lp->blur ? j_str(src, lp->blur, "filter", where) : NULL;
    const char *edges = lp->blur ? j_str(src, lp->blur, "edges", where) : NULL;
    if (!passes || !filter || !edges)
        return false;
    /* the blur unit implements the filter; the engine only needs to know it is the one the unit draws */
    if (strcmp(filter, "box") != 0 || strcmp(edges, "clamp") != 0)
        return j_fail(src, where, "a %s blur with %s edges; the blur unit this engine draws is a clamped box",
                      filter, edges);
    lp->nblur = cJSON_GetArraySize(passes);
    if (lp->nblur < 1 || lp->nblur > MAX_BLUR)
        return j_fail(src, where, "%d blur passes; this engine draws 1 to %d", lp->nblur, MAX_BLUR);
    if (!make_render_pass(e->g, format, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_FORMAT_UNDEFINED, false, 0,
                          &lp->blur_pass))
        return false;
    for (int k = 0; k < lp->nblur; k++)
        if (!gpu_image_new(e->g, format, lp->width, lp->height, 1,
                           VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT
                           | VK_IMAGE_USAGE_TRANSFER_SRC_BIT, VK_IMAGE_ASPECT_COLOR_BIT, &lp->targets[k + 1])
            || !make_framebuffer(e->g, lp->blur_pass, &lp->targets[k + 1].view, 1, lp->width, lp->height,
                                 &lp->blur_framebuffers[k]))
            return false;
    return true;
}

/* The description's depth target and rasterizer state into lp->state (and the clear), checked against what this
 * engine draws and the export's map size; the caller makes the images. */
static bool read_depth_state(engine *e, const cJSON *dp, const char *where, light_pass *lp)
{
    const json_src *src = &e->m->src;
    const char *kind = j_str(src, dp, "kind", where);
    double size[2], clear, constant, slope, clamp;
    const cJSON *depth = j_obj(src, dp, "depth", where), *matrix = j_obj(src, dp, "matrix", where);
    const cJSON *bias = depth ? j_obj(src, depth, "bias", where) : NULL;
    const char *format = depth ? j_str(src, depth, "format", where) : NULL;
    const char *cull = depth ? j_str(src, depth, "cull", where) : NULL;
    int32_t compare;
    VkFormat dformat;
    uint32_t bytes;
    if (!kind || !matrix || !bias || !format || !cull || !j_nums(src, dp, "size", where, size, 2)
        || !j_num(src, depth, "clear", where, &clear) || !j_bool(src, depth, "write", where, &lp->state.depth_write)
        || !lower_enum(e, depth, "compare_op", "VK_COMPARE_OP_", where, &compare)
        || !j_num(src, bias, "constant", where, &constant) || !j_num(src, bias, "slope", where, &slope)
        || !j_num(src, bias, "clamp", where, &clamp))
        return false;
    if (strcmp(kind, "depth") != 0 && strcmp(kind, "moments") != 0)
        return j_fail(src, where, "kind %s: this engine draws depth and moments passes", kind);
    if (size[0] < 1 || size[1] < 1 || size[0] > 16384 || size[1] > 16384)
        return j_fail(src, where, "size %g x %g", size[0], size[1]);
    lp->moments = strcmp(kind, "moments") == 0;
    lp->width = (uint32_t)size[0];
    lp->height = (uint32_t)size[1];
    if ((int)lp->width != lp->fl->size[0] || (int)lp->height != lp->fl->size[1])
        return fail("%s: lights.%s.size is %dx%d; the build's map is %ux%u (%s) — render with the build's map size",
                    e->f->file, lp->name, lp->fl->size[0], lp->fl->size[1], lp->width, lp->height, where);
    if (clamp != 0.0)
        return j_fail(src, where, "a depth bias clamp (%g) needs the depthBiasClamp feature, which this engine does "
                      "not enable", clamp);
    if (!vk_format(format, &dformat, &bytes) || dformat != VK_FORMAT_D32_SFLOAT)
        return j_fail(src, where, "depth format %s; this engine draws D32_SFLOAT maps", format);
    if (!light_view_proj(e, where, matrix, lp) || !cull_mode(e, cull, &lp->state.cull)
        || !front_face(e, &lp->state.front_face))
        return false;
    lp->state.width = lp->width;
    lp->state.height = lp->height;
    lp->state.depth_test = true;
    lp->state.depth_compare = (VkCompareOp)compare;
    lp->state.bias_constant = (float)constant;
    lp->state.bias_slope = (float)slope;
    lp->clears[lp->moments ? 1 : 0].depthStencil.depth = (float)clear;
    return true;
}

/* Kind moments: a moments target beside the depth (the casters' fragment stage writes it), then the blur's. */
static bool moments_target(engine *e, const cJSON *dp, const char *where, light_pass *lp)
{
    const json_src *src = &e->m->src;
    gpu *g = e->g;
    const cJSON *moments = j_obj(src, dp, "moments", where);
    const char *mformat = moments ? j_str(src, moments, "format", where) : NULL;
    double mclear[4];
    VkFormat cformat;
    uint32_t bytes;
    if (!mformat || !j_nums(src, moments, "clear", where, mclear, 4))
        return false;
    if (!vk_format(mformat, &cformat, &bytes) || cformat != VK_FORMAT_R32G32B32A32_SFLOAT)
        return j_fail(src, where, "moments format %s; this engine draws R32G32B32A32_SFLOAT moments", mformat);
    if (!gpu_format_has(g, cformat, VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT | VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT
                                    | VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT))
        return fail("%s cannot render into and linearly filter %s", g->props.deviceName, mformat);
    for (int i = 0; i < 4; i++)
        lp->clears[0].color.float32[i] = (float)mclear[i];
    lp->state.color = true;
    if (!gpu_image_new(g, cformat, lp->width, lp->height, 1, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT,
                       VK_IMAGE_ASPECT_COLOR_BIT, &lp->targets[0])
        || !make_render_pass(g, cformat, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, lp->depth.format, false, 0,
                             &lp->render_pass))
        return false;
    VkImageView views[2] = {lp->targets[0].view, lp->depth.view};
    lp->state.render_pass = lp->render_pass;
    return make_framebuffer(g, lp->render_pass, views, 2, lp->width, lp->height, &lp->framebuffer)
        && blur_targets(e, lp, cformat, moments, where);
}

static bool setup_pass(engine *e, const char *name, const cJSON *dp, light_pass *lp, int face)
{
    gpu *g = e->g;
    char where[128];
    snprintf(where, sizeof where, "lights.%s.depth_pass", name);
    lp->name = name;
    lp->desc = dp;
    lp->face = face;
    if (!(lp->fl = frame_light(e->f, name)))
        return fail("%s: lights: no %s, which the build shadows (%s) — export the frame of this build", e->f->file,
                    name, where);
    if (face >= 0 && lp->fl->nfaces != 6)
        return fail("%s: lights.%s has no face_matrices, and the build draws its six faces (%s.faces) — export the "
                    "frame of this build", e->f->file, name, where);
    if (!read_depth_state(e, dp, where, lp))
        return false;
    /* A map the shaders sample (kind depth) is kept and filtered as the sampler row says (bilinear): the device
     * must sample and linearly filter D32_SFLOAT (lavapipe in Mesa 25 does; the renderer refuses otherwise). */
    VkImageUsageFlags usage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | (lp->moments ? 0 : VK_IMAGE_USAGE_SAMPLED_BIT)
                            | (lp->moments ? 0 : VK_IMAGE_USAGE_TRANSFER_SRC_BIT);  /* copied into an array */
    VkFormatFeatureFlags need = VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT
        | (lp->moments ? 0 : VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT | VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT);
    if (!gpu_format_has(g, VK_FORMAT_D32_SFLOAT, need))
        return fail("%s cannot %s D32_SFLOAT, which %s's map needs", g->props.deviceName,
                    lp->moments ? "render depth into" : "render into and linearly filter", name);
    if (!gpu_image_new(g, VK_FORMAT_D32_SFLOAT, lp->width, lp->height, 1, usage, VK_IMAGE_ASPECT_DEPTH_BIT, &lp->depth))
        return false;
    if (lp->moments)
        return moments_target(e, dp, where, lp);
    lp->state.color = false;
    if (!make_render_pass(g, VK_FORMAT_UNDEFINED, 0, VK_FORMAT_D32_SFLOAT, true, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                          &lp->render_pass))
        return false;
    lp->state.render_pass = lp->render_pass;
    return make_framebuffer(g, lp->render_pass, &lp->depth.view, 1, lp->width, lp->height, &lp->framebuffer);
}

bool light_passes(engine *e)
{
    const cJSON *l;
    int n = 0;
    cJSON_ArrayForEach(l, e->m->lights) {
        const cJSON *dp = j_opt(l, "depth_pass");
        n += cJSON_IsObject(dp) ? (j_opt(dp, "faces") ? 6 : 1) : 0;
    }
    e->passes = calloc((size_t)n + 1, sizeof *e->passes);
    if (!e->passes)
        return fail("out of memory");
    cJSON_ArrayForEach(l, e->m->lights) {
        const cJSON *dp = j_opt(l, "depth_pass");
        if (!cJSON_IsObject(dp))
            continue;
        if (!j_opt(dp, "faces")) {
            if (!setup_pass(e, l->string, dp, &e->passes[e->npasses++], -1))
                return false;
            continue;
        }
        /* a point light's six faces: one pass each (face k's matrix), copied into the layers of one array */
        light_pass *first = &e->passes[e->npasses];
        for (int k = 0; k < 6; k++)
            if (!setup_pass(e, l->string, dp, &e->passes[e->npasses++], k))
                return false;
        if (!face_array(e, first))
            return false;
    }
    return true;
}

/* The image a pass's result is sampled through: its depth, or its last blur target. */
const gpu_image *pass_result(const light_pass *lp)
{
    return lp->moments ? &lp->targets[lp->nblur] : &lp->depth;
}

/* Face 0's pass holds the 2D array of six layers that its light's permutations read. */
bool face_array(engine *e, light_pass *first)
{
    const gpu_image *src = pass_result(first);
    VkImageAspectFlags aspect = first->moments ? VK_IMAGE_ASPECT_COLOR_BIT : VK_IMAGE_ASPECT_DEPTH_BIT;
    return gpu_image_array_new(e->g, src->format, first->width, first->height, 6,
                               VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT, aspect, &first->array);
}

/* Sources' results into the layers of `array`, every image left SHADER_READ_ONLY. */
static void record_layer_copies(VkCommandBuffer cmd, const gpu_image *const *sources, int n, const gpu_image *array,
                                VkImageAspectFlags aspect)
{
    VkImageMemoryBarrier bar[2];
    VkImageLayout held = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, src = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    VkImageLayout dst = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    VkPipelineStageFlags before = VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT
                                | VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT;
    bar[0] = (VkImageMemoryBarrier){VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER, NULL, 0, VK_ACCESS_TRANSFER_WRITE_BIT,
                                    VK_IMAGE_LAYOUT_UNDEFINED, dst, VK_QUEUE_FAMILY_IGNORED, VK_QUEUE_FAMILY_IGNORED,
                                    array->image, {aspect, 0, 1, 0, (uint32_t)n}};
    vkCmdPipelineBarrier(cmd, before, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, NULL, 0, NULL, 1, bar);
    for (int k = 0; k < n; k++) {
        bar[0] = (VkImageMemoryBarrier){VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER, NULL, VK_ACCESS_SHADER_READ_BIT,
                                        VK_ACCESS_TRANSFER_READ_BIT, held, src, VK_QUEUE_FAMILY_IGNORED,
                                        VK_QUEUE_FAMILY_IGNORED, sources[k]->image, {aspect, 0, 1, 0, 1}};
        vkCmdPipelineBarrier(cmd, before, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, NULL, 0, NULL, 1, bar);
        VkImageCopy region = {{aspect, 0, 0, 1}, {0, 0, 0}, {aspect, 0, (uint32_t)k, 1}, {0, 0, 0},
                              {array->width, array->height, 1}};
        vkCmdCopyImage(cmd, sources[k]->image, src, array->image, dst, 1, &region);
        bar[0].srcAccessMask = VK_ACCESS_TRANSFER_READ_BIT, bar[0].dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
        bar[0].oldLayout = src, bar[0].newLayout = held;
        vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT
                             | VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, NULL, 0, NULL, 1, bar);
    }
    bar[1] = (VkImageMemoryBarrier){VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER, NULL, VK_ACCESS_TRANSFER_WRITE_BIT,
                                    VK_ACCESS_SHADER_READ_BIT, dst, held, VK_QUEUE_FAMILY_IGNORED,
                                    VK_QUEUE_FAMILY_IGNORED, array->image, {aspect, 0, 1, 0, (uint32_t)n}};
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT, 0, 0, NULL, 0,
                         NULL, 1, &bar[1]);
}

/* A dynamic set's pair's array (made on first use): its lights' pass results in the set's order, a point light's
 * six faces each, at the layers its first_layers names (each light's ordinal in the pair × its layers). */
bool pair_array_of(engine *e, const cJSON *pair, const char *where, VkImageView *view)
{
    for (int i = 0; i < e->npairs; i++)
        if (e->pairs[i].pair == pair) {
            *view = e->pairs[i].image.view;
            return true;
        }
    const cJSON *lights = j_arr(&e->m->src, pair, "lights", where), *ln;
    int n = 0;
    cJSON_ArrayForEach(ln, lights)
        for (int l = 0; cJSON_IsString(ln) && l < e->npasses; l++)
            n += strcmp(e->passes[l].name, ln->valuestring) == 0;
    if (n == 0)
        return j_fail(&e->m->src, where, "a shadowed pair with no drawn light: this engine has no map to bind");
    if (e->npairs == e->cappairs) {
        int cap = e->cappairs ? 2 * e->cappairs : 8;
        pair_array *more = realloc(e->pairs, (size_t)cap * sizeof *more);
        if (!more)
            return fail("out of memory");
        e->pairs = more, e->cappairs = cap;
    }
    pair_array *pa = &e->pairs[e->npairs];
    memset(pa, 0, sizeof *pa);
    if (!(pa->sources = calloc((size_t)n, sizeof *pa->sources)))
        return fail("out of memory");
    e->npairs++;
    pa->pair = pair;
    const light_pass *first = NULL;
    cJSON_ArrayForEach(ln, lights)
        for (int l = 0; cJSON_IsString(ln) && l < e->npasses; l++)
            if (strcmp(e->passes[l].name, ln->valuestring) == 0) {
                first = first ? first : &e->passes[l];
                pa->sources[pa->nsources++] = pass_result(&e->passes[l]);
            }
    VkImageAspectFlags aspect = first->moments ? VK_IMAGE_ASPECT_COLOR_BIT : VK_IMAGE_ASPECT_DEPTH_BIT;
    if (!gpu_image_array_new(e->g, pa->sources[0]->format, first->width, first->height, (uint32_t)n,
                             VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT, aspect, &pa->image))
        return false;
    *view = pa->image.view;
    return true;
}

/* After every pass: each face's result copied into its layer of face 0's array, and each dynamic pair's lights'
 * into its array; left SHADER_READ_ONLY. */
void record_face_copies(const engine *e, VkCommandBuffer cmd)
{
    for (int i = 0; i < e->npairs; i++) {
        const pair_array *pa = &e->pairs[i];
        bool depth = pa->image.format == VK_FORMAT_D32_SFLOAT;
        record_layer_copies(cmd, pa->sources, pa->nsources, &pa->image,
                            depth ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT);
    }
    for (int l = 0; l + 5 < e->npasses; l++) {
        const light_pass *lp = &e->passes[l];
        if (lp->face != 0)
            continue;
        VkImageAspectFlags aspect = lp->moments ? VK_IMAGE_ASPECT_COLOR_BIT : VK_IMAGE_ASPECT_DEPTH_BIT;
        VkImageMemoryBarrier pre[7], post[7];
        for (int k = 0; k < 7; k++) {
            VkImage img = k < 6 ? pass_result(&e->passes[l + k])->image : lp->array.image;
            VkImageSubresourceRange range = {aspect, 0, 1, 0, k < 6 ? 1 : 6};
            VkImageLayout held = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
            VkImageLayout moved = k < 6 ? VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL : VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
            pre[k] = (VkImageMemoryBarrier){VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER, NULL,
                                            k < 6 ? VK_ACCESS_SHADER_READ_BIT : 0,
                                            k < 6 ? VK_ACCESS_TRANSFER_READ_BIT : VK_ACCESS_TRANSFER_WRITE_BIT,
                                            k < 6 ? held : VK_IMAGE_LAYOUT_UNDEFINED, moved,
                                            VK_QUEUE_FAMILY_IGNORED, VK_QUEUE_FAMILY_IGNORED, img, range};
            post[k] = (VkImageMemoryBarrier){VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER, NULL,
                                             k < 6 ? VK_ACCESS_TRANSFER_READ_BIT : VK_ACCESS_TRANSFER_WRITE_BIT,
                                             VK_ACCESS_SHADER_READ_BIT, moved, held,
                                             VK_QUEUE_FAMILY_IGNORED, VK_QUEUE_FAMILY_IGNORED, img, range};
        }
        VkPipelineStageFlags before = VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT
                                    | VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
        vkCmdPipelineBarrier(cmd, before, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, NULL, 0, NULL, 7, pre);
        for (int k = 0; k < 6; k++) {
            VkImageCopy region = {{aspect, 0, 0, 1}, {0, 0, 0}, {aspect, 0, (uint32_t)k, 1}, {0, 0, 0},
                                  {lp->width, lp->height, 1}};
            vkCmdCopyImage(cmd, pass_result(&e->passes[l + k])->image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                           lp->array.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
        }
        vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT, 0, 0, NULL,
                             0, NULL, 7, post);
    }
}

bool light_pass_of(const engine *e, const char *light, const light_pass **out)
{
    for (int i = 0; i < e->npasses; i++)
        if (strcmp(e->passes[i].name, light) == 0) {
            *out = &e->passes[i];
            return true;
        }
    return false;
}
