/* See vk_device.h. */
#include "vk_device.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "util.h"

#define LAYER "VK_LAYER_KHRONOS_validation"

static const char *result_name(VkResult r)
{
    switch (r) {
    case VK_SUCCESS: return "VK_SUCCESS";
    case VK_ERROR_OUT_OF_HOST_MEMORY: return "VK_ERROR_OUT_OF_HOST_MEMORY";
    case VK_ERROR_OUT_OF_DEVICE_MEMORY: return "VK_ERROR_OUT_OF_DEVICE_MEMORY";
    case VK_ERROR_INITIALIZATION_FAILED: return "VK_ERROR_INITIALIZATION_FAILED";
    case VK_ERROR_DEVICE_LOST: return "VK_ERROR_DEVICE_LOST";
    case VK_ERROR_LAYER_NOT_PRESENT: return "VK_ERROR_LAYER_NOT_PRESENT";
    case VK_ERROR_EXTENSION_NOT_PRESENT: return "VK_ERROR_EXTENSION_NOT_PRESENT";
    case VK_ERROR_FEATURE_NOT_PRESENT: return "VK_ERROR_FEATURE_NOT_PRESENT";
    case VK_ERROR_INCOMPATIBLE_DRIVER: return "VK_ERROR_INCOMPATIBLE_DRIVER";
    case VK_ERROR_FORMAT_NOT_SUPPORTED: return "VK_ERROR_FORMAT_NOT_SUPPORTED";
    case VK_ERROR_INVALID_SHADER_NV: return "VK_ERROR_INVALID_SHADER_NV";
    default: return "another VkResult";
    }
}

bool vk_failed(const char *what, VkResult r)
{
    return fail("%s: VkResult %d (%s)", what, (int)r, result_name(r));
}

/* Every warning and error the layer reports, of every type, is printed and counted; the run then fails. */
static VKAPI_ATTR VkBool32 VKAPI_CALL on_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                 VkDebugUtilsMessageTypeFlagsEXT types,
                                                 const VkDebugUtilsMessengerCallbackDataEXT *data, void *user)
{
    gpu *g = user;
    const char *level = severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT ? "error" : "warning";
    const char *kind = types & VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT ? "validation"
                     : types & VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT ? "performance" : "general";
    fprintf(stderr, "engine-c: validation layer (%s, %s): %s\n", level, kind,
            data && data->pMessage ? data->pMessage : "(no message)");
    if (g)
        g->messages++;
    return VK_FALSE;  /* the call goes on, as the specification requires of a messenger */
}

static VkDebugUtilsMessengerCreateInfoEXT messenger_info(gpu *g)
{
    VkDebugUtilsMessengerCreateInfoEXT info = {.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    info.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT
                     | VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    info.pfnUserCallback = on_message;
    info.pUserData = g;
    return info;
}

static bool has_layer(void)
{
    uint32_t n = 0;
    if (vkEnumerateInstanceLayerProperties(&n, NULL) != VK_SUCCESS)
        return false;
    VkLayerProperties *layers = calloc(n + 1, sizeof *layers);
    bool found = false;
    if (layers && vkEnumerateInstanceLayerProperties(&n, layers) == VK_SUCCESS)
        for (uint32_t i = 0; i < n; i++)
            found |= strcmp(layers[i].layerName, LAYER) == 0;
    free(layers);
    return found;
}

static bool create_instance(gpu *g)
{
    if (!has_layer())
        return fail("the Vulkan loader lists no " LAYER " — install vulkan-validationlayers (`make setup`): "
                    "this engine runs with it on");
    VkApplicationInfo app = {.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.pApplicationName = "engine-c";
    app.pEngineName = "engine-c";
    app.apiVersion = VK_API_VERSION_1_1;  /* the packs' SPIR-V is 1.3: Vulkan 1.1 */
    const char *layers[] = {LAYER};
    const char *extensions[] = {VK_EXT_DEBUG_UTILS_EXTENSION_NAME};
    /* The same messenger in pNext catches what vkCreateInstance and vkDestroyInstance themselves report. */
    VkDebugUtilsMessengerCreateInfoEXT debug = messenger_info(g);
    VkInstanceCreateInfo info = {.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    info.pNext = &debug;
    info.pApplicationInfo = &app;
    info.enabledLayerCount = 1;
    info.ppEnabledLayerNames = layers;
    info.enabledExtensionCount = 1;
    info.ppEnabledExtensionNames = extensions;
    VkResult r = vkCreateInstance(&info, NULL, &g->instance);
    if (r != VK_SUCCESS)
        return vk_failed("vkCreateInstance (install mesa-vulkan-drivers for lavapipe: `make setup`)", r);
    PFN_vkCreateDebugUtilsMessengerEXT create =
        (PFN_vkCreateDebugUtilsMessengerEXT)vkGetInstanceProcAddr(g->instance, "vkCreateDebugUtilsMessengerEXT");
    if (!create)
        return fail("vkCreateDebugUtilsMessengerEXT is missing although " VK_EXT_DEBUG_UTILS_EXTENSION_NAME
                    " is enabled — reinstall vulkan-validationlayers");
    r = create(g->instance, &debug, NULL, &g->messenger);
    return r == VK_SUCCESS || vk_failed("vkCreateDebugUtilsMessengerEXT", r);
}

static bool pick_device(gpu *g, const char *wanted)
{
    uint32_t n = 0;
    VkResult r = vkEnumeratePhysicalDevices(g->instance, &n, NULL);
    if (r != VK_SUCCESS)
        return vk_failed("vkEnumeratePhysicalDevices", r);
    VkPhysicalDevice *all = calloc(n + 1, sizeof *all);
    if (!all)
        return fail("out of memory");
    vkEnumeratePhysicalDevices(g->instance, &n, all);
    char found[1024] = "";
    for (uint32_t i = 0; i < n && !g->physical; i++) {
        VkPhysicalDeviceProperties p;
        vkGetPhysicalDeviceProperties(all[i], &p);
        size_t len = strlen(found);
        snprintf(found + len, sizeof found - len, "%s%s", len ? ", " : "", p.deviceName);
        bool match = wanted ? strstr(p.deviceName, wanted) != NULL : p.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
        if (match) {
            g->physical = all[i];
            g->props = p;
        }
    }
    free(all);
    if (!g->physical)
        return fail("no Vulkan device %s%s%s (found: %s) — %s", wanted ? "named like '" : "of type CPU (lavapipe)",
                    wanted ? wanted : "", wanted ? "'" : "", found[0] ? found : "none",
                    wanted ? "give --device a part of one of those names" : "install mesa-vulkan-drivers, or name "
                    "another with --device");
    if (VK_API_VERSION_MINOR(g->props.apiVersion) < 1 && VK_API_VERSION_MAJOR(g->props.apiVersion) == 1)
        return fail("%s supports Vulkan %u.%u; the packs' SPIR-V 1.3 needs 1.1", g->props.deviceName,
                    VK_API_VERSION_MAJOR(g->props.apiVersion), VK_API_VERSION_MINOR(g->props.apiVersion));
    vkGetPhysicalDeviceMemoryProperties(g->physical, &g->memory);
    return true;
}

static bool create_device(gpu *g)
{
    uint32_t n = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(g->physical, &n, NULL);
    VkQueueFamilyProperties *families = calloc(n + 1, sizeof *families);
    if (!families)
        return fail("out of memory");
    vkGetPhysicalDeviceQueueFamilyProperties(g->physical, &n, families);
    g->family = UINT32_MAX;
    for (uint32_t i = 0; i < n && g->family == UINT32_MAX; i++)
        if (families[i].queueFlags & VK_QUEUE_GRAPHICS_BIT)
            g->family = i;
    free(families);
    if (g->family == UINT32_MAX)
        return fail("%s has no graphics queue", g->props.deviceName);
    float priority = 1.0f;
    VkDeviceQueueCreateInfo queue = {.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    queue.queueFamilyIndex = g->family;
    queue.queueCount = 1;
    queue.pQueuePriorities = &priority;
    /* Anisotropic filtering is optional: enabled where the device has it, since a sampler row may ask for it
     * (and is clamped to 1 where it does not, as the renderer does). */
    VkPhysicalDeviceFeatures have, want = {0};
    vkGetPhysicalDeviceFeatures(g->physical, &have);
    want.samplerAnisotropy = have.samplerAnisotropy;
    g->anisotropy = have.samplerAnisotropy == VK_TRUE;
    VkDeviceCreateInfo info = {.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    info.queueCreateInfoCount = 1;
    info.pQueueCreateInfos = &queue;
    info.pEnabledFeatures = &want;
    VkResult r = vkCreateDevice(g->physical, &info, NULL, &g->device);
    if (r != VK_SUCCESS)
        return vk_failed("vkCreateDevice", r);
    vkGetDeviceQueue(g->device, g->family, 0, &g->queue);
    VkCommandPoolCreateInfo pool = {.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pool.queueFamilyIndex = g->family;
    pool.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    if ((r = vkCreateCommandPool(g->device, &pool, NULL, &g->pool)) != VK_SUCCESS)
        return vk_failed("vkCreateCommandPool", r);
    VkCommandBufferAllocateInfo alloc = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    alloc.commandPool = g->pool;
    alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    alloc.commandBufferCount = 1;
    if ((r = vkAllocateCommandBuffers(g->device, &alloc, &g->cmd)) != VK_SUCCESS)
        return vk_failed("vkAllocateCommandBuffers", r);
    VkFenceCreateInfo fence = {.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    if ((r = vkCreateFence(g->device, &fence, NULL, &g->fence)) != VK_SUCCESS)
        return vk_failed("vkCreateFence", r);
    return true;
}

bool gpu_open(gpu *g, const char *device_name)
{
    memset(g, 0, sizeof *g);
    return create_instance(g) && pick_device(g, device_name) && create_device(g);
}

static void destroy_owned(gpu *g, const owned *o)
{
    VkDevice d = g->device;
    switch (o->kind) {
    case OWN_BUFFER: vkDestroyBuffer(d, o->u.buffer, NULL); break;
    case OWN_MEMORY: vkFreeMemory(d, o->u.memory, NULL); break;
    case OWN_IMAGE: vkDestroyImage(d, o->u.image, NULL); break;
    case OWN_VIEW: vkDestroyImageView(d, o->u.view, NULL); break;
    case OWN_SAMPLER: vkDestroySampler(d, o->u.sampler, NULL); break;
    case OWN_SET_LAYOUT: vkDestroyDescriptorSetLayout(d, o->u.set_layout, NULL); break;
    case OWN_PIPELINE_LAYOUT: vkDestroyPipelineLayout(d, o->u.pipeline_layout, NULL); break;
    case OWN_PIPELINE: vkDestroyPipeline(d, o->u.pipeline, NULL); break;
    case OWN_RENDER_PASS: vkDestroyRenderPass(d, o->u.render_pass, NULL); break;
    case OWN_FRAMEBUFFER: vkDestroyFramebuffer(d, o->u.framebuffer, NULL); break;
    case OWN_DESCRIPTOR_POOL: vkDestroyDescriptorPool(d, o->u.descriptor_pool, NULL); break;
    }
}

void gpu_close(gpu *g)
{
    if (g->device) {
        vkDeviceWaitIdle(g->device);  /* nothing in flight is destroyed (a failed run may stop mid-frame) */
        for (int i = g->nown - 1; i >= 0; i--)
            destroy_owned(g, &g->own[i]);
        if (g->fence)
            vkDestroyFence(g->device, g->fence, NULL);
        if (g->pool)
            vkDestroyCommandPool(g->device, g->pool, NULL);
        vkDestroyDevice(g->device, NULL);
    }
    free(g->own);
    if (g->messenger) {
        PFN_vkDestroyDebugUtilsMessengerEXT destroy =
            (PFN_vkDestroyDebugUtilsMessengerEXT)vkGetInstanceProcAddr(g->instance, "vkDestroyDebugUtilsMessengerEXT");
        if (destroy)
            destroy(g->instance, g->messenger, NULL);
    }
    if (g->instance)
        vkDestroyInstance(g->instance, NULL);
    int messages = g->messages;
    memset(g, 0, sizeof *g);
    g->messages = messages;
}

bool gpu_own(gpu *g, owned o)
{
    if (g->nown == g->capown) {
        int cap = g->capown ? 2 * g->capown : 64;
        owned *more = realloc(g->own, (size_t)cap * sizeof *more);
        if (!more) {
            destroy_owned(g, &o);  /* not kept: released now */
            return fail("out of memory");
        }
        g->own = more;
        g->capown = cap;
    }
    g->own[g->nown++] = o;
    return true;
}

/* The first memory type allowed by `bits` that has every flag of `want`; UINT32_MAX if none. */
static uint32_t memory_type(const gpu *g, uint32_t bits, VkMemoryPropertyFlags want)
{
    for (uint32_t i = 0; i < g->memory.memoryTypeCount; i++)
        if (bits & (1u << i) && (g->memory.memoryTypes[i].propertyFlags & want) == want)
            return i;
    return UINT32_MAX;
}

static bool allocate(gpu *g, VkMemoryRequirements req, VkMemoryPropertyFlags want, VkDeviceMemory *out)
{
    uint32_t type = memory_type(g, req.memoryTypeBits, want);
    if (type == UINT32_MAX && !(want & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT))
        type = memory_type(g, req.memoryTypeBits, 0);  /* device-local preferred, any will do */
    if (type == UINT32_MAX)
        return fail("%s has no memory type with properties 0x%x for this resource", g->props.deviceName, want);
    VkMemoryAllocateInfo info = {.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    info.allocationSize = req.size;
    info.memoryTypeIndex = type;
    VkResult r = vkAllocateMemory(g->device, &info, NULL, out);
    if (r != VK_SUCCESS)
        return vk_failed("vkAllocateMemory", r);
    return gpu_own(g, (owned){.kind = OWN_MEMORY, .u.memory = *out});
}

bool gpu_buffer_new(gpu *g, VkDeviceSize size, VkBufferUsageFlags usage, const void *data, gpu_buffer *out)
{
    memset(out, 0, sizeof *out);
    VkBufferCreateInfo info = {.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    info.size = size;
    info.usage = usage;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    VkResult r = vkCreateBuffer(g->device, &info, NULL, &out->buffer);
    if (r != VK_SUCCESS)
        return vk_failed("vkCreateBuffer", r);
    /* memory first in the list, so that the reverse-order tear-down destroys the buffer before freeing it */
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(g->device, out->buffer, &req);
    if (!allocate(g, req, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT, &out->memory)) {
        vkDestroyBuffer(g->device, out->buffer, NULL);
        return false;
    }
    if (!gpu_own(g, (owned){.kind = OWN_BUFFER, .u.buffer = out->buffer}))
        return false;
    if ((r = vkBindBufferMemory(g->device, out->buffer, out->memory, 0)) != VK_SUCCESS)
        return vk_failed("vkBindBufferMemory", r);
    if ((r = vkMapMemory(g->device, out->memory, 0, VK_WHOLE_SIZE, 0, &out->mapped)) != VK_SUCCESS)
        return vk_failed("vkMapMemory", r);
    out->size = size;
    if (data)
        memcpy(out->mapped, data, (size_t)size);
    else
        memset(out->mapped, 0, (size_t)size);
    return true;
}

static bool image_new(gpu *g, VkFormat format, uint32_t width, uint32_t height, uint32_t levels, uint32_t layers,
                      VkImageViewType type, VkImageUsageFlags usage, VkImageAspectFlags aspect, gpu_image *out);

bool gpu_image_new(gpu *g, VkFormat format, uint32_t width, uint32_t height, uint32_t levels, VkImageUsageFlags usage,
                   VkImageAspectFlags aspect, gpu_image *out)
{
    return image_new(g, format, width, height, levels, 1, VK_IMAGE_VIEW_TYPE_2D, usage, aspect, out);
}

bool gpu_image_array_new(gpu *g, VkFormat format, uint32_t width, uint32_t height, uint32_t layers,
                         VkImageUsageFlags usage, VkImageAspectFlags aspect, gpu_image *out)
{
    return image_new(g, format, width, height, 1, layers, VK_IMAGE_VIEW_TYPE_2D_ARRAY, usage, aspect, out);
}

static bool image_new(gpu *g, VkFormat format, uint32_t width, uint32_t height, uint32_t levels, uint32_t layers,
                      VkImageViewType type, VkImageUsageFlags usage, VkImageAspectFlags aspect, gpu_image *out)
{
    memset(out, 0, sizeof *out);
    VkImageCreateInfo info = {.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    info.imageType = VK_IMAGE_TYPE_2D;
    info.format = format;
    info.extent = (VkExtent3D){width, height, 1};
    info.mipLevels = levels;
    info.arrayLayers = layers;
    info.samples = VK_SAMPLE_COUNT_1_BIT;
    info.tiling = VK_IMAGE_TILING_OPTIMAL;
    info.usage = usage;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    VkResult r = vkCreateImage(g->device, &info, NULL, &out->image);
    if (r != VK_SUCCESS)
        return vk_failed("vkCreateImage", r);
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(g->device, out->image, &req);
    if (!allocate(g, req, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, &out->memory)) {
        vkDestroyImage(g->device, out->image, NULL);
        return false;
    }
    if (!gpu_own(g, (owned){.kind = OWN_IMAGE, .u.image = out->image}))
        return false;
    if ((r = vkBindImageMemory(g->device, out->image, out->memory, 0)) != VK_SUCCESS)
        return vk_failed("vkBindImageMemory", r);
    VkImageViewCreateInfo view = {.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    view.image = out->image;
    view.viewType = type;
    view.format = format;
    view.subresourceRange = (VkImageSubresourceRange){aspect, 0, levels, 0, layers};
    if ((r = vkCreateImageView(g->device, &view, NULL, &out->view)) != VK_SUCCESS)
        return vk_failed("vkCreateImageView", r);
    out->format = format;
    out->width = width;
    out->height = height;
    out->levels = levels;
    return gpu_own(g, (owned){.kind = OWN_VIEW, .u.view = out->view});
}

bool gpu_format_has(gpu *g, VkFormat format, VkFormatFeatureFlags need)
{
    VkFormatProperties p;
    vkGetPhysicalDeviceFormatProperties(g->physical, format, &p);
    return (p.optimalTilingFeatures & need) == need;
}

bool gpu_begin(gpu *g)
{
    VkCommandBufferBeginInfo begin = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    VkResult r = vkBeginCommandBuffer(g->cmd, &begin);
    return r == VK_SUCCESS || vk_failed("vkBeginCommandBuffer", r);
}

bool gpu_submit_wait(gpu *g)
{
    VkResult r = vkEndCommandBuffer(g->cmd);
    if (r != VK_SUCCESS)
        return vk_failed("vkEndCommandBuffer", r);
    VkSubmitInfo submit = {.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &g->cmd;
    if ((r = vkQueueSubmit(g->queue, 1, &submit, g->fence)) != VK_SUCCESS)
        return vk_failed("vkQueueSubmit", r);
    if ((r = vkWaitForFences(g->device, 1, &g->fence, VK_TRUE, UINT64_MAX)) != VK_SUCCESS)
        return vk_failed("vkWaitForFences", r);
    return true;
}
