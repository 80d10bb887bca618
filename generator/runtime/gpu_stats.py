"""AMD compiler statistics without an AMD GPU: Mesa's RADV null device, one process per GPU family.

RADV (in ``mesa-vulkan-drivers``) compiles for a GPU that is not there when ``RADV_FORCE_FAMILY``
names one and the Vulkan loader is given only RADV's ICD (``VK_ICD_FILENAMES``): Vulkan then
enumerates "Null hardware (RADV NAVI21)", which creates pipelines with ACO, Mesa's AMD shader
compiler, and reports them through ``VK_KHR_pipeline_executable_properties``: SGPRs and VGPRs
allocated, spills, code size, LDS, scratch, subgroups (waves) per SIMD, instructions, copies,
branches, latency, inverse throughput, clauses, pre-scheduling register counts, VALU/SALU/VMEM/SMEM
counts. It runs nothing (no queue work, no images: ``Device(compile_only=True)``).

Each family runs in its own process (``python -m generator.runtime.gpu_stats``), so that neither
the environment it needs nor RADV itself touches the process's lavapipe device; the families run
side by side. A :class:`Job` is the SPIR-V of a pipeline's stages; its pipeline layout and vertex
layout are read from the SPIR-V itself (analysis.reflect): graphics pipelines get the vertex
inputs the vertex shader declares (one tightly packed float buffer each, as the renderer binds
them) and the renderer's colour and depth formats (R8G8B8A8_UNORM, D32_SFLOAT); compute
pipelines their set 0. Statistics are keyed by the stage each executable compiles ("vert",
"frag", "comp") and by the driver's own statistic names.

The families (Mesa 25.0 names; `KNOWN_FAMILIES` were each tried here): DEFAULT_FAMILIES are what
engines ship to — polaris10 (GCN4: the generation of PS4 Pro and Xbox One X), navi21 (RDNA2: the
generation of PS5 and Xbox Series), vangogh (RDNA2: Steam Deck), navi31 (RDNA3: current PC parts
and, as phoenix, ROG Ally-class handhelds). Mesa 22.3 called RDNA3 "gfx1100"; 25.0 does not, so
gfx IP names are accepted as ALIASES of their family
(the null device itself is older than both).
"""
from __future__ import annotations

import base64
import difflib
import glob
import json
import os
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from types import SimpleNamespace

DEFAULT_FAMILIES = ("polaris10", "navi21", "vangogh", "navi31")
KNOWN_FAMILIES = ("bonaire", "hawaii", "polaris10", "vega10", "navi10", "navi21", "vangogh", "navi31", "navi33",
                  "phoenix", "gfx1150", "gfx1201")
# AMD's gfx IP names (what LLVM, RGA and Mesa 22.3 used) -> the RADV family compiled for.
ALIASES = {"gfx803": "polaris10", "gfx900": "vega10", "gfx1010": "navi10", "gfx1030": "navi21",
           "gfx1033": "vangogh", "gfx1100": "navi31", "gfx1102": "navi33", "gfx1103": "phoenix", "gfx1200": "gfx1201"}
ICD_GLOB = ("/usr/share/vulkan/icd.d/radeon_icd*.json", "/etc/vulkan/icd.d/radeon_icd*.json")
CAPTURE_STATISTICS = 0x40  # VK_PIPELINE_CREATE_CAPTURE_STATISTICS_BIT_KHR
CAPTURE_IR = 0x80  # VK_PIPELINE_CREATE_CAPTURE_INTERNAL_REPRESENTATIONS_BIT_KHR
STAGES = {0x1: "vert", 0x10: "frag", 0x20: "comp"}  # VkShaderStageFlagBits -> our stage names
TIMEOUT_S = 600

# The statistics the reports show, by the driver's name -> our key (everything else stays in JSON).
SHOWN = {"VGPRs": "vgprs", "SGPRs": "sgprs", "Spilled VGPRs": "spilled_vgprs", "Spilled SGPRs": "spilled_sgprs",
         "Instructions": "instructions", "Code size": "code_bytes", "Subgroups per SIMD": "waves_per_simd",
         "Scratch size": "scratch_bytes", "Latency": "latency", "Inverse Throughput": "inverse_throughput"}


class GpuStatsUnavailable(RuntimeError):
    """RADV's null device cannot be used here (the message says why and what to do)."""


@dataclass(frozen=True)
class Job:
    """One pipeline to compile: its key and the SPIR-V of each stage ("vert" + "frag", or "comp")."""

    key: str
    stages: tuple[tuple[str, bytes], ...]
    specialization: tuple[tuple[int, int], ...] = ()

    def as_json(self) -> dict:
        return {"key": self.key, "stages": [[s, base64.b64encode(b).decode()] for s, b in self.stages],
                "specialization": [list(x) for x in self.specialization]}


@dataclass
class Result:
    """Per family, per job key, per stage: {driver statistic name: value}; and what failed, per family."""

    stats: dict[str, dict[str, dict[str, dict[str, float]]]] = field(default_factory=dict)
    errors: dict[str, str] = field(default_factory=dict)
    devices: dict[str, str] = field(default_factory=dict)  # family -> "Null hardware (RADV NAVI21), Mesa 25.0.7"
    failed: dict[str, dict[str, str]] = field(default_factory=dict)  # job key -> {family: why it did not compile}

    def of(self, family: str, key: str, stage: str) -> dict[str, float] | None:
        return self.stats.get(family, {}).get(key, {}).get(stage)


def radv_icd() -> str | None:
    """The RADV ICD manifest that mesa-vulkan-drivers installs, or None."""
    for pattern in ICD_GLOB:
        found = sorted(glob.glob(pattern))
        if found:
            return found[0]
    return None


def unavailable() -> str:
    """'' when RADV's null device can be used, else one line saying why."""
    if os.environ.get("SHADERMATRIX_FORBID_DEVICE"):
        return f"no device may be opened here ({os.environ['SHADERMATRIX_FORBID_DEVICE']})"
    if radv_icd() is None:
        return ("RADV's Vulkan driver is not installed (no radeon_icd*.json in /usr/share/vulkan/icd.d) — "
                "install mesa-vulkan-drivers (`make setup`)")
    return ""


def check_families(families) -> tuple[str, ...]:
    """The families, each a name RADV knows here (a gfx IP name is taken for its family: gfx1100 is navi31);
    a ValueError naming the closest one otherwise."""
    out = []
    for f in families:
        f = f.strip().lower()
        f = ALIASES.get(f, f)
        if f not in KNOWN_FAMILIES:
            near = difflib.get_close_matches(f, KNOWN_FAMILIES + tuple(ALIASES), n=1)
            hint = f"did you mean '{near[0]}'? " if near else ""
            raise ValueError(f"unknown AMD family '{f}' — {hint}known: {', '.join(KNOWN_FAMILIES)}")
        if f not in out:
            out.append(f)
    if not out:
        raise ValueError(f"no AMD family given — e.g. {','.join(DEFAULT_FAMILIES)}")
    return tuple(out)


def statistics(jobs, families=DEFAULT_FAMILIES, ir_dir=None) -> Result:
    """Compile every job on RADV's null device of each family (one process each, side by side).

    ir_dir: where to save each executable's internal representations (ACO IR, disassembly) as
    ``<ir_dir>/<family>/<key>.<stage>.txt``, or None. Raises GpuStatsUnavailable when RADV cannot be used.
    """
    why = unavailable()
    if why:
        raise GpuStatsUnavailable(why)
    families = check_families(families)
    jobs = list(jobs)
    ir_dir = None if ir_dir is None else Path(ir_dir).resolve()  # the worker runs in the repository
    with tempfile.TemporaryDirectory(prefix=f"shadermatrix-radv-{os.getpid()}-") as tmp:
        request = Path(tmp) / "jobs.json"
        request.write_text(json.dumps([j.as_json() for j in jobs]))

        def one(family):
            out = Path(tmp) / f"{family}.json"
            env = {k: v for k, v in os.environ.items() if not k.startswith(("VK_", "RADV_", "MESA_"))}
            # RADV's own shader cache stays off: nothing is written to the user's ~/.cache, and every
            # figure comes from a compile of this run
            env.update(VK_ICD_FILENAMES=radv_icd(), RADV_FORCE_FAMILY=family, MESA_SHADER_CACHE_DISABLE="true")
            argv = [sys.executable, "-m", "generator.runtime.gpu_stats", str(request), str(out)]
            if ir_dir is not None:
                argv.append(str(Path(ir_dir) / family))
            try:
                r = subprocess.run(argv, env=env, capture_output=True, text=True, timeout=TIMEOUT_S,
                                   cwd=Path(__file__).resolve().parents[2])
            except subprocess.TimeoutExpired:
                return family, None, f"RADV {family}: no answer in {TIMEOUT_S} s"
            if r.returncode != 0 or not out.exists():
                last = [x for x in r.stderr.splitlines() if x.strip()]
                return family, None, f"RADV {family}: {last[-1] if last else f'exit {r.returncode}'}"
            return family, json.loads(out.read_text()), ""

        result = Result()
        with ThreadPoolExecutor(max_workers=max(1, min(len(families), os.cpu_count() or 1))) as pool:
            for family, got, error in pool.map(one, families):
                if error:
                    result.errors[family] = error
                else:
                    result.stats[family], result.devices[family] = got["stats"], got["device"]
                    for key, why in got["errors"].items():
                        result.failed.setdefault(key, {})[family] = why
    return result


# ------------------------------------------------------------------ the worker process

_KINDS = {"uniform_buffer": "uniform", "storage_buffer": "storage", "sampled_image": "sampled_image",
          "sampler": "sampler"}
_VERTEX_FORMATS = {"float": "R32_SFLOAT", "vec2": "R32G32_SFLOAT", "vec3": "R32G32B32_SFLOAT",
                   "vec4": "R32G32B32A32_SFLOAT"}


def _layouts(modules) -> dict[int, dict[int, str]]:
    """{set: {binding: kind}} of every resource the modules declare."""
    from ..analysis.reflect import reflect

    out: dict[int, dict[int, str]] = {}
    for spirv in modules:
        for res in reflect(spirv).resources:
            if res.kind not in _KINDS:
                raise ValueError(f"set {res.set} binding {res.binding}: {res.kind} is not a kind this runtime binds")
            out.setdefault(res.set, {})[res.binding] = _KINDS[res.kind]
    return out


def _vertex_inputs(vert: bytes):
    from ..analysis.reflect import reflect

    ep = reflect(vert).entry("vert")
    bad = [f"{v.name or v.location}: {v.type}" for v in ep.inputs if v.type not in _VERTEX_FORMATS]
    if bad:
        raise ValueError(f"vertex inputs of a type the renderer does not bind ({', '.join(bad)}): float vectors only")
    return [SimpleNamespace(location=v.location, name=v.name or f"in{v.location}", format=_VERTEX_FORMATS[v.type])
            for v in ep.inputs]


def _value(stat) -> float:
    """A statistic's value by its VkPipelineExecutableStatisticFormatKHR: bool32, int64, uint64, float64."""
    v, fmt = stat.value, int(stat.format)
    if fmt == 0:
        return int(bool(v.b32))
    if fmt == 3:
        return float(v.f64)
    return int(v.i64 if fmt == 1 else v.u64)


def _read(device, pipeline, capture_ir: bool) -> tuple[dict, dict]:
    """({stage: {statistic: value}}, {stage: internal representations as text}) of a created pipeline."""
    vk = device.vk
    props = vk.vkGetDeviceProcAddr(device.handle, "vkGetPipelineExecutablePropertiesKHR")
    stats = vk.vkGetDeviceProcAddr(device.handle, "vkGetPipelineExecutableStatisticsKHR")
    stats_of, ir_of = {}, {}
    for i, ex in enumerate(props(device.handle, vk.VkPipelineInfoKHR(pipeline=pipeline))):
        stage = next((name for bit, name in STAGES.items() if int(ex.stages) & bit), f"stages{int(ex.stages):#x}")
        info = vk.VkPipelineExecutableInfoKHR(pipeline=pipeline, executableIndex=i)
        stats_of[stage] = {str(s.name): _value(s) for s in stats(device.handle, info)}
        if capture_ir:
            ir_of[stage] = _internal_representations(device, pipeline, i)
    return stats_of, ir_of


def _internal_representations(device, pipeline, index: int) -> str:
    """Every text representation of executable `index` (ACO IR, disassembly …), one after the other."""
    vk = device.vk
    import vulkan._vulkan as raw  # the binding's wrapper of this two-call query mishandles pData; cffi's lib is direct

    ffi = vk.ffi
    name = ffi.new("char[]", b"vkGetPipelineExecutableInternalRepresentationsKHR")
    fn = ffi.cast("PFN_vkGetPipelineExecutableInternalRepresentationsKHR",
                  raw.lib.vkGetDeviceProcAddr(device.handle, name))
    info = ffi.new("VkPipelineExecutableInfoKHR*", {"sType": vk.VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_INFO_KHR,
                                                    "pipeline": pipeline, "executableIndex": index})
    count = ffi.new("uint32_t*")
    fn(device.handle, info, count, ffi.NULL)
    reps = ffi.new("VkPipelineExecutableInternalRepresentationKHR[]", count[0])
    for k in range(count[0]):
        reps[k].sType = vk.VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_INTERNAL_REPRESENTATION_KHR
    fn(device.handle, info, count, reps)  # sizes
    buffers = []
    for k in range(count[0]):
        buffers.append(ffi.new("char[]", reps[k].dataSize))
        reps[k].pData = buffers[-1]
    fn(device.handle, info, count, reps)
    parts = []
    for k in range(count[0]):
        if reps[k].isText:
            text = ffi.string(ffi.cast("char*", reps[k].pData)).decode(errors="replace")
            parts.append(f";; {ffi.string(reps[k].name).decode()}: {ffi.string(reps[k].description).decode()}\n{text}")
    return "\n".join(parts)


def _one(device, target, job: dict, flags: int) -> tuple[dict, dict]:
    """Create one job's pipeline with statistics captured; ({stage: statistics}, {stage: IR text})."""
    from .compute import ComputePipeline
    from .graphics import GraphicsPipeline

    stages = {s: base64.b64decode(b) for s, b in job["stages"]}
    spec = {int(k): int(v) for k, v in job["specialization"]} or None
    if "comp" in stages:
        sets = _layouts([stages["comp"]])
        binding = sets.get(0, {})
        if set(sets) - {0} or sorted(binding) != list(range(len(binding))):
            raise ValueError(f"a compute job binds set 0, bindings 0 … n-1 (got {sets})")
        p = ComputePipeline(device, stages["comp"], tuple(binding[b] for b in sorted(binding)),
                            specialization=spec, flags=flags)
    else:
        p = GraphicsPipeline(device, target, stages["vert"], stages["frag"], _vertex_inputs(stages["vert"]),
                             _layouts([stages["vert"], stages["frag"]]), specialization=spec, flags=flags)
    try:
        return _read(device, p.handle, bool(flags & CAPTURE_IR))
    finally:
        p.destroy()


def _worker(request: Path, out: Path, ir_dir: Path | None) -> int:
    from .device import Device
    from .rendertarget import RenderPassOnly
    from ..io import atomic_write

    device = Device(prefer="Null hardware", compile_only=True)
    results, errors = {}, {}
    flags = CAPTURE_STATISTICS | (CAPTURE_IR if ir_dir is not None else 0)
    try:
        target = RenderPassOnly(device)
        for job in json.loads(request.read_text()):
            try:  # one shader that cannot be made into a pipeline costs its own figures, not the family's
                results[job["key"]], ir = _one(device, target, job, flags)
            except Exception as e:  # noqa: BLE001 — reported per job, in one line
                errors[job["key"]] = f"{type(e).__name__}: {e}".splitlines()[0]
                continue
            for stage, text in ir.items():
                atomic_write(Path(ir_dir) / f"{job['key']}.{stage}.txt", text.encode())
    finally:
        device.close()
    v = int(device.properties.driverVersion)  # Mesa encodes its version as VK_MAKE_VERSION
    name = f"{device.name}, Mesa {v >> 22}.{(v >> 12) & 0x3FF}.{v & 0xFFF}"
    atomic_write(out, json.dumps({"device": name, "stats": results, "errors": errors}, sort_keys=True).encode())
    return 0


if __name__ == "__main__":
    args = sys.argv[1:]
    sys.exit(_worker(Path(args[0]), Path(args[1]), Path(args[2]) if len(args) > 2 else None))
