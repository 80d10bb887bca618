"""Packed parameter blocks (link/interface.py `layout`): scalars and vectors share vec4s at their natural alignment.

The rules are what docs/design/link.md ("Uniform layout") states: vectors and matrices first in declared order,
then scalars into the first free component; each group (a material's bricks, its surface state, each light)
from a new vec4. End to end, the packed bytes are checked against the SPIR-V (tests/assemble/test_manifest.py)
and read back by every language's shaders (tests/eval, tests/runtime/test_render.py).
"""
from __future__ import annotations

import struct

import pytest

from generator.lang.types import FLOAT, MAT4, VEC3, VEC4, vector
from generator.link.interface import Slot, layout, pack

VEC2 = vector("float", 2)


def _placed(values, start=0):
    slots, end = layout([(n, n, None, ty, None, None) for n, ty in values], start)
    return {s.name: (s.index, s.swizzle) for s in slots}, end


def test_a_scalar_before_a_vec3_takes_the_w_after_it():
    assert _placed([("alpha", FLOAT), ("f0", VEC3)]) == ({"f0": (0, ".xyz"), "alpha": (0, ".w")}, 1)


def test_vectors_keep_their_declared_order_and_scalars_fill_the_holes():
    got, end = _placed([("a", FLOAT), ("v", VEC2), ("b", VEC3), ("c", FLOAT), ("d", FLOAT), ("m", MAT4),
                        ("e", VEC2), ("q", VEC4), ("f", FLOAT)])
    assert got == {"v": (0, ".xy"), "b": (1, ".xyz"), "m": (2, ""), "e": (0, ".zw"), "q": (6, ""),
                   "a": (1, ".w"), "c": (7, ".x"), "d": (7, ".y"), "f": (7, ".z")}
    assert end == 8


def test_every_value_sits_at_its_natural_alignment_inside_one_vec4():
    values = [("s0", FLOAT), ("p", VEC2), ("s1", FLOAT), ("s2", FLOAT), ("t", VEC3), ("r", VEC2), ("s3", FLOAT),
              ("u", VEC3), ("w", VEC2)]
    slots, end = layout([(n, n, None, ty, None, None) for n, ty in values])
    words = [w for s in slots for w in s.words()]
    assert len(words) == len(set(words)) and max(words) < 4 * end  # no two values share a word
    for s in slots:
        n = s.ty.components
        assert s.component in {1: (0, 1, 2, 3), 2: (0, 2), 3: (0,)}[n], s
        assert s.offset == 16 * s.index + 4 * s.component
    assert end == 4  # 16 floats in 4 vec4s, where one vec4 per value took 9


def test_layout_starts_where_it_is_told_and_pack_writes_each_value_at_its_words():
    slots, end = layout([("m_alpha", "alpha", None, FLOAT, None, None), ("m_f0", "f0", None, VEC3, None, None),
                         ("m_M", "M", None, MAT4, None, None)], start=2)
    assert [(s.index, s.component) for s in slots] == [(2, 3), (2, 0), (3, 0)] and end == 7
    for s in slots:
        s.base = 16
    assert [s.offset for s in slots] == [16 + 32 + 12, 48, 64]
    data = pack(slots, {"m_alpha": 0.25, "m_f0": 0.5, "m_M": list(range(16))}, end)  # a scalar for a vec3 splats
    words = struct.unpack(f"<{4 * end}f", data)
    assert words[8:12] == (0.5, 0.5, 0.5, 0.25) and words[12:28] == tuple(float(x) for x in range(16))
    assert not any(words[:8])


@pytest.fixture(scope="module")
def lib():
    from generator.library.bricks import load_library
    return load_library()


def test_the_ubershader_variant_is_a_prefix_of_the_specialized_block_with_surface_state(lib):
    """The surface state's values pack from a new vec4: the bricks' slots (the ubershader's MaterialEntry.data)
    keep their places, so the renderer's and an engine's one upload serves both."""
    from generator.link import link_permutation
    from generator.spec.permutation import Permutation
    from generator.spec.surface import Surface

    brdf, packing = "lambert+microfacet(ndf=ggx,fresnel=schlick,vis=smith_schlick)", "constants(normal=vertex)"
    plain = link_permutation(Permutation(brdf, (), packing), lib).material
    masked = link_permutation(Permutation(brdf, (), packing, surface=Surface(alpha="mask", emissive="factor")),
                              lib).material
    assert [(s.name, s.offset) for s in masked[:len(plain)]] == [(s.name, s.offset) for s in plain]
    first = max(s.index for s in plain) + 1
    assert {s.param for s in masked[len(plain):]} == {"base_alpha", "alpha_cutoff", "emissive"}
    assert all(s.index >= first for s in masked[len(plain):])


def test_each_light_packs_into_vec4s_of_its_own(lib):
    from generator.link import link_permutation
    from generator.spec.permutation import LightKey, Permutation

    lp = link_permutation(Permutation("lambert", (LightKey("directional", "shadow_map"), LightKey("point", "none")),
                                      "constants(normal=vertex)"), lib)
    rows = [{s.index for s in ls} for ls in lp.lights]
    assert rows[0] and rows[1] and max(rows[0]) < min(rows[1])
    assert all(isinstance(s, Slot) for ls in lp.lights for s in ls)
