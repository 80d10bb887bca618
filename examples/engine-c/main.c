/* engine-c: renders one frame of a scene from a build's outputs and a frame export alone, on Vulkan with the
 * validation layer on, and writes it as a PNG. See README.md for what it reads and how each field maps.
 *
 *   engine-c [--device NAME] BUILD_DIR FRAME_DIR OUT.png
 *
 * Exit status: 0 drawn and written; 1 bad input or a Vulkan failure (a message says which); 2 bad usage;
 * 3 the validation layer reported something (each message is printed). OUT.png is written only on 0: a failed
 * run leaves no picture that could be taken for a good one. */
#include <shadermatrix/pack.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "png.h"
#include "render.h"
#include "scene.h"
#include "util.h"
#include "vk_device.h"

static const char USAGE[] =
    "usage: engine-c [--device NAME] BUILD_DIR FRAME_DIR OUT.png\n"
    "  BUILD_DIR  a `shadermatrix build --platform vulkan --pack` output folder (manifest.json)\n"
    "  FRAME_DIR  a `shadermatrix render --export` folder (frame.json and meshes/)\n"
    "  OUT.png    the frame, RGBA8\n"
    "  --device NAME  the Vulkan device whose name contains NAME (default: the first CPU device, lavapipe)\n";

/* The vulkan pack the manifest lists: its sha256 checked, then opened by pack.h (which checks every blob's
 * hash and the pack key), and its metadata checked to hold SPIR-V for Vulkan. */
static bool open_pack(const manifest *m, unsigned char **bytes, smpack *pack)
{
    char *path = path_join(m->dir, m->pack_path);
    size_t size = 0;
    *bytes = path ? read_file(path, &size) : NULL;
    bool ok = *bytes && check_sha256(path, *bytes, size, m->pack_sha256);
    if (ok) {
        smpack_status s = smpack_open_memory(pack, *bytes, size);
        if (s != SMPACK_OK)
            ok = fail("%s: %s: %s — build again with `--pack`", path, smpack_status_name(s), smpack_error(pack));
    }
    if (ok) {
        char key[65];
        for (int i = 0; i < 32; i++)
            snprintf(key + 2 * i, 3, "%02x", pack->key[i]);
        if (strcmp(key, m->pack_key) != 0)
            ok = fail("%s: pack key %.16s…, the manifest's %.16s… — build again with `--pack`", path, key, m->pack_key);
    }
    if (ok) {
        size_t n = 0;
        const char *text = smpack_meta(pack, &n);
        cJSON *meta = cJSON_ParseWithLength(text, n);
        const cJSON *platform = j_opt(meta, "platform"), *blob = j_opt(meta, "blob");
        if (!cJSON_IsString(platform) || strcmp(platform->valuestring, "vulkan") != 0 || !cJSON_IsString(blob)
            || strcmp(blob->valuestring, "spirv") != 0)
            ok = fail("%s: its metadata says platform %s, blob %s; this engine loads the vulkan pack's SPIR-V", path,
                      cJSON_IsString(platform) ? platform->valuestring : "?", cJSON_IsString(blob) ? blob->valuestring : "?");
        cJSON_Delete(meta);
    }
    free(path);
    return ok;
}

int main(int argc, char **argv)
{
    const char *device = NULL, *args[3];
    int nargs = 0;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--device") == 0 && i + 1 < argc)
            device = argv[++i];
        else if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            fputs(USAGE, stdout);
            return 0;
        } else if (argv[i][0] == '-' || nargs == 3) {
            fprintf(stderr, "engine-c: unexpected argument '%s'\n%s", argv[i], USAGE);
            return 2;
        } else
            args[nargs++] = argv[i];
    }
    if (nargs != 3) {
        fputs(USAGE, stderr);
        return 2;
    }
    manifest m;
    frame f;
    smpack pack;
    gpu g;
    engine e;
    unsigned char *pack_bytes = NULL, *rgba = NULL;
    memset(&pack, 0, sizeof pack);
    memset(&g, 0, sizeof g);
    memset(&e, 0, sizeof e);
    memset(&f, 0, sizeof f);
    bool ok = manifest_load(args[0], &m) && frame_load(args[1], &m, &f) && open_pack(&m, &pack_bytes, &pack);
    if (ok && !(rgba = malloc(4 * (size_t)f.width * (size_t)f.height)))
        ok = fail("out of memory for a %dx%d frame", f.width, f.height);
    ok = ok && gpu_open(&g, device);
    if (ok) {
        e.g = &g;
        e.m = &m;
        e.f = &f;
        e.pack = &pack;
        ok = engine_render(&e, rgba);
    }
    gpu_close(&g);  /* before the PNG: whatever the layer says at tear-down (a leak) fails the run too */
    engine_free(&e);
    if (ok && !g.messages)
        ok = png_write_rgba(args[2], rgba, (uint32_t)f.width, (uint32_t)f.height);
    free(rgba);
    smpack_close(&pack);
    free(pack_bytes);
    frame_free(&f);
    manifest_free(&m);
    if (g.messages) {
        fprintf(stderr, "engine-c: the validation layer reported %d message(s) — the run fails\n", g.messages);
        return 3;
    }
    return ok ? 0 : 1;
}
