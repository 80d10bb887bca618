/* The descriptor sets of every draw, written from what its program's interface names: a block by its name
 * (resources.c makes its buffer), a light's map where the light's depth pass `binds` says (checked against the
 * interface's set and binding), a material's texture from materials.<m>.textures (its binding checked too), a
 * baked table from tables[], each with the sampler of the row the manifest gives it. */
#include "render.h"

#include <stdio.h>
#include <string.h>

/* ------------------------------------------------------------------ textures of a draw */

/* Where `binds` of the light's depth pass says permutation `perm` reads texture t of light t->light. */
static bool light_texture(engine *e, const draw_item *it, const texture_ref *t, VkImageView *view, int *row)
{
    const manifest *m = e->m;
    const mobject *o = &m->objects[it->object];
    const cJSON *ln = cJSON_GetArrayItem(o->light_names, t->light);
    const cJSON *pair = NULL;
    const cJSON *dyn = j_opt(m->dynamic_light_sets, o->light_set);
    if (dyn) {  /* a dynamic set: t->light is the pair's index; its first drawn light's binds say where */
        const cJSON *x;
        cJSON_ArrayForEach(x, j_opt(dyn, "pairs")) {
            const cJSON *index = j_opt(x, "light_index");
            if (cJSON_IsNumber(index) && index->valueint == t->light)
                pair = x;
        }
        const cJSON *lights = j_opt(pair, "lights");
        ln = NULL;
        for (int k = 0; !ln && k < cJSON_GetArraySize(lights); k++) {
            const light_pass *any;
            const cJSON *name = cJSON_GetArrayItem(lights, k);
            if (cJSON_IsString(name) && light_pass_of(e, name->valuestring, &any))
                ln = name;
        }
        if (!ln)
            return fail("%s: %s reads pair %d's %s of dynamic set %s, which has no drawn light — this engine binds "
                        "a shadowed pair's array of its lights' maps", m->file, o->permutation, t->light, t->name,
                        o->light_set);
    }
    const light_pass *lp;
    if (!cJSON_IsString(ln))
        return fail("%s: %s reads light %d's %s; light set %s has no light %d", m->file, o->permutation, t->light,
                    t->name, o->light_set, t->light);
    if (!light_pass_of(e, ln->valuestring, &lp))
        return fail("%s: %s reads %s of light %s, which has no depth_pass — rebuild the scene", m->file,
                    o->permutation, t->name, ln->valuestring);
    const cJSON *binds = j_opt(lp->desc, "binds"), *b;
    cJSON_ArrayForEach(b, binds) {
        const cJSON *perm = j_opt(b, "permutation"), *index = j_opt(b, "light_index"), *tex = j_opt(b, "texture");
        if (!cJSON_IsString(perm) || strcmp(perm->valuestring, o->permutation) != 0 || !cJSON_IsNumber(index)
            || index->valueint != t->light || !cJSON_IsString(tex) || strcmp(tex->valuestring, t->name) != 0)
            continue;
        char where[128];
        snprintf(where, sizeof where, "lights.%s.depth_pass.binds[%s]", lp->name, o->permutation);
        int set, binding, sampler_binding;
        const char *image = j_str(&m->src, b, "image", where);
        if (!image || !j_int(&m->src, b, "set", where, 0, 31, &set) || !j_int(&m->src, b, "binding", where, 0, 1023, &binding)
            || !j_int(&m->src, b, "sampler_binding", where, 0, 1023, &sampler_binding)
            || !j_int(&m->src, b, "sampler_state", where, 0, 1 << 20, row))
            return false;
        if (set != t->set || binding != t->binding || sampler_binding != t->sampler_binding)
            return j_fail(&m->src, where, "set %d binding %d/%d; the permutation's interface binds %s at %d %d/%d",
                          set, binding, sampler_binding, t->name, t->set, t->binding, t->sampler_binding);
        if (pair) {  /* the pair's lights' maps, each its layers */
            if (!t->array)
                return j_fail(&m->src, where, "%s of a dynamic set's pair is not a 2d_array", t->name);
            return pair_array_of(e, pair, where, view);
        }
        if (t->array != (lp->face == 0))
            return j_fail(&m->src, where, "%s is %s, and light %s has %s", t->name, t->array ? "a 2d_array" : "2D",
                          lp->name, lp->face == 0 ? "six faces" : "one map");
        if (lp->face == 0 && strcmp(image, lp->moments ? "moments" : "depth") == 0)
            *view = lp->array.view;  /* a point light's six faces, one layer each */
        else if (strcmp(image, "depth") == 0 && !lp->moments)
            *view = lp->depth.view;
        else if (strcmp(image, "moments") == 0 && lp->moments)
            *view = lp->targets[lp->nblur].view;
        else
            return j_fail(&m->src, where, "image %s of a %s pass", image, lp->moments ? "moments" : "depth");
        return true;
    }
    return fail("%s: lights.%s.depth_pass.binds has no entry for %s's %s (light %d) — rebuild the scene", m->file,
                lp->name, o->permutation, t->name, t->light);
}

/* A material's texture (materials.<m>.textures.<name>) or a baked table (tables[] of that texture name). */
static bool material_texture(engine *e, const draw_item *it, const texture_ref *t, VkImageView *view, int *row)
{
    const manifest *m = e->m;
    const json_src *src = &m->src;
    const mobject *o = &m->objects[it->object];
    const cJSON *r = j_opt(j_opt(j_opt(m->materials, o->material), "textures"), t->name);
    char where[160];
    if (r) {
        snprintf(where, sizeof where, "materials.%s.textures.%s", o->material, t->name);
        if (j_opt(r, "set")) {  /* where the build reflected it: the same binding as the interface's */
            int set, binding, sb;
            if (!j_int(src, r, "set", where, 0, 31, &set) || !j_int(src, r, "binding", where, 0, 1023, &binding)
                || !j_int(src, r, "sampler_binding", where, 0, 1023, &sb))
                return false;
            if (set != t->set || binding != t->binding || sb != t->sampler_binding)
                return j_fail(src, where, "set %d binding %d/%d; %s binds it at %d %d/%d", set, binding, sb,
                              it->pipe->prog->name, t->set, t->binding, t->sampler_binding);
        }
        const cJSON *s = j_obj(src, r, "sampler", where);
        return s && j_int(src, s, "index", where, 0, 1 << 20, row) && texture_of_row(e, r, where, view);
    }
    int i = 0;
    const cJSON *tab;
    cJSON_ArrayForEach(tab, m->tables) {
        const cJSON *name = j_opt(tab, "texture");
        snprintf(where, sizeof where, "tables[%d]", i++);
        if (!cJSON_IsString(name) || strcmp(name->valuestring, t->name) != 0)
            continue;
        const cJSON *s = j_obj(src, tab, "sampler", where);
        return s && j_int(src, s, "index", where, 0, 1 << 20, row) && texture_of_row(e, tab, where, view);
    }
    return fail("%s: %s samples %s; neither materials.%s.textures nor tables lists it — rebuild the scene", m->file,
                it->pipe->prog->name, t->name, o->material);
}

/* The blur pass k reads the previous image: the moments target, then the last pass's, through the sampler row
 * the light's depth_pass.moments.blur names (bilinear, level 0, clamped: the passes read texel centres). */
static bool blur_texture(engine *e, const draw_item *it, VkImageView *view, int *row)
{
    const light_pass *lp = &e->passes[it->pass];
    *view = lp->targets[it->blur].view;
    const cJSON *blur = j_opt(j_opt(lp->desc, "moments"), "blur");
    return j_int(&e->m->src, blur, "sampler_state", "depth_pass.moments.blur", 0, 1 << 20, row);
}

/* ------------------------------------------------------------------ descriptor sets */

static bool write_item_sets(engine *e, draw_item *it)
{
    const program_layout *l = &it->pipe->layout;
    const program *p = it->pipe->prog;
    for (int s = 0; s < l->nsets; s++) {
        if (!l->nbindings[s])
            continue;  /* an empty set layout in a gap: nothing is read there, nothing bound */
        VkDescriptorSetAllocateInfo alloc = {.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
        alloc.descriptorPool = e->pool;
        alloc.descriptorSetCount = 1;
        alloc.pSetLayouts = &l->sets[s];
        VkResult r = vkAllocateDescriptorSets(e->g->device, &alloc, &it->sets[s]);
        if (r != VK_SUCCESS)
            return vk_failed("vkAllocateDescriptorSets", r);
        VkDescriptorBufferInfo buffers[MAX_SET_BINDINGS];
        VkDescriptorImageInfo images[MAX_SET_BINDINGS];
        VkWriteDescriptorSet writes[MAX_SET_BINDINGS];
        for (int i = 0; i < l->nbindings[s]; i++) {
            const set_binding *b = &l->bindings[s][i];
            VkWriteDescriptorSet *w = &writes[i];
            *w = (VkWriteDescriptorSet){.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
            w->dstSet = it->sets[s];
            w->dstBinding = b->binding;
            w->descriptorCount = 1;
            if (b->kind == BIND_BLOCK || b->kind == BIND_STORAGE) {
                w->descriptorType = b->kind == BIND_BLOCK ? VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER
                                                          : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
                buffers[i] = (VkDescriptorBufferInfo){VK_NULL_HANDLE, 0, VK_WHOLE_SIZE};
                if (!block_buffer(e, it, &p->blocks[b->ref], &buffers[i].buffer))
                    return false;
                w->pBufferInfo = &buffers[i];
                continue;
            }
            const texture_ref *t = &p->textures[b->ref];
            VkImageView view = VK_NULL_HANDLE;
            int row = -1;
            bool ok = it->blur >= 0 ? blur_texture(e, it, &view, &row)
                    : t->light >= 0 ? (it->pass < 0 ? light_texture(e, it, t, &view, &row)
                                                    : fail("%s: a depth pass's unit reads a light's map", p->name))
                                    : material_texture(e, it, t, &view, &row);
            char where[96];
            snprintf(where, sizeof where, "the sampler of %s (%s)", t->name, p->name);
            VkSampler sampler = VK_NULL_HANDLE;
            if (!ok || (b->kind == BIND_SAMPLER && !sampler_of_row(e, row, where, &sampler)))
                return false;
            images[i] = (VkDescriptorImageInfo){sampler, b->kind == BIND_IMAGE ? view : VK_NULL_HANDLE,
                                                VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
            w->descriptorType = b->kind == BIND_IMAGE ? VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE : VK_DESCRIPTOR_TYPE_SAMPLER;
            w->pImageInfo = &images[i];
        }
        vkUpdateDescriptorSets(e->g->device, (uint32_t)l->nbindings[s], writes, 0, NULL);
    }
    return true;
}

/* One pool for the frame, sized by counting every draw's bindings. */
bool write_sets(engine *e)
{
    uint32_t sets = 0, counts[4] = {0, 0, 0, 0};
    for (int d = 0; d < e->ndraws; d++) {
        const program_layout *l = &e->draws[d].pipe->layout;
        for (int s = 0; s < l->nsets; s++) {
            sets += l->nbindings[s] > 0;
            for (int i = 0; i < l->nbindings[s]; i++)
                counts[l->bindings[s][i].kind]++;
        }
    }
    VkDescriptorPoolSize sizes[4];
    uint32_t n = 0;
    const VkDescriptorType types[4] = {VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE,
                                       VK_DESCRIPTOR_TYPE_SAMPLER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER};
    for (int k = 0; k < 4; k++)
        if (counts[k])
            sizes[n++] = (VkDescriptorPoolSize){types[k], counts[k]};
    if (!sets)
        return true;
    VkDescriptorPoolCreateInfo info = {.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    info.maxSets = sets;
    info.poolSizeCount = n;
    info.pPoolSizes = sizes;
    VkResult r = vkCreateDescriptorPool(e->g->device, &info, NULL, &e->pool);
    if (r != VK_SUCCESS)
        return vk_failed("vkCreateDescriptorPool", r);
    if (!gpu_own(e->g, (owned){.kind = OWN_DESCRIPTOR_POOL, .u.descriptor_pool = e->pool}))
        return false;
    for (int d = 0; d < e->ndraws; d++)
        if (!write_item_sets(e, &e->draws[d]))
            return false;
    return true;
}
