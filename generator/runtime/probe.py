"""Which Vulkan devices this machine has (lavapipe is what the tests run on).

Uses the `vulkan` PyPI binding (cffi). It loads libvulkan when imported, so
the import itself is guarded: on a machine without a loader, or without any
ICD, :func:`vulkan_devices` returns ``[]`` and :func:`vulkan_status` says why.
"""
from __future__ import annotations

_DEVICE_TYPES = {0: "other", 1: "integrated-gpu", 2: "discrete-gpu", 3: "virtual-gpu", 4: "cpu"}


def _version(v: int) -> str:
    """A packed VK_MAKE_API_VERSION value as "major.minor.patch"."""
    return f"{(v >> 22) & 0x7F}.{(v >> 12) & 0x3FF}.{v & 0xFFF}"


def vulkan_status() -> tuple[list[dict], str | None]:
    """(devices, reason): reason is None when the query ran, else why it could not."""
    try:
        import vulkan as vk
    except Exception as exc:  # OSError when libvulkan is absent; cffi errors otherwise
        return [], f"Vulkan loader not usable: {exc} (install libvulkan1 — run `make setup`)"
    app = vk.VkApplicationInfo(
        sType=vk.VK_STRUCTURE_TYPE_APPLICATION_INFO, pApplicationName="shadermatrix-probe",
        applicationVersion=1, pEngineName="shadermatrix", engineVersion=1,
        apiVersion=vk.VK_MAKE_VERSION(1, 1, 0))
    info = vk.VkInstanceCreateInfo(sType=vk.VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO, pApplicationInfo=app)
    try:
        instance = vk.vkCreateInstance(info, None)
    except Exception as exc:  # VkErrorIncompatibleDriver: no ICD at all
        return [], f"vkCreateInstance failed: {type(exc).__name__} {exc} (is mesa-vulkan-drivers installed?)"
    try:
        devices = []
        for phys in vk.vkEnumeratePhysicalDevices(instance):
            props = vk.vkGetPhysicalDeviceProperties(phys)
            name = props.deviceName
            if isinstance(name, bytes):
                name = name.decode("utf-8", errors="replace")
            devices.append({
                "name": str(name),
                "api_version": _version(props.apiVersion),
                "driver_version": int(props.driverVersion),
                "device_type": _DEVICE_TYPES.get(int(props.deviceType), str(props.deviceType)),
                "vendor_id": int(props.vendorID),
                "device_id": int(props.deviceID),
            })
    except Exception as exc:
        return [], f"vkEnumeratePhysicalDevices failed: {type(exc).__name__} {exc}"
    finally:
        vk.vkDestroyInstance(instance, None)
    return devices, None if devices else "the Vulkan loader found no physical device"


def vulkan_devices() -> list[dict]:
    """Physical devices: name, api_version ("1.3.230"), driver_version, device_type, ids.

    ``[]`` when there is no usable loader or device; see :func:`vulkan_status`.
    """
    return vulkan_status()[0]


def lavapipe_present() -> bool:
    """True if a Mesa lavapipe device ("llvmpipe (LLVM …)") is visible."""
    return any(d["name"].startswith("llvmpipe") for d in vulkan_devices())
