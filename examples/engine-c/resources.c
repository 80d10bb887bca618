/* What the draws read: meshes, textures from the KTX2 files, samplers from the manifest's rows, and the
 * uniform blocks and a dynamic light set's storage buffers. Each is made once and shared by every draw that reads
 * the same thing. */
#include "render.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vk_enums.h"

/* ------------------------------------------------------------------ meshes */

/* Each mesh file is one buffer, read as vertex buffers at its attributes' offsets and as the index buffer at its
 * indices' offset. A mirrored object (negative determinant) has a mesh of its own in the export, its winding
 * already reversed, so its front faces stay counter-clockwise as the conventions' front face says. */
bool upload_meshes(engine *e)
{
    const frame *f = e->f;
    e->meshes = calloc((size_t)f->nmeshes + 1, sizeof *e->meshes);
    if (!e->meshes)
        return fail("out of memory");
    for (int i = 0; i < f->nmeshes; i++) {
        const mesh *me = &f->meshes[i];
        if (!gpu_buffer_new(e->g, me->size, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | VK_BUFFER_USAGE_INDEX_BUFFER_BIT,
                            me->bytes, &e->meshes[i]))
            return false;
    }
    return true;
}

/* ------------------------------------------------------------------ textures */

typedef struct texture_want {
    const char *path, *sha256, *format;
    int width, height, levels;  /* levels -1: any (a table states none) */
} texture_want;

static bool load_texture(engine *e, const texture_want *w, const char *where, VkImageView *view)
{
    for (int i = 0; i < e->ntextures; i++)
        if (strcmp(e->textures[i].path, w->path) == 0) {
            *view = e->textures[i].image.view;
            return true;
        }
    if (e->ntextures == e->captextures) {
        int cap = e->captextures ? 2 * e->captextures : 16;
        texture_entry *more = realloc(e->textures, (size_t)cap * sizeof *more);
        if (!more)
            return fail("out of memory");
        e->textures = more;
        e->captextures = cap;
    }
    char *path = path_join(e->m->dir, w->path);
    size_t size = 0;
    unsigned char *data = path ? read_file(path, &size) : NULL;
    ktx2_image k = {0};  /* read below (its format) even when the file could not be read */
    bool ok = data && check_sha256(path, data, size, w->sha256) && ktx2_parse(data, size, path, &k);
    if (ok && (strcmp(k.format, w->format) != 0 || (int)k.width != w->width || (int)k.height != w->height
               || (w->levels >= 0 && (int)k.levels != w->levels)))
        ok = fail("%s: the file is %s %ux%u, %u levels; %s says %s %dx%d, %d levels — rebuild the scene", path,
                  k.format, k.width, k.height, k.levels, where, w->format, w->width, w->height, w->levels);
    VkFormat format = (VkFormat)k.vk_format;
    VkFormatFeatureFlags need = VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT | VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT
                              | VK_FORMAT_FEATURE_TRANSFER_DST_BIT;
    if (ok && !gpu_format_has(e->g, format, need))
        ok = fail("%s cannot sample %s with linear filtering (%s)", e->g->props.deviceName, k.format, path);
    texture_entry *t = &e->textures[e->ntextures];
    memset(t, 0, sizeof *t);
    t->path = w->path;
    VkDeviceSize total = 0;
    for (uint32_t i = 0; ok && i < k.levels; i++) {
        t->level_offset[i] = total;
        total += (k.level_bytes[i] + 15) / 16 * 16;  /* a copy's offset: a multiple of the texel size and of 4 */
    }
    ok = ok && gpu_image_new(e->g, format, k.width, k.height, k.levels,
                             VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT, VK_IMAGE_ASPECT_COLOR_BIT,
                             &t->image)
         && gpu_buffer_new(e->g, total, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, NULL, &t->staging);
    for (uint32_t i = 0; ok && i < k.levels; i++)
        memcpy((unsigned char *)t->staging.mapped + t->level_offset[i], k.level_data[i], k.level_bytes[i]);
    free(data);
    free(path);
    if (!ok)
        return false;
    e->ntextures++;
    *view = t->image.view;
    return true;
}

/* The KTX2 file of a material's texture row (materials.<m>.textures.<name>) or of a baked table row (tables[i]),
 * uploaded with its whole mip chain. */
bool texture_of_row(engine *e, const cJSON *row, const char *where, VkImageView *view)
{
    const json_src *src = &e->m->src;
    texture_want w = {0};
    if (!(w.path = j_str(src, row, "path", where)) || !(w.sha256 = j_str(src, row, "sha256", where))
        || !(w.format = j_str(src, row, "format", where)))
        return false;
    if (j_opt(row, "table")) {  /* a baked table: format unorm8 | fp16 | fp32, size [W, H] */
        static const char *names[][2] = {{"unorm8", "R8G8B8A8_UNORM"}, {"fp16", "R16G16B16A16_SFLOAT"},
                                         {"fp32", "R32G32B32A32_SFLOAT"}};
        const char *f = w.format;
        w.format = NULL;
        for (int i = 0; i < 3; i++)
            if (strcmp(f, names[i][0]) == 0)
                w.format = names[i][1];
        double size[2];
        const char *dim = j_str(src, row, "dimension", where);
        if (!w.format || !dim || !j_nums(src, row, "size", where, size, 2))
            return w.format ? false : j_fail(src, where, "table format %s is not unorm8, fp16 or fp32", f);
        if (strcmp(dim, "2d") != 0)
            return j_fail(src, where, "a %s table; this engine binds 2D ones", dim);
        if (!(size[0] >= 1 && size[0] <= 1 << 16 && size[1] >= 1 && size[1] <= 1 << 16))
            return j_fail(src, where, "a table of %g x %g texels", size[0], size[1]);
        w.width = (int)size[0];
        w.height = (int)size[1];
        w.levels = -1;
    } else if (!j_int(src, row, "width", where, 1, 1 << 16, &w.width)
               || !j_int(src, row, "height", where, 1, 1 << 16, &w.height)
               || !j_int(src, row, "levels", where, 1, KTX2_MAX_LEVELS, &w.levels)) {
        return false;
    }
    return load_texture(e, &w, where, view);
}

bool sampler_of_row(engine *e, int index, const char *where, VkSampler *out)
{
    const json_src *src = &e->m->src;
    if (!e->samplers) {
        e->nsamplers = cJSON_GetArraySize(e->m->samplers);
        if (!(e->samplers = calloc((size_t)e->nsamplers + 1, sizeof *e->samplers)))
            return fail("out of memory");
    }
    if (index < 0 || index >= e->nsamplers)
        return j_fail(src, where, "sampler row %d; samplers has %d rows", index, e->nsamplers);
    if (!e->samplers[index]) {
        char at[64];
        snprintf(at, sizeof at, "samplers[%d].platforms", index);
        const cJSON *row = cJSON_GetArrayItem(e->m->samplers, index);
        const cJSON *platforms = j_obj(src, row, "platforms", at + 0);
        const cJSON *vk = platforms ? j_obj(src, platforms, "vulkan", at) : NULL;
        snprintf(at, sizeof at, "samplers[%d].platforms.vulkan", index);
        if (!vk || !sampler_create(e->g, src, vk, at, &e->samplers[index]))
            return false;
    }
    *out = e->samplers[index];
    return true;
}

void record_texture_uploads(engine *e, VkCommandBuffer cmd)
{
    for (int i = 0; i < e->ntextures; i++) {
        const texture_entry *t = &e->textures[i];
        VkImageSubresourceRange all = {VK_IMAGE_ASPECT_COLOR_BIT, 0, t->image.levels, 0, 1};
        VkImageMemoryBarrier to_dst = {.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
        to_dst.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
        to_dst.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;  /* every texel is replaced */
        to_dst.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
        to_dst.srcQueueFamilyIndex = to_dst.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
        to_dst.image = t->image.image;
        to_dst.subresourceRange = all;
        vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, NULL, 0,
                             NULL, 1, &to_dst);
        VkBufferImageCopy regions[KTX2_MAX_LEVELS];
        for (uint32_t l = 0; l < t->image.levels; l++) {
            uint32_t w = t->image.width >> l ? t->image.width >> l : 1, h = t->image.height >> l ? t->image.height >> l : 1;
            regions[l] = (VkBufferImageCopy){t->level_offset[l], 0, 0, {VK_IMAGE_ASPECT_COLOR_BIT, l, 0, 1}, {0, 0, 0},
                                             {w, h, 1}};
        }
        vkCmdCopyBufferToImage(cmd, t->staging.buffer, t->image.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                               t->image.levels, regions);
        VkImageMemoryBarrier to_read = to_dst;
        to_read.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
        to_read.dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
        to_read.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
        to_read.newLayout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
        vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT,
                             VK_PIPELINE_STAGE_VERTEX_SHADER_BIT | VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT, 0, 0, NULL,
                             0, NULL, 1, &to_read);
    }
}

/* ------------------------------------------------------------------ uniform blocks */

static bool put_floats(const engine *e, unsigned char *block, const block_ref *b, const cJSON *at_json,
                       const char *what, const double *values, int n)
{
    int offset, size;
    char where[160];
    snprintf(where, sizeof where, "block %s.%s", b->name, what);
    if (!j_int(&e->m->src, at_json, "offset", where, 0, b->size, &offset)
        || !j_int(&e->m->src, at_json, "size", where, 0, b->size, &size))
        return false;
    if (size != 4 * n || offset % 4 || offset + size > b->size)
        return j_fail(&e->m->src, where, "%d bytes at %d; this engine writes %d floats inside the %d-byte block",
                      size, offset, n, b->size);
    for (int i = 0; i < n; i++) {
        float v = (float)values[i];  /* float64 as the export holds it, rounded once as the renderer rounds */
        memcpy(block + offset + 4 * i, &v, 4);
    }
    return true;
}

/* normal_matrix: the inverse transpose of model's upper 3 × 3 (column-major `model`), in double, as a mat4
 * whose fourth row and column are (0, 0, 0, 1) (conventions.object_block). The inverse transpose stored
 * column-major is the inverse stored row-major: out[4c + r] = inverse[c][r]. */
static bool normal_matrix(const double model[16], double out[16])
{
    double a[3][3];
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            a[r][c] = model[4 * c + r];
    double cof[3][3];
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) {
            int r1 = (r + 1) % 3, r2 = (r + 2) % 3, c1 = (c + 1) % 3, c2 = (c + 2) % 3;
            cof[r][c] = a[r1][c1] * a[r2][c2] - a[r1][c2] * a[r2][c1];
        }
    double det = a[0][0] * cof[0][0] + a[0][1] * cof[0][1] + a[0][2] * cof[0][2];
    if (det == 0.0)
        return false;
    memset(out, 0, 16 * sizeof *out);
    /* inverse[i][j] = cof[j][i] / det; (inverse transpose)[r][c] = inverse[c][r] = cof[r][c] / det */
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            out[4 * c + r] = cof[r][c] / det;
    out[15] = 1.0;
    return true;
}

/* Frame and Object: the values the export gives, at the members the block lists. */
static bool engine_block(engine *e, const draw_item *it, const block_ref *b, unsigned char *data)
{
    const json_src *src = &e->m->src;
    const cJSON *members = j_arr(src, b->json, "members", b->name), *mem;
    if (!members)
        return false;
    cJSON_ArrayForEach(mem, members) {
        const char *name = j_str(src, mem, "name", b->name);
        if (!name)
            return false;
        double values[16];
        int n = 0;
        if (strcmp(b->name, "Frame") == 0 && strcmp(name, "view_proj") == 0) {
            memcpy(values, it->pass < 0 ? e->f->view_proj : e->passes[it->pass].view_proj, sizeof values);
            n = 16;
        } else if (strcmp(b->name, "Frame") == 0 && strcmp(name, "camera_pos") == 0) {
            memcpy(values, it->pass < 0 ? e->f->eye : e->passes[it->pass].fl->eye, 3 * sizeof *values);
            values[3] = 1.0;
            n = 4;
        } else if (strcmp(b->name, "Object") == 0 && strcmp(name, "model") == 0) {
            memcpy(values, e->f->objects[it->object].model, sizeof values);
            n = 16;
        } else if (strcmp(b->name, "Object") == 0 && strcmp(name, "normal_matrix") == 0) {
            if (!normal_matrix(e->f->objects[it->object].model, values))
                return fail("%s: objects[%d] (%s): its model matrix is singular: no normal matrix", e->f->file,
                            it->object, e->f->objects[it->object].name);
            n = 16;
        } else {
            return j_fail(src, b->name, "member %s: this engine does not know what it holds", name);
        }
        if (!put_floats(e, data, b, mem, name, values, n))
            return false;
    }
    return true;
}

/* Material and Lights: the upload's bytes; in Lights each shadowed light's shadow_matrix (and pcf_texel where
 * the export gives one) written at its parameter's offset. */
static bool upload_block(engine *e, const draw_item *it, const block_ref *b, unsigned char *data)
{
    const json_src *src = &e->m->src;
    const mobject *o = &e->m->objects[it->object];
    char where[160];
    snprintf(where, sizeof where, "permutations[%s].uploads[%s, %s]", o->permutation, o->material, o->light_set);
    const char *hex = j_str(src, o->upload, b->name, where);
    if (!hex)
        return false;
    size_t n = 0;
    unsigned char *bytes = hex_decode(hex, &n);
    if (!bytes)
        return j_fail(src, where, "%s is not hex digits, two a byte", b->name);
    if (n != (size_t)b->size) {
        free(bytes);
        return j_fail(src, where, "%s is %zu bytes; the block is %d", b->name, n, b->size);
    }
    memcpy(data, bytes, n);
    free(bytes);
    if (strcmp(b->name, "Lights") != 0)
        return true;
    const cJSON *params = j_arr(src, b->json, "parameters", b->name), *p;
    cJSON_ArrayForEach(p, params) {
        const cJSON *name = j_opt(p, "name"), *light = j_opt(p, "light");
        if (!cJSON_IsString(name) || !cJSON_IsNumber(light))
            continue;
        const cJSON *ln = cJSON_GetArrayItem(o->light_names, light->valueint);
        const flight *fl = cJSON_IsString(ln) ? frame_light(e->f, ln->valuestring) : NULL;
        if (!fl)
            continue;  /* not shadowed: its values are the upload's */
        if (strcmp(name->valuestring, "shadow_matrix") == 0 && !put_floats(e, data, b, p, "shadow_matrix",
                                                                          fl->shadow_matrix, 16))
            return false;
        /* a point light's faces 1 … 5 (face 0's is shadow_matrix) */
        int face = 0;
        if (fl->nfaces == 6 && sscanf(name->valuestring, "shadow_matrix_%d", &face) == 1 && face >= 1 && face <= 5
            && !put_floats(e, data, b, p, name->valuestring, fl->faces[face], 16))
            return false;
        if (strcmp(name->valuestring, "pcf_texel") == 0 && fl->has_texel
            && !put_floats(e, data, b, p, "pcf_texel", &fl->pcf_texel, 1))
            return false;
    }
    return true;
}

/* The blur pass's Blur block: ivec4 axis_radius = (axis x, axis y, radius, 0). */
static bool blur_block(engine *e, const draw_item *it, const block_ref *b, unsigned char *data)
{
    const json_src *src = &e->m->src;
    const light_pass *lp = &e->passes[it->pass];
    const cJSON *passes = j_opt(lp->blur, "passes");
    double axis[2], radius;
    if (!j_nums(src, cJSON_GetArrayItem(passes, it->blur), "axis", "moments.blur.passes[i]", axis, 2)
        || !j_num(src, lp->blur, "radius", "moments.blur", &radius))
        return false;
    const cJSON *members = j_arr(src, b->json, "members", b->name), *mem;
    cJSON_ArrayForEach(mem, members) {
        const cJSON *name = j_opt(mem, "name");
        int offset;
        if (!cJSON_IsString(name) || strcmp(name->valuestring, "axis_radius") != 0)
            return j_fail(src, b->name, "a member this engine does not know");
        if (!j_int(src, mem, "offset", b->name, 0, b->size - 16, &offset))
            return false;
        int32_t v[4] = {(int32_t)axis[0], (int32_t)axis[1], (int32_t)radius, 0};
        memcpy(data + offset, v, sizeof v);
    }
    return true;
}

/* One pair's lights into `data` (a buffer of `count` elements of `stride` bytes) from element `at`: each light's
 * parameters (the manifest's lights.<name>.params) at the layout's offsets, as float32, after its `id` as int32 at
 * offset 0 when the pair has one (a switch loop's buffer: its ids.x). */
static bool fill_pair(const engine *e, const cJSON *pair, const char *where, const char *bname, int stride,
                      unsigned char *data, int at)
{
    const json_src *src = &e->m->src;
    const cJSON *layout = j_arr(src, pair, "layout", where), *lights = j_arr(src, pair, "lights", where);
    const cJSON *id = j_opt(pair, "id");
    int32_t ids[4] = {0, 0, 0, 0};
    if (!layout || !lights)
        return false;
    if (id && !j_int(src, pair, "id", where, 0, 1 << 16, &ids[0]))
        return false;
    bool ok = true;
    int k = at;
    const cJSON *ln;
    cJSON_ArrayForEach(ln, lights) {
        const cJSON *light = cJSON_IsString(ln) ? j_opt(e->m->lights, ln->valuestring) : NULL;
        const cJSON *params = j_opt(light, "params"), *slot;
        if (!params)
            return j_fail(src, where, "light %d of %s is not in lights", k - at, bname);
        if (id)
            memcpy(data + (size_t)k * (size_t)stride, ids, sizeof ids);
        cJSON_ArrayForEach(slot, layout) {
            const cJSON *name = j_opt(slot, "name");
            int offset, bytes;
            if (!cJSON_IsString(name) || !j_int(src, slot, "offset", where, 0, stride - 4, &offset)
                || !j_int(src, slot, "size", where, 4, stride, &bytes) || offset + bytes > stride || offset % 4
                || bytes % 4 || bytes > 64 || (id && offset < (int)sizeof ids))  /* whole floats, at most a mat4 */
                return j_fail(src, where, "a layout entry of %s this engine cannot place", bname);
            const cJSON *v = j_opt(params, name->valuestring);
            int n = bytes / 4;
            double values[16] = {0};
            /* a shadowed light's matrices (a point light's faces) and pcf_texel: the export's, as in Lights */
            const flight *fl = cJSON_IsString(ln) ? frame_light(e->f, ln->valuestring) : NULL;
            int face = -1;
            if (fl && strcmp(name->valuestring, "shadow_matrix") == 0)
                face = 0;
            else if (fl && fl->nfaces == 6 && sscanf(name->valuestring, "shadow_matrix_%d", &face) == 1)
                face = face >= 1 && face <= 5 ? face : -1;
            if (fl && face >= 0 && n == 16) {
                const double *mat = face == 0 ? fl->shadow_matrix : fl->faces[face];
                for (int c = 0; c < 16; c++) {
                    float f = (float)mat[c];
                    memcpy(data + (size_t)k * (size_t)stride + (size_t)offset + 4 * (size_t)c, &f, 4);
                }
                continue;
            }
            if (fl && fl->has_texel && n == 1 && strcmp(name->valuestring, "pcf_texel") == 0) {
                float f = (float)fl->pcf_texel;
                memcpy(data + (size_t)k * (size_t)stride + (size_t)offset, &f, 4);
                continue;
            }
            /* a shadowed pair's first layer: this set's (a light of two sets has one per set), not lights.<name>'s */
            const cJSON *layers = j_opt(pair, "first_layers");
            if (layers && n == 1 && strcmp(name->valuestring, "shadow_first_layer") == 0) {
                const cJSON *at_k = cJSON_GetArrayItem(layers, k - at);
                if (!cJSON_IsNumber(at_k))
                    return j_fail(src, where, "first_layers of %s has no entry for light %d", bname, k - at);
                float f = (float)at_k->valuedouble;
                memcpy(data + (size_t)k * (size_t)stride + (size_t)offset, &f, 4);
                continue;
            }
            bool numbers = cJSON_IsArray(v) && cJSON_GetArraySize(v) == n;
            for (int c = 0; numbers && c < n; c++)
                numbers = cJSON_IsNumber(cJSON_GetArrayItem(v, c));
            if (cJSON_IsNumber(v))
                for (int c = 0; c < n; c++)
                    values[c] = v->valuedouble;  /* a scalar fills a vector's components, as the generator packs */
            else if (numbers)
                for (int c = 0; c < n; c++)
                    values[c] = cJSON_GetArrayItem(v, c)->valuedouble;
            else
                return j_fail(src, where, "light %s has no %d-float value %s", ln->valuestring, n, name->valuestring);
            for (int c = 0; c < n; c++) {
                float f = (float)values[c];
                memcpy(data + (size_t)k * (size_t)stride + (size_t)offset + 4 * (size_t)c, &f, 4);
            }
        }
        k++;
    }
    return ok;
}

/* Keeps `size` bytes of `data` as the GPU buffer of block `name` per `key` (e->blocks, freed with the engine). */
static bool keep_buffer(engine *e, const char *name, const void *key, const cJSON *layout, const void *data,
                        size_t size, VkBuffer *out)
{
    if (e->nblocks == e->capblocks) {
        int more_cap = e->capblocks ? 2 * e->capblocks : 32;
        block_entry *more = realloc(e->blocks, (size_t)more_cap * sizeof *more);
        if (!more)
            return fail("out of memory");
        e->blocks = more, e->capblocks = more_cap;
    }
    block_entry *entry = &e->blocks[e->nblocks];
    if (!gpu_buffer_new(e->g, (VkDeviceSize)size, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, data, &entry->buffer))
        return false;
    entry->name = name, entry->key = key, entry->layout = layout;
    e->nblocks++;
    *out = entry->buffer.buffer;
    return true;
}

/* A tiled dynamic set's LightTiles buffer, as dynamic_light_sets[set].tiles.fill says, with the simplest culling
 * there is: one tile (tiles_x = tiles_y = 1, a tile larger than any framebuffer) whose list for pair i is every
 * element of pair i's buffer. Culling only skips lights that add nothing, so this draws what render's culled
 * tiles draw. Words: tiles_x, tiles_y, tile_size, pairs; (offset, count) per pair; the lists. */
static bool tile_buffer(engine *e, const cJSON *set, const cJSON *tiles, const char *where, const block_ref *b,
                        VkBuffer *out)
{
    const json_src *src = &e->m->src;
    for (int i = 0; i < e->nblocks; i++)
        if (e->blocks[i].key == tiles && strcmp(e->blocks[i].name, b->name) == 0) {
            *out = e->blocks[i].buffer.buffer;
            return true;
        }
    const cJSON *pairs = j_arr(src, set, "pairs", where), *x;
    int npairs = cJSON_GetArraySize(pairs), total = 0, header, record;
    if (!j_int(src, tiles, "header_words", where, 4, 4, &header) || !j_int(src, tiles, "record_words", where, 2, 2,
                                                                           &record))
        return false;
    cJSON_ArrayForEach(x, pairs) {
        const cJSON *lights = j_opt(x, "lights");
        total += cJSON_IsArray(lights) ? cJSON_GetArraySize(lights) : 0;
    }
    size_t words = (size_t)(header + record * npairs + total);
    words += (4 - words % 4) % 4;  /* whole uvec4 elements */
    uint32_t *w = calloc(words, 4);
    if (!w)
        return fail("out of memory");
    w[0] = 1, w[1] = 1, w[2] = 1u << 16, w[3] = (uint32_t)npairs;
    uint32_t at = (uint32_t)(header + record * npairs);
    int i = 0;
    cJSON_ArrayForEach(x, pairs) {  /* pairs in the key's order: pair i's record is record i of the one tile */
        const cJSON *lights = j_opt(x, "lights");
        uint32_t n = cJSON_IsArray(lights) ? (uint32_t)cJSON_GetArraySize(lights) : 0;
        w[header + record * i] = at, w[header + record * i + 1] = n;
        for (uint32_t k = 0; k < n; k++)
            w[at + k] = k;
        at += n, i++;
    }
    bool ok = keep_buffer(e, b->name, tiles, NULL, w, words * 4, out);
    free(w);
    return ok;
}

/* A dynamic light set's storage buffer `b` (LightBuffer<i>), filled as the manifest's dynamic_light_sets says:
 * the pairs whose block it is (one, or with loop "switch" every pair of the set) list their lights in order;
 * a pair's element k (stride bytes) is at element first + k (first absent: 0) and holds lights[k]'s parameters.
 * Bound whole: the shader's light count is its size / stride; no light gets 4 bytes (a count of 0; a buffer
 * cannot be empty). */
static bool light_buffer(engine *e, const draw_item *it, const block_ref *b, VkBuffer *out)
{
    const json_src *src = &e->m->src;
    if (it->object < 0)
        return fail("%s: storage block %s read by a pass that draws no object", it->pipe->prog->name, b->name);
    const mobject *o = &e->m->objects[it->object];
    char where[200];
    snprintf(where, sizeof where, "dynamic_light_sets[%s]", o->light_set);
    const cJSON *set = j_opt(e->m->dynamic_light_sets, o->light_set), *pair = NULL, *x;
    if (!set)
        return j_fail(src, where, "%s reads storage block %s, and light set %s is not a dynamic one",
                      it->pipe->prog->name, b->name, o->light_set);
    const cJSON *tiles = j_opt(set, "tiles"), *tblock = tiles ? j_opt(tiles, "block") : NULL;
    if (cJSON_IsString(tblock) && strcmp(tblock->valuestring, b->name) == 0)
        return tile_buffer(e, set, tiles, where, b, out);
    const cJSON *pairs = j_arr(src, set, "pairs", where);
    int count = 0;
    cJSON_ArrayForEach(x, pairs) {  /* the first pair of the block keys the cache; all of them count */
        const cJSON *name = j_opt(x, "block"), *lights = j_opt(x, "lights");
        if (cJSON_IsString(name) && strcmp(name->valuestring, b->name) == 0) {
            pair = pair ? pair : x;
            count += cJSON_IsArray(lights) ? cJSON_GetArraySize(lights) : 0;
        }
    }
    if (!pair)
        return j_fail(src, where, "no pair's block is %s", b->name);
    for (int i = 0; i < e->nblocks; i++)
        if (e->blocks[i].key == pair && strcmp(e->blocks[i].name, b->name) == 0) {
            *out = e->blocks[i].buffer.buffer;
            return true;
        }
    int stride, cap;
    if (!j_int(src, pair, "stride", where, 16, 1 << 16, &stride) || !j_int(src, set, "max", where, 1, 1 << 16, &cap))
        return false;
    if (count > cap)
        return j_fail(src, where, "%d lights, more than its max %d", count, cap);
    size_t size = count ? (size_t)count * (size_t)stride : 4;
    unsigned char *data = calloc(size, 1);
    if (!data)
        return fail("out of memory");
    bool ok = true;
    cJSON_ArrayForEach(x, pairs) {
        const cJSON *name = j_opt(x, "block"), *lights = j_opt(x, "lights");
        if (!ok || !cJSON_IsString(name) || strcmp(name->valuestring, b->name) != 0)
            continue;
        int first = 0, own;
        int n = cJSON_IsArray(lights) ? cJSON_GetArraySize(lights) : 0;
        ok = j_int(src, x, "stride", where, 16, 1 << 16, &own)
             && (!j_opt(x, "first") || j_int(src, x, "first", where, 0, count, &first));
        if (ok && (own != stride || first + n > count))
            ok = j_fail(src, where, "the pairs of %s disagree on its stride or overlap", b->name);
        ok = ok && fill_pair(e, x, where, b->name, stride, data, first);
    }
    ok = ok && keep_buffer(e, b->name, pair, j_opt(pair, "layout"), data, size, out);
    free(data);
    return ok;
}

bool block_buffer(engine *e, const draw_item *it, const block_ref *b, VkBuffer *out)
{
    if (b->storage)
        return light_buffer(e, it, b, out);
    const void *key;
    bool object = strcmp(b->name, "Object") == 0, upload = !strcmp(b->name, "Material") || !strcmp(b->name, "Lights");
    if (strcmp(b->name, "Frame") == 0)
        key = it->pass < 0 ? (const void *)e : (const void *)&e->passes[it->pass];
    else if (object || upload) {
        if (it->object < 0)
            return fail("%s: block %s read by a pass that draws no object", it->pipe->prog->name, b->name);
        key = object ? (const void *)&e->f->objects[it->object] : (const void *)e->m->objects[it->object].upload;
    } else if (strcmp(b->name, "Blur") == 0 && it->blur >= 0)
        key = cJSON_GetArrayItem(j_opt(e->passes[it->pass].blur, "passes"), it->blur);
    else
        return fail("%s: %s reads a uniform block '%s' (set %d, binding %d); this engine does not know what to "
                    "put there — extend examples/engine-c with the manifest", e->m->file, it->pipe->prog->name,
                    b->name, b->set, b->binding);
    for (int i = 0; i < e->nblocks; i++) {
        block_entry *x = &e->blocks[i];
        if (x->key == key && strcmp(x->name, b->name) == 0) {
            if (!cJSON_Compare(j_opt(x->layout, "members"), j_opt(b->json, "members"), 1)
                || (int)x->buffer.size != b->size)
                return fail("%s: block %s of %s is laid out unlike the same block of another program — this "
                            "engine shares one buffer", e->m->file, b->name, it->pipe->prog->name);
            *out = x->buffer.buffer;
            return true;
        }
    }
    if (e->nblocks == e->capblocks) {
        int cap = e->capblocks ? 2 * e->capblocks : 32;
        block_entry *more = realloc(e->blocks, (size_t)cap * sizeof *more);
        if (!more)
            return fail("out of memory");
        e->blocks = more;
        e->capblocks = cap;
    }
    unsigned char *data = calloc((size_t)b->size, 1);
    if (!data)
        return fail("out of memory");
    bool ok = upload ? upload_block(e, it, b, data) : strcmp(b->name, "Blur") == 0 ? blur_block(e, it, b, data)
                                                                                  : engine_block(e, it, b, data);
    block_entry *x = &e->blocks[e->nblocks];
    ok = ok && gpu_buffer_new(e->g, (VkDeviceSize)b->size, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, data, &x->buffer);
    free(data);
    if (!ok)
        return false;
    x->name = b->name;
    x->key = key;
    x->layout = b->json;
    e->nblocks++;
    *out = x->buffer.buffer;
    return true;
}
