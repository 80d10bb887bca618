"""manifest.json format 1 against its JSON Schema (generator/assemble/manifest.schema.json).

The schema is closed and describes every field once; every build the tests run is validated before its
manifest is written (tests/conftest.py sets SHADERMATRIX_CHECK_MANIFEST); the builds here reach every field
the schema describes, so it keeps no field the build no longer writes; and the render state is stated as
fields, per material and per permutation, agreeing with the surface state the permutation key carries.
"""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from generator.assemble import manifest as M
from tests.conftest import CHECK_MANIFEST_ENV

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "scenes" / "example.toml"
# What no build here writes, and why (each needs what this machine may lack, or a source a back end refuses)
NOT_REACHED = {
    "d3d12_stage.dxil": "DXIL is written only where a dxc is on PATH",
    "essl.unsupported": "written only for a source glslang refuses as GLSL ES 3.10, which no shipped brick makes",
    "depth_shader.errors": "written only for a depth unit that does not compile, which no shipped brick makes",
}


def _cli(*args) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "generator.cli", *map(str, args)], cwd=REPO, capture_output=True,
                          text=True, timeout=600)


def _build(*args) -> dict:
    r = _cli("build", *args, "-q")
    assert r.returncode == 0, r.stderr[-3000:]
    return json.loads((Path(args[args.index("--out") + 1]) / "manifest.json").read_text())


def _state_scene() -> str:
    """The example with every surface state, a factored and a painted table, and comparison and moments maps."""
    text = EXAMPLE.read_text()
    for old, new in [
        ('[materials.old_paint]', '[materials.old_paint]\nalpha = "blend"\ndouble_sided = true\nvertex_color = true'),
        ('[materials.painted_wood]', '[materials.painted_wood]\nalpha = "mask"\nemissive = "texture"\n'
                                     'params = { rho_d = [1.0, 1.0, 1.0], n = 16.0, f0 = [0.04, 0.04, 0.04], '
                                     'alpha_cutoff = 0.3 }'),
        ('params = { rho_d = [1.0, 1.0, 1.0], n = 16.0, f0 = [0.04, 0.04, 0.04] }\n', ''),
        ('brdf = "lambert+blinn_phong_normalized"', 'brdf = "lambert+blinn_phong_factored"\nemissive = "factor"'),
        ('brdf = "microfacet(ndf=ggx,fresnel=schlick,vis=smith_schlick)"\nparams = { alpha = 0.15, ',
         'brdf = "lambert+ndf_map"\nparams = { '),
        ('shadow = "shadow_map"', 'shadow = "pcf_hardware"'),
        ('[lights.fill]\ntype = "point"', '[lights.fill]\ntype = "point"\nshadow = "vsm"'),
    ]:
        assert old in text, old
        text = text.replace(old, new, 1)
    return text


@pytest.fixture(scope="module")
def built(tmp_path_factory) -> dict[str, dict]:
    """Manifests of builds that between them write every field: the scenes of scenes/ (the example with packs, with
    packs only and on one platform), masked shadow casters, every surface state with tables, a glTF file, textures with samplers, a
    removed permutation, a stale and a failed one, a scene with no object, an environment."""
    tmp = tmp_path_factory.mktemp("manifests")
    out: dict[str, dict] = {}
    out["example"] = _build(EXAMPLE, "--out", tmp / "example", "--pack")
    out["textured.toml"] = _build(REPO / "scenes" / "textured.toml", "--out", tmp / "textured.toml")
    out["depth_mask"] = _build(REPO / "tests" / "scenes" / "depth_mask.toml", "--out", tmp / "depth_mask")
    out["dynamic"] = _build(REPO / "tests" / "scenes" / "dynamic_lights.toml", "--out", tmp / "dynamic")  # light buffers
    dyn = (REPO / "tests" / "scenes" / "dynamic_lights.toml").read_text()
    assert "max = 64\n" in dyn
    (tmp / "switch.toml").write_text(dyn.replace("max = 64\n", 'max = 64\nloop = "switch"\n', 1))
    out["switch"] = _build(tmp / "switch.toml", "--out", tmp / "switch", "--platform", "vulkan")  # one buffer, ids
    from tests.runtime.test_dynamic_shadows import MIXED, POINTS, _scene as shadowed
    (tmp / "buffer_shadows.toml").write_text(shadowed(MIXED + POINTS[:1], True))  # depth arrays of buffer lights
    out["buffer_shadows"] = _build(tmp / "buffer_shadows.toml", "--out", tmp / "buffer_shadows", "--platform", "vulkan")
    tiled = (REPO / "tests" / "scenes" / "dynamic_lights.toml").read_text().replace(
        "[light_sets.crowd]\ndynamic = true\n", '[light_sets.crowd]\ndynamic = true\nculling = "tiles"\n')
    (tmp / "tiled.toml").write_text(tiled)
    out["tiled"] = _build(tmp / "tiled.toml", "--out", tmp / "tiled")  # a tiled set's LightTiles
    (tmp / "environment.toml").write_text(  # image-based lighting: its values and textures marked "environment"
        '[scene]\nenvironment = "sky"\nubershader = false\n[environments.sky]\nsky = "default"\nsize = 16\n'
        '[materials.metal]\nbrdf = "microfacet(ndf=ggx,fresnel=schlick,vis=smith_ggx_height_correlated)"\n'
        '[light_sets]\nnone = []\n[[objects]]\nmaterial = "metal"\nlights = "none"\n')
    out["environment"] = _build(tmp / "environment.toml", "--out", tmp / "environment", "--platform", "vulkan")
    out["spot_shadow"] = _build(REPO / "tests" / "scenes" / "spot_shadow.toml", "--out", tmp / "spot",
                                "--platform", "vulkan")  # a perspective shadow fit (its padding)
    out["vulkan"] = _build(EXAMPLE, "--out", tmp / "vulkan", "--platform", "vulkan")
    out["pack_only"] = _build(EXAMPLE, "--out", tmp / "pack_only", "--pack-only")  # "artifacts": "packs"
    (tmp / "state.toml").write_text(_state_scene())
    out["state"] = _build(tmp / "state.toml", "--out", tmp / "state", "--pack")
    from tests.scene.test_gltf import sample_doc
    out["gltf"] = _build(sample_doc().write_gltf(tmp / "sample.gltf"), "--out", tmp / "gltf")
    from tests.scene.test_textures import WOOD, write_scene  # images named, a sampler with what WebGPU lacks
    (tmp / "textured").mkdir()
    textured = write_scene(tmp / "textured", WOOD + '[materials.bare]\nbrdf = "lambert+phong_normalized"\n'
                           'packing = "albedo_texture(normal=normal_map)"\n'
                           'samplers = { albedo_map = { anisotropy = 8, lod_bias = -0.5 } }\n', objects=("wood", "bare"))
    out["textured"] = _build(textured, "--out", tmp / "textured" / "out")
    text = EXAMPLE.read_text()
    (tmp / "fewer.toml").write_text(text[:text.index("[[objects]]")] + '[[objects]]\nname = "only"\n'
                                    'material = "red_plastic"\nlights = "indoor"\n')
    shutil.copytree(tmp / "example", tmp / "removed")
    out["removed"] = _build(tmp / "fewer.toml", "--out", tmp / "removed", "--keep-removed")
    (tmp / "empty.toml").write_text(text[:text.index("[[objects]]")])
    out["empty"] = _build(tmp / "empty.toml", "--out", tmp / "empty")
    # a brick naga refuses after a good build: every entry stale; a fresh directory: every entry failed
    engine = tmp / "engine"
    engine.mkdir()
    good = (REPO / "bricks" / "output" / "linear.py").read_text()
    (engine / "tinted.py").write_text(good)
    (tmp / "tinted.toml").write_text(text.replace('output = "linear"', 'output = "tinted"'))
    _build(tmp / "tinted.toml", "--out", tmp / "stale", "--bricks", engine)
    assert "return vec4(color, 1.0)" in good
    (engine / "tinted.py").write_text(good.replace("return vec4(color, 1.0)", "k = 1\n    q = k / 0\n"
                                                   "    return vec4(color * float(q), 1.0)"))
    for name in ("stale", "failed"):
        r = _cli("build", tmp / "tinted.toml", "--out", tmp / name, "--bricks", engine, "-q")
        assert r.returncode == 1 and "Division by zero" in r.stderr, r.stderr[-2000:]
        out[name] = json.loads((tmp / name / "manifest.json").read_text())
    out["_dir"] = tmp  # type: ignore[assignment]
    return out


def _manifests(built) -> dict[str, dict]:
    return {k: v for k, v in built.items() if not k.startswith("_")}


# ------------------------------------------------------------------------------------------ the schema

def _nodes(node: dict, where="#"):
    """Every subschema that describes values, with where it is (not the conditions of if/then: they only require)."""
    yield where, node
    for k, v in node.items():
        if k in ("properties", "$defs"):
            for name, sub in v.items():
                yield from _nodes(sub, f"{where}/{k}/{name}")
        elif k in ("items", "additionalProperties", "propertyNames") and isinstance(v, dict):
            yield from _nodes(v, f"{where}/{k}")
        elif k in ("oneOf", "anyOf"):
            for i, sub in enumerate(v):
                yield from _nodes(sub, f"{where}/{k}/{i}")


def test_the_schema_is_draft_2020_12_of_format_1():
    from jsonschema import Draft202012Validator
    s = M.schema()
    Draft202012Validator.check_schema(s)
    assert s["$schema"] == "https://json-schema.org/draft/2020-12/schema"
    assert s["properties"]["format_version"] == {**s["properties"]["format_version"], "const": M.FORMAT_VERSION}
    assert "format_version" in s["required"] and f"format {M.FORMAT_VERSION}" in s["title"]


def test_every_object_is_closed_and_every_field_is_described():
    s = M.schema()
    for name, d in s["$defs"].items():
        assert d.get("title"), f"$defs/{name} has no title (the section heading of docs/reference/manifest.md)"
    titles = [d["title"] for d in s["$defs"].values()]
    assert len(set(titles)) == len(titles), "two $defs share a title (one heading, one anchor, on the page)"
    for where, node in _nodes(s):
        if "properties" in node:
            assert node.get("additionalProperties") is False, f"{where}: an object with fields must be closed"
            for k, p in node["properties"].items():
                assert p.get("description", "").strip(), f"{where}/properties/{k} has no description"
        extra = node.get("additionalProperties")
        if isinstance(extra, dict):  # a map keyed by names: its keys are constrained or named, its values described
            assert node.get("propertyNames", {}).get("title"), f"{where}: a map without propertyNames.title"
            assert extra.get("description", "").strip(), f"{where}/additionalProperties has no description"
        if node.get("type") == "object" and "properties" not in node and not isinstance(extra, dict):
            assert node.get("maxProperties") == 0, f"{where}: an object schema that says nothing of its fields"


def test_every_build_of_the_test_session_is_validated():
    # the hook is on for every test: in this process and, through the environment, in every command it starts
    assert CHECK_MANIFEST_ENV == M.CHECK_ENV and os.environ.get(M.CHECK_ENV) == "1"


# ------------------------------------------------------------------------------------------ the builds

@pytest.mark.toolchain
def test_every_manifest_validates_and_is_format_1(built):
    for name, m in _manifests(built).items():
        assert M.problems(m) == [], name
        assert next(iter(m)) == "format_version" and m["format_version"] == 1, name
    statuses = {e["status"] for m in _manifests(built).values() for e in [*m["permutations"], *m.get("removed", [])]}
    assert statuses == {"ok", "stale", "failed", "removed"}
    assert built["empty"]["ubershader"] == {} and built["failed"]["ubershader"]["status"] == "failed"


def _seen(schema: dict, manifests) -> set[str]:
    """`<def>.<field>` of every field the manifests write, `$defs` resolved as the validator resolves them."""
    from jsonschema import Draft202012Validator
    defs = schema["$defs"]
    seen: set[str] = set()

    def walk(value, node: dict, owner: str) -> None:
        if "$ref" in node:
            owner = node["$ref"].rsplit("/", 1)[1]
            node = defs[owner]
        for key in ("oneOf", "anyOf"):
            if key in node:  # the alternative the value matches
                for alt in node[key]:
                    if Draft202012Validator({**alt, "$defs": defs}).is_valid(value):
                        walk(value, alt, owner)
                        return
        if isinstance(value, list) and "items" in node:
            for x in value:
                walk(x, node["items"], owner)
        elif isinstance(value, dict):
            props = node.get("properties", {})
            for k, v in value.items():
                if k in props:
                    seen.add(f"{owner}.{k}")
                    walk(v, props[k], owner)
                elif isinstance(node.get("additionalProperties"), dict):
                    walk(v, node["additionalProperties"], owner)

    for m in manifests:
        walk(m, schema, "manifest")
    return seen


@pytest.mark.toolchain
def test_the_builds_reach_every_field_the_schema_describes(built):
    s = M.schema()
    described = {f"manifest.{k}" for k in s["properties"]}
    described |= {f"{name}.{k}" for name, d in s["$defs"].items() for k in d.get("properties", {})}
    unwritten = described - _seen(s, _manifests(built).values()) - set(NOT_REACHED)
    assert not unwritten, (f"the schema describes {sorted(unwritten)}, which no build writes — remove them from "
                           "generator/assemble/manifest.schema.json, or build what writes them here")
    assert set(NOT_REACHED) <= described  # an exemption for a field the schema no longer has goes too


@pytest.mark.toolchain
@pytest.mark.parametrize("where", ["", "/permutations/0", "/permutations/0/render_state/depth",
                                   "/materials/cobblestone/render_state", "/ubershader/tables/material_entry",
                                   "/permutations/0/platforms/webgpu/reflection/bind_groups/0/buffer", "/packs/0"])
def test_an_unknown_field_anywhere_is_a_schema_error(built, where):
    m = json.loads(json.dumps(built["example"]))
    node = m
    for part in filter(None, where.split("/")):
        node = node[int(part)] if isinstance(node, list) else node[part]
    node["bogus"] = 1
    found = M.problems(m)
    assert found and found[0].startswith(f"{where or '/'}: ") and "'bogus'" in found[0], found


@pytest.mark.toolchain
def test_a_build_whose_manifest_does_not_match_fails_and_keeps_the_last_one(built, tmp_path):
    """A permutation kept from the last build keeps its entry whole: an entry with a field the schema does not
    describe (here added by hand) reaches the new manifest, and the build refuses to write it."""
    out = tmp_path / "out"
    shutil.copytree(built["_dir"] / "example", out)
    m = json.loads((out / "manifest.json").read_text())
    m["permutations"][0]["bogus"] = True
    edited = (json.dumps(m, indent=2) + "\n").encode()
    (out / "manifest.json").write_bytes(edited)
    r = _cli("build", EXAMPLE, "--out", out, "--pack", "-q")
    assert r.returncode == 1, r.stderr
    assert "does not match format 1's schema" in r.stderr and "/permutations/0: " in r.stderr and "'bogus'" in r.stderr
    assert (out / "manifest.json").read_bytes() == edited  # not replaced


# ------------------------------------------------------------------------------------------ render state

OPAQUE = {"alpha_mode": "opaque", "blend": None, "cull": "back", "depth": {"test": True, "write": True, "compare": "less"}}


def _surface(perm_id: str) -> dict[str, str]:
    """The surface state a permutation key spells (the test reads the key; an engine reads render_state)."""
    return dict(p.split("=", 1) for p in perm_id.split(";") if p.split("=", 1)[0] in ("alpha", "double_sided"))


@pytest.mark.toolchain
def test_render_state_is_stated_per_material_and_per_permutation(built):
    m = built["state"]
    mats = {k: v["render_state"] for k, v in m["materials"].items()}
    assert mats["cobblestone"] == OPAQUE
    assert mats["old_paint"] == {
        "alpha_mode": "blend", "cull": "none", "depth": {"test": True, "write": False, "compare": "less"},
        "blend": {"color": {"src": "src_alpha", "dst": "one_minus_src_alpha", "op": "add"},
                  "alpha": {"src": "one", "dst": "one_minus_src_alpha", "op": "add"}, "premultiplied": False}}
    assert mats["painted_wood"] == {**OPAQUE, "alpha_mode": "mask", "alpha_cutoff": 0.3}
    assert m["materials"]["painted_wood"]["params"]["alpha_cutoff"] == 0.3
    perms = {e["hash"]: e for e in m["permutations"]}
    for o in m["objects"]:  # a permutation's state is its materials' without their values
        e = perms[o["permutation"]]
        mine = {k: v for k, v in mats[o["material"]].items() if k != "alpha_cutoff"}
        assert e["render_state"] == mine, o["name"]


@pytest.mark.toolchain
def test_render_state_agrees_with_the_surface_state_of_every_key(built):
    blend = {"color": {"src": "src_alpha", "dst": "one_minus_src_alpha", "op": "add"},
             "alpha": {"src": "one", "dst": "one_minus_src_alpha", "op": "add"}, "premultiplied": False}
    n = 0
    for name, m in _manifests(built).items():
        for e in [*m["permutations"], *m.get("removed", [])]:
            sf = _surface(e["id"])
            alpha = sf.get("alpha", "opaque")
            assert e["render_state"] == {
                "alpha_mode": alpha, "blend": blend if alpha == "blend" else None,
                "cull": "none" if sf.get("double_sided") == "true" else "back",
                "depth": {"test": True, "write": alpha != "blend", "compare": "less"}}, (name, e["id"])
            n += 1
    assert n >= 20
    g = built["gltf"]["materials"]  # glTF: alphaMode MASK with alphaCutoff 0.4, doubleSided
    assert g["leaf"]["render_state"] == {**OPAQUE, "alpha_mode": "mask", "alpha_cutoff": 0.4, "cull": "none"}
    assert g["textured_metal"]["render_state"] == OPAQUE
    assert "render_state" not in built["example"]["ubershader"]  # it implements no surface state
