"""The ubershader's sources: a vertex and fragment shader per language, and the compute stand-in tests run."""
from __future__ import annotations

import hashlib

from ..library.bricks import Library
from ..link.uber import ALPHA_MODE_FUNCTION, Uber, link_ubershader
from ..spec.permutation import Permutation
from ..backends import LANGUAGES, language
from ..backends.base import Emitted
from . import Composed, _emit, _function, _provenance, _render, _templates_used


def uber_key(perms: list[Permutation]) -> str:
    """The ubershader's id: the canonical keys it stands in for, in order (the order numbers the variants)."""
    return "ubershader:" + "|".join(p.canonical() for p in perms)


def _call_args(u: Uber, material: dict | None) -> list[dict]:
    out = []
    for name, ty in u.signature:
        if ty.kind == "texture":
            out.append({"kind": "texture", "name": name})
        elif name == "material" and material is not None:
            out.append({"kind": "expr", "name": name, "text": material})
        else:
            out.append({"kind": "local", "name": name})
    return out


def _precision(perms) -> str:
    """The permutations' precision when they all share one (a scene's), else fp32."""
    found = {p.precision for p in perms}
    return found.pop() if len(found) == 1 else "fp32"


def compose_ubershader(perms: list[Permutation], lib: Library, languages=LANGUAGES,
                       specialized: bool = False) -> tuple[Composed, Uber]:
    """The fragment ubershader (and its vertex shader) standing in for every permutation of `perms`.

    specialized: the variant is specialization constant 0, one pipeline per material variant.
    """
    u = link_ubershader(perms, lib, specialized=specialized)
    iface = u.interface()
    key = uber_key(perms) + (";specialized" if specialized else "")
    h = hashlib.sha256(key.encode()).hexdigest()[:12]
    prog = u.program
    bricks = {p: b.module.source_hash for p, b in prog.bricks.items()}
    templates, sources = {}, []
    precision = _precision(perms)
    for lang in map(language, languages):
        target = lang.target(precision)
        emitted = _emit(lib, target, prog)
        emitted, shade = target.entry32(emitted, _function(prog, "shade"))  # fp16: a 32-bit wrapper
        for stage, tname in (("vertex", lang.template("vertex")), ("fragment", lang.template("ubershader"))):
            used = _templates_used(lang, tname)
            templates.update(used)
            ctx = {"provenance": _provenance("ubershader", f"{len(perms)} permutations", h, bricks, used),
                   "inputs": iface.surface, "textures": iface.textures, "shade": shade,
                   "call_args": _call_args(u, lang.material_index), "iface": iface, **lang.context(),
                   "double_sided": u.double_sided, "material_index": lang.material_index,
                   # the main's discard reads the entry's alpha mode (link/uber.py ALPHA_MODE_FUNCTION)
                   "alpha_mode": ALPHA_MODE_FUNCTION if "mask" in u.alpha_modes else ""}
            sources.append(_render(lib, tname, target, ctx, emitted if stage == "fragment" else Emitted(""),
                                   f"ubershader.{'frag' if stage == 'fragment' else 'vert'}.{lang.name}"))
    return Composed(key, h, sources, bricks, templates, iface), u


def compose_uber_kernel(perms: list[Permutation], lib: Library, languages=LANGUAGES,
                        specialized: bool = False) -> tuple[Composed, Uber]:
    """The ubershader's shade() in a compute kernel: the material index per sample in P.w (backends/*/templates/shade.*.j2).

    specialized: the variant comes from specialization constant 0 (link.uber.SPEC_VARIANT).
    """
    u = link_ubershader(perms, lib, kernel=True, specialized=specialized)
    iface = u.interface(kernel=True)
    key = uber_key(perms)
    h = hashlib.sha256((f"kernel:{int(specialized)}:" + key).encode()).hexdigest()[:12]
    prog = u.program
    bricks = {p: b.module.source_hash for p, b in prog.bricks.items()}
    layout_ = ["P", "Ng", "V"] + (["T"] if "T" in u.surface else []) + (["uv"] if "uv" in u.surface else [])
    templates, sources = {}, []
    precision = _precision(perms)
    for lang in map(language, languages):
        target = lang.target(precision)
        emitted = _emit(lib, target, prog)
        emitted, shade = target.entry32(emitted, _function(prog, "shade"))  # fp16: a 32-bit wrapper
        tname = lang.template("shade")
        used = _templates_used(lang, tname)
        templates.update(used)
        ctx = {"provenance": _provenance("ubershader kernel", f"{len(perms)} permutations", h, bricks, used),
               "inputs": u.surface, "samples": layout_, "call_args": _call_args(u, None), "shade": shade,
               "material_vec4s": 1, "light_vec4s": 1, "uber": True}
        sources.append(_render(lib, tname, target, ctx, emitted, f"{h}.comp.{lang.name}"))
    return Composed(key, h, sources, bricks, templates, iface), u
