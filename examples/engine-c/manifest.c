/* Reading BUILD/manifest.json: the fields this engine draws by, checked before any Vulkan object exists.
 * The field meanings are docs/reference/manifest.md's; this file only finds and checks them. */
#include "scene.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vk_enums.h"

#define REBUILD "build the scene again (`shadermatrix build SCENE --out DIR --platform vulkan --pack`)"

static bool stage_bit(const char *stage, VkShaderStageFlags *bit)
{
    if (strcmp(stage, "vert") == 0)
        *bit = VK_SHADER_STAGE_VERTEX_BIT;
    else if (strcmp(stage, "frag") == 0)
        *bit = VK_SHADER_STAGE_FRAGMENT_BIT;
    else
        return false;
    return true;
}

/* Adds one stage's uniform (or, storage: storage) blocks to p->blocks, merging a block both stages read (same
 * set, binding, name). */
static bool add_blocks(const manifest *m, program *p, const cJSON *list, VkShaderStageFlags bit, const char *where,
                       bool storage)
{
    const json_src *src = &m->src;
    int i = 0;
    const cJSON *b;
    cJSON_ArrayForEach(b, list) {
        char at[256];
        snprintf(at, sizeof at, "%s[%d]", where, i++);
        block_ref r = {0};
        r.json = b;
        if (!(r.name = j_str(src, b, "name", at)) || !j_int(src, b, "set", at, 0, 31, &r.set)
            || !j_int(src, b, "binding", at, 0, 1023, &r.binding)
            || !j_int(src, b, "size", at, storage ? 0 : 1, 65536, &r.size))
            return false;
        const char *kind = j_str(src, b, "kind", at);
        if (!kind)
            return false;
        r.storage = storage;
        if (strcmp(kind, storage ? "storage" : "uniform") != 0)
            return j_fail(src, at, "block %s is a %s block in %s", r.name, kind, where);
        int k;
        for (k = 0; k < p->nblocks; k++)
            if (p->blocks[k].set == r.set && p->blocks[k].binding == r.binding)
                break;
        if (k < p->nblocks) {
            if (strcmp(p->blocks[k].name, r.name) != 0 || p->blocks[k].size != r.size)
                return j_fail(src, at, "set %d binding %d is %s here and %s in another stage", r.set, r.binding,
                              r.name, p->blocks[k].name);
            p->blocks[k].stages |= bit;
            continue;
        }
        if (p->nblocks == MAX_BLOCKS)
            return j_fail(src, at, "more than %d blocks", MAX_BLOCKS);
        r.stages = bit;
        p->blocks[p->nblocks++] = r;
    }
    return true;
}

static bool add_textures(const manifest *m, program *p, const cJSON *list, VkShaderStageFlags bit, const char *where)
{
    const json_src *src = &m->src;
    int i = 0;
    const cJSON *t;
    cJSON_ArrayForEach(t, list) {
        char at[256];
        snprintf(at, sizeof at, "%s[%d]", where, i++);
        texture_ref r = {0};
        if (!(r.name = j_str(src, t, "name", at)) || !j_int(src, t, "set", at, 0, 31, &r.set)
            || !j_int(src, t, "binding", at, 0, 1023, &r.binding)
            || !j_int(src, t, "sampler_binding", at, 0, 1023, &r.sampler_binding))
            return false;
        const char *dim = j_str(src, t, "dimension", at);
        if (!dim)
            return false;
        if (j_opt(t, "environment"))  /* image-based lighting: its cube and table are not build artifacts yet */
            return j_fail(src, at, "texture %s is an environment's (image-based lighting), which this engine does not "
                          "draw yet; draw the scene with `shadermatrix render`", r.name);
        r.light = -1;
        if (j_opt(t, "light") && !j_int(src, t, "light", at, 0, 255, &r.light))
            return false;
        r.array = strcmp(dim, "2d_array") == 0 && r.light >= 0;  /* six shadow faces, or a pair's lights' maps */
        if (strcmp(dim, "2d") != 0 && !r.array)
            return j_fail(src, at, "texture %s is %s; this engine binds 2D textures (and a light's 2d_array of "
                          "shadow faces) only", r.name, dim);
        int k;
        for (k = 0; k < p->ntextures; k++)
            if (p->textures[k].set == r.set && p->textures[k].binding == r.binding)
                break;
        if (k < p->ntextures) {
            p->textures[k].stages |= bit;
            continue;
        }
        if (p->ntextures == MAX_TEXTURES)
            return j_fail(src, at, "more than %d textures", MAX_TEXTURES);
        r.stages = bit;
        p->textures[p->ntextures++] = r;
    }
    return true;
}

bool program_parse(const manifest *m, const cJSON *entry, const char *name, bool frag, program *p)
{
    const json_src *src = &m->src;
    memset(p, 0, sizeof *p);
    p->json = entry;
    p->name = name;
    p->has_frag = frag;
    if (!(p->hash = j_str(src, entry, "hash", name)) || !(p->input_key = j_str(src, entry, "input_key", name)))
        return false;
    char where[256];
    snprintf(where, sizeof where, "%s.interface", name);
    const cJSON *iface = j_obj(src, entry, "interface", name);
    if (!iface)
        return false;
    const char *stages[2] = {"vert", "frag"};
    for (int s = 0; s < (frag ? 2 : 1); s++) {
        char at[256];
        snprintf(at, sizeof at, "%s.%s", where, stages[s]);
        VkShaderStageFlags bit = 0;
        stage_bit(stages[s], &bit);
        const cJSON *st = j_obj(src, iface, stages[s], where);
        if (!st || !(p->entry[s] = j_str(src, st, "entry_point", at)))
            return false;
        const cJSON *blocks = j_arr(src, st, "uniform_blocks", at);
        if (!blocks)
            return false;
        char list[300];
        snprintf(list, sizeof list, "%s.uniform_blocks", at);
        if (!add_blocks(m, p, blocks, bit, list, false))
            return false;
        const cJSON *storage = j_opt(st, "storage_blocks");  /* a dynamic light set's buffers (resources.c) */
        snprintf(list, sizeof list, "%s.storage_blocks", at);
        if (storage && !add_blocks(m, p, storage, bit, list, true))
            return false;
        const cJSON *textures = j_opt(st, "textures");
        snprintf(list, sizeof list, "%s.textures", at);
        if (textures && !add_textures(m, p, textures, bit, list))
            return false;
    }
    const cJSON *vert = j_opt(iface, "vert");
    const cJSON *inputs = j_arr(src, vert, "inputs", where);
    if (!inputs)
        return false;
    int i = 0;
    const cJSON *in;
    cJSON_ArrayForEach(in, inputs) {
        char at[256];
        snprintf(at, sizeof at, "%s.vert.inputs[%d]", where, i);
        if (p->ninputs == MAX_INPUTS)
            return j_fail(src, at, "more than %d vertex inputs", MAX_INPUTS);
        vertex_input *v = &p->inputs[p->ninputs];
        if (!j_int(src, in, "location", at, 0, 31, &v->location) || !(v->name = j_str(src, in, "name", at))
            || !(v->format_name = j_str(src, in, "format", at)))
            return false;
        if (!vk_format(v->format_name, &v->format, &v->bytes) || v->bytes == 0 || v->format == VK_FORMAT_D32_SFLOAT)
            return j_fail(src, at, "vertex format %s is not one this engine binds (R32…_SFLOAT)", v->format_name);
        p->ninputs++;
        i++;
    }
    return true;
}

const block_ref *program_block(const program *p, const char *name)
{
    for (int i = 0; i < p->nblocks; i++)
        if (strcmp(p->blocks[i].name, name) == 0)
            return &p->blocks[i];
    return NULL;
}

bool depth_program(const manifest *m, const char *unit, const cJSON *stages, program *out)
{
    char where[160];
    snprintf(where, sizeof where, "depth_shaders.%s", unit);
    const cJSON *entry = j_opt(m->depth_shaders, unit);
    if (!cJSON_IsObject(entry))
        return j_fail(&m->src, "depth_shaders", "no unit '%s', which a depth pass draws with", unit);
    bool vert = false, frag = false;
    const cJSON *s;
    cJSON_ArrayForEach(s, stages) {
        if (cJSON_IsString(s) && strcmp(s->valuestring, "vert") == 0)
            vert = true;
        else if (cJSON_IsString(s) && strcmp(s->valuestring, "frag") == 0)
            frag = true;
        else
            return j_fail(&m->src, where, "a caster's stage %s is neither vert nor frag",
                          cJSON_IsString(s) ? s->valuestring : "(not a string)");
    }
    if (!vert)
        return j_fail(&m->src, where, "a caster drawn without its vertex stage");
    const char *status = j_str(&m->src, entry, "status", where);
    if (!status)
        return false;
    if (strcmp(status, "failed") == 0)
        return j_fail(&m->src, where, "the depth unit failed to build");
    return program_parse(m, entry, unit, frag, out);  /* `unit` lives in the manifest's tree */
}

/* The vulkan pack of `packs[]`. */
static bool find_pack(manifest *m)
{
    const cJSON *packs = j_opt(m->root, "packs");
    const cJSON *p;
    cJSON_ArrayForEach(p, packs) {
        const cJSON *platform = j_opt(p, "platform");
        if (cJSON_IsString(platform) && strcmp(platform->valuestring, "vulkan") == 0) {
            m->pack_path = j_str(&m->src, p, "path", "packs[vulkan]");
            m->pack_sha256 = j_str(&m->src, p, "sha256", "packs[vulkan]");
            m->pack_key = j_str(&m->src, p, "key", "packs[vulkan]");
            return m->pack_path && m->pack_sha256 && m->pack_key;
        }
    }
    return fail("%s: packs: no vulkan pack — build with `--platform vulkan --pack`: this engine loads its "
                "shaders from the pack", m->file);
}

/* The conventions this engine sets up the viewport by: Vulkan's own (depth 0..1, NDC +y down, row 0 at the top). */
static bool check_conventions(manifest *m)
{
    const json_src *src = &m->src;
    const cJSON *c = j_obj(src, m->root, "conventions", "manifest");
    const cJSON *pl = c ? j_obj(src, c, "platforms", "conventions") : NULL;
    m->conv = pl ? j_obj(src, pl, "vulkan", "conventions.platforms") : NULL;
    const cJSON *clip = m->conv ? j_obj(src, m->conv, "clip", "conventions.platforms.vulkan") : NULL;
    if (!clip)
        return false;
    const char *want[3][2] = {{"depth_range", "0..1"}, {"ndc_y", "down"}, {"framebuffer_origin", "top-left"}};
    for (int i = 0; i < 3; i++) {
        const char *v = j_str(src, clip, want[i][0], "conventions.platforms.vulkan.clip");
        if (!v)
            return false;
        if (strcmp(v, want[i][1]) != 0)
            return j_fail(src, "conventions.platforms.vulkan.clip", "%s is %s; this engine's viewport is Vulkan's "
                          "(%s)", want[i][0], v, want[i][1]);
    }
    return true;
}

static bool load_objects(manifest *m)
{
    const json_src *src = &m->src;
    const cJSON *objects = j_arr(src, m->root, "objects", "manifest");
    if (!objects)
        return false;
    m->nobjects = cJSON_GetArraySize(objects);
    m->objects = calloc((size_t)m->nobjects + 1, sizeof *m->objects);
    if (!m->objects)
        return fail("out of memory");
    int i = 0;
    const cJSON *o;
    cJSON_ArrayForEach(o, objects) {
        char at[64];
        snprintf(at, sizeof at, "objects[%d]", i);
        mobject *x = &m->objects[i++];
        if (!(x->name = j_str(src, o, "name", at)) || !(x->material = j_str(src, o, "material", at))
            || !(x->light_set = j_str(src, o, "light_set", at)) || !(x->permutation = j_str(src, o, "permutation", at)))
            return false;
        x->perm = -1;
        for (int k = 0; k < m->nperms; k++)
            if (m->perms[k].hash && strcmp(m->perms[k].hash, x->permutation) == 0)
                x->perm = k;
        if (x->perm < 0)
            return j_fail(src, at, "object %s's permutation %s is not a built permutation (missing or failed)",
                          x->name, x->permutation);
        x->light_names = j_opt(m->light_sets, x->light_set);
        if (!cJSON_IsArray(x->light_names))
            return j_fail(src, at, "light set %s is not in light_sets", x->light_set);
        const cJSON *uploads = j_arr(src, m->perms[x->perm].json, "uploads", x->permutation);
        const cJSON *u;
        cJSON_ArrayForEach(u, uploads) {
            const cJSON *mat = j_opt(u, "material"), *set = j_opt(u, "light_set");
            if (cJSON_IsString(mat) && cJSON_IsString(set) && strcmp(mat->valuestring, x->material) == 0
                && strcmp(set->valuestring, x->light_set) == 0)
                x->upload = u;
        }
        if (!x->upload)
            return j_fail(src, at, "permutation %s has no upload for material %s with light set %s", x->permutation,
                          x->material, x->light_set);
    }
    return true;
}

static bool load_permutations(manifest *m)
{
    const json_src *src = &m->src;
    const cJSON *perms = j_arr(src, m->root, "permutations", "manifest");
    if (!perms)
        return false;
    m->perms = calloc((size_t)cJSON_GetArraySize(perms) + 1, sizeof *m->perms);
    if (!m->perms)
        return fail("out of memory");
    int i = 0;
    const cJSON *p;
    cJSON_ArrayForEach(p, perms) {
        char at[64];
        snprintf(at, sizeof at, "permutations[%d]", i++);
        const char *status = j_str(src, p, "status", at), *hash = j_str(src, p, "hash", at);
        if (!status || !hash)
            return false;
        if (strcmp(status, "failed") == 0)
            continue;  /* no files; an object drawn with it is refused in load_objects */
        if (!program_parse(m, p, hash, true, &m->perms[m->nperms]))
            return false;
        m->nperms++;
    }
    return true;
}

bool manifest_load(const char *build_dir, manifest *m)
{
    memset(m, 0, sizeof *m);
    m->dir = path_join(build_dir, "");
    m->file = path_join(build_dir, "manifest.json");
    if (!m->dir || !m->file)
        return fail("out of memory");
    m->src.file = m->file;
    m->src.hint = REBUILD;
    size_t size = 0;
    char *text = (char *)read_file(m->file, &size);
    if (!text)
        return false;
    m->root = json_parse_file(m->file, text, size, REBUILD);
    free(text);
    if (!m->root)
        return false;
    const json_src *src = &m->src;
    int version = 0;
    if (!j_int(src, m->root, "format_version", "manifest", 0, 1000000, &version))
        return false;
    if (version != 1)
        return j_fail(src, "format_version", "%d; this engine reads format 1", version);
    const cJSON *platforms = j_arr(src, m->root, "platforms", "manifest"), *pl;
    bool vulkan = false;
    cJSON_ArrayForEach(pl, platforms)
        vulkan |= cJSON_IsString(pl) && strcmp(pl->valuestring, "vulkan") == 0;
    if (!platforms)
        return false;
    if (!vulkan)
        return j_fail(src, "platforms", "no vulkan among them — build with `--platform vulkan`");
    if (!check_conventions(m) || !find_pack(m))
        return false;
    if (!(m->materials = j_obj(src, m->root, "materials", "manifest"))
        || !(m->lights = j_obj(src, m->root, "lights", "manifest"))
        || !(m->light_sets = j_obj(src, m->root, "light_sets", "manifest")))
        return false;
    /* samplers is there only when something samples a texture (a scene of lights without maps has none) */
    if (j_opt(m->root, "samplers") && !(m->samplers = j_arr(src, m->root, "samplers", "manifest")))
        return false;
    m->depth_shaders = j_opt(m->root, "depth_shaders");
    m->tables = j_opt(m->root, "tables");
    m->dynamic_light_sets = j_opt(m->root, "dynamic_light_sets");
    return load_permutations(m) && load_objects(m);
}

void manifest_free(manifest *m)
{
    cJSON_Delete(m->root);
    free(m->perms);
    free(m->objects);
    free(m->dir);
    free(m->file);
    memset(m, 0, sizeof *m);
}
