"""The C engine (examples/engine-c) draws a scene from a build's outputs and the frame export alone — no Python
while it renders — and its PNG equals `shadermatrix render --mode specialized` within 1 LSB on at least 99 % of
channels, with the Khronos validation layer on and silent; where its inputs are wrong it says so and fails.

The tolerance: the renderer compiles its own GLSL while the engine loads the build's optimized SPIR-V from the
pack, so a float may round differently in the last place, which can move a channel by one step of 8 bits; two
steps or more is a real difference (a wrong binding, block, matrix or state moves whole regions, as the tests
below that edit one field show). Measured on lavapipe (Mesa 25), 128 × 80: every channel equal (largest difference
0) on all thirteen scenes (the dynamic light set's, in both loop forms and tiled, a point light's six faces with pcf
and with vsm, and a dynamic set of shadowed buffer lights, too).
"""
from __future__ import annotations

import json
import math
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import require

REPO = Path(__file__).resolve().parents[2]
ENGINE_SRC = REPO / "examples" / "engine-c"
SIZE = "128x80"
LSB, FRACTION = 1, 0.99  # the tolerance (module docstring)
pytestmark = [pytest.mark.lavapipe, pytest.mark.toolchain]


def _cli(*args, timeout=300) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "generator.cli", *map(str, args)], cwd=REPO, capture_output=True,
                          text=True, timeout=timeout)


@pytest.fixture(scope="module")
def engine(tmp_path_factory) -> Path:
    """The engine built by gcc out of tree, as a user of the example builds it."""
    for tool in ("gcc", "make"):
        require(shutil.which(tool) is not None, f"{tool} not found — run `make setup` (scripts/setup.sh)")
    for header in ("vulkan/vulkan.h", "cjson/cJSON.h"):
        require(Path("/usr/include", header).exists(), f"/usr/include/{header} missing — run `make setup` "
                "(libvulkan-dev, libcjson-dev)")
    from generator.runtime.device import Device, VulkanUnavailable
    try:
        Device(validation=True).close()
    except VulkanUnavailable as exc:
        require(False, str(exc))
    out = tmp_path_factory.mktemp("engine-c")
    r = subprocess.run(["make", "-C", str(ENGINE_SRC), f"BUILD={out}", "CC=gcc"], capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    assert not (ENGINE_SRC / "build").exists(), "an out-of-tree build wrote into the source folder"
    return out / "engine-c"


def _image(texels: np.ndarray) -> str:
    from tests.scene.test_gltf import png_bytes, png_data_uri
    h, w = texels.shape[:2]
    return png_data_uri(png_bytes([tuple(int(c) for c in px) for px in texels.reshape(-1, 4)], (w, h)))


def gltf_scene(path: Path) -> Path:
    """A textured glTF scene: a base-colour and a normal texture (8 × 8, so with mips), a texture behind a nearest,
    clamped sampler, an alpha-masked double-sided leaf, a blended pane, a node mirrored by its scale, under a
    directional and a point light."""
    from tests.scene.test_gltf import Doc
    g = Doc()
    y, x = np.mgrid[0:8, 0:8]
    checker = np.where(((x // 2 + y // 2) % 2)[..., None] == 0, [200, 90, 40, 255], [40, 120, 200, 0])
    bumps = np.stack([128 + 60 * np.sin(x * math.pi / 4), 128 + 60 * np.cos(y * math.pi / 4),
                      np.full(x.shape, 230), np.full(x.shape, 255)], -1)
    g.d["samplers"].append({"magFilter": 9728, "minFilter": 9728, "wrapS": 33071, "wrapT": 33071})
    textures = []
    for name, texels, sampler in (("base.png", checker, 0), ("normal.png", bumps, 0), ("sign.png", checker, 1)):
        g.d["images"].append({"name": name, "uri": _image(texels)})
        g.d["textures"].append({"source": len(g.d["images"]) - 1, "sampler": sampler})
        textures.append(len(g.d["textures"]) - 1)
    base, normal, sign = textures
    brick = g.material(name="brick", normalTexture={"index": normal}, pbrMetallicRoughness={
        "baseColorTexture": {"index": base}, "metallicFactor": 0.0, "roughnessFactor": 0.6})
    leaf = g.material(name="leaf", alphaMode="MASK", alphaCutoff=0.5, doubleSided=True, pbrMetallicRoughness={
        "baseColorTexture": {"index": base}, "metallicFactor": 0.0, "roughnessFactor": 0.8})
    pane = g.material(name="pane", alphaMode="BLEND", pbrMetallicRoughness={
        "baseColorFactor": [0.3, 0.5, 0.9, 0.5], "metallicFactor": 0.0, "roughnessFactor": 0.3})
    signm = g.material(name="sign", pbrMetallicRoughness={"baseColorTexture": {"index": sign}, "metallicFactor": 0.0})
    s = math.sqrt(0.5)
    g.node(name="floor", mesh=g.quad_mesh("floor_mesh", brick), scale=[3, 1, 3])
    g.node(name="leaf", mesh=g.quad_mesh("leaf_mesh", leaf), translation=[-1.5, 0.8, 0.5],
           rotation=[0.38, 0, 0, 0.925])
    g.node(name="pane", mesh=g.quad_mesh("pane_mesh", pane), translation=[0.5, 1.0, 1.0], scale=[0.8, 1, 0.8])
    g.node(name="sign", mesh=g.quad_mesh("sign_mesh", signm), translation=[1.8, 0.3, -0.8], scale=[-0.7, 1, 0.7])
    g.d["extensionsUsed"] = ["KHR_lights_punctual"]
    g.d["extensions"] = {"KHR_lights_punctual": {"lights": [
        {"name": "sun", "type": "directional", "color": [1, 0.9, 0.8], "intensity": 1.5},
        {"name": "bulb", "type": "point", "intensity": 6.0, "range": 10.0}]}}
    g.node(name="sun_node", rotation=[-s, 0, 0, s], extensions={"KHR_lights_punctual": {"light": 0}})
    g.node(name="bulb_node", translation=[0.5, 2.5, 1.5], extensions={"KHR_lights_punctual": {"light": 1}})
    return g.write_gltf(path)


# Baked tables (fp32 and fp16, read with their rows' samplers) under a pcf light, whose tap spacing the export gives.
TABLES = """[scene]
name = "tables"

[materials.factored]
brdf = "lambert+blinn_phong_factored"
params = { rho_d = [0.6, 0.3, 0.2], n = 40.0, f0 = [0.2, 0.2, 0.2] }

[materials.ramp]
brdf = "microfacet(ndf=ggx,fresnel=fresnel_ramp,vis=smith_schlick)"
params = { alpha = 0.3 }

[lights.sun]
type = "directional"
shadow = "pcf"
params = { direction = [0.3, 0.9, 0.3], color = [3.0, 2.9, 2.7] }

[light_sets]
sun = ["sun"]

[[objects]]
name = "factored"
material = "factored"
lights = "sun"

[[objects]]
name = "ramp"
material = "ramp"
lights = "sun"
"""


def _written(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


def _point_vsm(tmp: Path) -> Path:
    """tests/scenes/point_ring.toml with its light's filter vsm (no pcf parameters), its placement beside it."""
    src = REPO / "tests" / "scenes" / "point_ring.toml"
    text = src.read_text().replace('shadow = "pcf"', 'shadow = "vsm"').replace(", shadow_bias = 0.002, pcf_taps = 1.0", "")
    assert 'shadow = "vsm"' in text and "pcf_taps" not in text
    shutil.copy(src.with_name("point_ring.placement.toml"), tmp / "point_vsm.placement.toml")
    return _written(tmp / "point_vsm.toml", text)


def _dynamic_shadow(tmp: Path) -> Path:
    from tests.runtime.test_dynamic_shadows import MIXED, PLACEMENT, SPOTS, _scene

    (tmp / "dynamic_shadow.placement.toml").write_text(PLACEMENT)
    return _written(tmp / "dynamic_shadow.toml", _scene([*MIXED, *SPOTS[2:]], True))


def _switched(tmp: Path) -> Path:
    """tests/scenes/dynamic_lights.toml with its dynamic set's loop = "switch", its placement beside it."""
    src = REPO / "tests" / "scenes" / "dynamic_lights.toml"
    text = src.read_text().replace("[light_sets.crowd]\ndynamic = true\n", '[light_sets.crowd]\ndynamic = true\nloop = "switch"\n')
    assert 'loop = "switch"' in text
    shutil.copy(src.with_name("dynamic_lights.placement.toml"), tmp / "dynamic_switch.placement.toml")
    return _written(tmp / "dynamic_switch.toml", text)


def _tiled(tmp: Path) -> Path:
    """tests/scenes/dynamic_lights.toml with its dynamic set's culling = "tiles", its placement beside it: render
    culls its spots against 16-pixel tiles, the engine puts every light in one tile, and both draw alike."""
    src = REPO / "tests" / "scenes" / "dynamic_lights.toml"
    text = src.read_text().replace("[light_sets.crowd]\ndynamic = true\n", '[light_sets.crowd]\ndynamic = true\nculling = "tiles"\n')
    assert 'culling = "tiles"' in text
    shutil.copy(src.with_name("dynamic_lights.placement.toml"), tmp / "dynamic_tiles.placement.toml")
    return _written(tmp / "dynamic_tiles.toml", text)


SCENES = {"example": lambda tmp: REPO / "scenes" / "example.toml",
          "textured": lambda tmp: REPO / "scenes" / "textured.toml",
          "gltf": lambda tmp: gltf_scene(tmp / "textured.gltf"),
          # masked casters (mask and mask_moments units) and a vsm light (moments, blur)
          "depth_mask": lambda tmp: REPO / "tests" / "scenes" / "depth_mask.toml",
          "tables": lambda tmp: _written(tmp / "tables.toml", TABLES),
          # a spot light's perspective map with pcf, and an object outside its light set that casts nothing
          "spot_shadow": lambda tmp: REPO / "tests" / "scenes" / "spot_shadow.toml",
          # a point light's six faces (pcf): six depth passes copied into the layers of one 2D array
          "point_shadow": lambda tmp: REPO / "tests" / "scenes" / "point_ring.toml",
          # the same with vsm: each face's moments blurred, then copied into its layer
          "point_vsm": lambda tmp: _point_vsm(tmp),
          # a dynamic set's shadowed pairs: two pcf spots in one array, a vsm point light's six faces, a
          # pcf_hardware directional light (tests/runtime/test_dynamic_shadows.py's mixed set, 2 spots more)
          "dynamic_shadow": lambda tmp: _dynamic_shadow(tmp),
          # a dynamic light set: 16 points and 2 spots in two storage buffers (manifest dynamic_light_sets)
          "dynamic": lambda tmp: REPO / "tests" / "scenes" / "dynamic_lights.toml",
          # the same lights in one storage buffer, one loop switching on the pair (loop = "switch": ids, first)
          "dynamic_switch": lambda tmp: _switched(tmp),
          # the same lights read through a LightTiles index list per tile (culling = "tiles")
          "dynamic_tiles": lambda tmp: _tiled(tmp),
          # a masked, two blended (drawn back to front, as the export's draw_order says) and a double-sided object
          "surface_state": lambda tmp: REPO / "tests" / "scenes" / "surface_state.toml"}


@pytest.fixture(scope="module")
def prepared(tmp_path_factory):
    """name -> (build folder, export folder, the render's frame): built with --pack, rendered with --export."""
    done = {}

    def get(name: str):
        if name not in done:
            tmp = tmp_path_factory.mktemp(name)
            scene = SCENES[name](tmp)
            r = _cli("build", scene, "--out", tmp / "build", "--platform", "vulkan", "--pack")
            assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
            r = _cli("render", scene, "--mode", "specialized", "--build", tmp / "build", "--out", tmp / "render",
                     "--size", SIZE, "--frames", "1", "--export", tmp / "export")
            assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
            done[name] = (tmp / "build", tmp / "export", tmp / "render" / "frame_0000.png")
        return done[name]
    return get


def run_engine(engine: Path, build: Path, export: Path, out: Path) -> subprocess.CompletedProcess:
    return subprocess.run([str(engine), str(build), str(export), str(out)], capture_output=True, text=True,
                          timeout=120)


def pixels(path: Path) -> np.ndarray:
    from PIL import Image
    with Image.open(path) as im:
        assert im.mode == "RGBA", f"{path}: {im.mode}, not RGBA as render writes"
        return np.asarray(im).astype(np.int64)


def compare(ours: Path, theirs: Path) -> tuple[int, float]:
    """(the largest channel difference, the fraction of channels within LSB) of two frames of one size."""
    a, b = pixels(ours), pixels(theirs)
    assert a.shape == b.shape, f"{ours} is {a.shape}, the render's frame {b.shape}"
    d = np.abs(a - b)
    return int(d.max()), float((d <= LSB).mean())


@pytest.mark.parametrize("name", SCENES)
def test_the_engine_draws_what_render_draws(engine, prepared, name, tmp_path):
    build, export, reference = prepared(name)
    r = run_engine(engine, build, export, tmp_path / "engine.png")
    assert r.returncode == 0, f"exit {r.returncode}:\n{r.stderr[-4000:]}"
    assert "validation layer" not in r.stderr, r.stderr
    worst, within = compare(tmp_path / "engine.png", reference)
    assert within >= FRACTION, (f"{name}: {within:.4%} of channels within {LSB} LSB of render's (at least "
                                f"{FRACTION:.0%} wanted), largest difference {worst}")
    img = pixels(reference)
    drawn = (np.abs(img[..., :3] - img[0, 0, :3]).max(-1) > 2).mean()
    assert drawn > 0.05, f"{name}: only {drawn:.1%} of the frame is not background: the comparison says little"


def _edited(src: Path, dst: Path, edit) -> Path:
    """A copy of build `src` whose manifest `edit(manifest)` changed."""
    shutil.copytree(src, dst)
    m = json.loads((dst / "manifest.json").read_text())
    edit(m)
    (dst / "manifest.json").write_text(json.dumps(m))
    return dst


def _perm(m: dict, obj: str) -> dict:
    o = next(o for o in m["objects"] if o["name"] == obj)
    return next(p for p in m["permutations"] if p["hash"] == o["permutation"])


def test_a_layout_unlike_the_shaders_is_a_validation_failure(engine, prepared, tmp_path):
    """The messenger catches what the layer says: a Material block moved to another binding in the interface
    makes a pipeline layout its SPIR-V does not match; the run fails (exit 3) and the frame is not drawn."""
    build, export, _ = prepared("example")

    def move(m):
        block = next(b for b in _perm(m, "ground")["interface"]["frag"]["uniform_blocks"] if b["name"] == "Material")
        block["binding"] = 7
    r = run_engine(engine, _edited(build, tmp_path / "b", move), export, tmp_path / "out.png")
    assert r.returncode == 3, f"exit {r.returncode}: {r.stderr[-3000:]}"
    assert "VUID-" in r.stderr and "validation layer" in r.stderr, r.stderr
    assert not (tmp_path / "out.png").exists()


@pytest.mark.parametrize("what", ["material", "shadow_matrix", "sampler", "casters", "light_buffer"])
def test_what_the_engine_reads_changes_the_picture(engine, prepared, tmp_path, what):
    """The comparison can fail: one value changed in what the engine reads — a Material upload (the ground's
    rho_d), the sun's fitted matrix in the export, a sampler row, a light's casters (spot_shadow's box left out),
    a dynamic set's lights (half of its points left out of their buffer) — moves the picture past the tolerance."""
    build, export, reference = prepared({"sampler": "textured", "casters": "spot_shadow",
                                         "light_buffer": "dynamic"}.get(what, "example"))
    if what == "material":
        def darker(m):
            u = _perm(m, "ground")["uploads"][0]
            u["Material"] = "0000003f" * 3 + u["Material"][24:]  # rho_d (0.9, 0.9, 0.9) -> 0.5
        build = _edited(build, tmp_path / "b", darker)
    elif what == "sampler":
        def nearest(m):
            for row in m["samplers"]:
                row["platforms"]["vulkan"].update(magFilter="VK_FILTER_NEAREST", minFilter="VK_FILTER_NEAREST")
        build = _edited(build, tmp_path / "b", nearest)
    elif what == "light_buffer":
        def fewer(m):
            pair = m["dynamic_light_sets"]["crowd"]["pairs"][0]
            assert pair["pair"] == "*point/none" and len(pair["lights"]) == 16
            del pair["lights"][8:]  # the engine's buffer, and so the shader's count, is 8 lights
        build = _edited(build, tmp_path / "b", fewer)
    else:
        shutil.copytree(export, tmp_path / "x")
        export = tmp_path / "x"
        doc = json.loads((export / "frame.json").read_text())
        if what == "casters":  # the floor alone: the box's shadow goes
            assert doc["lights"]["spot"]["casters"] == [0, 1]
            doc["lights"]["spot"]["casters"] = [0]
        else:
            doc["lights"]["sun"]["shadow_matrix"][12] += 0.2  # the map shifted by a tenth of its width
        (export / "frame.json").write_text(json.dumps(doc))
    r = run_engine(engine, build, export, tmp_path / "out.png")
    assert r.returncode == 0, r.stderr[-3000:]
    worst, within = compare(tmp_path / "out.png", reference)
    assert worst > LSB and within < 1.0, (worst, within)


def _flip_byte(path: Path, at: int = -1) -> None:
    data = bytearray(path.read_bytes())
    data[at] ^= 0x01
    path.write_bytes(bytes(data))


BAD = {
    "a texture's byte": (lambda b, x: _flip_byte(next((b / "textures").glob("*.ktx2"))), "sha256"),
    "a pack's byte": (lambda b, x: _flip_byte(next((b / "packs").glob("*.smpack")), 200), "sha256"),
    "a mesh's byte": (lambda b, x: _flip_byte(next((x / "meshes").glob("*.bin"))), "sha256"),
    "manifest not JSON": (lambda b, x: (b / "manifest.json").write_text('{"format_version": 1,\n  "x": }'),
                          "manifest.json:2:8: not valid JSON"),
    "a manifest of format 2": (lambda b, x: _json_edit(b / "manifest.json", lambda m: m.update(format_version=2)),
                               "format_version: 2; this engine reads format 1"),
    "a shadowed light missing": (lambda b, x: _json_edit(x / "frame.json", lambda d: d["lights"].pop("sun")),
                                 "lights: no sun, which the build shadows"),
    "a block this engine does not know": (
        lambda b, x: _json_edit(b / "manifest.json", lambda m: _perm(m, "bench")["interface"]["frag"]
                                ["uniform_blocks"][2].update(name="Environment")),
        "uniform block 'Environment'"),
    "another scene's export": (lambda b, x: _json_edit(x / "frame.json", lambda d: d.update(scene="elsewhere")),
                               "scene: elsewhere; the build"),
    "a light's map of 1e300 texels": (
        lambda b, x: _json_edit(x / "frame.json", lambda d: d["lights"]["sun"].update(size=[1e300, 1e300])),
        "lights.sun: size 1e+300 x 1e+300 is not a map of 1 to 16384 texels a side"),
    "a caster the export lacks": (
        lambda b, x: _json_edit(x / "frame.json", lambda d: d["lights"]["sun"].update(casters=[0, 99])),
        "lights.sun: casters holds a number out of range, not an index of the"),
    "an object the manifest lacks": (
        lambda b, x: _json_edit(x / "frame.json", lambda d: d["objects"][0].update(name="sofa")),
        "object sofa; the manifest's object 0 is bench"),
}


def _json_edit(path: Path, edit) -> None:
    doc = json.loads(path.read_text())
    edit(doc)
    path.write_text(json.dumps(doc))


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_input_is_a_message_and_no_picture(engine, prepared, tmp_path, case):
    build, export, _ = prepared("example")
    shutil.copytree(build, tmp_path / "b")
    shutil.copytree(export, tmp_path / "x")
    damage, said = BAD[case]
    damage(tmp_path / "b", tmp_path / "x")
    r = run_engine(engine, tmp_path / "b", tmp_path / "x", tmp_path / "out.png")
    assert r.returncode == 1, f"exit {r.returncode}: {r.stderr[-3000:]}"
    assert said in r.stderr and r.stderr.startswith("engine-c: "), r.stderr
    assert "validation layer" not in r.stderr, r.stderr
    assert not (tmp_path / "out.png").exists()


def test_usage(engine, tmp_path):
    r = subprocess.run([str(engine), str(tmp_path)], capture_output=True, text=True, timeout=30)
    assert r.returncode == 2 and r.stderr.startswith("usage: engine-c"), r.stderr
