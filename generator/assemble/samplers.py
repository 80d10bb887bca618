"""Sampler states in each platform's own words: what an engine passes to vkCreateSampler, a D3D12 sampler
descriptor, glSamplerParameter or GPUDevice.createSampler.

A state (scene/textures.Sampler.as_dict) is API-neutral: mag and min filter, mipmap mode, wrap per axis,
anisotropy, LOD bias, compare op. One function per API spells it (each platform class's ``spell_sampler``
names its own; `spell(state)` gives the state for every platform), with the same meaning everywhere:

- ``mipmap = "none"`` is level 0 only: Vulkan ``mipmapMode`` NEAREST with ``maxLod`` 0.25 (the Vulkan
  specification's note on emulating GL's non-mipmapped min filters: with maxLod 0 the clamped LOD is never
  above 0, so the mag filter would be used under minification too, and a min filter that differs from the
  mag filter would be ignored), D3D12 ``MaxLOD`` 0.25 and WebGPU ``lodMaxClamp`` 0.25 alike, GL
  ``GL_LINEAR``/``GL_NEAREST`` min filters (no mipmap). Otherwise every level is read (Vulkan ``VK_LOD_CLAMP_NONE``, D3D12 ``D3D12_FLOAT32_MAX``,
  WebGPU's default 32).
- ``anisotropy > 1``: Vulkan ``anisotropyEnable``, D3D12's ANISOTROPIC filter, GL
  ``GL_TEXTURE_MAX_ANISOTROPY`` (GL 4.6, or EXT_texture_filter_anisotropic), WebGPU ``maxAnisotropy``.
- ``lod_bias``: WebGPU samplers have none, and OpenGL ES none either (``GL_TEXTURE_LOD_BIAS`` is desktop GL):
  a non-zero bias is listed under ``unsupported`` there (apply it in the shader, e.g. textureSampleBias).
- ``compare`` (a shadow map's comparison sampler): Vulkan ``compareEnable`` + ``compareOp``, D3D12's
  COMPARISON filter + ``ComparisonFunc``, GL ``GL_COMPARE_REF_TO_TEXTURE`` + ``GL_TEXTURE_COMPARE_FUNC``,
  WebGPU ``compare``.
- wrap ``clamp`` is clamp to the edge texel everywhere (no border colour is read).
"""
from __future__ import annotations

VK_LOD_CLAMP_NONE = 1000.0
D3D12_FLOAT32_MAX = 3.402823466e38
# compare op -> (Vulkan, D3D12, GL, WebGPU)
COMPARE_OPS = {
    "never": ("VK_COMPARE_OP_NEVER", "D3D12_COMPARISON_FUNC_NEVER", "GL_NEVER", "never"),
    "less": ("VK_COMPARE_OP_LESS", "D3D12_COMPARISON_FUNC_LESS", "GL_LESS", "less"),
    "equal": ("VK_COMPARE_OP_EQUAL", "D3D12_COMPARISON_FUNC_EQUAL", "GL_EQUAL", "equal"),
    "less_or_equal": ("VK_COMPARE_OP_LESS_OR_EQUAL", "D3D12_COMPARISON_FUNC_LESS_EQUAL", "GL_LEQUAL", "less-equal"),
    "greater": ("VK_COMPARE_OP_GREATER", "D3D12_COMPARISON_FUNC_GREATER", "GL_GREATER", "greater"),
    "not_equal": ("VK_COMPARE_OP_NOT_EQUAL", "D3D12_COMPARISON_FUNC_NOT_EQUAL", "GL_NOTEQUAL", "not-equal"),
    "greater_or_equal": ("VK_COMPARE_OP_GREATER_OR_EQUAL", "D3D12_COMPARISON_FUNC_GREATER_EQUAL", "GL_GEQUAL",
                         "greater-equal"),
    "always": ("VK_COMPARE_OP_ALWAYS", "D3D12_COMPARISON_FUNC_ALWAYS", "GL_ALWAYS", "always"),
}
_WRAP = {"repeat": ("VK_SAMPLER_ADDRESS_MODE_REPEAT", "D3D12_TEXTURE_ADDRESS_MODE_WRAP", "GL_REPEAT", "repeat"),
         "mirrored": ("VK_SAMPLER_ADDRESS_MODE_MIRRORED_REPEAT", "D3D12_TEXTURE_ADDRESS_MODE_MIRROR",
                      "GL_MIRRORED_REPEAT", "mirror-repeat"),
         "clamp": ("VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE", "D3D12_TEXTURE_ADDRESS_MODE_CLAMP", "GL_CLAMP_TO_EDGE",
                   "clamp-to-edge")}

# the largest LOD of a sampler that reads level 0 only: above 0, so that minification (LOD > 0) still selects
# the min filter, and below 0.5, so that nearest mipmap selection stays at level 0
LEVEL_0_ONLY = 0.25


def vulkan(s: dict) -> dict:
    mip = "NEAREST" if s["mipmap"] == "none" else s["mipmap"].upper()
    return {"magFilter": f"VK_FILTER_{s['mag_filter'].upper()}", "minFilter": f"VK_FILTER_{s['min_filter'].upper()}",
            "mipmapMode": f"VK_SAMPLER_MIPMAP_MODE_{mip}",
            "addressModeU": _WRAP[s["wrap_u"]][0], "addressModeV": _WRAP[s["wrap_v"]][0],
            "addressModeW": _WRAP[s["wrap_u"]][0], "mipLodBias": s["lod_bias"],
            "anisotropyEnable": s["anisotropy"] > 1, "maxAnisotropy": float(s["anisotropy"]),
            "compareEnable": s["compare"] is not None,
            "compareOp": COMPARE_OPS[s["compare"]][0] if s["compare"] else "VK_COMPARE_OP_NEVER",
            "minLod": 0.0, "maxLod": LEVEL_0_ONLY if s["mipmap"] == "none" else VK_LOD_CLAMP_NONE}


def d3d12(s: dict) -> dict:
    point = {"linear": "LINEAR", "nearest": "POINT"}
    mip = point["nearest" if s["mipmap"] == "none" else s["mipmap"]]
    cmp = "COMPARISON_" if s["compare"] else ""
    if s["anisotropy"] > 1:
        name = f"D3D12_FILTER_{cmp}ANISOTROPIC"
    else:
        mn, mag = point[s["min_filter"]], point[s["mag_filter"]]
        # D3D12 names a filter by the runs of equal modes: MIN_MAG_MIP_LINEAR, MIN_LINEAR_MAG_MIP_POINT, …
        if mn == mag == mip:
            body = f"MIN_MAG_MIP_{mn}"
        elif mn == mag:
            body = f"MIN_MAG_{mn}_MIP_{mip}"
        elif mag == mip:
            body = f"MIN_{mn}_MAG_MIP_{mag}"
        else:
            body = f"MIN_{mn}_MAG_{mag}_MIP_{mip}"
        name = f"D3D12_FILTER_{cmp}{body}"
    return {"Filter": name, "AddressU": _WRAP[s["wrap_u"]][1], "AddressV": _WRAP[s["wrap_v"]][1],
            "AddressW": _WRAP[s["wrap_u"]][1], "MipLODBias": s["lod_bias"], "MaxAnisotropy": s["anisotropy"],
            "ComparisonFunc": COMPARE_OPS[s["compare"]][1] if s["compare"] else "D3D12_COMPARISON_FUNC_NEVER",
            "MinLOD": 0.0, "MaxLOD": LEVEL_0_ONLY if s["mipmap"] == "none" else D3D12_FLOAT32_MAX}


def gl(s: dict) -> dict:
    mn = s["min_filter"].upper()
    minf = f"GL_{mn}" if s["mipmap"] == "none" else f"GL_{mn}_MIPMAP_{s['mipmap'].upper()}"
    out = {"GL_TEXTURE_MAG_FILTER": f"GL_{s['mag_filter'].upper()}", "GL_TEXTURE_MIN_FILTER": minf,
           "GL_TEXTURE_WRAP_S": _WRAP[s["wrap_u"]][2], "GL_TEXTURE_WRAP_T": _WRAP[s["wrap_v"]][2],
           "GL_TEXTURE_MAX_ANISOTROPY": float(s["anisotropy"]), "GL_TEXTURE_LOD_BIAS": s["lod_bias"],
           "GL_TEXTURE_COMPARE_MODE": "GL_COMPARE_REF_TO_TEXTURE" if s["compare"] else "GL_NONE"}
    if s["compare"]:
        out["GL_TEXTURE_COMPARE_FUNC"] = COMPARE_OPS[s["compare"]][2]
    if s["lod_bias"]:
        out["unsupported"] = ["GL_TEXTURE_LOD_BIAS on OpenGL ES (apply the bias in the shader)"]
    return out


def webgpu(s: dict) -> dict:
    out = {"addressModeU": _WRAP[s["wrap_u"]][3], "addressModeV": _WRAP[s["wrap_v"]][3],
           "magFilter": s["mag_filter"], "minFilter": s["min_filter"],
           "mipmapFilter": "nearest" if s["mipmap"] == "none" else s["mipmap"],
           "lodMinClamp": 0.0, "lodMaxClamp": LEVEL_0_ONLY if s["mipmap"] == "none" else 32.0,
           "maxAnisotropy": s["anisotropy"]}
    if s["compare"]:
        out["compare"] = COMPARE_OPS[s["compare"]][3]
    if s["lod_bias"]:
        out["unsupported"] = ["lod_bias (WebGPU samplers have none: use textureSampleBias)"]
    return out


def spell(state: dict, platforms=None) -> dict:
    """{platform: the state in its API's words} for each of `platforms` (default: every platform), as each
    platform class spells it (Platform.spell_sampler: one of the functions above)."""
    from .platforms import PLATFORM_TABLE, PLATFORMS
    return {p: PLATFORM_TABLE[p].spell_sampler(state) for p in (PLATFORMS if platforms is None else platforms)}
