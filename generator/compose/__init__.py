"""Compose bricks and templates into per-target shader sources.

For a Permutation: a vertex and a fragment shader per language. For a BRDF
spec: a compute eval kernel per language (f_r over a buffer of samples).
Only the inputs, interpolants, uniforms and textures the chosen bricks read
are declared. Every file starts with a provenance header; output is a pure
function of the bricks, templates and generator version (no timestamps).
"""
from __future__ import annotations

import hashlib
from dataclasses import dataclass, field

import jinja2

from .. import __version__
from ..library.bricks import Library
from ..link import EvalProgram, Interface, LinkedPermutation, Slot, eval_program, link_permutation
from ..spec.permutation import Permutation
from ..backends import LANGUAGES, TEMPLATE_PACKAGES, Language, language, template_file
from ..backends.base import Emitted
from ..backends.clike.records import FunctionRecords


class _TemplateLoader(jinja2.PrefixLoader):
    """Templates by name: "glsl/fragment.glsl.j2" is fragment.glsl.j2 in the templates/ folder of the back end
    owning folder "glsl" (backends.TEMPLATE_PACKAGES), read by a jinja2.PackageLoader wherever the package is
    installed. (A build's depfile lists the templates its composed units name, not what a process loaded.)"""

    # A template compiles under its full name, as it did from one folder (PrefixLoader.load would hand the
    # package's loader the name without its folder): Jinja's messages name "glsl/fragment.glsl.j2".
    load = jinja2.BaseLoader.load


class _CompiledTemplates(jinja2.BytecodeCache):
    """Compiled templates by their name and the sha1 of their source (Jinja checks it on every load, and compiles
    again when the file changed): what a Templates' environment compiles, a later one loads instead of compiling
    (200 ms for the 21 templates). Content-addressed, so it changes no output and nothing of one build reaches
    another; every environment using it is made by jinja_env, with the same settings."""

    def __init__(self):
        self._code: dict[str, bytes] = {}

    def load_bytecode(self, bucket) -> None:
        code = self._code.get(bucket.key)
        if code is not None:
            bucket.bytecode_from_string(code)  # a checksum that differs resets the bucket: compiled again

    def dump_bytecode(self, bucket) -> None:
        self._code[bucket.key] = bucket.bytecode_to_string()


_COMPILED = _CompiledTemplates()


def jinja_env() -> jinja2.Environment:
    """A Jinja environment over the back ends' templates (StrictUndefined: a missing value is an error, not an
    empty string)."""
    return jinja2.Environment(
        loader=_TemplateLoader({folder: jinja2.PackageLoader(package, "templates")
                                 for folder, package in TEMPLATE_PACKAGES.items()}),
        undefined=jinja2.StrictUndefined,
        trim_blocks=True,
        lstrip_blocks=True,
        keep_trailing_newline=True,
        autoescape=False,
        bytecode_cache=_COMPILED,
    )


class Templates:
    """The templates units are rendered from: one Jinja environment, which loads (through PackageLoader) and
    compiles each template once, however many units render it."""

    def __init__(self):
        self.env = jinja_env()

    def render(self, name: str, **ctx) -> str:
        return self.env.get_template(name).render(**ctx)


@dataclass
class Composing:
    """What composition keeps between the units of one library: its templates, and the C-like emitters' records
    of the linked functions they emitted (a linked brick function is shared by every program of a library, so
    an emitter replays it instead of walking it again: backends/clike/records.py).

    Held in the library's memo (composing(lib)), so it lives exactly as long as the library: a build composes
    with its own, a build worker (which gets the bricks without the memo) with one of its own, and nothing of
    one library's composition is seen by another."""

    templates: Templates = field(default_factory=Templates)
    records: FunctionRecords = field(default_factory=FunctionRecords)


_COMPOSING = ("compose", "state")  # its key in Library.memo


def composing(lib: Library) -> Composing:
    """The composition state of library `lib` (made on its first unit)."""
    state = lib.memo.get(_COMPOSING)
    if state is None:
        state = lib.memo[_COMPOSING] = Composing()
    return state


@dataclass
class Source:
    language: str
    stage: str
    text: str
    line_map: list = field(default_factory=list)


@dataclass
class Composed:
    """Everything built for one permutation or one eval spec."""

    key: str  # canonical id
    hash: str
    sources: list[Source]
    bricks: dict[str, str]  # display path -> source hash
    templates: dict[str, str]  # template name -> hash
    interface: Interface
    material: list[Slot] = field(default_factory=list)
    lights: list[list[Slot]] = field(default_factory=list)
    dialects: list[Source] = field(default_factory=list)  # platform dialects (gl, essl): validated, not SPIR-V
    environment: list[Slot] = field(default_factory=list)  # the environment's values in the Lights block


def _template_hash(name: str) -> str:
    return hashlib.sha256(template_file(name).read_bytes()).hexdigest()[:12]


def _templates_used(lang: Language, main: str) -> dict[str, str]:
    """The template and the templates it imports, with their hashes (for provenance and cache keys)."""
    return {n: _template_hash(n) for n in (main, *lang.imports)}


LINE_RESET = "//@line-reset"


def _function(prog, name: str):
    """The linked function `name` of a program (an entry point)."""
    return next(f for f in prog.functions if f.name == name)


def _emit(lib: Library, target, prog, globals_: bool = True):
    """The program's structs, globals (unless not `globals_`) and functions in `target`, replaying what this
    library's units emitted before (Composing.records)."""
    return target.emit(prog.structs, prog.functions, prog.globals if globals_ else (), records=composing(lib).records)


def placed(text: str, target, emitted, name: str) -> tuple[str, int]:
    """A rendered template's text with its #line resets written for file `name`, and the line at which the
    emitted functions start in it (their line map is shifted by that much)."""
    lines = text.split("\n")
    for i, line in enumerate(lines):
        if line.strip() == LINE_RESET:
            lines[i] = target.line_reset(i + 2, name)
    text = "\n".join(lines)
    return text, (text[: text.index(emitted.text)].count("\n") if emitted.text else 0)


def _render(lib: Library, template: str, target, ctx: dict, emitted, name: str) -> Source:
    """Render one template with the library's Templates; `name` is the generated file's name for #line resets."""
    text, offset = placed(composing(lib).templates.render(template, target=target, functions=emitted.text, **ctx),
                          target, emitted, name)
    stage = template.split("/")[1].split(".")[0]
    stage = {"vertex": "vert", "fragment": "frag", "ubershader": "frag", "eval": "comp", "shade": "comp"}[stage]
    return Source(target.name, stage, text, emitted.shifted(offset))


def _provenance(kind: str, key: str, h: str, bricks: dict, templates: dict) -> list[str]:
    lines = [f"generated by shadermatrix {__version__} — do not edit", f"{kind}: {key}", f"hash: {h}"]
    lines += [f"brick {p} sha256:{s[:12]}" for p, s in sorted(bricks.items())]
    lines += [f"template {t} sha256:{s}" for t, s in sorted(templates.items())]
    return lines


# ------------------------------------------------------------------ eval kernel

def compose_eval(spec: str, lib: Library, languages=LANGUAGES, ep: EvalProgram | None = None,
                 precision: str = "fp32") -> Composed:
    """The compute eval kernel of one BRDF spec (or a linked `ep`): f_r for each (L, V, N[, T]) sample
    (precision "fp16": the BRDF computes in half; samples, parameters and result stay 32-bit)."""
    ep = ep or eval_program(spec, lib)
    prog, canon, h = ep.program, ep.spec, ep.hash
    if precision != "fp32":  # an fp16 kernel is another kernel: its key, hash and name say so (fp32 ones unchanged)
        canon = f"{canon};precision={precision}"
        h = hashlib.sha256(("eval:" + canon).encode()).hexdigest()[:12]
    bricks = {p: b.module.source_hash for p, b in prog.bricks.items()}
    templates = {}
    sources = []
    for lang in map(language, languages):
        target = lang.target(precision)
        emitted = _emit(lib, target, prog, globals_=False)
        emitted, entry = target.entry32(emitted, _function(prog, ep.entry))  # fp16: a 32-bit wrapper
        tname = lang.template("eval")
        used = _templates_used(lang, tname)
        templates.update(used)
        ctx = {"provenance": _provenance("eval", canon, h, bricks, used),
               "params": ep.slots, "param_vec4s": max(ep.param_vec4s, 1), "tangent": ep.tangent,
               "brdf": entry, "switch": ep.entry == "brdf_switch",
               "textures": ep.interface.textures}
        sources.append(_render(lib, tname, target, ctx, emitted, f"{h}.comp.{lang.name}"))
    return Composed(canon, h, sources, bricks, templates, ep.interface)


# ------------------------------------------------------------------ permutation

def _call_args(lp) -> list[dict]:
    """How a template passes each shade() parameter: a local, a texture, or a slot of a block."""
    slots = {s.name: ("material", s) for s in lp.material} | {s.name: ("lights", s) for ls in lp.lights for s in ls} \
        | {s.name: ("lights", s) for s in lp.environment}
    out = []
    for name, ty in lp.glue.signature:
        if ty.kind == "texture":
            out.append({"kind": "texture", "name": name})
        elif name in slots:
            out.append({"kind": slots[name][0], "name": name, "slot": slots[name][1]})
        else:
            out.append({"kind": "local", "name": name})
    return out


def compose_shade_kernel(perm: Permutation, lib: Library, languages=LANGUAGES) -> Composed:
    """A compute kernel running the permutation's shade() per sample (P, Ng, V[, T][, uv] from a buffer).

    The fragment glue, executed without a graphics pipeline: tests run it on lavapipe.
    Layout: link.SHADE_KERNEL (set 0: samples 0, result 1, Info 2, Lights 3, Material 4, light buffers 5+).
    """
    lp = link_permutation(perm, lib, kernel=True)
    prog, iface = lp.program, lp.interface
    h = hashlib.sha256(("shade:" + perm.canonical()).encode()).hexdigest()[:12]
    bricks = {p: b.module.source_hash for p, b in prog.bricks.items()}
    surface = iface.surface
    layout_ = ["P", "Ng", "V"] + (["T"] if "T" in surface else []) + (["uv"] if "uv" in surface else [])
    templates, sources = {}, []
    for lang in map(language, languages):
        target = lang.target(perm.precision)
        emitted = _emit(lib, target, prog)
        emitted, shade = target.entry32(emitted, _function(prog, "shade"))  # fp16: a 32-bit wrapper
        tname = lang.template("shade")
        used = _templates_used(lang, tname)
        templates.update(used)
        ctx = {"provenance": _provenance("shade kernel", perm.canonical(), h, bricks, used),
               "inputs": surface, "samples": layout_, "call_args": _call_args(lp), "shade": shade,
               "material_vec4s": iface.block("Material").members[-1]["size"] // 16,
               "light_vec4s": iface.block("Lights").members[-1]["size"] // 16, "uber": False}
        sources.append(_render(lib, tname, target, ctx, emitted, f"{h}.comp.{lang.name}"))
    return Composed(perm.canonical(), h, sources, bricks, templates, iface, material=lp.material, lights=lp.lights)


def compose_permutation(perm: Permutation | LinkedPermutation, lib: Library, languages=LANGUAGES,
                        dialects=()) -> Composed:
    """Vertex and fragment shaders of one permutation in each language, and in each platform dialect of
    `dialects` ("gl": GLSL 4.50 core for OpenGL, "essl": GLSL ES 3.10; backends/gl/emit.py) into .dialects.
    `perm` linked already (link.link_permutation of its spec.resolve value) is composed as it is."""
    lp = perm if isinstance(perm, LinkedPermutation) else link_permutation(perm, lib)
    perm = lp.perm
    iface = lp.interface
    bricks = {p: b.module.source_hash for p, b in lp.program.bricks.items()}
    templates = {}
    sources = []
    for lang in languages:
        sources += _stage_sources(lib, lp, language(lang), "permutation", bricks, templates)
    extra = []
    for d in dialects:  # the platform dialects (GL's: gl/templates/, with the Vulkan GLSL's macros)
        extra += _stage_sources(lib, lp, language(d), f"permutation ({d})", bricks, templates)
    return Composed(perm.canonical(), perm.hash, sources, bricks, templates, iface, material=lp.material,
                    lights=lp.lights, dialects=extra, environment=lp.environment)


def _stage_sources(lib: Library, lp: LinkedPermutation, lang: Language, label: str, bricks, templates) -> list[Source]:
    """A permutation's vertex and fragment shaders in language or dialect `lang` (sources named
    <hash>.<vert|frag>.<lang.name>); the templates used and their hashes go into `templates`."""
    perm, prog, iface, h = lp.perm, lp.program, lp.interface, lp.perm.hash
    mat, lights = iface.block("Material"), iface.block("Lights")
    target = lang.target(perm.precision, iface)
    emitted = _emit(lib, target, prog)
    emitted, shade = target.entry32(emitted, _function(prog, "shade"))  # fp16: a 32-bit wrapper
    call_args = _call_args(lp)
    out = []
    for stage in ("vertex", "fragment"):
        tname = lang.template(stage)
        used = _templates_used(lang, tname)
        templates.update(used)
        ctx = {"provenance": _provenance(label, perm.canonical(), h, bricks, used),
               "inputs": iface.surface, "material_vec4s": mat.members[-1]["size"] // 16 if mat else 0,
               "light_vec4s": lights.members[-1]["size"] // 16 if lights else 0,
               "textures": iface.textures, "call_args": call_args, "shade": shade, "surface": perm.surface,
               "iface": iface, **lang.context()}
        out.append(_render(lib, tname, target, ctx, emitted if stage == "fragment" else Emitted(""),
                           f"{h}.{'frag' if stage == 'fragment' else 'vert'}.{lang.name}"))
    return out
