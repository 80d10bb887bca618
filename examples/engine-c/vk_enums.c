/* See vk_enums.h. Only the names a format-1 manifest can write are listed; extend the table with the
 * manifest (a test renders every scene `render` draws, so a missing name shows up as a failing test). */
#include "vk_enums.h"

#include <ctype.h>
#include <stdio.h>
#include <string.h>

#define E(x) {#x, (int32_t)x}

static const struct {
    const char *name;
    int32_t value;
} TABLE[] = {
    E(VK_FILTER_NEAREST), E(VK_FILTER_LINEAR),
    E(VK_SAMPLER_MIPMAP_MODE_NEAREST), E(VK_SAMPLER_MIPMAP_MODE_LINEAR),
    E(VK_SAMPLER_ADDRESS_MODE_REPEAT), E(VK_SAMPLER_ADDRESS_MODE_MIRRORED_REPEAT),
    E(VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE), E(VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER),
    E(VK_SAMPLER_ADDRESS_MODE_MIRROR_CLAMP_TO_EDGE),
    E(VK_COMPARE_OP_NEVER), E(VK_COMPARE_OP_LESS), E(VK_COMPARE_OP_EQUAL), E(VK_COMPARE_OP_LESS_OR_EQUAL),
    E(VK_COMPARE_OP_GREATER), E(VK_COMPARE_OP_NOT_EQUAL), E(VK_COMPARE_OP_GREATER_OR_EQUAL),
    E(VK_COMPARE_OP_ALWAYS),
    E(VK_FRONT_FACE_COUNTER_CLOCKWISE), E(VK_FRONT_FACE_CLOCKWISE),
    E(VK_CULL_MODE_NONE), E(VK_CULL_MODE_FRONT_BIT), E(VK_CULL_MODE_BACK_BIT), E(VK_CULL_MODE_FRONT_AND_BACK),
    E(VK_BLEND_FACTOR_ZERO), E(VK_BLEND_FACTOR_ONE), E(VK_BLEND_FACTOR_SRC_COLOR),
    E(VK_BLEND_FACTOR_ONE_MINUS_SRC_COLOR), E(VK_BLEND_FACTOR_DST_COLOR), E(VK_BLEND_FACTOR_ONE_MINUS_DST_COLOR),
    E(VK_BLEND_FACTOR_SRC_ALPHA), E(VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA), E(VK_BLEND_FACTOR_DST_ALPHA),
    E(VK_BLEND_FACTOR_ONE_MINUS_DST_ALPHA),
    E(VK_BLEND_OP_ADD), E(VK_BLEND_OP_SUBTRACT), E(VK_BLEND_OP_REVERSE_SUBTRACT), E(VK_BLEND_OP_MIN),
    E(VK_BLEND_OP_MAX),
    E(VK_FORMAT_R8G8B8A8_UNORM), E(VK_FORMAT_R8G8B8A8_SRGB), E(VK_FORMAT_R16G16B16A16_SFLOAT),
    E(VK_FORMAT_R32G32B32A32_SFLOAT), E(VK_FORMAT_D32_SFLOAT), E(VK_FORMAT_R32_SFLOAT),
    E(VK_FORMAT_R32G32_SFLOAT), E(VK_FORMAT_R32G32B32_SFLOAT),
};

bool vk_enum(const char *family, const char *name, int32_t *out)
{
    if (!name || strncmp(name, family, strlen(family)) != 0)
        return false;
    for (size_t i = 0; i < sizeof TABLE / sizeof TABLE[0]; i++)
        if (strcmp(TABLE[i].name, name) == 0) {
            *out = TABLE[i].value;
            return true;
        }
    return false;
}

bool vk_enum_lower(const char *family, const char *lower, int32_t *out)
{
    char name[96];
    size_t n = strlen(family);
    if (!lower || n + strlen(lower) + 1 > sizeof name)
        return false;
    memcpy(name, family, n);
    for (size_t i = 0; lower[i]; i++)
        name[n++] = (char)toupper((unsigned char)lower[i]);
    name[n] = 0;
    return vk_enum(family, name, out);
}

static const struct {
    const char *name;
    uint32_t bytes;
} SIZES[] = {
    {"R32_SFLOAT", 4}, {"R32G32_SFLOAT", 8}, {"R32G32B32_SFLOAT", 12}, {"R32G32B32A32_SFLOAT", 16},
    {"R8G8B8A8_UNORM", 4}, {"R8G8B8A8_SRGB", 4}, {"R16G16B16A16_SFLOAT", 8}, {"D32_SFLOAT", 4},
};

bool vk_format(const char *name, VkFormat *out, uint32_t *bytes)
{
    char full[64];
    int32_t v;
    if (!name)
        return false;
    snprintf(full, sizeof full, "VK_FORMAT_%s", name);
    if (!vk_enum("VK_FORMAT_", full, &v))
        return false;
    *out = (VkFormat)v;
    *bytes = 0;
    for (size_t i = 0; i < sizeof SIZES / sizeof SIZES[0]; i++)
        if (strcmp(SIZES[i].name, name) == 0)
            *bytes = SIZES[i].bytes;
    return true;
}
