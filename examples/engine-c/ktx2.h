/* A reader of the KTX 2.0 files a build writes: uncompressed, one 2D image with its mip chain.
 *
 * What it takes (generator/io/ktx2.py writes exactly this; KTX 2.0 specification, "File Structure" and
 * "Level Index"): the 12-byte identifier, vkFormat R8G8B8A8_UNORM (37), R8G8B8A8_SRGB (43),
 * R16G16B16A16_SFLOAT (97) or R32G32B32A32_SFLOAT (109) with the matching typeSize, at most 65535 texels a side, pixelDepth 0,
 * layerCount 0, faceCount 1, supercompressionScheme 0, and a level index (byte 80, 24 bytes a level,
 * level 0 first) whose every entry lies inside the file and holds exactly max(1, W >> i) × max(1, H >> i)
 * texels. The data format descriptor and key/value data are not interpreted: the vkFormat says it all
 * for these four formats, and the manifest states the same format again, which the caller compares. */
#ifndef ENGINE_KTX2_H
#define ENGINE_KTX2_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define KTX2_MAX_LEVELS 16     /* the full chain of KTX2_MAX_SIDE */
#define KTX2_MAX_SIDE 65535u   /* texels a side; the build's images are at most 16384 */

typedef struct ktx2_image {
    uint32_t vk_format;   /* the VkFormat value */
    const char *format;   /* its name without VK_FORMAT_, as the manifest spells it */
    uint32_t width, height, levels;
    uint32_t texel_bytes; /* 4, 8 or 16 */
    const unsigned char *level_data[KTX2_MAX_LEVELS];  /* into the file's bytes, level 0 first */
    size_t level_bytes[KTX2_MAX_LEVELS];
} ktx2_image;

/* Parses `data` (the whole file); `shown` names it in messages. false with `engine-c: FILE: …` otherwise. */
bool ktx2_parse(const unsigned char *data, size_t size, const char *shown, ktx2_image *out);

#endif
