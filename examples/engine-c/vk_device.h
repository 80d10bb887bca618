/* The Vulkan device: instance with the Khronos validation layer and a debug messenger, the physical device
 * (lavapipe unless --device names another), one graphics queue, one command buffer, and every object the
 * engine creates, owned here and destroyed in reverse order of creation at gpu_close (so that the layer's
 * leak checks at vkDestroyDevice stay silent). */
#ifndef ENGINE_VK_DEVICE_H
#define ENGINE_VK_DEVICE_H

#include <stdbool.h>
#include <stdint.h>

#include <vulkan/vulkan.h>

typedef enum own_kind {
    OWN_BUFFER, OWN_MEMORY, OWN_IMAGE, OWN_VIEW, OWN_SAMPLER, OWN_SET_LAYOUT, OWN_PIPELINE_LAYOUT, OWN_PIPELINE,
    OWN_RENDER_PASS, OWN_FRAMEBUFFER, OWN_DESCRIPTOR_POOL
} own_kind;

typedef struct owned {
    own_kind kind;
    union {
        VkBuffer buffer;
        VkDeviceMemory memory;
        VkImage image;
        VkImageView view;
        VkSampler sampler;
        VkDescriptorSetLayout set_layout;
        VkPipelineLayout pipeline_layout;
        VkPipeline pipeline;
        VkRenderPass render_pass;
        VkFramebuffer framebuffer;
        VkDescriptorPool descriptor_pool;
    } u;
} owned;

typedef struct gpu {
    VkInstance instance;
    VkDebugUtilsMessengerEXT messenger;
    VkPhysicalDevice physical;
    VkPhysicalDeviceProperties props;
    VkPhysicalDeviceMemoryProperties memory;
    VkDevice device;
    uint32_t family;
    VkQueue queue;
    VkCommandPool pool;
    VkCommandBuffer cmd;
    VkFence fence;
    bool anisotropy;            /* samplerAnisotropy enabled (the device has it) */
    int messages;               /* validation messages seen: any makes the run fail */
    owned *own;
    int nown, capown;
} gpu;

/* A buffer in host-visible, coherent memory, mapped for its whole life. */
typedef struct gpu_buffer {
    VkBuffer buffer;
    VkDeviceMemory memory;
    VkDeviceSize size;
    void *mapped;
} gpu_buffer;

typedef struct gpu_image {
    VkImage image;
    VkDeviceMemory memory;
    VkImageView view;
    VkFormat format;
    uint32_t width, height, levels;
} gpu_image;

/* `device_name`: a substring of the device to use, or NULL for the first CPU device (lavapipe). */
bool gpu_open(gpu *g, const char *device_name);
void gpu_close(gpu *g);

bool gpu_own(gpu *g, owned o);
bool gpu_buffer_new(gpu *g, VkDeviceSize size, VkBufferUsageFlags usage, const void *data, gpu_buffer *out);
/* A 2D image of `levels` levels with a view of `aspect`; optimal tiling, device memory. */
bool gpu_image_new(gpu *g, VkFormat format, uint32_t width, uint32_t height, uint32_t levels, VkImageUsageFlags usage,
                   VkImageAspectFlags aspect, gpu_image *out);
/* One level of `layers` layers, viewed as a 2D array (a point light's six shadow faces). */
bool gpu_image_array_new(gpu *g, VkFormat format, uint32_t width, uint32_t height, uint32_t layers,
                         VkImageUsageFlags usage, VkImageAspectFlags aspect, gpu_image *out);
/* Whether the device's optimal tiling has every bit of `need` for `format`. */
bool gpu_format_has(gpu *g, VkFormat format, VkFormatFeatureFlags need);
/* Starts recording into the one command buffer; gpu_submit_wait submits it and waits for the fence. */
bool gpu_begin(gpu *g);
bool gpu_submit_wait(gpu *g);
/* A message for a failed call: `engine-c: WHAT: VkResult N (NAME)`; returns false. */
bool vk_failed(const char *what, VkResult r);

#endif
