/* See ktx2.h. Every offset and length is checked before it is used, in 64-bit arithmetic that cannot wrap:
 * a cut or edited file is a message, never a read outside it. */
#include "ktx2.h"

#include <string.h>

#include "util.h"

static const unsigned char IDENTIFIER[12] = {0xAB, 'K', 'T', 'X', ' ', '2', '0', 0xBB, '\r', '\n', 0x1A, '\n'};

static uint32_t u32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static uint64_t u64(const unsigned char *p)
{
    return (uint64_t)u32(p) | (uint64_t)u32(p + 4) << 32;
}

static const struct {
    uint32_t vk;
    const char *name;
    uint32_t type_size, texel_bytes;
} FORMATS[] = {
    {37, "R8G8B8A8_UNORM", 1, 4},
    {43, "R8G8B8A8_SRGB", 1, 4},
    {97, "R16G16B16A16_SFLOAT", 2, 8},
    {109, "R32G32B32A32_SFLOAT", 4, 16},
};

#define HINT "rebuild the scene (`shadermatrix build`): the build writes uncompressed RGBA KTX2"

bool ktx2_parse(const unsigned char *data, size_t size, const char *shown, ktx2_image *out)
{
    memset(out, 0, sizeof *out);
    if (size < 80)
        return fail("%s: %zu bytes, shorter than the 80-byte KTX2 header and index — %s", shown, size, HINT);
    if (memcmp(data, IDENTIFIER, sizeof IDENTIFIER) != 0)
        return fail("%s: not a KTX 2.0 file (wrong identifier) — %s", shown, HINT);
    uint32_t vk_format = u32(data + 12), type_size = u32(data + 16), width = u32(data + 20),
             height = u32(data + 24), depth = u32(data + 28), layers = u32(data + 32), faces = u32(data + 36),
             levels = u32(data + 40), scheme = u32(data + 44);
    int f = -1;
    for (int i = 0; i < (int)(sizeof FORMATS / sizeof FORMATS[0]); i++)
        if (FORMATS[i].vk == vk_format)
            f = i;
    if (f < 0)
        return fail("%s: vkFormat %u is not one this engine reads (R8G8B8A8_UNORM, R8G8B8A8_SRGB, "
                    "R16G16B16A16_SFLOAT, R32G32B32A32_SFLOAT) — %s", shown, vk_format, HINT);
    if (type_size != FORMATS[f].type_size)
        return fail("%s: typeSize %u, not %u as %s requires — %s", shown, type_size, FORMATS[f].type_size,
                    FORMATS[f].name, HINT);
    if (scheme != 0)
        return fail("%s: supercompressionScheme %u; this engine reads uncompressed files — %s", shown, scheme, HINT);
    if (width > KTX2_MAX_SIDE || height > KTX2_MAX_SIDE)  /* so that W x H x 16 bytes cannot wrap below */
        return fail("%s: %u x %u texels; this engine reads images of at most %u a side — %s", shown, width, height,
                    KTX2_MAX_SIDE, HINT);
    if (width == 0 || height == 0 || depth != 0 || layers != 0 || faces != 1)
        return fail("%s: %u x %u, depth %u, %u layers, %u faces: this engine reads one 2D image (no arrays, no "
                    "cube maps, not 1D) — %s", shown, width, height, depth, layers, faces, HINT);
    uint32_t full = 0;
    for (uint32_t m = width > height ? width : height; m; m >>= 1)
        full++;
    if (levels == 0 || levels > full || levels > KTX2_MAX_LEVELS)
        return fail("%s: levelCount %u; a %u x %u image has 1 to %u levels stored — %s", shown, levels, width,
                    height, full, HINT);
    if ((uint64_t)size < 80 + 24 * (uint64_t)levels)
        return fail("%s: %zu bytes end inside the level index — %s", shown, size, HINT);
    out->vk_format = vk_format;
    out->format = FORMATS[f].name;
    out->width = width;
    out->height = height;
    out->levels = levels;
    out->texel_bytes = FORMATS[f].texel_bytes;
    for (uint32_t i = 0; i < levels; i++) {
        const unsigned char *e = data + 80 + 24 * (size_t)i;
        uint64_t offset = u64(e), length = u64(e + 8), raw = u64(e + 16);
        uint64_t w = width >> i ? width >> i : 1, h = height >> i ? height >> i : 1;
        uint64_t want = w * h * FORMATS[f].texel_bytes;
        if (length != want || raw != want)
            return fail("%s: level %u is %llu bytes (%llu uncompressed), not the %llu of %llu x %llu texels — %s",
                        shown, i, (unsigned long long)length, (unsigned long long)raw, (unsigned long long)want,
                        (unsigned long long)w, (unsigned long long)h, HINT);
        if (offset > (uint64_t)size || length > (uint64_t)size - offset)
            return fail("%s: level %u (byte %llu, %llu bytes) runs past the end of the %zu-byte file — %s", shown,
                        i, (unsigned long long)offset, (unsigned long long)length, size, HINT);
        if (offset < 80 + 24 * (uint64_t)levels)
            return fail("%s: level %u starts at byte %llu, inside the header — %s", shown, i,
                        (unsigned long long)offset, HINT);
        out->level_data[i] = data + offset;
        out->level_bytes[i] = (size_t)length;
    }
    return true;
}
