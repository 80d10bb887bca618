"""manifest.json's reflection (from the Interface) against what the compiled SPIR-V declares, and the scene values.

Every permutation of the example scene, in GLSL, HLSL and WGSL, both stages: the descriptor
resources (set, binding, kind, image dimension), the block layouts (offsets, types, strides,
sizes), the stage inputs and outputs (locations, types) and the entry point read from the
binary (generator/analysis/reflect.py) are exactly what the manifest says.
"""
from __future__ import annotations

import json
import re
import struct
from pathlib import Path

import pytest

from generator.analysis.reflect import reflect

REPO = Path(__file__).resolve().parents[2]
FORMATS = {"vec2": "R32G32_SFLOAT", "vec3": "R32G32B32_SFLOAT", "vec4": "R32G32B32A32_SFLOAT"}
EXAMPLE = REPO / "scenes" / "example.toml"


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    from generator.assemble import BuildContext, build
    from generator.library.bricks import load_library
    from generator.scene.load import load_scene

    out = tmp_path_factory.mktemp("manifest")
    lib = load_library()
    res = build(load_scene(EXAMPLE, lib), out, BuildContext(lib))
    assert res.ok, res.failures
    return out, json.loads((out / "manifest.json").read_text())


def _flat(members: list[dict]) -> list[str]:
    out = []
    for m in members:
        ty = m["type"]
        if "members" in m:  # an array of structs: its element's layout, as flatten_layout spells it
            ty = "{" + ",".join(_flat(m["members"])) + "}" + ty[ty.index("["):]
        leaf = f"{m['offset']}:{ty}"
        if "array_stride" in m:
            leaf += f" s{m['array_stride']}"
        if "matrix_stride" in m:
            leaf += f" m{m['matrix_stride']}"
        out.append(leaf)
    return out


def _expected_resources(stage: dict) -> list[tuple]:
    out = []
    for b in stage.get("uniform_blocks", []):
        out.append((b["set"], b["binding"], "uniform_buffer", None, b["size"], tuple(_flat(b["members"]))))
    for b in stage.get("storage_blocks", []):
        out.append((b["set"], b["binding"], "storage_buffer", None, b["size"], tuple(_flat(b["members"]))))
    for t in stage.get("textures", []):
        out.append((t["set"], t["binding"], "sampled_image", t["dimension"], None, ()))
        out.append((t["set"], t["sampler_binding"], "sampler", None, None, ()))
    return sorted(out)


def _reflected_resources(entry) -> list[tuple]:
    from generator.analysis.reflect import flatten_layout
    return sorted((r.set, r.binding, r.kind, r.texture_dim, r.size, tuple(flatten_layout(r.members)))
                  for r in entry.resources)


def _stage_vars(vars_) -> list[tuple]:
    return sorted((v.location, v.type) for v in vars_)


def _locations(items: list[dict]) -> list[tuple]:
    return sorted((x["location"], x["type"]) for x in items)


@pytest.mark.toolchain
def test_reflection_matches_the_spirv_of_every_permutation_in_every_language(built):
    out, manifest = built
    checked = 0
    for perm in manifest["permutations"]:
        iface = perm["interface"]
        for lang, stages in perm["languages"].items():
            for stage, item in stages.items():
                entry = reflect((out / item["spirv"]).read_bytes()).entry(stage)
                want = iface[stage]
                where = f"{perm['hash']} {lang} {stage}"
                assert entry.name == want["entry_point"], where
                assert _reflected_resources(entry) == _expected_resources(want), where
                assert _stage_vars(entry.inputs) == _locations(want["inputs"]), where
                assert _stage_vars(entry.outputs) == _locations(want["outputs"]), where
                for x in want["inputs"] if stage == "vert" else []:  # the format an engine's vertex layout uses
                    assert FORMATS[x["type"]] == x["format"], (where, x)
                checked += 1
    assert checked == 5 * 3 * 2


@pytest.mark.toolchain
def test_ubershader_reflection_matches_its_spirv_in_every_language(built):
    out, manifest = built
    uber = manifest["ubershader"]
    for lang, stages in uber["languages"].items():
        for stage, item in stages.items():
            entry = reflect((out / item["spirv"]).read_bytes()).entry(stage)
            want = uber["interface"][stage]
            where = f"ubershader {lang} {stage}"
            assert _reflected_resources(entry) == _expected_resources(want), where
            assert _stage_vars(entry.inputs) == _locations(want["inputs"]), where
            assert _stage_vars(entry.outputs) == _locations(want["outputs"]), where


ALIGNED = {4: (0, 4, 8, 12), 8: (0, 8), 12: (0,), 16: (0,), 64: (0,)}  # bytes -> where in a vec4 it may start


@pytest.mark.toolchain
def test_every_parameter_is_packed_inside_the_vec4_array_the_spirv_declares(built):
    """Each parameter lies in its block's `data` vec4 array as the SPIR-V of every language lays it out, at its
    natural alignment within one vec4 (a vec3 at .xyz, a vec2 at .xy or .zw, a mat4 on whole vec4s: the bytes std140,
    HLSL cbuffers and WGSL agree on), and no two parameters share a byte."""
    from generator.analysis.reflect import flatten_layout
    out, manifest = built
    packed = 0
    for perm in manifest["permutations"]:
        blocks = [b for b in perm["interface"]["frag"]["uniform_blocks"] if b.get("parameters")]
        for lang, stages in perm["languages"].items():
            res = {(r.set, r.binding): r for r in reflect((out / stages["frag"]["spirv"]).read_bytes()).entry("frag").resources}
            for b in blocks:
                where = (perm["hash"], lang, b["name"])
                # the vec4 array after any header (`data`; HLSL `<block>_data`; naga wraps the block in a struct)
                leaf = flatten_layout(res[(b["set"], b["binding"])].members)[-1]
                found = re.fullmatch(r"(\d+):vec4\[(\d+)\] s16", leaf)
                assert found, (where, leaf)
                start, end = int(found[1]), int(found[1]) + 16 * int(found[2])
                taken = set()
                for p in b["parameters"]:
                    lo, hi = p["offset"], p["offset"] + p["size"]
                    assert start <= lo and hi <= end, (where, p)
                    assert (lo - start) % 16 in ALIGNED[p["size"]], (where, p)
                    assert p["size"] > 16 or (lo - start) // 16 == (hi - 1 - start) // 16, (where, p)
                    assert not taken & set(range(lo, hi)), (where, p)
                    taken |= set(range(lo, hi))
                    packed += (lo - start) % 16 != 0
    assert packed, "some scalar shares a vec4 with another parameter"


def test_uploads_are_the_scene_values_at_their_offsets(built):
    _, manifest = built
    gold = manifest["materials"]["polished_gold"]["params"]
    assert gold == {"alpha": 0.15, "f0": [1.0, 0.71, 0.29]}
    sets = manifest["light_sets"]
    assert sets == {"indoor": ["lamp", "fill"], "outdoor": ["sun", "lamp"]}
    objects = {o["name"]: o for o in manifest["objects"]}
    assert objects["statue"]["material"] == "polished_gold" and objects["statue"]["light_set"] == "outdoor"
    perm = next(p for p in manifest["permutations"] if p["hash"] == objects["statue"]["permutation"])
    up = next(u for u in perm["uploads"] if u["material"] == "polished_gold")
    assert up["objects"] == ["statue"] and up["light_set"] == "outdoor"
    blocks = {b["name"]: b for b in perm["interface"]["frag"]["uniform_blocks"]}
    data = bytes.fromhex(up["Material"])
    assert len(data) == blocks["Material"]["size"]
    for p in blocks["Material"]["parameters"]:
        n = p["size"] // 4
        got = struct.unpack_from(f"<{n}f", data, p["offset"])
        want = gold[p["name"]] if isinstance(gold[p["name"]], list) else [gold[p["name"]]]
        assert got == pytest.approx(want, rel=1e-7), p["name"]
    lights = bytes.fromhex(up["Lights"])
    assert len(lights) == blocks["Lights"]["size"]
    lamp = manifest["lights"]["lamp"]["params"]
    pos = next(p for p in blocks["Lights"]["parameters"] if p["name"] == "position" and p["light"] == 1)
    assert struct.unpack_from("<3f", lights, pos["offset"]) == pytest.approx(lamp["position"])
