/* The draws of the frame and the one command buffer that records them.
 *
 * The objects of each shadowed light's sets (the export's casters) are drawn into its map (the light's description
 * names the unit; a masked object's own unit), then the blur passes of a moments light, then the objects in the export's
 * draw_order into the colour target with their permutations; bindings.c writes each draw's descriptor sets. */
#include "render.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The program of depth unit `unit` with `stages`, parsed once. */
static bool unit_program(engine *e, const char *unit, const cJSON *stages, const program **out)
{
    bool frag = false;
    const cJSON *s;
    cJSON_ArrayForEach(s, stages)
        frag |= cJSON_IsString(s) && strcmp(s->valuestring, "frag") == 0;
    for (int i = 0; i < e->nunits; i++)
        if (strcmp(e->units[i].name, unit) == 0 && e->units[i].has_frag == frag) {
            *out = &e->units[i];
            return true;
        }
    if (e->nunits == e->capunits)
        return fail("more depth units than this engine's table holds (%d)", e->capunits);
    if (!depth_program(e->m, unit, stages, &e->units[e->nunits]))
        return false;
    *out = &e->units[e->nunits++];
    return true;
}

/* The pipeline of program p in pass `pass` (-1 colour, else a light's; `blur`: that light's blur passes). */
static bool pipe_of(engine *e, const program *p, int pass, bool blur, pipe_entry **out)
{
    int key = blur ? 1000 + pass : pass;
    for (int i = 0; i < e->npipes; i++)
        if (e->pipes[i].prog == p && e->pipes[i].pass == key) {
            *out = &e->pipes[i];
            return true;
        }
    if (e->npipes == e->cappipes)
        return fail("more pipelines than this engine's table holds (%d)", e->cappipes);
    pipe_entry *pe = &e->pipes[e->npipes];
    pe->prog = p;
    pe->pass = key;
    pipeline_state st;
    if (pass < 0) {
        if (!color_state(e, p, &st))
            return false;
    } else {
        const light_pass *lp = &e->passes[pass];
        st = lp->state;
        if (blur) {  /* a fullscreen triangle over a colour target: no depth, nothing culled */
            st.render_pass = lp->blur_pass;
            st.depth_test = st.depth_write = false;
            st.cull = VK_CULL_MODE_NONE;
            st.bias_constant = st.bias_slope = 0.0f;
            st.color = true;
        }
    }
    if (!layout_create(e->g, p, &pe->layout) || !pipeline_create(e->g, e->pack, p, &pe->layout, &st, &pe->pipeline))
        return false;
    e->npipes++;
    *out = pe;
    return true;
}

/* A draw of `object` (or of the blur's triangle) with pe: its vertex inputs bound to the mesh's attributes. */
static bool add_item(engine *e, pipe_entry *pe, int object, int pass, int blur)
{
    if (e->ndraws == e->capdraws)
        return fail("more draws than this engine's table holds (%d)", e->capdraws);
    draw_item *it = &e->draws[e->ndraws];
    memset(it, 0, sizeof *it);
    it->pipe = pe;
    it->object = object;
    it->pass = pass;
    it->blur = blur;
    const program *p = pe->prog;
    if (blur >= 0) {
        if (p->ninputs != 1 || strcmp(p->inputs[0].name, "a_position") != 0)
            return fail("%s: the blur unit reads vertex inputs other than a_position; this engine draws its "
                        "triangle with positions only", p->name);
        it->vertex_buffers[0] = e->fullscreen.buffer;
        it->index_buffer = e->fullscreen.buffer;
        it->index_offset = 36;
        it->index_count = 3;
        e->ndraws++;
        return true;
    }
    const fobject *fo = &e->f->objects[object];
    const mesh *me = &e->f->meshes[fo->mesh];
    for (int k = 0; k < p->ninputs; k++) {
        const vertex_input *in = &p->inputs[k];
        const mesh_attr *a = NULL;
        for (int i = 0; i < me->nattrs; i++)
            if (strcmp(me->attrs[i].name, in->name) == 0)
                a = &me->attrs[i];
        if (!a)
            return fail("%s: mesh %s of object %s has no %s, which %s reads — export the frame again", e->f->file,
                        me->path, fo->name, in->name, p->name);
        if (strcmp(a->format_name, in->format_name) != 0)
            return fail("%s: mesh %s's %s is %s; %s reads it as %s", e->f->file, me->path, in->name, a->format_name,
                        p->name, in->format_name);
        it->vertex_buffers[k] = e->meshes[fo->mesh].buffer;
        it->vertex_offsets[k] = a->offset;
    }
    it->index_buffer = e->meshes[fo->mesh].buffer;
    it->index_offset = me->index_offset;
    it->index_count = me->index_count;
    e->ndraws++;
    return true;
}

static bool fullscreen(engine *e)
{
    /* the triangle the blur description names: a_position (-1, -1, 0), (3, -1, 0), (-1, 3, 0); then 0, 1, 2 */
    unsigned char data[48];
    const float pos[9] = {-1.0f, -1.0f, 0.0f, 3.0f, -1.0f, 0.0f, -1.0f, 3.0f, 0.0f};
    const uint32_t idx[3] = {0, 1, 2};
    memcpy(data, pos, 36);
    memcpy(data + 36, idx, 12);
    return gpu_buffer_new(e->g, sizeof data, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | VK_BUFFER_USAGE_INDEX_BUFFER_BIT,
                          data, &e->fullscreen);
}

/* Whether object i is drawn into light fl's map: it is among the export's casters (every object where the export
 * lists none). */
static bool casts(const flight *fl, int i)
{
    const cJSON *c;
    if (!fl->casters)
        return true;
    cJSON_ArrayForEach(c, fl->casters)
        if ((int)c->valuedouble == i)
            return true;
    return false;
}

static bool build_items(engine *e)
{
    const manifest *m = e->m;
    const json_src *src = &m->src;
    int n = m->nobjects;
    e->capunits = 2 * n + 8;
    e->cappipes = m->nperms + e->npasses * (n + 2) + 8;
    e->capdraws = n * (1 + e->npasses) + e->npasses * MAX_BLUR + 8;
    e->units = calloc((size_t)e->capunits, sizeof *e->units);
    e->pipes = calloc((size_t)e->cappipes, sizeof *e->pipes);
    e->draws = calloc((size_t)e->capdraws, sizeof *e->draws);
    if (!e->units || !e->pipes || !e->draws)
        return fail("out of memory");
    for (int l = 0; l < e->npasses; l++) {
        const light_pass *lp = &e->passes[l];
        char where[128];
        snprintf(where, sizeof where, "lights.%s.depth_pass.casters", lp->name);
        const cJSON *casters = j_obj(src, lp->desc, "casters", where);
        const cJSON *opaque = casters ? j_obj(src, casters, "opaque", where) : NULL;
        const cJSON *masked = casters ? j_obj(src, casters, "masked", where) : NULL;
        if (!opaque || !masked)
            return false;
        for (int i = 0; i < n; i++) {  /* the objects of its light sets cast (the export's casters) */
            if (!casts(lp->fl, i))
                continue;
            const cJSON *c = j_opt(masked, m->objects[i].permutation);
            if (!c)
                c = opaque;
            const char *unit = j_str(src, c, "unit", where);
            const cJSON *stages = j_arr(src, c, "stages", where);
            const program *p;
            pipe_entry *pe;
            if (!unit || !stages || !unit_program(e, unit, stages, &p) || !pipe_of(e, p, l, false, &pe)
                || !add_item(e, pe, i, l, -1))
                return false;
        }
        if (!lp->moments)
            continue;
        const char *unit = j_str(src, lp->blur, "unit", where);
        cJSON *stages = cJSON_CreateStringArray((const char *[]){"vert", "frag"}, 2);
        const program *p;
        pipe_entry *pe;
        bool ok = unit && stages && unit_program(e, unit, stages, &p) && (e->fullscreen.buffer || fullscreen(e))
               && pipe_of(e, p, l, true, &pe);
        cJSON_Delete(stages);
        for (int k = 0; ok && k < lp->nblur; k++)
            ok = add_item(e, pe, -1, l, k);
        if (!ok)
            return false;
    }
    for (int k = 0; k < e->f->ndraw; k++) {
        int i = e->f->draw_order[k];
        pipe_entry *pe;
        if (!pipe_of(e, &m->perms[m->objects[i].perm], -1, false, &pe) || !add_item(e, pe, i, -1, -1))
            return false;
    }
    return true;
}

/* ------------------------------------------------------------------ recording */

static void draw(VkCommandBuffer cmd, const draw_item *it)
{
    const pipe_entry *pe = it->pipe;
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pe->pipeline);
    for (int s = 0; s < pe->layout.nsets; s++)
        if (it->sets[s])
            vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pe->layout.layout, (uint32_t)s, 1,
                                    &it->sets[s], 0, NULL);
    if (pe->prog->ninputs)
        vkCmdBindVertexBuffers(cmd, 0, (uint32_t)pe->prog->ninputs, it->vertex_buffers, it->vertex_offsets);
    vkCmdBindIndexBuffer(cmd, it->index_buffer, it->index_offset, VK_INDEX_TYPE_UINT32);
    vkCmdDrawIndexed(cmd, it->index_count, 1, 0, 0, 0);
}

static void begin_pass(VkCommandBuffer cmd, VkRenderPass pass, VkFramebuffer fb, uint32_t w, uint32_t h,
                       const VkClearValue *clears, uint32_t n)
{
    VkRenderPassBeginInfo begin = {.sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
    begin.renderPass = pass;
    begin.framebuffer = fb;
    begin.renderArea = (VkRect2D){{0, 0}, {w, h}};
    begin.clearValueCount = n;
    begin.pClearValues = clears;
    vkCmdBeginRenderPass(cmd, &begin, VK_SUBPASS_CONTENTS_INLINE);
}

/* What the layer calls invalid is not run: a driver may crash on it (lavapipe does on a pipeline whose layout
 * does not match its shaders), and the run has failed anyway. */
static bool not_invalid(const engine *e)
{
    if (e->g->messages)
        return fail("the validation layer reported %d message(s) so far: the frame is not submitted",
                    e->g->messages);
    return true;
}

static bool record_and_submit(engine *e)
{
    gpu *g = e->g;
    VkCommandBuffer cmd = g->cmd;
    if (!gpu_begin(g))
        return false;
    record_texture_uploads(e, cmd);
    for (int l = 0; l < e->npasses; l++) {
        const light_pass *lp = &e->passes[l];
        begin_pass(cmd, lp->render_pass, lp->framebuffer, lp->width, lp->height, lp->clears, lp->moments ? 2 : 1);
        for (int d = 0; d < e->ndraws; d++)
            if (e->draws[d].pass == l && e->draws[d].blur < 0)
                draw(cmd, &e->draws[d]);
        vkCmdEndRenderPass(cmd);
        for (int k = 0; k < lp->nblur; k++) {
            begin_pass(cmd, lp->blur_pass, lp->blur_framebuffers[k], lp->width, lp->height, lp->clears, 1);
            for (int d = 0; d < e->ndraws; d++)
                if (e->draws[d].pass == l && e->draws[d].blur == k)
                    draw(cmd, &e->draws[d]);
            vkCmdEndRenderPass(cmd);
        }
    }
    record_face_copies(e, cmd);  /* a point light's faces into the layers its permutations read */
    VkClearValue clears[2];
    memcpy(clears[0].color.float32, e->f->clear_color, sizeof clears[0].color.float32);
    clears[1].depthStencil = (VkClearDepthStencilValue){e->f->clear_depth, 0};
    uint32_t w = (uint32_t)e->f->width, h = (uint32_t)e->f->height;
    begin_pass(cmd, e->render_pass, e->framebuffer, w, h, clears, 2);
    for (int d = 0; d < e->ndraws; d++)
        if (e->draws[d].pass < 0)
            draw(cmd, &e->draws[d]);
    vkCmdEndRenderPass(cmd);
    /* the colour image (TRANSFER_SRC_OPTIMAL after the pass) into the host-visible buffer, row 0 first */
    VkBufferImageCopy region = {0, 0, 0, {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1}, {0, 0, 0}, {w, h, 1}};
    vkCmdCopyImageToBuffer(cmd, e->color.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, e->readback.buffer, 1, &region);
    VkBufferMemoryBarrier to_host = {.sType = VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER};
    to_host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    to_host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    to_host.srcQueueFamilyIndex = to_host.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    to_host.buffer = e->readback.buffer;
    to_host.size = VK_WHOLE_SIZE;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 0, NULL, 1, &to_host, 0,
                         NULL);
    return not_invalid(e) && gpu_submit_wait(g);
}

bool engine_render(engine *e, unsigned char *rgba)
{
    if (!upload_meshes(e) || !color_target(e) || !light_passes(e) || !build_items(e) || !not_invalid(e)
        || !write_sets(e) || !record_and_submit(e))
        return false;
    memcpy(rgba, e->readback.mapped, 4 * (size_t)e->f->width * (size_t)e->f->height);
    return true;
}

void engine_free(engine *e)
{
    free(e->textures);
    free(e->samplers);
    free(e->meshes);
    free(e->blocks);
    free(e->passes);
    for (int i = 0; i < e->npairs; i++)
        free(e->pairs[i].sources);
    free(e->pairs);
    free(e->units);
    free(e->pipes);
    free(e->draws);
    memset(e, 0, sizeof *e);
}
