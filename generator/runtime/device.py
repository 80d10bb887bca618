"""A Vulkan device on Mesa lavapipe: instance, validation messages, queue, memory, buffers, images, samplers.

A small layer over the `vulkan` PyPI binding (cffi), meant to grow from compute
to graphics: :class:`Device` owns the instance, the logical device, one queue
(graphics+compute when the family has both), a command pool and the list of
validation messages; :mod:`.compute` builds pipelines on top of it.

Textures (runtime/images.py): :class:`Image` is a sampled 2D or cube image (level 0, or a mip chain)
uploaded from NumPy arrays through a staging buffer; :class:`Sampler` is by default the
project's own filter, exactly the one the NumPy target reproduces
(generator/backends/numpy/resources.py): bilinear, clamp-to-edge, texel centres
at (i + 0.5) / W, level 0; or a sampler state a manifest spells for Vulkan.

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
from typing import TYPE_CHECKING

import numpy as np

from ..lang.errors import EnvironmentMissing

if TYPE_CHECKING:
    from .images import Image, Sampler

STATISTICS_EXTENSION = "VK_KHR_pipeline_executable_properties"
VALIDATION_LAYER = "VK_LAYER_KHRONOS_validation"


STORAGE_INPUT_OUTPUT_16 = 4436  # SPIR-V capability StorageInputOutput16
_FLOAT16 = 9  # SPIR-V capability Float16
_OP_CAPABILITY = 17


def _capabilities(spirv: bytes):
    """(word offset, capability) of each OpCapability; capabilities open every module."""
    words = np.frombuffer(spirv, np.uint32)
    i = 5
    while i + 1 < len(words) and int(words[i]) & 0xFFFF == _OP_CAPABILITY:
        yield i, int(words[i + 1])
        i += max(int(words[i]) >> 16, 1)


def uses_float16(spirv: bytes) -> bool:
    """Whether the module declares OpCapability Float16 (an fp16 shader)."""
    return any(c == _FLOAT16 for _, c in _capabilities(spirv))


def drop_capabilities(spirv: bytes, drop: set[int]) -> bytes:
    """The module without its `OpCapability X` instructions for X in `drop` (nothing else changes)."""
    words = np.frombuffer(spirv, np.uint32)
    cut = {i for i, c in _capabilities(spirv) if c in drop}
    if not cut:
        return spirv
    keep = np.ones(len(words), bool)
    for i in cut:
        keep[i: i + 2] = False
    return words[keep].astype(np.uint32).tobytes()


class VulkanUnavailable(EnvironmentMissing, RuntimeError):
    """No usable Vulkan loader, lavapipe device or validation layer; the message says why and what to do."""


class Fp16Unsupported(EnvironmentMissing, RuntimeError):
    """fp16 shaders asked of a device without shaderFloat16 and 16-bit storage (exit 3: the environment)."""


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


class Device:
    """Instance + lavapipe logical device + one queue and command pool; collects validation messages."""

    def __init__(self, validation: bool = False, prefer: str = "llvmpipe", compile_only: bool = False):
        if os.environ.get("SHADERMATRIX_FORBID_DEVICE"):  # the test tiers: only lavapipe tests open a device
            raise RuntimeError(f"a Vulkan device opened where none may ({os.environ['SHADERMATRIX_FORBID_DEVICE']})")
        vk = self.vk = _vk()
        self.validation = validation
        # compile_only: a device that creates pipelines and reads the compiler's own figures
        # (VK_KHR_pipeline_executable_properties; an error where the device lacks it) and runs nothing:
        # no command pool, no fence (RADV's null device, runtime/gpu_stats.py, has no hardware to run on)
        self.compile_only = compile_only
        self.messages: list[ValidationMessage] = []
        self.features: dict[str, bool] = {}  # fp16 features the device reports (filled in by _open)
        self.sampler_anisotropy = False  # samplerAnisotropy, enabled where the device has it (samplers may filter so)
        self.handle = self.instance = self._messenger = self.command_pool = self.fence = None
        self._owned: list = []  # objects with destroy(), released in reverse order by close()
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
        # VK_EXT_pipeline_creation_feedback (when the driver has it): pipelines report cache hits.
        have = {e.extensionName for e in vk.vkEnumerateDeviceExtensionProperties(self.physical, None)}
        self.extensions = [e for e in ("VK_EXT_pipeline_creation_feedback",) if e in have]
        features = None
        # fp16: half arithmetic (shaderFloat16) and 16-bit storage access, which naga's f16
        # modules declare, are enabled wherever the device reports them; self.features says which.
        self.features = self._fp16_features(have)
        storage = {k: vk.VK_TRUE for k in ("storageBuffer16BitAccess", "uniformAndStorageBuffer16BitAccess")
                   if self.features.get(k)}
        f16 = s16 = vk.VkPhysicalDevice16BitStorageFeatures(**storage) if storage else None
        if self.features.get("shaderFloat16"):  # the instance is Vulkan 1.1: the extension, not 1.2 core
            self.extensions.append("VK_KHR_shader_float16_int8")
            f16 = vk.VkPhysicalDeviceShaderFloat16Int8Features(pNext=s16, shaderFloat16=vk.VK_TRUE)
        if self.compile_only:
            if STATISTICS_EXTENSION not in have:
                raise VulkanUnavailable(f"{self.name} has no {STATISTICS_EXTENSION}: it cannot report compiler "
                                        "statistics")
            self.extensions.append(STATISTICS_EXTENSION)
            features = vk.VkPhysicalDevicePipelineExecutablePropertiesFeaturesKHR(pNext=f16,
                                                                                  pipelineExecutableInfo=vk.VK_TRUE)
        features = features if features is not None else f16
        # anisotropic filtering is an optional feature: a scene's sampler asks for it (runtime/images.Sampler clamps
        # the state to 1 where the device lacks it, and says so)
        have_features = vk.vkGetPhysicalDeviceFeatures(self.physical)
        self.sampler_anisotropy = bool(have_features.samplerAnisotropy)
        # a brick's texturecube_array is a CUBE_ARRAY view and SPIR-V's SampledCubeArray: enabled where present
        self.image_cube_array = bool(have_features.imageCubeArray)
        self.handle = vk.vkCreateDevice(self.physical, vk.VkDeviceCreateInfo(
            pNext=features, pQueueCreateInfos=[queue_info],
            pEnabledFeatures=vk.VkPhysicalDeviceFeatures(samplerAnisotropy=vk.VK_TRUE if self.sampler_anisotropy
                                                         else vk.VK_FALSE,
                                                         imageCubeArray=vk.VK_TRUE if self.image_cube_array
                                                         else vk.VK_FALSE),
            ppEnabledExtensionNames=self.extensions), None)
        del features, f16, s16  # alive across the call
        if self.compile_only:
            return
        self.queue = vk.vkGetDeviceQueue(self.handle, self.queue_family, 0)
        self.command_pool = vk.vkCreateCommandPool(self.handle, vk.VkCommandPoolCreateInfo(
            flags=vk.VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT, queueFamilyIndex=self.queue_family), None)
        self.fence = vk.vkCreateFence(self.handle, vk.VkFenceCreateInfo(), None)

    def _fp16_features(self, extensions: set) -> dict[str, bool]:
        """What the physical device reports for fp16: shaderFloat16 (VkPhysicalDeviceShaderFloat16Int8Features of
        VK_KHR_shader_float16_int8, core in Vulkan 1.2) and the 16-bit storage features (core in Vulkan 1.1)."""
        vk = self.vk
        out = dict.fromkeys(("shaderFloat16", "storageBuffer16BitAccess", "uniformAndStorageBuffer16BitAccess",
                             "storagePushConstant16", "storageInputOutput16"), False)
        try:
            f16 = vk.VkPhysicalDeviceShaderFloat16Int8Features()
            s16 = vk.VkPhysicalDevice16BitStorageFeatures(pNext=f16)
            vk.vkGetPhysicalDeviceFeatures2(self.physical, vk.VkPhysicalDeviceFeatures2(pNext=s16))
        except Exception:  # a loader or driver without vkGetPhysicalDeviceFeatures2: no fp16
            return out
        # the instance asks for Vulkan 1.1, so shaderFloat16 is usable through VK_KHR_shader_float16_int8 only
        out["shaderFloat16"] = bool(f16.shaderFloat16) and "VK_KHR_shader_float16_int8" in extensions
        for k in list(out)[1:]:
            out[k] = bool(getattr(s16, k))
        return out

    def fit_spirv(self, spirv: bytes) -> bytes:
        """A module as this device takes it: naga declares StorageInputOutput16 in every module that enables
        f16, whether or not a 16-bit stage input or output exists; the project's fp16 shaders keep their
        interface 32-bit (backends/clike/walk.py), so where the device lacks storageInputOutput16 (lavapipe) the
        capability is dropped. Every other module passes unchanged. A module using 16-bit floats on a device
        without fp16 (Device.fp16) is Fp16Unsupported (exit 3): every pipeline is created through here."""
        if not uses_float16(spirv):
            return spirv
        if not self.fp16:
            raise Fp16Unsupported(f"{self.name} does not report shaderFloat16 and 16-bit storage: fp16 shaders "
                                  "cannot run there — use precision fp32, or float16 with the numpy target")
        if self.features.get("storageInputOutput16"):
            return spirv
        return drop_capabilities(spirv, {STORAGE_INPUT_OUTPUT_16})

    @property
    def fp16(self) -> bool:
        """Whether fp16 shaders run here: shaderFloat16, and the 16-bit storage access naga's f16 modules declare."""
        return all(self.features.get(k) for k in ("shaderFloat16", "storageBuffer16BitAccess",
                                                  "uniformAndStorageBuffer16BitAccess"))

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

    def image(self, data, srgb: bool = False, cube: bool | None = None) -> "Image":
        """A sampled :class:`~.images.Image` holding `data` ((H, W, C) 2D or (6, H, W, C) cube; float32 or uint8)."""
        from .images import Image
        return Image(self, data, srgb, cube)

    def sampler(self) -> "Sampler":
        """A new :class:`~.images.Sampler` (bilinear, clamp-to-edge, level 0) owned by this device."""
        from .images import Sampler
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
            if not self.compile_only:
                vk.vkDeviceWaitIdle(self.handle)
            for obj in reversed(list(self._owned)):
                obj.destroy()
            self._owned.clear()
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
    """SHADERMATRIX_VALIDATION=1 turns the validation layer on for the devices eval sessions and renders open."""
    return os.environ.get("SHADERMATRIX_VALIDATION", "").strip().lower() in ("1", "true", "yes")
