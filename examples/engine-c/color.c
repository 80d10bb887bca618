/* The colour pass: its target (one format for every object: the permutations' output.attachment, spelled by
 * conventions.platforms.vulkan.attachments.color; the depth attachment the conventions name) and each
 * permutation's pipeline state from its render_state, with the conventions' cull modes and front face. */
#include "render.h"

#include <stdio.h>
#include <string.h>

#include "vk_enums.h"

/* A permutation's pipeline state: its render_state, the conventions' cull modes and front face. */
bool color_state(const engine *e, const program *p, pipeline_state *st)
{
    const json_src *src = &e->m->src;
    char where[96];
    snprintf(where, sizeof where, "permutations[%s].render_state", p->hash);
    const cJSON *rs = j_obj(src, p->json, "render_state", p->hash);
    const char *cull = rs ? j_str(src, rs, "cull", where) : NULL;
    const cJSON *depth = rs ? j_obj(src, rs, "depth", where) : NULL;
    int32_t compare;
    memset(st, 0, sizeof *st);
    st->render_pass = e->render_pass;
    st->width = (uint32_t)e->f->width;
    st->height = (uint32_t)e->f->height;
    st->color = true;
    if (!cull || !depth || !cull_mode(e, cull, &st->cull) || !front_face(e, &st->front_face)
        || !j_bool(src, depth, "test", where, &st->depth_test) || !j_bool(src, depth, "write", where, &st->depth_write)
        || !lower_enum(e, depth, "compare", "VK_COMPARE_OP_", where, &compare))
        return false;
    st->depth_compare = (VkCompareOp)compare;
    const cJSON *blend = j_opt(rs, "blend");
    if (!blend || cJSON_IsNull(blend))
        return true;
    const cJSON *c = j_obj(src, blend, "color", where), *a = j_obj(src, blend, "alpha", where);
    int32_t v[6];
    if (!c || !a || !lower_enum(e, c, "src", "VK_BLEND_FACTOR_", where, &v[0])
        || !lower_enum(e, c, "dst", "VK_BLEND_FACTOR_", where, &v[1]) || !lower_enum(e, c, "op", "VK_BLEND_OP_", where, &v[2])
        || !lower_enum(e, a, "src", "VK_BLEND_FACTOR_", where, &v[3])
        || !lower_enum(e, a, "dst", "VK_BLEND_FACTOR_", where, &v[4]) || !lower_enum(e, a, "op", "VK_BLEND_OP_", where, &v[5]))
        return false;
    st->blend = true;
    st->src_color = (VkBlendFactor)v[0];
    st->dst_color = (VkBlendFactor)v[1];
    st->color_op = (VkBlendOp)v[2];
    st->src_alpha = (VkBlendFactor)v[3];
    st->dst_alpha = (VkBlendFactor)v[4];
    st->alpha_op = (VkBlendOp)v[5];
    return true;
}

/* The colour target: one attachment for every object, so every drawn permutation must ask for the same. */
bool color_target(engine *e)
{
    const manifest *m = e->m;
    const json_src *src = &m->src;
    const char *key = NULL;
    for (int i = 0; i < m->nobjects; i++) {
        const program *p = &m->perms[m->objects[i].perm];
        const cJSON *out = j_obj(src, p->json, "output", p->hash);
        const char *a = out ? j_str(src, out, "attachment", p->hash) : NULL;
        if (!a)
            return false;
        if (key && strcmp(key, a) != 0)
            return fail("%s: the objects' permutations draw into %s and %s colour attachments; this engine draws "
                        "one target", m->file, key, a);
        key = a;
    }
    if (!key)
        return fail("%s: no objects to draw — give the scene objects", m->file);
    if (strcmp(key, e->f->color_attachment) != 0)
        return fail("%s: color_attachment %s; the manifest's permutations draw into %s — export the frame of this "
                    "build", e->f->file, e->f->color_attachment, key);
    int32_t color, depth;
    if (!convention_enum(e, "attachments", "color", key, "VK_FORMAT_", &color)
        || !convention_enum(e, "attachments", "depth", NULL, "VK_FORMAT_", &depth))
        return false;
    if (color != VK_FORMAT_R8G8B8A8_SRGB && color != VK_FORMAT_R8G8B8A8_UNORM)
        return j_fail(src, "conventions.platforms.vulkan.attachments.color", "format %d: this engine reads back "
                      "R8G8B8A8 targets only", color);
    e->color_format = (VkFormat)color;
    gpu *g = e->g;
    uint32_t w = (uint32_t)e->f->width, h = (uint32_t)e->f->height;
    if (!gpu_format_has(g, e->color_format, VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT | VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BLEND_BIT)
        || !gpu_format_has(g, (VkFormat)depth, VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT))
        return fail("%s cannot render into the colour format %d with blending, or depth format %d",
                    g->props.deviceName, color, depth);
    if (!gpu_image_new(g, e->color_format, w, h, 1, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                       VK_IMAGE_ASPECT_COLOR_BIT, &e->color)
        || !gpu_image_new(g, (VkFormat)depth, w, h, 1, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT,
                          VK_IMAGE_ASPECT_DEPTH_BIT, &e->depth)
        || !make_render_pass(g, e->color_format, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, (VkFormat)depth, false, 0,
                             &e->render_pass))
        return false;
    VkImageView views[2] = {e->color.view, e->depth.view};
    return make_framebuffer(g, e->render_pass, views, 2, w, h, &e->framebuffer)
        && gpu_buffer_new(g, 4 * (VkDeviceSize)w * h, VK_BUFFER_USAGE_TRANSFER_DST_BIT, NULL, &e->readback);
}
