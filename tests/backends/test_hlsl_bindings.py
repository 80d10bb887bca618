"""Every HLSL resource carries its Vulkan binding explicitly: `[[vk::binding(B, S)]]` beside `register(xB, spaceS)`.

cbuffers included (Frame, Object, Lights, Material, the eval kernel's Params, a shade kernel's Info, the
ubershader's Draw), so an HLSL front end that places resources only by the explicit Vulkan binding (Slang, DXC's
-spirv without -fvk-*-shift) binds them where glslang does, with no fallback from the register.
"""
from __future__ import annotations

import re

import pytest

DECL = re.compile(r"^(?P<head>.*?)\b(?:cbuffer\s+)?(?P<name>\w+)\s*:\s*register\((?P<cls>[btsu])(?P<n>\d+), space(?P<s>\d+)\)",
                  re.M)
VK = re.compile(r"\[\[vk::binding\((\d+), (\d+)\)\]\]")


@pytest.fixture(scope="module")
def sources():
    from generator.compose import compose_eval, compose_permutation, compose_shade_kernel
    from generator.compose.uber import compose_ubershader
    from generator.library.bricks import load_library
    from generator.spec.permutation import LightKey, Permutation

    lib = load_library()
    textured = Permutation("lambert+microfacet(ndf=ggx,fresnel=schlick,vis=smith_schlick)",
                           (LightKey("directional", "shadow_map"), LightKey("point", "none")),
                           "albedo_texture(normal=normal_map)")
    plain = Permutation("lambert+blinn_phong_normalized", (LightKey("point", "none"),), "constants(normal=vertex)")
    out = {"fragment": compose_permutation(textured, lib, ("hlsl",)).sources,
           "shade kernel": compose_shade_kernel(plain, lib, ("hlsl",)).sources,
           "eval kernel": compose_eval("lambert+blinn_phong_normalized", lib, ("hlsl",)).sources,
           "ubershader": compose_ubershader([textured, plain], lib, ("hlsl",))[0].sources}
    return {f"{what} {s.stage}": s.text for what, srcs in out.items() for s in srcs if s.language == "hlsl"}


def test_every_register_has_the_same_vk_binding(sources):
    seen = set()
    for where, text in sources.items():
        decls = list(DECL.finditer(text))
        assert decls, where
        for d in decls:
            vk = VK.search(d["head"])
            assert vk, (where, d[0])
            assert (int(vk[1]), int(vk[2])) == (int(d["n"]), int(d["s"])), (where, d[0])
            seen.add(d["cls"])
    assert {"b", "t", "s"} <= seen
    cbuffers = {name for text in sources.values() for name in re.findall(r"cbuffer (\w+)", text)}
    assert {"Frame", "Object", "Lights", "Material", "Params", "Info", "Draw"} <= cbuffers, cbuffers
