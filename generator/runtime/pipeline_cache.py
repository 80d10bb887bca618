"""A VkPipelineCache persisted in a file per device, never trusted blindly.

The file is what vkGetPipelineCacheData returns: a header (VkPipelineCacheHeaderVersionOne:
uint32 headerSize ≥ 32, uint32 headerVersion = 1, uint32 vendorID, uint32 deviceID,
uint8 pipelineCacheUUID[16]) then the driver's data. On load the header is checked
against the device: a file that is too short, has another header version, or was written
by another vendor, device or driver build (pipelineCacheUUID) is reported in one line
(`problem`), ignored (the cache starts empty) and replaced on the next save. Saving
writes to a temporary name and renames (io.atomic_write), so an interrupted save never
leaves a half-written cache.

Measured on lavapipe (Mesa 22.3 and 25.0): its cache data is the 32-byte header alone and
pipeline creation feedback never reports a cache hit, so on lavapipe this file saves no
compile time (Mesa's shader disk cache does: runtime/shader_cache.py); the file format and
its checks are the same on every driver.
"""
from __future__ import annotations

import struct
from pathlib import Path

from ..io import atomic_write

HEADER = struct.Struct("<IIII16s")  # headerSize, headerVersion, vendorID, deviceID, pipelineCacheUUID
HEADER_VERSION_ONE = 1


def _lib():
    import vulkan._vulkan as raw  # the binding wraps no vkGetPipelineCacheData; cffi's lib has it
    return raw.lib


def device_header(device) -> tuple[int, int, bytes]:
    """(vendorID, deviceID, pipelineCacheUUID) of the device's physical device."""
    p = device.properties
    return int(p.vendorID), int(p.deviceID), bytes(p.pipelineCacheUUID)


def check(data: bytes, device) -> str:
    """'' when `data` is a pipeline cache this device wrote, else what is wrong with it."""
    if len(data) < HEADER.size:
        return f"truncated: {len(data)} bytes, shorter than the {HEADER.size}-byte header"
    size, version, vendor, dev, uuid = HEADER.unpack_from(data)
    if size < HEADER.size or size > len(data):
        return f"not a Vulkan pipeline cache (header size {size})"
    if version != HEADER_VERSION_ONE:
        return f"header version {version}, not {HEADER_VERSION_ONE}"
    want = device_header(device)
    if (vendor, dev, uuid) != want:
        return (f"written by another device or driver (vendor {vendor:#x}, device {dev:#x}, cache UUID "
                f"{uuid.hex()}; this one: {want[0]:#x}, {want[1]:#x}, {want[2].hex()})")
    return ""


class PipelineCacheFile:
    """A VkPipelineCache loaded from `path` (when it checks out) and saved back to it."""

    def __init__(self, device, path):
        vk = self.vk = device.vk
        self.device, self.path = device, Path(path)
        self.problem = ""  # one line when an existing file was ignored
        self.loaded = 0  # bytes of valid data it started from
        data, exists = b"", self.path.exists()
        if exists:
            data = self.path.read_bytes()
            why = check(data, device)
            if why:
                self.problem = f"{self.path}: pipeline cache ignored, {why} — it is replaced on save"
                data = b""
        self.loaded = len(data)
        buf = vk.ffi.from_buffer(data) if data else vk.ffi.NULL
        self._keep = buf  # cffi memory must live across the call
        self.handle = vk.vkCreatePipelineCache(device.handle, vk.VkPipelineCacheCreateInfo(
            initialDataSize=len(data), pInitialData=buf), None)
        device.own(self)

    def data(self) -> bytes:
        """What the driver holds now (vkGetPipelineCacheData)."""
        vk, lib = self.vk, _lib()
        size = vk.ffi.new("size_t*")
        lib.vkGetPipelineCacheData(self.device.handle, self.handle, size, vk.ffi.NULL)
        buf = vk.ffi.new("char[]", size[0])
        lib.vkGetPipelineCacheData(self.device.handle, self.handle, size, buf)
        return vk.ffi.buffer(buf, size[0])[:]

    def save(self) -> bool:
        """Write the cache to its file atomically; False when the bytes were already there."""
        return atomic_write(self.path, self.data())

    def destroy(self) -> None:
        if self.handle is None:
            return
        if self in self.device._owned:
            self.device._owned.remove(self)
        self.vk.vkDestroyPipelineCache(self.device.handle, self.handle, None)
        self.handle = None
