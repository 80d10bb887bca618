"""A Vulkan device on Mesa lavapipe: instance, validation messages, queue, memory, buffers, images, samplers.

A small layer over the `vulkan` PyPI binding (cffi), meant to grow from compute
to graphics: :class:`Device` owns the instance, the logical device, one queue
(graphics+compute when the family has both), a command pool and the list of
validation messages; :mod:`.compute` builds pipelines on top of it.

Textures: :class:`Image` is a sampled 2D or cube image (level 0 only) uploaded
from a NumPy array through a staging buffer; :class:`Sampler` is the one filter
the project uses, exactly the one the NumPy target reproduces
(generator/targets/numpy_resources.py): bilinear, clamp-to-edge, texel centres
at (i + 0.5) / W, level 0.

With ``validation=True`` the Khronos validation layer is enabled and a
VK_EXT_debug_utils messenger (also chained into instance creation, so messages
from vkCreateInstance/vkDestroyInstance are caught) appends every warning and
error to :attr:`Device.messages`. Tests assert that list stays empty.

Pitfalls of the binding (../shared/TOOLCHAIN.md) handled here: the binding keeps
ONE debug-utils callback per process (a module global), so the callback is
one module-level function that routes by ``pUserData`` to its device;
``vkMapMemory`` returns a cffi buffer, which numpy views without a copy.
"""
from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

VALIDATION_LAYER = "VK_LAYER_KHRONOS_validation"


class VulkanUnavailable(RuntimeError):
    """No usable Vulkan loader, lavapipe device or validation layer; the message says why and what to do."""


@dataclass(frozen=True)
class ValidationMessage:
    severity: str  # "warning" | "error"
    kind: str      # "general" | "validation" | "performance"
    id_name: str
    text: str

    def __str__(self) -> str:
        return f"[{self.severity}/{self.kind}] {self.id_name}: {self.text}"


def _vk():
    try:
        import vulkan as vk
    except Exception as exc:  # OSError without libvulkan; cffi errors otherwise
        raise VulkanUnavailable(f"Vulkan loader not usable: {exc} — install libvulkan1 (`make setup`)") from None
    return vk


_DEVICES: dict[int, "Device"] = {}  # id -> open device, for the one debug callback the binding allows


def _on_message(severity, types, data, user_data):
    vk = _vk()
    dev = _DEVICES.get(int(vk.ffi.cast("uintptr_t", user_data)))
    if dev is not None:
        sev = "error" if severity & vk.VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT else "warning"
        kind = ("validation" if types & vk.VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT else
                "performance" if types & vk.VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT else "general")
        name = vk.ffi.string(data.pMessageIdName).decode(errors="replace") if data.pMessageIdName else ""
        text = vk.ffi.string(data.pMessage).decode(errors="replace") if data.pMessage else ""
        dev.messages.append(ValidationMessage(sev, kind, name, text))
    return 0  # VK_FALSE: never abort the call


class Buffer:
    """A host-visible, coherent buffer, mapped for its whole life; `.array(dtype)` views it without a copy."""

    def __init__(self, device: "Device", size: int, usage: int):
        vk = device.vk
        self.device, self.size = device, int(size)
        self.handle = vk.vkCreateBuffer(device.handle, vk.VkBufferCreateInfo(
            size=self.size, usage=usage, sharingMode=vk.VK_SHARING_MODE_EXCLUSIVE), None)
        self.memory = None
        try:
            req = vk.vkGetBufferMemoryRequirements(device.handle, self.handle)
            self.memory = vk.vkAllocateMemory(device.handle, vk.VkMemoryAllocateInfo(
                allocationSize=req.size, memoryTypeIndex=device.host_memory_type(req.memoryTypeBits)), None)
            vk.vkBindBufferMemory(device.handle, self.handle, self.memory, 0)
            self._mapped = vk.vkMapMemory(device.handle, self.memory, 0, self.size, 0)
        except BaseException:  # out of memory, no host-visible type: free what was created
            vk.vkDestroyBuffer(device.handle, self.handle, None)
            if self.memory is not None:
                vk.vkFreeMemory(device.handle, self.memory, None)
            self.handle = self.memory = None
            raise

    def array(self, dtype=np.uint8) -> np.ndarray:
        """The mapped memory as a writable 1-D numpy array (a view: valid until destroy())."""
        return np.frombuffer(self._mapped, dtype=dtype)

    def write(self, data) -> None:
        raw = np.ascontiguousarray(data).view(np.uint8).reshape(-1)
        if raw.size > self.size:
            raise ValueError(f"{raw.size} bytes do not fit a buffer of {self.size}")
        self.array()[: raw.size] = raw

    def destroy(self) -> None:
        if self.handle is None:
            return
        vk, dev = self.device.vk, self.device.handle
        if self in self.device._owned:
            self.device._owned.remove(self)
        self._mapped = None
        vk.vkUnmapMemory(dev, self.memory)
        vk.vkDestroyBuffer(dev, self.handle, None)
        vk.vkFreeMemory(dev, self.memory, None)
        self.handle = None


# ------------------------------------------------------------------ images

_FORMAT_FEATURE_TRANSFER_DST = 0x00008000  # core in Vulkan 1.1; the binding has only a _KHR alias, = None


def _image_format(vk, dtype, srgb: bool):
    if dtype == np.float32:
        if srgb:
            raise ValueError("srgb=True needs uint8 texels (sRGB formats are 8-bit); float data is linear")
        return vk.VK_FORMAT_R32G32B32A32_SFLOAT
    if dtype == np.uint8:
        return vk.VK_FORMAT_R8G8B8A8_SRGB if srgb else vk.VK_FORMAT_R8G8B8A8_UNORM
    raise TypeError(f"texels must be float32 or uint8, got {dtype}")


def texels(data, cube: bool | None = None) -> tuple[np.ndarray, bool]:
    """(array, cube): `data` as a C-contiguous (layers, H, W, 4) float32 or uint8 array.

    (H, W, C) is a 2D texture, (6, H, W, C) a cube (faces +X, -X, +Y, -Y, +Z, -Z, as
    Vulkan orders layers of a cube view); C ≤ 4 channels, the missing ones filled as
    Vulkan expands formats with fewer components (0, alpha 1 / 255); a 2D texture
    may also come as (1, H, W, C), the shape this returns. Other float
    dtypes become float32; integer data other than uint8 is refused.
    """
    a = np.asarray(data)
    if cube is None:
        cube = a.ndim == 4 and a.shape[0] == 6
    if not cube and a.ndim == 4 and a.shape[0] == 1:  # already (layers, H, W, C), as this returns it
        a = a[0]
    if a.ndim != (4 if cube else 3) or (cube and a.shape[0] != 6):
        raise ValueError(f"a {'cube' if cube else '2D'} texture is {'(6, H, W, C)' if cube else '(H, W, C)'}, "
                         f"got shape {a.shape}")
    if a.dtype.kind == "f" and a.dtype != np.float32:
        a = a.astype(np.float32)
    if a.dtype not in (np.float32, np.uint8):
        raise TypeError(f"texels must be float32 or uint8, got {a.dtype}")
    if not cube:
        a = a[None]
    h, w, c = a.shape[1:]
    if not (1 <= c <= 4) or h < 1 or w < 1:
        raise ValueError(f"a texture needs H, W ≥ 1 and 1-4 channels, got {a.shape[1:]}")
    if cube and h != w:
        raise ValueError(f"cube faces must be square, got {h}x{w}")
    if c < 4:
        full = np.zeros(a.shape[:3] + (4,), a.dtype)
        full[..., 3] = 255 if a.dtype == np.uint8 else 1.0
        full[..., :c] = a
        a = full
    return np.ascontiguousarray(a), bool(cube)


class Image:
    """A sampled image of level 0 only: 2D, or cube (6 layers, CUBE_COMPATIBLE, a CUBE view).

    Formats: float32 texels are VK_FORMAT_R32G32B32A32_SFLOAT; uint8 texels are
    R8G8B8A8_UNORM, or R8G8B8A8_SRGB with ``srgb=True`` (sampling then decodes
    rgb with the sRGB EOTF before filtering; alpha stays linear). `data` is
    (H, W, C) or (6, H, W, C) (see :func:`texels`). The texels go through a
    host-visible staging buffer and one one-time command buffer with the layout
    transitions UNDEFINED → TRANSFER_DST_OPTIMAL → SHADER_READ_ONLY_OPTIMAL, the
    layout the image stays in (:attr:`layout`) for compute shaders to sample.
    Owned by its device: released by Device.close unless destroyed earlier.
    """

    def __init__(self, device: "Device", data, srgb: bool = False, cube: bool | None = None):
        vk = device.vk
        arr, self.cube = texels(data, cube)
        self.device, self.srgb = device, bool(srgb)
        self.layers, self.height, self.width = arr.shape[:3]
        self.dtype = arr.dtype
        self.format = _image_format(vk, arr.dtype, self.srgb)
        self.layout = vk.VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL
        self.nbytes = arr.nbytes
        feats = vk.vkGetPhysicalDeviceFormatProperties(device.physical, self.format).optimalTilingFeatures
        need = (vk.VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT | vk.VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT
                | _FORMAT_FEATURE_TRANSFER_DST)
        if feats & need != need:
            raise VulkanUnavailable(f"{device.name} cannot sample format {self.format} with linear filtering "
                                    "from optimal tiling")
        self.handle = self.memory = self.view = None
        dev = device.handle
        try:
            self.handle = vk.vkCreateImage(dev, vk.VkImageCreateInfo(
                flags=vk.VK_IMAGE_CREATE_CUBE_COMPATIBLE_BIT if self.cube else 0,
                imageType=vk.VK_IMAGE_TYPE_2D, format=self.format,
                extent=vk.VkExtent3D(width=self.width, height=self.height, depth=1),
                mipLevels=1, arrayLayers=self.layers, samples=vk.VK_SAMPLE_COUNT_1_BIT,
                tiling=vk.VK_IMAGE_TILING_OPTIMAL,
                usage=vk.VK_IMAGE_USAGE_SAMPLED_BIT | vk.VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                sharingMode=vk.VK_SHARING_MODE_EXCLUSIVE, initialLayout=vk.VK_IMAGE_LAYOUT_UNDEFINED), None)
            req = vk.vkGetImageMemoryRequirements(dev, self.handle)
            self.memory = vk.vkAllocateMemory(dev, vk.VkMemoryAllocateInfo(
                allocationSize=req.size, memoryTypeIndex=device.local_memory_type(req.memoryTypeBits)), None)
            vk.vkBindImageMemory(dev, self.handle, self.memory, 0)
            self.view = vk.vkCreateImageView(dev, vk.VkImageViewCreateInfo(
                image=self.handle, format=self.format,
                viewType=vk.VK_IMAGE_VIEW_TYPE_CUBE if self.cube else vk.VK_IMAGE_VIEW_TYPE_2D,
                components=vk.VkComponentMapping(**dict.fromkeys("rgba", vk.VK_COMPONENT_SWIZZLE_IDENTITY)),
                subresourceRange=self._range()), None)
            self.upload(arr)
        except BaseException:
            self.destroy()
            raise
        device.own(self)

    def _range(self):
        vk = self.device.vk
        return vk.VkImageSubresourceRange(aspectMask=vk.VK_IMAGE_ASPECT_COLOR_BIT, baseMipLevel=0, levelCount=1,
                                          baseArrayLayer=0, layerCount=self.layers)

    def upload(self, data) -> None:
        """Replace all texels (same shape and dtype) through a staging buffer; waits for the copy."""
        vk, device = self.device.vk, self.device
        arr, _ = texels(data, self.cube)
        if arr.shape != (self.layers, self.height, self.width, 4) or arr.dtype != self.dtype:
            raise ValueError(f"upload of {arr.shape} {arr.dtype} into an image of "
                             f"{(self.layers, self.height, self.width, 4)} {self.dtype}")
        staging = device.buffer(arr.nbytes, vk.VK_BUFFER_USAGE_TRANSFER_SRC_BIT)
        try:
            staging.write(arr)
            rng = self._range()
            # Earlier submissions were waited for (Device.submit), so the first barrier needs no source
            # scope; UNDEFINED discards the old texels, all of which the copy replaces.
            to_dst = vk.VkImageMemoryBarrier(
                srcAccessMask=0, dstAccessMask=vk.VK_ACCESS_TRANSFER_WRITE_BIT,
                oldLayout=vk.VK_IMAGE_LAYOUT_UNDEFINED, newLayout=vk.VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                srcQueueFamilyIndex=vk.VK_QUEUE_FAMILY_IGNORED, dstQueueFamilyIndex=vk.VK_QUEUE_FAMILY_IGNORED,
                image=self.handle, subresourceRange=rng)
            to_read = vk.VkImageMemoryBarrier(
                srcAccessMask=vk.VK_ACCESS_TRANSFER_WRITE_BIT, dstAccessMask=vk.VK_ACCESS_SHADER_READ_BIT,
                oldLayout=vk.VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, newLayout=self.layout,
                srcQueueFamilyIndex=vk.VK_QUEUE_FAMILY_IGNORED, dstQueueFamilyIndex=vk.VK_QUEUE_FAMILY_IGNORED,
                image=self.handle, subresourceRange=rng)
            # Tightly packed layers one after another: one region covers them all.
            region = vk.VkBufferImageCopy(
                bufferOffset=0, bufferRowLength=0, bufferImageHeight=0,
                imageSubresource=vk.VkImageSubresourceLayers(aspectMask=vk.VK_IMAGE_ASPECT_COLOR_BIT, mipLevel=0,
                                                             baseArrayLayer=0, layerCount=self.layers),
                imageOffset=vk.VkOffset3D(x=0, y=0, z=0),
                imageExtent=vk.VkExtent3D(width=self.width, height=self.height, depth=1))

            def record(cmd):
                vk.vkCmdPipelineBarrier(cmd, vk.VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, vk.VK_PIPELINE_STAGE_TRANSFER_BIT,
                                        0, 0, None, 0, None, 1, [to_dst])
                vk.vkCmdCopyBufferToImage(cmd, staging.handle, self.handle, vk.VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                                          1, [region])
                vk.vkCmdPipelineBarrier(cmd, vk.VK_PIPELINE_STAGE_TRANSFER_BIT,
                                        vk.VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 0, None, 0, None, 1, [to_read])

            device.submit(record)
        finally:
            staging.destroy()

    def destroy(self) -> None:
        dev = self.device.handle
        if dev is None or (self.handle is None and self.memory is None):
            return
        vk = self.device.vk
        if self in self.device._owned:
            self.device._owned.remove(self)
        if self.view is not None:
            vk.vkDestroyImageView(dev, self.view, None)
        if self.handle is not None:
            vk.vkDestroyImage(dev, self.handle, None)
        if self.memory is not None:
            vk.vkFreeMemory(dev, self.memory, None)
        self.view = self.handle = self.memory = None


class Sampler:
    """The project's one sampler: exactly the filter the NumPy target reproduces.

    VK_FILTER_LINEAR for min and mag (bilinear), mipmapMode NEAREST, minLod =
    maxLod = 0 (level 0 only), VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE on u, v and w,
    normalized coordinates (texel i's centre at (i + 0.5) / W), no anisotropy,
    no compare. generator/targets/numpy_resources.py computes the same bilinear
    clamp-to-edge fetch with exact float64 weights; a GPU rounds the weights to
    its sub-texel precision (see tests/test_runtime_images.py for lavapipe's).
    Cube views filter seamlessly across faces in Vulkan; the NumPy target clamps
    within a face, so they differ within half a texel of a face edge.
    Owned by its device: released by Device.close unless destroyed earlier.
    """

    def __init__(self, device: "Device"):
        vk = device.vk
        self.device = device
        clamp = vk.VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE
        self.handle = vk.vkCreateSampler(device.handle, vk.VkSamplerCreateInfo(
            magFilter=vk.VK_FILTER_LINEAR, minFilter=vk.VK_FILTER_LINEAR,
            mipmapMode=vk.VK_SAMPLER_MIPMAP_MODE_NEAREST,
            addressModeU=clamp, addressModeV=clamp, addressModeW=clamp, mipLodBias=0.0,
            anisotropyEnable=vk.VK_FALSE, maxAnisotropy=1.0, compareEnable=vk.VK_FALSE,
            compareOp=vk.VK_COMPARE_OP_ALWAYS, minLod=0.0, maxLod=0.0,
            borderColor=vk.VK_BORDER_COLOR_FLOAT_TRANSPARENT_BLACK, unnormalizedCoordinates=vk.VK_FALSE), None)
        device.own(self)

    def destroy(self) -> None:
        dev = self.device.handle
        if dev is None or self.handle is None:
            return
        if self in self.device._owned:
            self.device._owned.remove(self)
        self.device.vk.vkDestroySampler(dev, self.handle, None)
        self.handle = None


class Device:
    """Instance + lavapipe logical device + one queue and command pool; collects validation messages."""

    def __init__(self, validation: bool = False, prefer: str = "llvmpipe"):
        if os.environ.get("SHADERMATRIX_FORBID_DEVICE"):  # the test tiers: only lavapipe tests open a device
            raise RuntimeError(f"a Vulkan device opened where none may ({os.environ['SHADERMATRIX_FORBID_DEVICE']})")
        vk = self.vk = _vk()
        self.validation = validation
        self.messages: list[ValidationMessage] = []
        self.handle = self.instance = self._messenger = self.command_pool = self.fence = None
        self._owned: list = []  # objects with destroy(), released in reverse order by close()
        self.cache: dict = {}  # objects callers keep per device (compiled eval kernels)
        self._user = vk.ffi.cast("void *", id(self))
        _DEVICES[id(self)] = self
        try:
            self._open(prefer)
        except BaseException:
            self.close()
            raise

    # ------------------------------------------------------------ set-up
    def _open(self, prefer: str) -> None:
        vk = self.vk
        layers, exts, pnext = [], [], None
        if self.validation:
            have = {p.layerName for p in vk.vkEnumerateInstanceLayerProperties()}
            if VALIDATION_LAYER not in have:
                raise VulkanUnavailable(f"{VALIDATION_LAYER} not installed — install vulkan-validationlayers "
                                        "(`make setup`)")
            layers, exts = [VALIDATION_LAYER], ["VK_EXT_debug_utils"]
            pnext = self._messenger_info = vk.VkDebugUtilsMessengerCreateInfoEXT(
                messageSeverity=(vk.VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT
                                 | vk.VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT),
                messageType=(vk.VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT
                             | vk.VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT
                             | vk.VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT),
                pfnUserCallback=_on_message, pUserData=self._user)
        app = vk.VkApplicationInfo(pApplicationName="shadermatrix", applicationVersion=1,
                                   pEngineName="shadermatrix", engineVersion=1,
                                   apiVersion=vk.VK_MAKE_VERSION(1, 1, 0))
        try:
            self.instance = vk.vkCreateInstance(vk.VkInstanceCreateInfo(
                pNext=pnext, pApplicationInfo=app, ppEnabledLayerNames=layers,
                ppEnabledExtensionNames=exts), None)
        except vk.VkError as exc:
            raise VulkanUnavailable(f"vkCreateInstance failed ({type(exc).__name__}) — install "
                                    "mesa-vulkan-drivers for lavapipe (`make setup`)") from None
        if self.validation:
            create = vk.vkGetInstanceProcAddr(self.instance, "vkCreateDebugUtilsMessengerEXT")
            self._destroy_messenger = vk.vkGetInstanceProcAddr(self.instance, "vkDestroyDebugUtilsMessengerEXT")
            self._messenger = create(self.instance, self._messenger_info, None)

        found = []
        for phys in vk.vkEnumeratePhysicalDevices(self.instance):
            props = vk.vkGetPhysicalDeviceProperties(phys)
            found.append(str(props.deviceName))
            if str(props.deviceName).startswith(prefer):
                self.physical, self.properties = phys, props
                break
        else:
            raise VulkanUnavailable(f"no '{prefer}' Vulkan device (found: {', '.join(found) or 'none'}) — "
                                    "install mesa-vulkan-drivers (`make setup`)")
        self.name = str(self.properties.deviceName)
        self.limits = self.properties.limits
        self.timestamp_period_ns = float(self.limits.timestampPeriod)
        families = vk.vkGetPhysicalDeviceQueueFamilyProperties(self.physical)
        want = vk.VK_QUEUE_COMPUTE_BIT
        self.queue_family = next(i for i, f in enumerate(families) if f.queueFlags & want)
        self.timestamp_bits = int(families[self.queue_family].timestampValidBits)
        self.memory_properties = vk.vkGetPhysicalDeviceMemoryProperties(self.physical)

        queue_info = vk.VkDeviceQueueCreateInfo(queueFamilyIndex=self.queue_family, queueCount=1,
                                                pQueuePriorities=[1.0])
        self.handle = vk.vkCreateDevice(self.physical, vk.VkDeviceCreateInfo(
            pQueueCreateInfos=[queue_info], pEnabledFeatures=vk.VkPhysicalDeviceFeatures()), None)
        self.queue = vk.vkGetDeviceQueue(self.handle, self.queue_family, 0)
        self.command_pool = vk.vkCreateCommandPool(self.handle, vk.VkCommandPoolCreateInfo(
            flags=vk.VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT, queueFamilyIndex=self.queue_family), None)
        self.fence = vk.vkCreateFence(self.handle, vk.VkFenceCreateInfo(), None)

    def host_memory_type(self, type_bits: int) -> int:
        """A memory type the host can map coherently (device-local too when there is one: lavapipe)."""
        vk, mp = self.vk, self.memory_properties
        host = vk.VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | vk.VK_MEMORY_PROPERTY_HOST_COHERENT_BIT
        best = None
        for i in range(mp.memoryTypeCount):
            flags = mp.memoryTypes[i].propertyFlags
            if type_bits & (1 << i) and flags & host == host:
                if flags & vk.VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT:
                    return i
                best = i if best is None else best
        if best is None:
            raise VulkanUnavailable(f"{self.name} has no host-visible coherent memory")
        return best

    def local_memory_type(self, type_bits: int) -> int:
        """A device-local memory type (for images); any allowed type when none is device-local."""
        vk, mp = self.vk, self.memory_properties
        allowed = [i for i in range(mp.memoryTypeCount) if type_bits & (1 << i)]
        if not allowed:
            raise VulkanUnavailable(f"{self.name} has no memory type for bits {type_bits:#x}")
        local = [i for i in allowed if mp.memoryTypes[i].propertyFlags & vk.VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT]
        return (local or allowed)[0]

    # ------------------------------------------------------------ objects
    def buffer(self, size: int, usage: int) -> Buffer:
        """A mapped buffer owned by this device (released by close() unless destroyed earlier)."""
        b = Buffer(self, max(int(size), 16), usage)
        self._owned.append(b)
        return b

    def image(self, data, srgb: bool = False, cube: bool | None = None) -> Image:
        """A sampled :class:`Image` holding `data` ((H, W, C) 2D or (6, H, W, C) cube; float32 or uint8)."""
        return Image(self, data, srgb, cube)

    def sampler(self) -> Sampler:
        """A new :class:`Sampler` (bilinear, clamp-to-edge, level 0) owned by this device."""
        return Sampler(self)

    def own(self, obj):
        """Release `obj` (anything with destroy()) when the device closes."""
        self._owned.append(obj)
        return obj

    def submit(self, record) -> None:
        """Record commands with `record(command_buffer)`, submit them, wait for completion."""
        vk = self.vk
        cmd = vk.vkAllocateCommandBuffers(self.handle, vk.VkCommandBufferAllocateInfo(
            commandPool=self.command_pool, level=vk.VK_COMMAND_BUFFER_LEVEL_PRIMARY, commandBufferCount=1))[0]
        try:
            vk.vkBeginCommandBuffer(cmd, vk.VkCommandBufferBeginInfo(
                flags=vk.VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT))
            record(cmd)
            vk.vkEndCommandBuffer(cmd)
            vk.vkResetFences(self.handle, 1, [self.fence])
            vk.vkQueueSubmit(self.queue, 1, [vk.VkSubmitInfo(pCommandBuffers=[cmd])], self.fence)
            vk.vkWaitForFences(self.handle, 1, [self.fence], vk.VK_TRUE, 0xFFFFFFFFFFFFFFFF)
        finally:
            vk.vkFreeCommandBuffers(self.handle, self.command_pool, 1, [cmd])

    # ------------------------------------------------------------ tear-down
    def close(self) -> None:
        """Destroy everything this device created; validation messages of the tear-down are still collected."""
        vk = self.vk
        if self.handle is not None:
            vk.vkDeviceWaitIdle(self.handle)
            for obj in reversed(list(self._owned)):
                obj.destroy()
            self._owned.clear()
            self.cache.clear()
            if self.fence is not None:
                vk.vkDestroyFence(self.handle, self.fence, None)
            if self.command_pool is not None:
                vk.vkDestroyCommandPool(self.handle, self.command_pool, None)
            vk.vkDestroyDevice(self.handle, None)
            self.handle = None
        if self._messenger is not None:
            self._destroy_messenger(self.instance, self._messenger, None)
            self._messenger = None
        if self.instance is not None:
            vk.vkDestroyInstance(self.instance, None)
            self.instance = None
        _DEVICES.pop(id(self), None)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def validation_requested() -> bool:
    """SHADERMATRIX_VALIDATION=1 turns the validation layer on for the process-wide device."""
    return os.environ.get("SHADERMATRIX_VALIDATION", "").strip().lower() in ("1", "true", "yes")
