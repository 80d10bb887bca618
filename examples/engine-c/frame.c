/* Reading the frame export: FRAME_DIR/frame.json and its meshes (the layout `shadermatrix render --export`
 * writes: docs/reference for the format). Every number that indexes or sizes memory is checked here, so the
 * Vulkan side never reads a mesh file outside its bytes nor draws an index past its vertices. */
#include "scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vk_enums.h"

#define EXPORT "export the frame again (`shadermatrix render SCENE --mode specialized --build BUILD --export DIR`)"

static bool load_mesh(frame *f, const cJSON *j, const char *dir, int index, mesh *me)
{
    const json_src *src = &f->src;
    char at[64];
    snprintf(at, sizeof at, "meshes[%d]", index);
    const char *rel = j_str(src, j, "path", at), *sha = j_str(src, j, "sha256", at);
    int vcount, bytes;
    if (!rel || !sha || !j_int(src, j, "vertex_count", at, 1, 1 << 28, &vcount)
        || !j_int(src, j, "bytes", at, 0, 0x7FFFFFFF, &bytes))
        return false;
    me->vertex_count = (uint32_t)vcount;
    if (!(me->path = path_join(dir, rel)))
        return fail("out of memory");
    if (!(me->bytes = read_file(me->path, &me->size)) || !check_sha256(me->path, me->bytes, me->size, sha))
        return false;
    if (me->size != (size_t)bytes)
        return j_fail(src, at, "bytes %d; %s is %zu bytes", bytes, me->path, me->size);
    const cJSON *attrs = j_obj(src, j, "attributes", at), *a;
    if (!attrs)
        return false;
    cJSON_ArrayForEach(a, attrs) {
        char where[128];
        snprintf(where, sizeof where, "%s.attributes.%s", at, a->string);
        if (me->nattrs == MAX_ATTRIBUTES)
            return j_fail(src, where, "more than %d attributes", MAX_ATTRIBUTES);
        mesh_attr *x = &me->attrs[me->nattrs++];
        int offset, stride;
        x->name = a->string;
        if (!j_int(src, a, "offset", where, 0, 0x7FFFFFFF, &offset) || !j_int(src, a, "stride", where, 1, 256, &stride)
            || !(x->format_name = j_str(src, a, "format", where)))
            return false;
        x->offset = (uint32_t)offset;
        x->stride = (uint32_t)stride;
        VkFormat fmt;
        uint32_t bytes;
        if (!vk_format(x->format_name, &fmt, &bytes) || bytes == 0)
            return j_fail(src, where, "format %s is not a vertex format this engine reads", x->format_name);
        if (x->stride != bytes || x->offset % 4)
            return j_fail(src, where, "stride %u, offset %u: an attribute array is tightly packed %s (stride %u) "
                          "at a multiple of 4 bytes", x->stride, x->offset, x->format_name, bytes);
        if ((uint64_t)x->offset + (uint64_t)x->stride * me->vertex_count > me->size)
            return j_fail(src, where, "%u vertices from byte %u run past the %zu-byte %s", me->vertex_count,
                          x->offset, me->size, me->path);
    }
    const cJSON *ind = j_obj(src, j, "indices", at);
    char where[96];
    snprintf(where, sizeof where, "%s.indices", at);
    int ioffset, count;
    const char *ifmt = ind ? j_str(src, ind, "format", where) : NULL;
    if (!ifmt || !j_int(src, ind, "offset", where, 0, 0x7FFFFFFF, &ioffset)
        || !j_int(src, ind, "count", where, 0, 1 << 30, &count))
        return false;
    me->index_offset = (uint32_t)ioffset;
    me->index_count = (uint32_t)count;
    if (strcmp(ifmt, "uint32") != 0)
        return j_fail(src, where, "format %s; this engine reads uint32 indices", ifmt);
    if (count == 0 || count % 3 || ioffset % 4)
        return j_fail(src, where, "count %d at byte %d: a triangle list of whole triangles, 4-byte aligned", count,
                      ioffset);
    if ((uint64_t)me->index_offset + 4 * (uint64_t)me->index_count > me->size)
        return j_fail(src, where, "%u indices from byte %u run past the %zu-byte %s", me->index_count,
                      me->index_offset, me->size, me->path);
    for (uint32_t i = 0; i < me->index_count; i++) {
        const unsigned char *p = me->bytes + me->index_offset + 4 * (size_t)i;
        uint32_t v = (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
        if (v >= me->vertex_count)
            return j_fail(src, where, "index %u is %u, past the mesh's %u vertices", i, v, me->vertex_count);
    }
    return true;
}

static bool load_objects(frame *f, const manifest *m)
{
    const json_src *src = &f->src;
    const cJSON *objects = j_arr(src, f->root, "objects", "frame");
    if (!objects)
        return false;
    f->nobjects = cJSON_GetArraySize(objects);
    if (f->nobjects != m->nobjects)
        return j_fail(src, "objects", "%d objects; the manifest %s has %d", f->nobjects, m->file, m->nobjects);
    f->objects = calloc((size_t)f->nobjects + 1, sizeof *f->objects);
    if (!f->objects)
        return fail("out of memory");
    int i = 0;
    const cJSON *o;
    cJSON_ArrayForEach(o, objects) {
        char at[64];
        snprintf(at, sizeof at, "objects[%d]", i);
        fobject *x = &f->objects[i];
        if (!(x->name = j_str(src, o, "name", at)) || !j_int(src, o, "mesh", at, 0, f->nmeshes - 1, &x->mesh)
            || !j_nums(src, o, "model", at, x->model, 16) || !j_bool(src, o, "mirrored", at, &x->mirrored))
            return false;
        if (strcmp(x->name, m->objects[i].name) != 0)
            return j_fail(src, at, "object %s; the manifest's object %d is %s (the same objects in the same order)",
                          x->name, i, m->objects[i].name);
        i++;
    }
    const cJSON *order = j_arr(src, f->root, "draw_order", "frame"), *d;
    if (!order)
        return false;
    f->ndraw = cJSON_GetArraySize(order);
    f->draw_order = calloc((size_t)f->ndraw + 1, sizeof *f->draw_order);
    char *seen = calloc((size_t)f->nobjects + 1, 1);
    bool ok = f->draw_order && seen;
    if (!ok)
        fail("out of memory");
    i = 0;
    cJSON_ArrayForEach(d, order) {
        if (!ok)
            break;
        double v = cJSON_IsNumber(d) ? d->valuedouble : -1;
        if (v != floor(v) || v < 0 || v >= f->nobjects || seen[(int)v])
            ok = j_fail(src, "draw_order", "item %d is not the index of an object not drawn yet", i);
        else
            seen[(int)v] = 1, f->draw_order[i++] = (int)v;
    }
    free(seen);
    return ok;
}

static bool load_lights(frame *f)
{
    const json_src *src = &f->src;
    const cJSON *lights = j_obj(src, f->root, "lights", "frame"), *l;
    if (!lights)
        return false;
    f->lights = calloc((size_t)cJSON_GetArraySize(lights) + 1, sizeof *f->lights);
    if (!f->lights)
        return fail("out of memory");
    cJSON_ArrayForEach(l, lights) {
        char at[128];
        snprintf(at, sizeof at, "lights.%s", l->string);
        flight *x = &f->lights[f->nlights++];
        x->name = l->string;
        double size[2];
        if (!j_nums(src, l, "shadow_matrix", at, x->shadow_matrix, 16) || !j_nums(src, l, "size", at, size, 2)
            || !j_nums(src, l, "eye", at, x->eye, 3))
            return false;
        if (!(size[0] >= 1 && size[0] <= 16384 && size[1] >= 1 && size[1] <= 16384) || size[0] != floor(size[0])
            || size[1] != floor(size[1]))
            return j_fail(src, at, "size %g x %g is not a map of 1 to 16384 texels a side", size[0], size[1]);
        x->size[0] = (int)size[0];
        x->size[1] = (int)size[1];
        const cJSON *texel = j_opt(l, "pcf_texel");
        if (texel && !cJSON_IsNull(texel)) {
            if (!j_num(src, l, "pcf_texel", at, &x->pcf_texel))
                return false;
            x->has_texel = true;
        }
        const cJSON *faces = j_opt(l, "face_matrices");
        if (faces) {  /* a point light's six faces (layer k face k), each one map's matrix */
            if (!cJSON_IsArray(faces) || cJSON_GetArraySize(faces) != 6)
                return j_fail(src, at, "face_matrices is not six matrices");
            for (int k = 0; k < 6; k++) {
                const cJSON *fm = cJSON_GetArrayItem(faces, k);
                if (cJSON_GetArraySize(fm) != 16)
                    return j_fail(src, at, "face_matrices[%d] is not 16 numbers", k);
                for (int i = 0; i < 16; i++) {
                    const cJSON *v = cJSON_GetArrayItem(fm, i);
                    if (!cJSON_IsNumber(v))
                        return j_fail(src, at, "face_matrices[%d][%d] is not a number", k, i);
                    x->faces[k][i] = v->valuedouble;
                }
            }
            x->nfaces = 6;
        }
        const cJSON *casters = j_opt(l, "casters"), *c;
        if (casters) {  /* the objects of its light sets (absent in an older export: every object casts) */
            if (!cJSON_IsArray(casters))
                return j_fail(src, at, "casters is not an array of object indices");
            cJSON_ArrayForEach(c, casters)
                if (!cJSON_IsNumber(c) || c->valuedouble != floor(c->valuedouble) || c->valuedouble < 0
                    || c->valuedouble >= f->nobjects)
                    return j_fail(src, at, "casters holds %s, not an index of the %d objects",
                                  cJSON_IsNumber(c) ? "a number out of range" : "a non-number", f->nobjects);
            x->casters = casters;
        }
    }
    return true;
}

bool frame_load(const char *frame_dir, const manifest *m, frame *f)
{
    memset(f, 0, sizeof *f);
    if (!(f->file = path_join(frame_dir, "frame.json")))
        return fail("out of memory");
    f->src.file = f->file;
    f->src.hint = EXPORT;
    const json_src *src = &f->src;
    size_t size = 0;
    char *text = (char *)read_file(f->file, &size);
    if (!text)
        return false;
    f->root = json_parse_file(f->file, text, size, EXPORT);
    free(text);
    if (!f->root)
        return false;
    const char *format = j_str(src, f->root, "format", "frame"), *platform;
    int version;
    if (!format || !j_int(src, f->root, "format_version", "frame", 0, 1000000, &version))
        return false;
    if (strcmp(format, "shadermatrix-frame") != 0 || version != 1)
        return j_fail(src, "format", "%s version %d; this engine reads shadermatrix-frame version 1", format, version);
    const char *scene = j_str(src, f->root, "scene", "frame"), *built = j_str(&m->src, m->root, "scene", "manifest");
    if (!(platform = j_str(src, f->root, "platform", "frame")) || !scene || !built)
        return false;
    if (strcmp(scene, built) != 0)
        return j_fail(src, "scene", "%s; the build %s is of %s", scene, m->file, built);
    if (strcmp(platform, "vulkan") != 0)
        return j_fail(src, "platform", "%s; this engine draws the vulkan platform's frame", platform);
    double sz[2], color[4], depth;
    const cJSON *clear = j_obj(src, f->root, "clear", "frame"), *camera = j_obj(src, f->root, "camera", "frame");
    if (!j_nums(src, f->root, "size", "frame", sz, 2) || !clear || !camera
        || !j_nums(src, clear, "color", "clear", color, 4) || !j_num(src, clear, "depth", "clear", &depth)
        || !j_nums(src, camera, "eye", "camera", f->eye, 3) || !j_nums(src, camera, "view_proj", "camera", f->view_proj, 16)
        || !(f->color_attachment = j_str(src, f->root, "color_attachment", "frame")))
        return false;
    if (sz[0] != floor(sz[0]) || sz[1] != floor(sz[1]) || sz[0] < 1 || sz[1] < 1 || sz[0] > 16384 || sz[1] > 16384)
        return j_fail(src, "size", "%g x %g is not a size of 1 to 16384 pixels a side", sz[0], sz[1]);
    f->width = (int)sz[0];
    f->height = (int)sz[1];
    for (int i = 0; i < 4; i++)
        f->clear_color[i] = (float)color[i];
    f->clear_depth = (float)depth;
    const cJSON *meshes = j_arr(src, f->root, "meshes", "frame"), *me;
    if (!meshes)
        return false;
    f->meshes = calloc((size_t)cJSON_GetArraySize(meshes) + 1, sizeof *f->meshes);
    if (!f->meshes)
        return fail("out of memory");
    cJSON_ArrayForEach(me, meshes) {
        mesh *x = &f->meshes[f->nmeshes++];  /* counted first: frame_free releases what a failed load read */
        if (!load_mesh(f, me, frame_dir, f->nmeshes - 1, x))
            return false;
    }
    return load_objects(f, m) && load_lights(f);
}

const flight *frame_light(const frame *f, const char *name)
{
    for (int i = 0; i < f->nlights; i++)
        if (strcmp(f->lights[i].name, name) == 0)
            return &f->lights[i];
    return NULL;
}

void frame_free(frame *f)
{
    for (int i = 0; i < f->nmeshes; i++) {
        free(f->meshes[i].path);
        free(f->meshes[i].bytes);
    }
    free(f->meshes);
    free(f->objects);
    free(f->draw_order);
    free(f->lights);
    cJSON_Delete(f->root);
    free(f->file);
    memset(f, 0, sizeof *f);
}
