"""Mesa's shader disk cache, persisted under an output directory, and the driver's own hit count.

On lavapipe a VkPipelineCache stores nothing (Mesa 22.3 and 25.0 alike: vkGetPipelineCacheData
returns the 32-byte header alone and creation feedback never reports a hit, see
runtime/pipeline_cache.py). The cache that lavapipe does hit is Mesa's *shader disk cache*:
llvmpipe keeps the machine code it JIT-compiles (vertex and fragment variants, compiled on the
first draw that uses a pipeline, not at vkCreateGraphicsPipelines) keyed by the shader and the
driver's identity (its build id, LLVM version and CPU features). `opened` points that cache at a
directory of ours (``MESA_SHADER_CACHE_DIR``) for the one instance it opens, and turns on
``MESA_SHADER_CACHE_SHOW_STATS`` (Mesa 25.0 here; Mesa 22.3 has no such variable), with which Mesa prints
``disk shader cache:  hits = H, misses = M`` from its C stdio when the instance is destroyed.
`closed` captures that line (and passes anything else printed meanwhile through to stdout),
so the render report can carry the driver's own count, not a guess of ours.

One directory serves any number of devices: Mesa's keys include the driver's identity, so a
foreign entry is a miss, never a wrong hit; its files carry their own checksums (a damaged
entry is a miss too, measured in tests/runtime/test_render.py).
"""
from __future__ import annotations

import ctypes
import os
import re
import sys
import tempfile
from contextlib import contextmanager
from pathlib import Path

STATS = re.compile(rb"disk shader cache:\s+hits = (\d+), misses = (\d+)\s*\n?")
ENV = ("MESA_SHADER_CACHE_DIR", "MESA_SHADER_CACHE_SHOW_STATS", "MESA_SHADER_CACHE_DISABLE")


@contextmanager
def opened(directory):
    """While the caller creates its Vulkan instance: Mesa's shader cache in `directory`, with statistics.

    The variables are read when the instance enumerates its physical devices, and restored on exit,
    so no other instance of the process is affected.
    """
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    saved = {k: os.environ.get(k) for k in ENV}
    os.environ["MESA_SHADER_CACHE_DIR"] = str(directory.resolve())
    os.environ["MESA_SHADER_CACHE_SHOW_STATS"] = "true"
    os.environ["MESA_SHADER_CACHE_DISABLE"] = "false"  # a user's "disable" would make every count vanish
    try:
        yield
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


def closed(close) -> tuple[int, int] | None:
    """Run `close()` (the device's tear-down) and return Mesa's (hits, misses), or None if it printed none.

    Mesa prints with printf into the C library's stdout buffer: file descriptor 1 is pointed at a
    temporary file while `close` runs and the buffer is flushed into it before fd 1 is restored.
    """
    libc = ctypes.CDLL(None)
    sys.stdout.flush()
    libc.fflush(None)
    try:
        saved = os.dup(1)
    except OSError:  # no standard output to borrow (closed): tear down without counting
        close()
        return None
    text = b""
    with tempfile.TemporaryFile() as tmp:
        os.dup2(tmp.fileno(), 1)
        try:
            close()
        finally:
            libc.fflush(None)
            os.dup2(saved, 1)
            os.close(saved)
            tmp.seek(0)
            text = tmp.read()
            rest = STATS.sub(b"", text)
            if rest:  # whatever else was printed meanwhile is not ours to swallow, even when close() failed
                out = getattr(sys.stdout, "buffer", None)
                out.write(rest) if out is not None else sys.stdout.write(rest.decode(errors="replace"))
                sys.stdout.flush()
    found = STATS.search(text)
    return (int(found[1]), int(found[2])) if found else None
