/* The Vulkan enum names the manifest spells as strings (sampler rows, conventions, render state), mapped to
 * their values. The manifest writes VkSamplerCreateInfo's members and the conventions' states by their C
 * names ("VK_FILTER_LINEAR"), and render_state's equations and depth test in lower case ("src_alpha",
 * "less"); both are looked up here, by family, so a name of another family is refused. A name the table does
 * not know is an error naming it: a newer manifest's state this engine does not implement yet. */
#ifndef ENGINE_VK_ENUMS_H
#define ENGINE_VK_ENUMS_H

#include <stdbool.h>
#include <stdint.h>

#include <vulkan/vulkan.h>

/* Looks `name` up among the enums whose names start with `family` ("VK_FILTER_", "VK_FORMAT_", …). */
bool vk_enum(const char *family, const char *name, int32_t *out);
/* Looks up family + upper-case(lower), e.g. ("VK_BLEND_FACTOR_", "src_alpha"). */
bool vk_enum_lower(const char *family, const char *lower, int32_t *out);

/* A vertex attribute or texel format name without VK_FORMAT_ ("R32G32B32_SFLOAT"): its value and its bytes
 * per element (0 where the table has no size for it). */
bool vk_format(const char *name, VkFormat *out, uint32_t *bytes);

#endif
