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
"""
from __future__ import annotations

from typing import NamedTuple

from ..io import sha256
from ..toolchain import tool_versions


class Platform(NamedTuple):
    """What the build needs for a platform and what its pack holds (one row of PLATFORM_TABLE)."""

    made_from: str  # the language `build` must build for the platform to be written (BuildContext.languages)
    language: str   # the dialect of its main artifact's source: the pack meta's and manifest ``packs``' "language"
    blob: str       # the kind of its main artifact in the manifest's stages and the pack (d3d12: "dxil" where built)


# The one table of the platforms, in build order. gl is made from the GLSL target (its `gl` dialect is a
# GlslTarget subclass composed beside the languages: DIALECTS) and ships the 4.50 core text, kind "glsl".
PLATFORM_TABLE: dict[str, Platform] = {
    "vulkan": Platform(made_from="glsl", language="glsl", blob="spirv"),
    "d3d12": Platform(made_from="hlsl", language="hlsl", blob="hlsl"),
    "gl": Platform(made_from="glsl", language="gl", blob="glsl"),
    "webgpu": Platform(made_from="wgsl", language="wgsl", blob="wgsl"),
}
PLATFORMS: tuple[str, ...] = tuple(PLATFORM_TABLE)
DIALECTS = {"gl": ("gl", "essl")}  # platform -> dialects composed beside the languages (compose.Composed.dialects)
EXT = {"gl": "glsl", "essl": "essl", "hlsl": "hlsl", "wgsl": "wgsl", "dxil": "dxil"}


def parse_platforms(text: str) -> list[str]:
    """"vulkan,gl" -> ["vulkan", "gl"] (in PLATFORMS order); ValueError naming the problem."""
    items = [x.strip() for x in text.split(",") if x.strip()]
    bad = [x for x in items if x not in PLATFORMS]
    if not items or bad or len(set(items)) != len(items):
        raise ValueError(f"{text!r} is not a comma-separated list of {', '.join(PLATFORMS)}, each at most once")
    return [p for p in PLATFORMS if p in items]


def dialects_of(platforms) -> tuple[str, ...]:
    return tuple(d for p in platforms for d in DIALECTS.get(p, ()))


def platform_tools(platform: str) -> dict[str, str]:
    """The exact versions of the tools that made and checked a platform's artifacts."""
    from ..toolchain.platforms import dxc_version
    t = tool_versions()
    return {"vulkan": lambda: {"glslc": t["glslc"], "glslang": t["glslang"], "spirv-tools": t["spirv-tools"],
                               "naga": t["naga"]},  # glslang: the HLSL's SPIR-V in the vulkan tree
            "d3d12": lambda: {"glslang": t["glslang"], "dxc": dxc_version()},
            "gl": lambda: {"glslang": t["glslang"]},
            "webgpu": lambda: {"naga": t["naga"]}}[platform]()


def all_tools(platforms) -> dict:
    """Every platform's tools (for the build's key: a tool installed or upgraded rebuilds)."""
    return {p: platform_tools(p) for p in platforms}


def write_platforms(write, name: str, composed, entry: dict, platforms, dialect_errors: dict, precision: str,
                    dxil=None) -> list[str]:
    """Fill entry["platforms"] for one permutation whose languages compiled (entry["languages"] is written);
    returns the errors that fail it (a GL core stage's among them, its source then written beside and named in
    entry["failed_sources"]). write(rel, data): the build's atomic writer. dialect_errors: job key ->
    glslangValidator errors. dxil(source) -> (bytes | None, errors): the DXC step (None: no dxc)."""
    from .reflection import platform_reflection
    langs = entry["languages"]
    sources = {(s.language, s.stage): s for s in [*composed.sources, *composed.dialects]}
    stages = sorted({s.stage for s in composed.sources}, key=("vert", "frag", "comp").index)
    out, errs = {}, []

    def put(tree: str, stage: str, data: bytes, kind: str) -> dict:
        digest = sha256(data)
        rel = f"{tree}/{name}.{stage}.{digest[:12]}.{EXT[kind]}"
        write(rel, data)
        return {"path": rel, "sha256": digest}

    for p in platforms:
        if PLATFORM_TABLE[p].made_from not in langs or (p == "gl" and ("gl", stages[0]) not in sources):
            continue  # a build of fewer languages (BuildContext.languages): the platforms they make
        d: dict = {"stages": {}}
        if p == "vulkan":
            for stage in stages:
                item = {"spirv": {"path": langs["glsl"][stage]["spirv"], "sha256": langs["glsl"][stage]["spirv_sha256"]}}
                for lang in langs:
                    item[lang] = {"path": langs[lang][stage]["source"], "sha256": langs[lang][stage]["source_sha256"],
                                  "spirv": langs[lang][stage]["spirv"]}
                d["stages"][stage] = item
            d.update(spirv_from="glsl", cost={s: langs["glsl"][s]["cost"] for s in stages})
        elif p == "d3d12":
            for stage in stages:
                src = sources[("hlsl", stage)]
                item = {"hlsl": put("d3d12", stage, src.text.encode(), "hlsl")}
                if dxil is not None:
                    blob, e = dxil(name, src, precision)
                    errs += e
                    if blob is not None:
                        item["dxil"] = put("d3d12", stage, blob, "dxil")
                d["stages"][stage] = item
            from ..toolchain.platforms import DX_PROFILES
            d.update(profiles={s: DX_PROFILES[(s, precision)] for s in stages},
                     dxil="built" if dxil is not None else "no dxc on PATH: HLSL only (docs/guide/install.md: where to get dxc)",
                     cost={s: langs["hlsl"][s]["cost"] for s in stages}, cost_from="hlsl SPIR-V (glslang)")
        elif p == "gl":
            es_errors = [e for s in stages for e in dialect_errors.get(f"{name}.{s}.essl", [])]
            for stage in stages:
                core = dialect_errors.get(f"{name}.{stage}.gl", [])
                text = sources[("gl", stage)].text.encode()
                if core:  # it fails the permutation: the source beside, as a compile failure's (build._write_all)
                    errs += core
                    rel = f"gl/{name}.{stage}.failed.{EXT['gl']}"
                    write(rel, text)
                    entry.setdefault("failed_sources", {})[f"gl.{stage}"] = rel
                    continue
                item = {"glsl": put("gl", stage, text, "gl")}
                if not es_errors:
                    item["essl"] = put("gl", stage, sources[("essl", stage)].text.encode(), "essl")
                d["stages"][stage] = item
            d.update(versions={"glsl": "450 core", "essl": "310 es"},
                     essl="ok" if not es_errors else {"unsupported": es_errors})
        elif p == "webgpu":
            for stage in stages:
                d["stages"][stage] = {"wgsl": put("webgpu", stage, sources[("wgsl", stage)].text.encode(),
                                                  "wgsl")}
            d.update(cost={s: langs["wgsl"][s]["cost"] for s in stages}, cost_from="wgsl SPIR-V (naga)")
        d["reflection"] = platform_reflection(composed.interface, p)
        d["tools"] = platform_tools(p)
        out[p] = d
    entry["platforms"] = out
    return errs


def platform_files(entry: dict):
    """(path, sha256) of every file a manifest entry's platforms name that its languages do not (vulkan's are
    the language tree's own files)."""
    for p, d in (entry.get("platforms") or {}).items():
        if p == "vulkan":
            continue
        for item in d.get("stages", {}).values():
            for art in item.values():
                yield art["path"], art["sha256"]
