"""glTF 2.0 scenes (generator/scene/gltf.py): the Khronos sample-style cases written
here (a textured metal, an alpha-masked leaf, a double-sided cloth, a mesh without tangents, lights of all three
types) map to the bricks, build in all three languages, share a permutation exactly where the shader is the same,
and every malformed file or unsupported shading extension is one error with the file and the JSON pointer."""
from __future__ import annotations

import copy
import json
import math
import struct
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from generator.lang import SourceError
from tests.conftest import require_tool

REPO = Path(__file__).resolve().parents[2]
BRDF = "lambert+microfacet(ndf=ggx,fresnel=schlick,vis=smith_ggx_height_correlated)"


@pytest.fixture(scope="module")
def lib():
    from generator.library.bricks import load_library
    return load_library(())


def run(*args):
    return subprocess.run([sys.executable, "-m", "generator.cli", *map(str, args)], cwd=REPO,
                          capture_output=True, text=True, timeout=300)


class Doc:
    """A glTF document and its one binary buffer, built in the test."""

    def __init__(self):
        self.bin = bytearray()
        self.d = {"asset": {"version": "2.0", "generator": "tests/scene/test_gltf.py"}, "scenes": [{"name": "main", "nodes": []}],
                  "scene": 0, "nodes": [], "meshes": [], "materials": [], "accessors": [], "bufferViews": [],
                  "buffers": [], "textures": [], "images": [], "samplers": [{}]}

    def accessor(self, values, atype, ctype=5126, target=34962, normalized=False):
        dt = {5126: "<f4", 5123: "<u2", 5125: "<u4"}[ctype]
        a = np.asarray(values, dtype=dt)
        data = a.tobytes()
        while len(self.bin) % 4:
            self.bin.append(0)
        self.d["bufferViews"].append({"buffer": 0, "byteOffset": len(self.bin), "byteLength": len(data), "target": target})
        self.bin += data
        acc = {"bufferView": len(self.d["bufferViews"]) - 1, "componentType": ctype, "count": len(a), "type": atype}
        if normalized:
            acc["normalized"] = True
        if atype == "VEC3" and ctype == 5126:
            acc["min"], acc["max"] = a.min(0).tolist(), a.max(0).tolist()
        self.d["accessors"].append(acc)
        return len(self.d["accessors"]) - 1

    def texture(self, name):
        """A texture of a 2 × 2 PNG embedded as a data URI (every image a material binds is read)."""
        self.d["images"].append({"name": name, "uri": png_data_uri()})
        self.d["textures"].append({"source": len(self.d["images"]) - 1, "sampler": 0})
        return len(self.d["textures"]) - 1

    def quad_mesh(self, name, material, tangents=True, colors=False, normals=True):
        p = [[-1, 0, -1], [1, 0, -1], [1, 0, 1], [-1, 0, 1]]
        attrs = {"POSITION": self.accessor(p, "VEC3"), "TEXCOORD_0": self.accessor([[0, 0], [1, 0], [1, 1], [0, 1]], "VEC2")}
        if normals:
            attrs["NORMAL"] = self.accessor([[0, 1, 0]] * 4, "VEC3")
        if tangents:
            attrs["TANGENT"] = self.accessor([[1, 0, 0, 1]] * 4, "VEC4")
        if colors:
            attrs["COLOR_0"] = self.accessor([[1, 0.5, 0.5, 1]] * 4, "VEC4")
        idx = self.accessor([0, 2, 1, 0, 3, 2], "SCALAR", 5123, 34963)
        prim = {"attributes": attrs, "indices": idx}
        if material is not None:
            prim["material"] = material
        self.d["meshes"].append({"name": name, "primitives": [prim]})
        return len(self.d["meshes"]) - 1

    def node(self, **node):
        self.d["nodes"].append(node)
        self.d["scenes"][0]["nodes"].append(len(self.d["nodes"]) - 1)
        return len(self.d["nodes"]) - 1

    def material(self, **m):
        self.d["materials"].append(m)
        return len(self.d["materials"]) - 1

    def finish(self):
        d = copy.deepcopy(self.d)
        d["buffers"] = [{"byteLength": len(self.bin)}]
        return d, bytes(self.bin)

    def write_gltf(self, path: Path) -> Path:
        d, b = self.finish()
        path.with_suffix(".bin").write_bytes(b)
        d["buffers"][0]["uri"] = path.with_suffix(".bin").name
        path.write_text(json.dumps(d, indent=1))
        return path

    def write_glb(self, path: Path) -> Path:
        d, b = self.finish()
        path.write_bytes(glb(json.dumps(d).encode(), b))
        return path


def png_bytes(texels=((200, 100, 50, 255), (20, 40, 60, 255), (0, 0, 0, 255), (255, 255, 255, 255)),
              size=(2, 2)) -> bytes:
    import io

    from PIL import Image
    buf = io.BytesIO()
    Image.frombytes("RGBA", size, bytes(c for px in texels for c in px)).save(buf, format="PNG")
    return buf.getvalue()


def png_data_uri(data: bytes | None = None) -> str:
    import base64
    return "data:image/png;base64," + base64.b64encode(png_bytes() if data is None else data).decode()


def glb(js: bytes, b: bytes) -> bytes:
    js += b" " * (-len(js) % 4)
    b += b"\0" * (-len(b) % 4)
    body = struct.pack("<II", len(js), 0x4E4F534A) + js + struct.pack("<II", len(b), 0x004E4942) + b
    return struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body


def sample_doc(extra_lights=True) -> Doc:
    """The five sample-style cases in one scene."""
    g = Doc()
    base, orm, nrm, leaf = g.texture("metal_base.png"), g.texture("metal_orm.png"), g.texture("n.png"), g.texture("leaf.png")
    metal = g.material(name="textured_metal", pbrMetallicRoughness={
        "baseColorFactor": [1, 0.8, 0.6, 1], "metallicFactor": 1.0, "roughnessFactor": 0.5,
        "baseColorTexture": {"index": base}, "metallicRoughnessTexture": {"index": orm}},
        normalTexture={"index": nrm}, occlusionTexture={"index": orm})
    leafm = g.material(name="leaf", alphaMode="MASK", alphaCutoff=0.4, doubleSided=True, pbrMetallicRoughness={
        "baseColorTexture": {"index": leaf}, "metallicFactor": 0.0, "roughnessFactor": 0.8})
    cloth = g.material(name="cloth", doubleSided=True, pbrMetallicRoughness={
        "baseColorFactor": [0.2, 0.3, 0.7, 1], "metallicFactor": 0.0, "roughnessFactor": 0.9})
    bumpy = g.material(name="bumpy", normalTexture={"index": nrm}, pbrMetallicRoughness={"metallicFactor": 0.0})
    g.node(name="statue", mesh=g.quad_mesh("statue_mesh", metal))
    g.node(name="leaf", mesh=g.quad_mesh("leaf_mesh", leafm), translation=[3, 0, 0])
    g.node(name="cloth", mesh=g.quad_mesh("cloth_mesh", cloth, colors=True), scale=[2, 1, 2])
    g.node(name="rock", mesh=g.quad_mesh("rock_mesh", bumpy, tangents=False))
    if extra_lights:
        g.d["extensionsUsed"] = ["KHR_lights_punctual"]
        g.d["extensions"] = {"KHR_lights_punctual": {"lights": [
            {"name": "sun", "type": "directional", "color": [1, 0.9, 0.8], "intensity": 3.0},
            {"name": "bulb", "type": "point", "intensity": 20.0, "range": 8.0},
            {"name": "torch", "type": "spot", "intensity": 50.0, "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.6}},
        ]}}
        s = math.sqrt(0.5)
        g.node(name="sun_node", rotation=[-s, 0, 0, s], extensions={"KHR_lights_punctual": {"light": 0}})  # −Z → −Y
        g.node(name="bulb_node", translation=[0, 3, 0], extensions={"KHR_lights_punctual": {"light": 1}})
        g.node(name="torch_node", translation=[0, 4, 1], rotation=[-s, 0, 0, s],
               extensions={"KHR_lights_punctual": {"light": 2}})
    return g


def test_sample_scene_maps_materials_lights_and_objects(tmp_path, lib):
    from generator.scene.load import load_scene
    scene = load_scene(sample_doc().write_gltf(tmp_path / "model.gltf"), lib)
    m = scene.materials
    assert {x.brdf for x in m.values()} == {BRDF}
    assert m["textured_metal"].packing == "gltf_metallic_roughness(normal=normal_map)"
    assert m["textured_metal"].params == {"base_color": [1.0, 0.8, 0.6], "metallic": 1.0, "roughness": 0.5}
    assert m["leaf"].packing == "albedo_texture(normal=vertex)"  # a dielectric with a base color texture only
    assert (m["leaf"].alpha_mode, m["leaf"].alpha_cutoff, m["leaf"].double_sided) == ("MASK", 0.4, True)
    assert m["cloth"].packing == "constants(normal=vertex)" and m["cloth"].double_sided
    assert m["cloth"].params["rho_d"] == [0.2, 0.3, 0.7] and m["cloth"].params["alpha"] == pytest.approx(0.81)
    assert m["bumpy"].packing == "constants(normal=normal_map)"
    assert m["bumpy"].params["f0"] == pytest.approx([0.04] * 3)
    lights = scene.lights
    assert [lights[n].type for n in scene.light_sets["main"]] == ["directional", "point_range", "spot"]
    assert lights["sun"].params["direction"] == pytest.approx([0, 1, 0], abs=1e-6)  # toward the light: +Y
    assert lights["sun"].params["color"] == pytest.approx([3.0, 2.7, 2.4])
    assert lights["bulb"].params == {"position": [0.0, 3.0, 0.0], "color": [20.0, 20.0, 20.0], "radius": 8.0}
    t = lights["torch"].params
    assert t["direction"] == pytest.approx([0, -1, 0], abs=1e-6) and (t["inner_angle"], t["outer_angle"]) == (0.2, 0.6)
    assert t["radius"] == 1e6  # no range: "infinite"
    objs = {o["name"]: o for o in scene.objects}
    assert list(objs) == ["statue", "leaf", "cloth", "rock"]
    assert objs["rock"]["tangents"] == "generated" and objs["statue"]["tangents"] == "file"
    assert objs["cloth"]["vertex_colors"] and objs["cloth"]["double_sided"]
    assert objs["leaf"]["model"][0][3] == 3.0
    rock = objs["rock"]["mesh"]
    assert rock.tangents[:, :3] == pytest.approx(np.tile([1, 0, 0], (4, 1)), abs=1e-6)  # +u is +x on this quad
    assert rock.tangents[:, 3] == pytest.approx([-1] * 4)  # B = cross(N, T) w = +z, where v grows
    assert rock.index_count == 6 and rock.vertex_count == 4
    assert len(scene.permutations) == 4 and all(o["light_set"] == "main" for o in scene.objects)
    assert any("KHR_lights_punctual accepted" in n for n in scene.notes)
    assert any("not MikkTSpace-exact" in n and "rock" in n for n in scene.notes)
    assert any("occlusionTexture is not read" in n for n in scene.notes)


def _key_of(tmp_path, lib, mutate, name):
    from generator.scene.load import load_scene
    g = sample_doc()
    mutate(g)
    scene = load_scene(g.write_gltf(tmp_path / f"{name}.gltf"), lib)
    return {o["name"]: o["permutation"] for o in scene.objects}


def test_permutations_change_exactly_where_the_shader_does(tmp_path, lib):
    ref = _key_of(tmp_path, lib, lambda g: None, "ref")

    def factors(g):  # other factor values: the same shader, other uniforms
        g.d["materials"][2]["pbrMetallicRoughness"]["baseColorFactor"] = [0.9, 0.1, 0.1, 1]
        g.d["materials"][0]["pbrMetallicRoughness"]["roughnessFactor"] = 0.1

    def tangents_in_file(g):  # rock with tangents in the file: generated ones give the same shader
        g.d["meshes"][3]["primitives"][0]["attributes"]["TANGENT"] = g.accessor([[1, 0, 0, 1]] * 4, "VEC4")

    def no_occlusion(g):  # occlusion is not read: no change
        del g.d["materials"][0]["occlusionTexture"]

    def cutoff(g):  # alphaCutoff is a uniform: materials with other cutoffs share the shader
        g.d["materials"][1]["alphaCutoff"] = 0.7

    def opaque_alpha(g):  # baseColorFactor's alpha is not read by an OPAQUE material
        g.d["materials"][2]["pbrMetallicRoughness"]["baseColorFactor"][3] = 0.3

    def dark_emissive_texture(g):  # an emissiveTexture under emissiveFactor 0 emits nothing: not sampled
        g.d["materials"][2]["emissiveTexture"] = {"index": 0}

    for mutate in (factors, tangents_in_file, no_occlusion, cutoff, opaque_alpha, dark_emissive_texture):
        assert _key_of(tmp_path, lib, mutate, mutate.__name__) == ref, mutate.__name__

    def no_normal_map(g):
        del g.d["materials"][0]["normalTexture"]

    def no_orm(g):  # the metal keeps gltf_metallic_roughness (a white ORM texture): metallic 1 needs base in f0
        del g.d["materials"][0]["pbrMetallicRoughness"]["metallicRoughnessTexture"]

    def no_base_texture(g):
        del g.d["materials"][1]["pbrMetallicRoughness"]["baseColorTexture"]

    got = _key_of(tmp_path, lib, no_normal_map, "nn")
    assert got["statue"] != ref["statue"] and {k: v for k, v in got.items() if k != "statue"} == \
        {k: v for k, v in ref.items() if k != "statue"}
    assert _key_of(tmp_path, lib, no_orm, "no") == ref
    got = _key_of(tmp_path, lib, no_base_texture, "nb")
    assert got["leaf"] != ref["leaf"] and {k: v for k, v in got.items() if k != "leaf"} == \
        {k: v for k, v in ref.items() if k != "leaf"}

    # the surface state (spec/surface.py): each of these changes the one object's shader, and nothing else
    def no_colors(g):
        del g.d["meshes"][2]["primitives"][0]["attributes"]["COLOR_0"]

    def single_sided_cloth(g):
        g.d["materials"][2]["doubleSided"] = False

    def opaque_leaf(g):
        g.d["materials"][1]["alphaMode"] = "OPAQUE"

    def blended_leaf(g):
        g.d["materials"][1]["alphaMode"] = "BLEND"

    def glowing_cloth(g):
        g.d["materials"][2]["emissiveFactor"] = [1.0, 0.5, 0.0]

    def glowing_textured_cloth(g):
        g.d["materials"][2]["emissiveFactor"] = [1.0, 0.5, 0.0]
        g.d["materials"][2]["emissiveTexture"] = {"index": 0}

    keys = {}
    for mutate, obj in ((no_colors, "cloth"), (single_sided_cloth, "cloth"), (opaque_leaf, "leaf"),
                        (blended_leaf, "leaf"), (glowing_cloth, "cloth"), (glowing_textured_cloth, "cloth")):
        got = _key_of(tmp_path, lib, mutate, mutate.__name__)
        assert got[obj] != ref[obj], mutate.__name__
        assert {k: v for k, v in got.items() if k != obj} == {k: v for k, v in ref.items() if k != obj}, \
            mutate.__name__
        keys[mutate.__name__] = got[obj]
    assert len(set(keys.values())) == len(keys)  # six different shaders

    def fewer_lights(g):
        g.d["scenes"][0]["nodes"] = g.d["scenes"][0]["nodes"][:-1]  # the spot's node leaves the scene
    got = _key_of(tmp_path, lib, fewer_lights, "fl")
    assert all(got[k] != ref[k] for k in ref)


@pytest.fixture(scope="module")
def tools():
    for t in ("glslc", "naga", "spirv-val", "spirv-opt"):
        require_tool(t)


@pytest.mark.toolchain
@pytest.mark.parametrize("suffix", [".gltf", ".glb"])
def test_builds_in_every_language(tmp_path, tools, suffix):
    g = sample_doc()
    path = g.write_gltf(tmp_path / "model.gltf") if suffix == ".gltf" else g.write_glb(tmp_path / "model.glb")
    out = tmp_path / "out"
    r = run("build", path, "--out", out, "--no-cache", "-j", "2")
    assert r.returncode == 0, r.stderr + r.stdout
    m = json.loads((out / "manifest.json").read_text())
    assert len(m["permutations"]) == 4
    for p in m["permutations"]:
        assert p["status"] == "ok" and set(p["languages"]) == {"glsl", "hlsl", "wgsl"}
    packs = sorted(p["id"].split("packing=")[1].split(";")[0] for p in m["permutations"])
    assert packs == ["albedo_texture(normal=vertex)", "constants(normal=normal_map)", "constants(normal=vertex)",
                     "gltf_metallic_roughness(normal=normal_map)"]
    assert sorted(o for p in m["permutations"] for o in p["objects"]) == ["cloth", "leaf", "rock", "statue"]


# --- malformed inputs: one line with the file and the JSON pointer, exit 1 ------------------------------------------

def _set(d, ptr, value):
    parts = ptr.strip("/").split("/")
    for k in parts[:-1]:
        d = d[int(k)] if isinstance(d, list) else d[k]
    if value is _DEL:
        del d[parts[-1]]
    elif isinstance(d, list):
        d[int(parts[-1])] = value
    else:
        d[parts[-1]] = value


_DEL = object()
BAD_JSON = [  # (id, pointer changed, new value, pointer in the message, words of the message)
    ("texture-index-out-of-range", "/materials/0/pbrMetallicRoughness/baseColorTexture/index", 99,
     "/materials/0/pbrMetallicRoughness/baseColorTexture/index", "textures index 99 does not exist"),
    ("texture-index-a-string", "/materials/0/normalTexture/index", "0", "/materials/0/normalTexture/index",
     "must be an integer"),
    ("metallic-out-of-range", "/materials/2/pbrMetallicRoughness/metallicFactor", 1.5,
     "/materials/2/pbrMetallicRoughness/metallicFactor", "outside [0.0, 1.0]"),
    ("bad-alpha-mode", "/materials/1/alphaMode", "CUTOUT", "/materials/1/alphaMode", "not an alpha mode"),
    ("no-asset", "/asset", _DEL, "/asset", "'asset' is required"),
    ("glTF-1", "/asset/version", "1.0", "/asset/version", "is not 2.x"),
    ("no-position", "/meshes/0/primitives/0/attributes/POSITION", _DEL, "/meshes/0/primitives/0/attributes/POSITION",
     "'POSITION' is required"),
    ("accessor-past-its-view", "/accessors/0/count", 400, "/accessors/0", "need"),
    ("normal-is-vec2", "/accessors/2/type", "VEC2", "/accessors/2/type", "needs VEC3"),
    ("uv-set-1", "/materials/1/pbrMetallicRoughness/baseColorTexture/texCoord", 1,
     "/materials/1/pbrMetallicRoughness/baseColorTexture/texCoord", "TEXCOORD_0"),
    ("textures-without-uv", "/meshes/0/primitives/0/attributes/TEXCOORD_0", _DEL, "/meshes/0/primitives/0/attributes",
     "samples textures but the primitive has no TEXCOORD_0"),
    ("node-cycle", "/nodes/0/children", [0], "/nodes/0/children/0", "node 0 is reached twice"),
    ("node-two-parents", "/nodes/0/children", [1], "/scenes/0/nodes/1", "node 1 is reached twice"),
    ("buffer-file-missing", "/buffers/0/uri", "nowhere.bin", "/buffers/0/uri", "cannot read glTF buffer"),
    ("light-index", "/nodes/4/extensions/KHR_lights_punctual/light", 7, "/nodes/4/extensions/KHR_lights_punctual/light",
     "light 7 does not exist"),
    ("spot-cone-inverted", "/extensions/KHR_lights_punctual/lights/2/spot/innerConeAngle", 0.9,
     "/extensions/KHR_lights_punctual/lights/2/spot/innerConeAngle", "not below outerConeAngle"),
    ("light-type", "/extensions/KHR_lights_punctual/lights/0/type", "area",
     "/extensions/KHR_lights_punctual/lights/0/type", "not a KHR_lights_punctual type"),
    ("scene-node-missing", "/scenes/0/nodes/0", 42, "/scenes/0/nodes/0", "not an index of nodes"),
    ("buffer-too-short", "/buffers/0/byteLength", 10 ** 6, "/buffers/0/byteLength", "the data has"),
    ("clearcoat", "/materials/0/extensions", {"KHR_materials_clearcoat": {"clearcoatFactor": 1}},
     "/materials/0/extensions/KHR_materials_clearcoat", "extension KHR_materials_clearcoat changes shading"),
    ("texture-transform-differs", "/materials/0/normalTexture/extensions", {"KHR_texture_transform": {"scale": [2, 2]}},
     "/materials/0/normalTexture/extensions/KHR_texture_transform",
     "differs from /materials/0/pbrMetallicRoughness/baseColorTexture's"),
    ("unknown-khr", "/extensionsRequired", ["KHR_materials_future"], "/extensionsRequired/0",
     "extension KHR_materials_future is not supported"),
    ("vendor-required", "/extensionsRequired", ["EXT_meshopt_compression"], "/extensionsRequired/0",
     "required extension EXT_meshopt_compression is not supported"),
]


@pytest.mark.parametrize("case", BAD_JSON, ids=[c[0] for c in BAD_JSON])
def test_malformed_gltf_names_the_json_pointer(tmp_path, lib, case):
    from generator.scene.load import load_scene
    _, ptr, value, where, words = case
    g = sample_doc()
    path = g.write_gltf(tmp_path / "model.gltf")
    d = json.loads(path.read_text())
    _set(d, ptr, value)
    path.write_text(json.dumps(d))
    with pytest.raises(SourceError) as e:
        load_scene(path, lib)
    assert str(e.value).startswith(f"{path}: {where}: "), str(e.value)
    assert words in str(e.value) and " — " in str(e.value)  # what is wrong — what to do
    assert "\n" not in str(e.value)


def test_embedded_buffer_flat_normals_default_material_strip(tmp_path, lib):
    """A data-URI buffer, a primitive without NORMAL (flat normals, unwelded), without material (glTF's default:
    white, metallic 1, roughness 1) and drawn as a triangle strip; a LINES primitive is skipped with a note."""
    import base64
    from generator.scene.load import load_scene
    g = Doc()
    pos = g.accessor([[0, 0, 0], [1, 0, 0], [0, 0, -1], [1, 0, -1]], "VEC3")
    g.d["meshes"].append({"name": "strip", "primitives": [{"attributes": {"POSITION": pos}, "mode": 5},
                                                            {"attributes": {"POSITION": pos}, "mode": 1}]})
    g.node(mesh=0)
    d, b = g.finish()
    d["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(b).decode()
    path = tmp_path / "strip.gltf"
    path.write_text(json.dumps(d))
    scene = load_scene(path, lib)
    (obj,) = scene.objects
    assert obj["name"] == "strip#0" and obj["light_set"] == "main" and obj["lights"] == []
    m = scene.materials[obj["material"]]
    assert m.packing == "constants(normal=vertex)" and m.params == {"rho_d": [0.0] * 3, "f0": [1.0] * 3, "alpha": 1.0}
    mesh = obj["mesh"]
    assert mesh.index_count == 6 and mesh.vertex_count == 6  # two triangles, unwelded for flat normals
    assert mesh.normals == pytest.approx(np.tile([0, 1, 0], (6, 1)))  # counter-clockwise seen from +y
    assert any("LINES are not shaded" in n for n in scene.notes)


def test_generated_tangents_follow_mirrored_uvs_and_quantized_uvs_decode(tmp_path, lib):
    """u mirrored: T = −x and w = +1 (B = cross(N, T) w still points where v grows, +z); TEXCOORD_0 as normalized
    uint16 (KHR_mesh_quantization) decodes to [0, 1]."""
    from generator.scene.load import load_scene
    g = Doc()
    nrm = g.texture("n.png")
    mat = g.material(name="m", normalTexture={"index": nrm})
    attrs = {"POSITION": g.accessor([[-1, 0, -1], [1, 0, -1], [1, 0, 1], [-1, 0, 1]], "VEC3"),
             "NORMAL": g.accessor([[0, 1, 0]] * 4, "VEC3"),
             "TEXCOORD_0": g.accessor([[65535, 0], [0, 0], [0, 65535], [65535, 65535]], "VEC2", 5123, normalized=True)}
    g.d["meshes"].append({"primitives": [{"attributes": attrs, "material": mat,
                                          "indices": g.accessor([0, 2, 1, 0, 3, 2], "SCALAR", 5123, 34963)}]})
    g.node(name="q", mesh=0)
    g.d["extensionsUsed"] = g.d["extensionsRequired"] = ["KHR_mesh_quantization"]
    scene = load_scene(g.write_glb(tmp_path / "q.glb"), lib)
    mesh = scene.objects[0]["mesh"]
    assert mesh.uvs == pytest.approx(np.array([[1, 0], [0, 0], [0, 1], [1, 1]]))
    assert mesh.tangents == pytest.approx(np.tile([-1, 0, 0, 1], (4, 1)), abs=1e-6)
    assert scene.extra["extensions"] == ["KHR_mesh_quantization"]


def test_accepted_extensions_are_listed(tmp_path, lib):
    from generator.scene.load import load_scene
    g = sample_doc()
    g.d["extensionsUsed"] += ["KHR_materials_emissive_strength", "EXT_texture_webp"]
    g.d["materials"][2]["extensions"] = {"KHR_materials_emissive_strength": {"emissiveStrength": 2.0}}
    g.d["materials"][2]["emissiveFactor"] = [1, 0.5, 0]
    scene = load_scene(g.write_gltf(tmp_path / "model.gltf"), lib)
    assert scene.extra["extensions"] == ["KHR_lights_punctual", "KHR_materials_emissive_strength"]
    assert any("EXT_texture_webp ignored" in n for n in scene.notes)
    cloth = next(o for o in scene.objects if o["name"] == "cloth")
    assert scene.materials[cloth["material"]].params["emissive"] == [2.0, 1.0, 0.0]  # factor · emissiveStrength
    assert scene.permutations[cloth["permutation"]].surface.emissive == "factor"


def _glb_bytes():
    d, b = sample_doc().finish()
    return glb(json.dumps(d).encode(), b)


BAD_GLB = [  # (id, bytes → bytes, location, words)
    ("truncated", lambda x: x[:-8], "byte 8 (header)", "the header says"),
    ("bad-magic", lambda x: b"gLTF" + x[4:], "byte 0 (header)", "magic is"),
    ("version-1", lambda x: x[:4] + struct.pack("<I", 1) + x[8:], "byte 4 (header)", "GLB version 1"),
    ("chunk-past-end", lambda x: x[:12] + struct.pack("<I", len(x)) + x[16:], "byte 12 (chunk 0)", "runs past the end"),
    ("bin-first", lambda x: x[:16] + struct.pack("<I", 0x004E4942) + x[20:], "byte 12 (chunk 0)",
     "the first chunk must be JSON"),
    ("header-only", lambda x: x[:12].replace(x[8:12], struct.pack("<I", 12)) + b"", "byte 12 (chunk 0)",
     "the first chunk must be JSON"),
    ("short", lambda x: x[:7], "byte 0 (header)", "shorter than the 12-byte GLB header"),
    ("json-broken", lambda x: x[:20] + b"]" + x[21:], "JSON chunk line 1 column", "JSON syntax error"),
]


@pytest.mark.parametrize("case", BAD_GLB, ids=[c[0] for c in BAD_GLB])
def test_broken_glb_chunks(tmp_path, lib, case):
    from generator.scene.load import load_scene
    _, change, where, words = case
    path = tmp_path / "model.glb"
    path.write_bytes(change(_glb_bytes()))
    with pytest.raises(SourceError) as e:
        load_scene(path, lib)
    assert str(e.value).startswith(f"{path}: {where}"), str(e.value)
    assert words in str(e.value)


def test_glb_without_its_bin_chunk(tmp_path, lib):
    from generator.scene.load import load_scene
    d, _ = sample_doc().finish()
    path = tmp_path / "model.glb"
    path.write_bytes(glb(json.dumps(d).encode(), b"")[:-8])  # drop the (empty) BIN chunk's header
    path.write_bytes(path.read_bytes()[:8] + struct.pack("<I", len(path.read_bytes())) + path.read_bytes()[12:])
    with pytest.raises(SourceError) as e:
        load_scene(path, lib)
    assert str(e.value).startswith(f"{path}: /buffers/0: has no uri, and the file has no GLB BIN chunk"), str(e.value)


def test_cli_exits_1_with_one_line(tmp_path):
    path = tmp_path / "bad.gltf"
    path.write_text('{"asset": {"version": "2.0"}, "materials": [{"pbrMetallicRoughness": {"baseColorTexture": '
                    '{"index": 3}}}], "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "material": 0}]}], '
                    '"nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}]}')
    r = run("matrix", path)
    assert r.returncode == 1
    lines = [x for x in r.stderr.splitlines() if x.strip()]
    assert lines == [f"error: {path}: /materials/0/pbrMetallicRoughness/baseColorTexture/index: textures index 3 "
                     "does not exist (the file has 0 textures) — add the textures it refers to"], r.stderr
    path.write_text('{"asset": {"version": "2.0"},\n  "nodes": [}')
    r = run("matrix", path)
    assert r.returncode == 1 and f"{path}:2:13: JSON syntax error" in r.stderr, r.stderr


def test_matrix_explain_and_accuracy_take_a_gltf_scene(tmp_path):
    g = sample_doc()
    g.d["extensionsUsed"] += ["KHR_materials_emissive_strength"]
    g.d["materials"][2]["extensions"] = {"KHR_materials_emissive_strength": {"emissiveStrength": 2.0}}
    path = g.write_gltf(tmp_path / "model.gltf")
    r = run("matrix", path, "--explain", "--no-compile")
    assert r.returncode == 0, r.stderr
    assert "## Importer notes: what was mapped, accepted or left out" in r.stdout and "emissiveStrength scales the emissive parameter" in r.stdout
    r = run("accuracy", path, "--targets", "numpy", "--dtypes", "float32", "--samples", "2", "--format", "json")
    assert r.returncode == 0, r.stderr
    specs = json.loads(r.stdout)["specs"]
    assert specs and all(s.split(": ")[1] == "lambert+microfacet(ndf=ggx,fresnel=schlick,vis=smith_ggx_height_correlated)"
                         for s in specs)
