"""What every platform is: the base class the rows of platforms.PLATFORM_TABLE derive from, the conventions
each declares, and the one permutation its manifest section is written from.

A platform declares as data what it is made from (the language whose build it needs), the dialects composed
for it beside the languages, the tools whose versions make its artifacts, the extensions of the artifact kinds
it writes and its conventions; it has two methods of its own: ``section`` (the stages and the fields after
them, from the composed sources and the per-language results) and ``reflection`` (the Interface in its
binding model). ``manifest`` adds the reflection and the tool versions the same way for every platform, so
the build's loop (platforms.write_platforms) asks nothing of a platform but these.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

from ..io import sha256


@dataclass(frozen=True)
class Conventions:
    """How a platform's API reads what the vertex stage writes. The shaders pass ``frame.view_proj * world``
    through unchanged, so these are the API's own rules, which an engine's projection and pipeline state
    follow (the runtime renders Vulkan's: runtime/camera.py, runtime/graphics.py)."""

    depth_range: str        # clip z / w mapped to the depth buffer: "0..1", or "-1..1" (OpenGL without clip control)
    ndc_y: str              # where NDC +y points in the framebuffer: "down" (Vulkan) or "up"
    framebuffer_origin: str  # where pixel row 0 is: "top-left", or "bottom-left" (OpenGL's window coordinates)
    front_face: str         # the winding of a front face as the API states it for the meshes' counter-clockwise
    #                         triangles (glTF 2.0's) under a projection into this clip space: "ccw" everywhere,
    #                         which D3D12 must be told (FrontCounterClockwise; its default is clockwise)


@dataclass
class Unit:
    """One permutation whose languages compiled, as its platforms' sections read it: its name (hash), the
    Composed sources and dialects, the manifest entry (``languages`` written), its precision, the dialect
    sources' glslangValidator errors (job key -> errors), the build's atomic writer and the platforms' binary
    steps ({platform: Platform.binary_step()}, those it has: d3d12's DXC where a dxc is on PATH). ``errors``
    collects what fails the permutation (a GL core stage's, DXC's)."""

    name: str
    composed: object
    entry: dict
    precision: str
    dialect_errors: dict
    write: Callable[[str, bytes], None]
    steps: dict[str, Callable] = field(default_factory=dict)
    errors: list[str] = field(default_factory=list)
    sources: dict = field(init=False)  # (language or dialect, stage) -> Source
    stages: list[str] = field(init=False)  # in pipeline order

    def __post_init__(self):
        c = self.composed
        self.sources = {(s.language, s.stage): s for s in [*c.sources, *c.dialects]}
        self.stages = sorted({s.stage for s in c.sources}, key=("vert", "frag", "comp").index)

    @property
    def langs(self) -> dict:
        """The entry's per-language results: language -> stage -> {source, spirv, their sha256, cost}."""
        return self.entry["languages"]

    def text(self, language: str, stage: str) -> bytes:
        return self.sources[(language, stage)].text.encode()

    def cost(self, language: str) -> dict:
        """Per stage, the cost of `language`'s SPIR-V (the module standing for a platform's artifact)."""
        return {s: self.langs[language][s]["cost"] for s in self.stages}


class Platform:
    """One platform: what `build --platform NAME` writes into OUT/NAME/ and the manifest's ``platforms.NAME``.
    Subclasses set the class attributes and implement ``section`` and ``reflection``."""

    name: str
    made_from: str  # the language `build` must build for the platform to be written (BuildContext(languages=...))
    language: str   # the dialect of its main artifact's source: the pack meta's and manifest ``packs``' "language"
    blob: str       # the kind of its main artifact in the manifest's stages and the pack (d3d12: "dxil" where built)
    dialects: tuple[str, ...] = ()  # composed beside the languages for it (compose.Composed.dialects)
    tools: tuple[str, ...] = ()     # whose exact versions its manifest and the build's key record
    ext: dict[str, str] = {}        # artifact kind -> file extension of what it writes into its own tree
    own_files: bool = True          # False: its stages name the language trees' files (they are tracked there)
    # the languages a check of it (assemble/checks.py) compiles when asked for (vulkan: any of them); a platform
    # with dialects is checked as its dialects, composed from its made_from
    checked_from: tuple[str, ...] = ()
    # dialects shipped where they validate: a failure is a note ("unsupported"), not an error (gl: GLSL ES)
    optional_dialects: tuple[str, ...] = ()
    dialect_titles: dict[str, str] = {}  # dialect -> how a note names it ("GLSL ES 3.10")
    binary: str | None = None       # the artifact kind an optional tool compiles its main source to (d3d12: dxil)
    ubershader: bool = False        # whether its pack holds the ubershader (its made_from's SPIR-V)
    conventions: Conventions
    # the conventions in the API's words (the manifest's conventions.platforms.<name>): the pipeline state that
    # makes a counter-clockwise triangle a front face, each cull mode of a render state, the attachment formats
    # by their API-neutral names (runtime/pipeline_state.py COLOR_FORMATS, DEPTH_FORMAT), and where a state
    # the API needs besides them (gl: the clip control that makes depth 0..1, the sRGB write switch) is named
    front_face_state: dict = {}
    cull_states: dict = {}
    formats: dict[str, str] = {}
    extra_state: dict[str, str] = {}

    def builds(self, unit: Unit) -> bool:
        """Whether this permutation's build makes the platform (a build of fewer languages makes fewer)."""
        return self.made_from in unit.langs and all((d, unit.stages[0]) in unit.sources for d in self.dialects)

    def binary_step(self):
        """The step compiling a stage's source to `binary`: callable(name, source, precision) -> (bytes | None,
        errors); None where the platform has none or its tool is not on PATH."""
        return None

    def check_note(self) -> str | None:
        """What a check of this platform leaves out on this machine (a tool not on PATH), or None."""
        return None

    def block_binding(self, set_: int, binding: int) -> dict:
        """Where a uniform block at Vulkan's (set, binding) binds on this platform, in its reflection's words; a
        value that differs by permutation (gl numbers its blocks per program) is None there."""
        raise NotImplementedError

    def conventions_section(self) -> dict:
        """The manifest's conventions.platforms.<name>: clip space, front face and cull modes, attachment
        formats and where the Object block binds (runtime/pipeline_state.py states what it holds)."""
        from ..runtime.pipeline_state import COLOR_FORMATS, DEPTH_CLEAR, DEPTH_FORMAT, OBJECT_SET_BINDING
        c = self.conventions
        d = {"clip": {"depth_range": c.depth_range, "ndc_y": c.ndc_y, "framebuffer_origin": c.framebuffer_origin},
             "front_face": {"winding": c.front_face, "state": dict(self.front_face_state)},
             "cull": {mode: dict(state) for mode, state in self.cull_states.items()},
             "attachments": {"color": {k: self.formats[f] for k, f in COLOR_FORMATS.items()},
                             "depth": self.formats[DEPTH_FORMAT], "depth_clear": DEPTH_CLEAR},
             "object_block": self.block_binding(*OBJECT_SET_BINDING)}
        if self.extra_state:
            d["state"] = dict(self.extra_state)
        return d

    def spell_sampler(self, state: dict) -> dict:
        """A sampler state (scene/textures.Sampler.as_dict) in this API's words (assemble/samplers.py)."""
        raise NotImplementedError

    def section(self, unit: Unit) -> dict:
        """{"stages": {stage: {kind: {"path", "sha256"}}}, and the platform's own fields after them}."""
        raise NotImplementedError

    def reflection(self, iface) -> dict:
        """The Interface in this platform's binding model, by the names its sources declare."""
        raise NotImplementedError

    def manifest(self, unit: Unit) -> dict:
        """The platform's manifest section: its section, then its reflection and its tools' versions."""
        d = self.section(unit)
        d["reflection"] = self.reflection(unit.composed.interface)
        d["tools"] = self.tool_versions()
        return d

    def tool_versions(self) -> dict[str, str]:
        """{tool: exact version} of the tools it names, in their order (dxc, optional, is "missing" where it is
        not on PATH; it is asked for only by a platform that names it)."""
        from ..toolchain import tool_versions
        from ..toolchain.platforms import dxc_version
        known = tool_versions()
        return {t: dxc_version() if t == "dxc" else known[t] for t in self.tools}

    def put(self, unit: Unit, stage: str, data: bytes, kind: str) -> dict:
        """Write one artifact into the platform's tree under a content name; its manifest item."""
        digest = sha256(data)
        rel = f"{self.name}/{unit.name}.{stage}.{digest[:12]}.{self.ext[kind]}"
        unit.write(rel, data)
        return {"path": rel, "sha256": digest}


# --------------------------------------------------------- the resources every binding model is spelled from

_STAGES = {"Frame": ["vert", "frag"], "Object": ["vert"]}  # every other block and texture: the fragment stage


def resource_rows(iface) -> list[tuple]:
    """(kind, set, binding, name, stages, extra) of every resource, in (set, binding) order: blocks, then each
    texture's image and sampler (the sampler at binding + 1)."""
    from ..backends import get_target
    glsl = get_target("glsl")
    rows = [(b.kind, b.set, b.binding, b.name, _STAGES.get(b.name, ["frag"]), {}) for b in iface.blocks]
    for t in iface.textures:
        compare = bool(getattr(t, "compare", False))
        info = {"dimension": t.dim, "compare": compare, "parameter": t.param}
        rows.append(("image", t.set, t.binding, glsl.ident(t.name), ["frag"], info))
        rows.append(("sampler", t.set, t.binding + 1, glsl.sampler_name(t.name), ["frag"], info))
    return sorted(rows, key=lambda r: (r[1], r[2]))
