"""Compose the depth passes' shaders: the units of link/depth.py in every language and platform dialect.

Each unit is a vertex and a fragment stage rendered from the back end's depth templates
(backends/<lang>/templates/depth_vertex.<lang>.j2 and depth_fragment.<lang>.j2, which import the same
macros as the material shaders: the Frame and Object blocks, block reads and texture arguments are spelled
by one hand). A mask unit's fragment stage holds the emitted `depth_mask` function of its MaskProgram. The
result is a compose.Composed like a permutation's, so the build writes, compiles, validates and reflects it
as it does every other unit (assemble/depth.py) and the renderer compiles it with its permutations.
"""
from __future__ import annotations

import hashlib
from dataclasses import dataclass, field

from ..backends import language
from ..backends.base import Emitted
from ..link.depth import (BLUR, DEPTH, blur_interface, depth_interface, mask_program, mask_unit)
from . import Composed, Source, _provenance, _templates_used, composing, placed

VERTEX, FRAGMENT = "depth_vertex", "depth_fragment"  # the templates' kinds (Language.template)


@dataclass
class DepthPlan:
    """Which depth units a scene needs: `depth` casters (a depth-only pass: shadow_map, pcf, pcf_hardware),
    `moments` (a VSM light: the moments stage and the blur), and the linked permutations (hash ->
    LinkedPermutation) whose alpha is "mask"."""

    depth: bool = False
    moments: bool = False
    masked: dict = field(default_factory=dict)

    @property
    def any(self) -> bool:
        return self.depth or self.moments


def unit_names(plan: DepthPlan) -> list[str]:
    """The units `plan` composes, in the order they are composed and listed."""
    if not plan.any:
        return []
    names = [DEPTH] + ([BLUR] if plan.moments else [])
    for h in sorted(plan.masked):
        names += [mask_unit(h, False)] if plan.depth else []
        names += [mask_unit(h, True)] if plan.moments else []
    return names


def compose_depth_units(plan: DepthPlan, lib, languages, dialects=()) -> dict[str, Composed]:
    """{unit name: Composed} of every unit `plan` needs (unit_names), in `languages` and `dialects`."""
    out = {}
    env = composing(lib).templates  # the library's templates, as every unit of it renders from
    for name in unit_names(plan):
        if name == DEPTH:
            out[name] = _compose(env, name, "depth pass: casters' position; moments", depth_interface(plan.moments),
                                 languages, dialects, {"moments": plan.moments, "fragment": plan.moments})
        elif name == BLUR:
            out[name] = _compose(env, name, "depth pass: one axis of the moments' box filter", blur_interface(),
                                 languages, dialects, {"blur": True, "moments": True, "fragment": True})
        else:
            h, _, kind = name.partition(".")
            lp = plan.masked[h]
            moments = kind == "mask_moments"
            mp = mask_program(lp, moments, lib.memo)
            bricks = {lp.resolved.packing.brick.display_path: lp.resolved.packing.brick.module.source_hash}
            # the unit's kind is in its key: a permutation's mask and mask_moments units get hashes of their own
            key = f"depth pass: coverage of {lp.perm.canonical()}" + ("; moments" if moments else "")
            out[name] = _compose(env, name, key, mp.interface,
                                 languages, dialects, {"mask": True, "moments": moments, "fragment": True,
                                                       "call_args": mp.call_args}, mp.program, bricks)
    return out


def _compose(env, name: str, key: str, iface, languages, dialects, flags: dict, prog=None,
             bricks: dict | None = None) -> Composed:
    """One unit: its vertex stage, and its fragment stage when `flags["fragment"]`, per language and dialect."""
    h = hashlib.sha256(("depth:" + key).encode()).hexdigest()[:12]
    bricks = bricks or {}
    templates: dict[str, str] = {}
    stages = [VERTEX] + ([FRAGMENT] if flags.get("fragment") else [])

    def sources(lang_name: str, label: str) -> list[Source]:
        lang = language(lang_name)
        target = lang.target("fp32", iface)
        emitted = Emitted("")
        if prog is not None:  # depth_mask alone: a few lines, walked each time (no brick functions to replay)
            emitted = target.emit(prog.structs, prog.functions, ())
        got = []
        for kind in stages:
            tname = lang.template(kind)
            used = _templates_used(lang, tname)
            templates.update(used)
            ctx = {"provenance": _provenance(label, key, h, bricks, used), "iface": iface,
                   "inputs": iface.surface, "textures": iface.textures, "mask": False, "moments": False,
                   "blur": False, "call_args": [], "mask_entry": "depth_mask", **flags, **lang.context()}
            stage = "frag" if kind == FRAGMENT else "vert"
            got.append(_render(env, tname, target, ctx, emitted if kind == FRAGMENT else Emitted(""),
                               f"{name}.{stage}.{lang.name}", stage))
        return got

    out = [s for lang in languages for s in sources(lang, "depth")]
    extra = [s for d in dialects for s in sources(d, f"depth ({d})")]
    return Composed(key, h, out, bricks, templates, iface, dialects=extra)


def _render(env, template: str, target, ctx: dict, emitted: Emitted, name: str, stage: str) -> Source:
    """Render one depth template (as compose._render does a material's: #line resets, the line map shifted)."""
    text, offset = placed(env.render(template, target=target, functions=emitted.text, **ctx), target, emitted, name)
    return Source(target.name, stage, text, emitted.shifted(offset))
