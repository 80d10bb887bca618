"""The persisted VkPipelineCache: checked against the device, ignored with one line when it is not ours."""
from __future__ import annotations

import struct

import pytest

from tests.lavapipe import device, no_validation_messages  # noqa: F401  (fixtures)

pytestmark = pytest.mark.lavapipe


def _pipeline(device, cache):
    from generator.compose import compose_eval
    from generator.library.bricks import load_library
    from generator.runtime.compute import STORAGE, UNIFORM, ComputePipeline
    from generator.toolchain import CompileJob, compile_many

    src = compose_eval("lambert", load_library(), ("glsl",)).sources[0]
    r = compile_many([CompileJob("pc.comp.glsl", "glsl", "comp", src.text)])["pc.comp.glsl"]
    return ComputePipeline(device, r.spirv, (STORAGE, STORAGE, UNIFORM), cache=cache)


@pytest.mark.toolchain
def test_saved_cache_is_reloaded_and_every_bad_file_is_ignored_with_its_reason(device, tmp_path):
    from generator.runtime.pipeline_cache import HEADER, PipelineCacheFile, device_header

    path = tmp_path / "lavapipe.cache"
    first = PipelineCacheFile(device, path)
    assert first.problem == "" and first.loaded == 0
    _pipeline(device, first).destroy()
    assert first.save() and not first.save()  # the second save finds the same bytes
    good = path.read_bytes()
    size, version, vendor, dev, uuid = HEADER.unpack_from(good)
    assert (size, version) == (32, 1) and (vendor, dev, uuid) == device_header(device)
    again = PipelineCacheFile(device, path)
    assert again.problem == "" and again.loaded == len(good)
    _pipeline(device, again).destroy()
    foreign = HEADER.pack(32, 1, vendor ^ 1, dev, uuid) + good[32:]
    cases = [(good[:20], "truncated"), (b"", "truncated: 0 bytes"), (foreign, "another device or driver"),
             (b"\x00" * 40, "not a Vulkan pipeline cache"), (HEADER.pack(32, 2, vendor, dev, uuid), "header version 2")]
    for data, why in cases:
        path.write_bytes(data)
        c = PipelineCacheFile(device, path)
        assert why in c.problem and str(path) in c.problem and "\n" not in c.problem, c.problem
        assert c.loaded == 0
        _pipeline(device, c).destroy()
        c.save()  # replaced atomically by what this device writes
        assert path.read_bytes()[:32] == good[:32]
        assert not list(tmp_path.glob(".*.tmp"))
    assert struct.calcsize("<IIII16s") == HEADER.size == 32
