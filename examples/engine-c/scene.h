/* What the engine reads: the build's manifest.json (the material contract) and the frame export
 * (frame.json and its meshes: what an engine takes from its own assets). Both are parsed with cJSON and
 * checked up front; the structures below point into the cJSON trees, which live as long as they do. */
#ifndef ENGINE_SCENE_H
#define ENGINE_SCENE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <cjson/cJSON.h>
#include <vulkan/vulkan.h>

#include "util.h"

#define MAX_BLOCKS 16
#define MAX_TEXTURES 32
#define MAX_INPUTS 16
#define MAX_ATTRIBUTES 16

/* A uniform block a program reads (interface.<stage>.uniform_blocks), with the stages that read it. */
typedef struct block_ref {
    const char *name;          /* Frame, Object, Material, Lights: what the engine puts there is by name */
    int set, binding, size;    /* size 0: a storage block (LightBuffer<i>), its bytes what the engine fills */
    bool storage;              /* interface.<stage>.storage_blocks: a dynamic light set's buffer */
    VkShaderStageFlags stages;
    const cJSON *json;         /* its members and parameters (offsets of each value) */
} block_ref;

/* A texture a program samples (interface.<stage>.textures): the image at `binding`, its sampler at
 * `sampler_binding`; `light` is the index into the object's light set for a light's map, else -1. */
typedef struct texture_ref {
    const char *name;
    int set, binding, sampler_binding, light;
    bool array;                /* a light's 2d_array: its six faces' layers */
    VkShaderStageFlags stages;
} texture_ref;

typedef struct vertex_input {
    int location;
    const char *name;          /* the mesh attribute of the same name feeds it */
    const char *format_name;
    VkFormat format;
    uint32_t bytes;
} vertex_input;

/* One shader program: a permutation, or a depth unit drawn with some of its stages. */
typedef struct program {
    const char *hash;          /* its name in the pack */
    const char *name;          /* shown in messages: the permutation hash or the depth unit's name */
    const char *input_key;     /* the pack entry's input key must be this */
    bool has_frag;
    const char *entry[2];      /* entry points of vert and frag */
    block_ref blocks[MAX_BLOCKS];
    int nblocks;
    texture_ref textures[MAX_TEXTURES];
    int ntextures;
    vertex_input inputs[MAX_INPUTS];
    int ninputs;
    const cJSON *json;         /* the manifest entry */
} program;

/* An object of the manifest and what it draws with. */
typedef struct mobject {
    const char *name, *material, *light_set, *permutation;
    int perm;                  /* index into manifest.perms */
    const cJSON *upload;       /* the permutation's uploads[] entry of (material, light_set) */
    const cJSON *light_names;  /* light_sets[light_set]: light i of the set is item i */
} mobject;

typedef struct manifest {
    cJSON *root;
    char *dir;                 /* the build folder: every path in the manifest is relative to it */
    char *file;                /* dir/manifest.json, for messages */
    json_src src;
    const cJSON *conv;         /* conventions.platforms.vulkan */
    const cJSON *materials, *lights, *light_sets, *samplers, *depth_shaders, *tables;
    const cJSON *dynamic_light_sets;  /* optional: per dynamic light set, its pairs' buffers (how to fill them) */
    const char *pack_path, *pack_sha256, *pack_key;
    program *perms;
    int nperms;
    mobject *objects;
    int nobjects;
} manifest;

typedef struct mesh_attr {
    const char *name;
    uint32_t offset, stride;
    const char *format_name;
} mesh_attr;

typedef struct mesh {
    char *path;
    unsigned char *bytes;      /* the whole .bin: attribute arrays, then the uint32 indices */
    size_t size;
    uint32_t vertex_count, index_count, index_offset;
    mesh_attr attrs[MAX_ATTRIBUTES];
    int nattrs;
} mesh;

typedef struct fobject {
    const char *name;
    int mesh;
    double model[16];          /* column-major, as the Object block stores it */
    bool mirrored;             /* negative determinant (its mesh's winding is already reversed) */
} fobject;

typedef struct flight {
    const char *name;
    double shadow_matrix[16];  /* column-major: world to the light's clip space */
    int nfaces;                /* 6 for a point light's faces (face_matrices), else 0 */
    double faces[6][16];       /* face k's matrix, drawn into layer k of its map */
    bool has_texel;
    double pcf_texel;
    int size[2];
    double eye[3];
    const cJSON *casters;      /* the objects drawn into its map (indices, checked), or NULL: every object */
} flight;

typedef struct frame {
    cJSON *root;
    char *file;
    json_src src;
    int width, height;
    const char *color_attachment;
    float clear_color[4];
    float clear_depth;
    double eye[3];
    double view_proj[16];      /* column-major */
    mesh *meshes;
    int nmeshes;
    fobject *objects;
    int nobjects;
    int *draw_order;
    int ndraw;
    flight *lights;
    int nlights;
} frame;

bool manifest_load(const char *build_dir, manifest *m);
void manifest_free(manifest *m);
/* The program of a depth unit drawn with `stages` (a JSON array of stage names); false with a message. */
bool depth_program(const manifest *m, const char *unit, const cJSON *stages, program *out);
/* Parses a manifest entry shaped as a permutation (its `interface`, `hash`, `input_key`) with or without
 * its fragment stage. */
bool program_parse(const manifest *m, const cJSON *entry, const char *name, bool frag, program *out);
const block_ref *program_block(const program *p, const char *name);

bool frame_load(const char *frame_dir, const manifest *m, frame *f);
void frame_free(frame *f);
const flight *frame_light(const frame *f, const char *name);

#endif
