"""Platforms: what `build --platform vulkan,d3d12,gl,webgpu` writes for each, and its manifest.

A platform is what an engine loads, built from the languages (the SPIR-V checks of every language —
glslc/naga, spirv-opt, spirv-val, cost — run whatever the platforms):

    platform  tree       artifacts per stage                         validated by                 reflection
    vulkan    vulkan/    SPIR-V of the GLSL (`spirv`), and the GLSL,  glslc + spirv-opt + spirv-val sets and bindings
              <lang>/    HLSL and WGSL sources with their SPIR-V     (every language)
                         (debugging: what the other front ends make)
    d3d12     d3d12/     HLSL for Shader Model 6 (`hlsl`, the same   glslang's HLSL front end;    registers bN/tN/sN,
                         text as vulkan's: `register(xN, spaceM)`,   DXC when on PATH             spaceM; input layout
                         [[vk::…]] attributes that DXC ignores for
                         DXIL); `dxil` when a `dxc` is on PATH
    gl        gl/        GLSL 4.50 core (`glsl`) and GLSL ES 3.10     glslangValidator (OpenGL     uniform-block bindings,
                         (`essl`, where it validates) — backends/gl/emit.py and ES rules)               texture units
    webgpu    webgpu/    WGSL (`wgsl`, the vulkan tree's text)        naga                         bind groups

Per permutation the manifest's ``platforms`` maps each built platform to ``{"stages": {stage: {kind:
{"path", "sha256"}}}, "reflection": …, "cost": {stage: …} (where a SPIR-V module stands for it),
"tools": {tool: version}, …}``; everything else about the entry (``languages``, ``interface``,
``uploads``) is what it was. GLSL ES is "where the bricks allow": a permutation whose ES source does not
validate gets ``"essl": {"unsupported": [errors]}`` instead of an artifact, and still builds; a GL core
error fails the permutation like a compile error, its source written beside as
``gl/<hash>.<stage>.failed.glsl`` and named in the entry's ``failed_sources`` (``"gl.<stage>"``).

Each platform is one class below and one entry of PLATFORM_TABLE: what it is made from, its dialects, its
tools, its conventions (platform_base.Conventions: depth range, NDC y, framebuffer origin, front face), what
its check compiles, its optional binary step, and the methods writing its section, its reflection and its
sampler states. Adding a platform is adding a class and its entry; write_platforms, the build's key
(all_tools), the writer, checks, packs, sampler spellings and the output tree read the table and nothing
else about a platform.
"""
from __future__ import annotations

from ..backends import LANGUAGES
from . import samplers
from .platform_base import Conventions, Platform, Unit, resource_rows


class Vulkan(Platform):
    """SPIR-V of the GLSL, and every language's source and SPIR-V (what the other front ends make): the
    language trees' own files, so nothing is written here."""

    name, made_from, language, blob = "vulkan", "glsl", "glsl", "spirv"
    tools = ("glslc", "glslang", "spirv-tools", "naga")  # glslang: the HLSL's SPIR-V in the vulkan tree
    own_files = False
    checked_from = LANGUAGES  # a vulkan check compiles every language it is given to SPIR-V
    ubershader = True
    conventions = Conventions(depth_range="0..1", ndc_y="down", framebuffer_origin="top-left", front_face="ccw")
    front_face_state = {"frontFace": "VK_FRONT_FACE_COUNTER_CLOCKWISE"}
    cull_states = {"back": {"cullMode": "VK_CULL_MODE_BACK_BIT"}, "none": {"cullMode": "VK_CULL_MODE_NONE"}}
    formats = {"R8G8B8A8_SRGB": "VK_FORMAT_R8G8B8A8_SRGB", "R8G8B8A8_UNORM": "VK_FORMAT_R8G8B8A8_UNORM",
               "D32_SFLOAT": "VK_FORMAT_D32_SFLOAT"}
    _TYPES = {"uniform": "uniform_buffer", "storage": "storage_buffer", "image": "sampled_image", "sampler": "sampler"}

    def section(self, unit: Unit) -> dict:
        langs, stages = unit.langs, {}
        for stage in unit.stages:
            item = {"spirv": {"path": langs["glsl"][stage]["spirv"], "sha256": langs["glsl"][stage]["spirv_sha256"]}}
            for lang in langs:
                item[lang] = {"path": langs[lang][stage]["source"], "sha256": langs[lang][stage]["source_sha256"],
                              "spirv": langs[lang][stage]["spirv"]}
            stages[stage] = item
        return {"stages": stages, "spirv_from": "glsl", "cost": unit.cost("glsl")}

    def reflection(self, iface) -> dict:
        """Descriptor (set, binding, descriptor type) per resource."""
        return {"descriptors": [{"set": s, "binding": b, "type": self._TYPES[k], "name": n, "stages": st, **x}
                                for k, s, b, n, st, x in resource_rows(iface)],
                "vertex_inputs": [{"location": v.location, "name": v.name, "format": v.format}
                                  for v in iface.vertex_inputs],
                "push_constants": []}

    def block_binding(self, set_: int, binding: int) -> dict:
        return {"set": set_, "binding": binding}

    def spell_sampler(self, state: dict) -> dict:
        return samplers.vulkan(state)


class D3D12(Platform):
    """HLSL for Shader Model 6 (the vulkan tree's text: ``register(xN, spaceM)``), DXIL where a dxc is on PATH."""

    name, made_from, language, blob = "d3d12", "hlsl", "hlsl", "hlsl"
    tools = ("glslang", "dxc")
    ext = {"hlsl": "hlsl", "dxil": "dxil"}
    checked_from, binary = ("hlsl",), "dxil"
    conventions = Conventions(depth_range="0..1", ndc_y="up", framebuffer_origin="top-left", front_face="ccw")
    front_face_state = {"FrontCounterClockwise": True}  # D3D12_RASTERIZER_DESC; its default is clockwise
    cull_states = {"back": {"CullMode": "D3D12_CULL_MODE_BACK"}, "none": {"CullMode": "D3D12_CULL_MODE_NONE"}}
    formats = {"R8G8B8A8_SRGB": "DXGI_FORMAT_R8G8B8A8_UNORM_SRGB", "R8G8B8A8_UNORM": "DXGI_FORMAT_R8G8B8A8_UNORM",
               "D32_SFLOAT": "DXGI_FORMAT_D32_FLOAT"}
    _CLASSES = {"uniform": ("CBV", "b"), "storage": ("SRV", "t"), "image": ("SRV", "t"), "sampler": ("Sampler", "s")}
    _FORMATS = {"R32G32B32_SFLOAT": "DXGI_FORMAT_R32G32B32_FLOAT", "R32G32B32A32_SFLOAT": "DXGI_FORMAT_R32G32B32A32_FLOAT",
                "R32G32_SFLOAT": "DXGI_FORMAT_R32G32_FLOAT"}
    _SEMANTICS = {"a_position": ("POSITION", 0), "a_normal": ("NORMAL", 0), "a_tangent": ("TANGENT", 0),
                  "a_uv": ("TEXCOORD", 0), "a_color": ("COLOR", 0)}  # backends/hlsl/templates/vertex.hlsl.j2

    def section(self, unit: Unit) -> dict:
        from ..toolchain.platforms import DX_PROFILES
        stages = {}
        for stage in unit.stages:
            src = unit.sources[("hlsl", stage)]
            item = {"hlsl": self.put(unit, stage, src.text.encode(), "hlsl")}
            step = unit.steps.get(self.name)
            if step is not None:
                blob, errors = step(unit.name, src, unit.precision)
                unit.errors += errors
                if blob is not None:
                    item[self.binary] = self.put(unit, stage, blob, self.binary)
            stages[stage] = item
        return {"stages": stages, "profiles": {s: DX_PROFILES[(s, unit.precision)] for s in unit.stages},
                "dxil": "built" if self.name in unit.steps else
                "no dxc on PATH: HLSL only (docs/guide/install.md: where to get dxc)",
                "cost": unit.cost("hlsl"), "cost_from": "hlsl SPIR-V (glslang)"}

    def reflection(self, iface) -> dict:
        """Register class and number, space, and the input layout's semantics."""
        cls = self._CLASSES
        return {"resources": [{"name": n, "type": cls[k][0], "register": f"{cls[k][1]}{b}", "space": s,
                               "visibility": st, **x} for k, s, b, n, st, x in resource_rows(iface)],
                "input_layout": [{"semantic": self._SEMANTICS[v.name][0], "semantic_index": self._SEMANTICS[v.name][1],
                                  "format": self._FORMATS[v.format], "name": v.name} for v in iface.vertex_inputs]}

    def block_binding(self, set_: int, binding: int) -> dict:
        return {"register": f"b{binding}", "space": set_}

    def binary_step(self):
        """DXC, or None when no dxc is on PATH (docs/guide/install.md: where to get one)."""
        from ..toolchain import CompileJob, find_tool
        from ..toolchain.jobs import job_key
        from ..toolchain.platforms import compile_dxil
        if find_tool("dxc") is None:
            return None
        return lambda name, src, precision: compile_dxil(
            CompileJob(job_key(name, src.stage, "dxil"), "hlsl", src.stage, src.text), precision)

    def check_note(self) -> str | None:
        from ..toolchain import find_tool
        if find_tool("dxc") is not None:
            return None
        return ("no dxc on PATH: d3d12 checks validate the HLSL with glslang's HLSL front end only, no DXIL "
                "(docs/guide/install.md: where to get dxc)")

    def spell_sampler(self, state: dict) -> dict:
        return samplers.d3d12(state)


class Gl(Platform):
    """GLSL 4.50 core and, where the bricks allow, GLSL ES 3.10: the `gl` and `essl` dialects (a GlslTarget
    subclass each, backends/gl/emit.py), validated by glslangValidator."""

    name, made_from, language, blob = "gl", "glsl", "gl", "glsl"
    dialects = ("gl", "essl")
    checked_from, optional_dialects = ("glsl",), ("essl",)
    dialect_titles = {"gl": "GLSL 4.50 core", "essl": "GLSL ES 3.10"}
    tools = ("glslang",)
    ext = {"gl": "glsl", "essl": "essl"}
    conventions = Conventions(depth_range="-1..1", ndc_y="up", framebuffer_origin="bottom-left", front_face="ccw")
    front_face_state = {"glFrontFace": "GL_CCW"}  # OpenGL's default
    cull_states = {"back": {"glEnable": "GL_CULL_FACE", "glCullFace": "GL_BACK"}, "none": {"glDisable": "GL_CULL_FACE"}}
    formats = {"R8G8B8A8_SRGB": "GL_SRGB8_ALPHA8", "R8G8B8A8_UNORM": "GL_RGBA8", "D32_SFLOAT": "GL_DEPTH_COMPONENT32F"}
    extra_state = {"depth_range_0_1": "glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE) (OpenGL 4.5 or ARB_clip_control; "
                                      "ES: EXT_clip_control) maps clip z / w in 0..1 to depth as the other platforms "
                                      "do; without it the projection must put z / w in -1..1",
                   "srgb_write": "glEnable(GL_FRAMEBUFFER_SRGB) on desktop OpenGL, or a GL_SRGB8_ALPHA8 attachment "
                                 "stores what is written unencoded (OpenGL ES encodes always)"}

    def section(self, unit: Unit) -> dict:
        name = unit.name
        es_errors = [e for s in unit.stages for e in unit.dialect_errors.get(f"{name}.{s}.essl", [])]
        stages = {}
        for stage in unit.stages:
            core = unit.dialect_errors.get(f"{name}.{stage}.gl", [])
            text = unit.text("gl", stage)
            if core:  # it fails the permutation: the source beside, as a compile failure's (write.Writer.unit)
                unit.errors += core
                rel = f"gl/{name}.{stage}.failed.{self.ext['gl']}"
                unit.write(rel, text)
                unit.entry.setdefault("failed_sources", {})[f"gl.{stage}"] = rel
                continue
            item = {"glsl": self.put(unit, stage, text, "gl")}
            if not es_errors:
                item["essl"] = self.put(unit, stage, unit.text("essl", stage), "essl")
            stages[stage] = item
        return {"stages": stages, "versions": {"glsl": "450 core", "essl": "310 es"},
                "essl": "ok" if not es_errors else {"unsupported": es_errors}}

    def reflection(self, iface) -> dict:
        """Uniform-block binding points, texture units and storage-block bindings (backends/gl/emit.py
        gl_bindings: Vulkan's pairs flattened per namespace)."""
        from ..backends.gl.emit import gl_bindings
        m = gl_bindings(iface.blocks, iface.textures)
        rows = resource_rows(iface)
        blocks = [r for r in rows if r[0] in ("uniform", "storage")]
        return {"uniform_blocks": [{"name": n, "binding": m["uniform"][(s, b)], "stages": st}
                                   for k, s, b, n, st, _ in blocks if k == "uniform"],
                "storage_blocks": [{"name": n, "binding": m["storage"][(s, b)], "stages": st}
                                   for k, s, b, n, st, _ in blocks if k == "storage"],
                "samplers": [{"name": n, "unit": m["texture"][(s, b)], "type": _gl_sampler(x), **x}
                             for k, s, b, n, st, x in rows if k == "image"],
                "vertex_inputs": [{"location": v.location, "name": v.name} for v in iface.vertex_inputs]}

    def block_binding(self, set_: int, binding: int) -> dict:
        return {"binding": None}  # gl_bindings numbers a program's blocks in order: see each reflection

    def spell_sampler(self, state: dict) -> dict:
        return samplers.gl(state)


def _gl_sampler(x: dict) -> str:
    if x["compare"]:
        return {"2d": "sampler2DShadow", "2d_array": "sampler2DArrayShadow"}[x["dimension"]]
    return {"2d": "sampler2D", "cube": "samplerCube", "2d_array": "sampler2DArray",
            "cube_array": "samplerCubeArray"}[x["dimension"]]


# GPUTextureViewDimension of each texture dimension
_VIEW_DIMENSIONS = {"2d": "2d", "cube": "cube", "2d_array": "2d-array", "cube_array": "cube-array"}


class WebGpu(Platform):
    """WGSL (the vulkan tree's text), validated by naga."""

    name, made_from, language, blob = "webgpu", "wgsl", "wgsl", "wgsl"
    tools = ("naga",)
    ext = {"wgsl": "wgsl"}
    checked_from = ("wgsl",)
    conventions = Conventions(depth_range="0..1", ndc_y="up", framebuffer_origin="top-left", front_face="ccw")
    front_face_state = {"frontFace": "ccw"}  # GPUPrimitiveState; the default
    cull_states = {"back": {"cullMode": "back"}, "none": {"cullMode": "none"}}
    formats = {"R8G8B8A8_SRGB": "rgba8unorm-srgb", "R8G8B8A8_UNORM": "rgba8unorm", "D32_SFLOAT": "depth32float"}
    _FORMATS = {"R32G32B32_SFLOAT": "float32x3", "R32G32B32A32_SFLOAT": "float32x4", "R32G32_SFLOAT": "float32x2"}
    _VISIBILITY = {"vert": "VERTEX", "frag": "FRAGMENT"}

    def section(self, unit: Unit) -> dict:
        return {"stages": {s: {"wgsl": self.put(unit, s, unit.text("wgsl", s), "wgsl")} for s in unit.stages},
                "cost": unit.cost("wgsl"), "cost_from": "wgsl SPIR-V (naga)"}

    def reflection(self, iface) -> dict:
        """Bind group, binding and the GPUBindGroupLayoutEntry resource type."""
        def resource(k, x):
            if k in ("uniform", "storage"):
                return {"buffer": {"type": "uniform" if k == "uniform" else "read-only-storage"}}
            if k == "image":
                return {"texture": {"sampleType": "depth" if x["compare"] else "float", "viewDimension": _VIEW_DIMENSIONS[x["dimension"]]}}
            return {"sampler": {"type": "comparison" if x["compare"] else "filtering"}}
        return {"bind_groups": [{"group": s, "binding": b, "name": n, "visibility": [self._VISIBILITY[v] for v in st],
                                 **resource(k, x)} for k, s, b, n, st, x in resource_rows(iface)],
                "vertex_inputs": [{"shaderLocation": v.location, "name": v.name, "format": self._FORMATS[v.format]}
                                  for v in iface.vertex_inputs]}

    def block_binding(self, set_: int, binding: int) -> dict:
        return {"group": set_, "binding": binding}

    def spell_sampler(self, state: dict) -> dict:
        return samplers.webgpu(state)


# The one table of the platforms, in build order (the manifest's and --platform's).
PLATFORM_TABLE: dict[str, Platform] = {p.name: p for p in (Vulkan(), D3D12(), Gl(), WebGpu())}
PLATFORMS: tuple[str, ...] = tuple(PLATFORM_TABLE)
DIALECTS = {p.name: p.dialects for p in PLATFORM_TABLE.values() if p.dialects}  # compose.Composed.dialects
EXT = {kind: ext for p in PLATFORM_TABLE.values() for kind, ext in p.ext.items()}  # artifact kind -> extension
# the tree holding every language's sources and SPIR-V (<tree>/<language>/): the platform whose stages name them
LANGUAGE_TREE = next(p.name for p in PLATFORM_TABLE.values() if not p.own_files)


def parse_platforms(text: str) -> list[str]:
    """"vulkan,gl" -> ["vulkan", "gl"] (in the table's order); ValueError naming the problem."""
    items = [x.strip() for x in text.split(",") if x.strip()]
    bad = [x for x in items if x not in PLATFORM_TABLE]
    if not items or bad or len(set(items)) != len(items):
        raise ValueError(f"{text!r} is not a comma-separated list of {', '.join(PLATFORM_TABLE)}, each at most once")
    return [p for p in PLATFORM_TABLE if p in items]


def dialects_of(platforms) -> tuple[str, ...]:
    return tuple(d for p in platforms for d in PLATFORM_TABLE[p].dialects)


def platform_tools(platform: str) -> dict[str, str]:
    """The exact versions of the tools that made and checked a platform's artifacts."""
    return PLATFORM_TABLE[platform].tool_versions()


def all_tools(platforms) -> dict:
    """Every platform's tools (for the build's key: a tool installed or upgraded rebuilds)."""
    return {p: platform_tools(p) for p in platforms}


def write_platforms(write, name: str, composed, entry: dict, platforms, dialect_errors: dict, precision: str,
                    steps=None) -> list[str]:
    """Fill entry["platforms"] for one permutation whose languages compiled (entry["languages"] is written);
    returns the errors that fail it (a GL core stage's among them, its source then written beside and named in
    entry["failed_sources"]). write(rel, data): the build's atomic writer. dialect_errors: job key ->
    glslangValidator errors. steps: {platform: its binary step} (Platform.binary_step; a platform absent: none)."""
    unit = Unit(name, composed, entry, precision, dialect_errors, write, steps or {})
    chosen = [PLATFORM_TABLE[p] for p in platforms]
    # a build of fewer languages (BuildContext(languages=...)) writes the platforms they make
    entry["platforms"] = {p.name: p.manifest(unit) for p in chosen if p.builds(unit)}
    return unit.errors


def platform_files(entry: dict):
    """(path, sha256) of every file a manifest entry's platforms name in their own trees (vulkan's are the
    language trees' files, tracked with them)."""
    for p, d in (entry.get("platforms") or {}).items():
        if not PLATFORM_TABLE[p].own_files:
            continue
        for item in d.get("stages", {}).values():
            for art in item.values():
                yield art["path"], art["sha256"]
