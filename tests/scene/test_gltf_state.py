"""The surface state in the key (generator/spec/surface.py): alpha mode, double-sided, vertex
colours and emission change the permutation exactly where they change the shader, keep every earlier key, compile
for every platform, and the renderer draws them (an alpha-masked object vanishes, a double-sided plane is lit from
behind, an emissive one glows)."""
from __future__ import annotations

import numpy as np
import pytest

from generator.lang import SourceError
from tests.conftest import require_tool

BRDF = "lambert+microfacet(ndf=ggx,fresnel=schlick,vis=smith_ggx_height_correlated)"


@pytest.fixture(scope="module")
def lib():
    from generator.library.bricks import load_library
    return load_library(())


def _perm(lib, packing="constants(normal=vertex)", **state):
    from generator.spec.permutation import LightKey, Permutation, canonical, parse_brdf, parse_spec
    from generator.spec.surface import Surface
    return Permutation(canonical(parse_brdf(BRDF, lib)), (LightKey("point", "none"),),
                       canonical(parse_spec(packing, lib, ("packing",))), surface=Surface(**state))


def test_the_default_state_keeps_every_earlier_key(lib):
    from generator.spec.permutation import Permutation
    from generator.spec.surface import Surface
    p = _perm(lib)
    assert p.canonical().endswith(";output=linear;precision=fp32")
    assert Permutation(p.brdf, p.lights, p.packing) == p and p.surface == Surface()
    leaf = _perm(lib, alpha="mask", double_sided=True, vertex_color=True, emissive="texture")
    assert leaf.canonical() == p.canonical() + ";alpha=mask;double_sided=true;vertex_color=true;emissive=texture"
    assert leaf.hash != p.hash


def _body(text: str) -> str:
    """A generated source without its provenance header (hash, bricks, templates: it differs per permutation):
    from the first line that is not a comment, blank, or the GLSL #version/#extension lines above the header."""
    lines = text.split("\n")
    head = ("//", "#version", "#extension")
    first = next((i for i, line in enumerate(lines) if line.strip() and not line.lstrip().startswith(head)),
                 len(lines))
    return "\n".join(lines[first:])


def test_each_axis_changes_the_shader_and_its_values_do_not(lib):
    from generator.compose import compose_permutation
    texts = {}
    cases = {"opaque": {}, "mask": {"alpha": "mask"}, "blend": {"alpha": "blend"},
             "double": {"double_sided": True}, "colors": {"vertex_color": True}, "glow": {"emissive": "factor"},
             "glow_tex": {"emissive": "texture"}}
    for name, state in cases.items():
        c = compose_permutation(_perm(lib, "albedo_texture(normal=normal_map)", **state), lib)
        texts[name] = "\n".join(_body(s.text) for s in c.sources)
    assert len(set(texts.values())) == len(cases)
    assert not any("sha256:" in t for t in texts.values())  # the provenance headers are cut
    assert "discard" in texts["mask"] and "discard" not in texts["blend"] + texts["opaque"]
    assert "gl_FrontFacing" in texts["double"] and "SV_IsFrontFace" in texts["double"] and \
        "@builtin(front_facing)" in texts["double"]
    assert "a_color" in texts["colors"] and "a_color" not in texts["opaque"]
    assert "t_emissive_map" in texts["glow_tex"] and "t_emissive_map" not in texts["glow"]
    c = compose_permutation(_perm(lib, "albedo_texture(normal=normal_map)", alpha="mask", emissive="factor"), lib)
    params = [s.param for s in c.material]
    assert params[-3:] == ["base_alpha", "alpha_cutoff", "emissive"]  # uniforms: a cutoff is no key value
    assert [t.param for t in c.interface.textures] == ["albedo_map", "normal_map"]  # coverage: the albedo's A


@pytest.mark.toolchain
def test_compiles_for_every_platform(lib):
    """Vulkan (SPIR-V from GLSL, HLSL, WGSL, validated), GL 4.50 core and ES 3.10 (glslang's GL mode)."""
    for t in ("glslc", "naga", "spirv-val", "glslangValidator"):
        require_tool(t)
    from generator.compose import compose_permutation
    from generator.toolchain import CompileJob, compile_many
    from generator.toolchain.platforms import validate_dialects
    perms = {"leaf": _perm(lib, "gltf_metallic_roughness(normal=vertex)", alpha="mask", double_sided=True),
             "cloth": _perm(lib, "constants(normal=normal_map)", double_sided=True, vertex_color=True),
             "glass": _perm(lib, "albedo_texture(normal=vertex)", alpha="blend", vertex_color=True,
                            emissive="texture")}
    jobs, dialects = [], []
    for name, p in perms.items():
        c = compose_permutation(p, lib, dialects=("gl", "essl"))
        for s, out in [(s, jobs) for s in c.sources] + [(s, dialects) for s in c.dialects]:
            out.append(CompileJob(f"{name}.{s.stage}.{s.language}", s.language, s.stage, s.text,
                                  line_map=tuple(map(tuple, s.line_map))))
    results = compile_many(jobs)
    assert len(results) == 18 and all(r.ok for r in results.values()), \
        [e for r in results.values() for e in r.errors()][:3]
    assert validate_dialects(dialects) == {j.key: [] for j in dialects}


TOML = """
[scene]
name = "state"

[materials.cut]
brdf = "lambert"
alpha = "mask"
params = { rho_d = [0.8, 0.8, 0.8], base_alpha = 0.2, alpha_cutoff = 0.5 }

[materials.kept]
brdf = "lambert"
alpha = "mask"
params = { rho_d = [0.8, 0.8, 0.8], base_alpha = 0.9, alpha_cutoff = 0.5 }

[materials.one_sided]
brdf = "lambert"
params = { rho_d = [0.8, 0.8, 0.8] }

[materials.two_sided]
brdf = "lambert"
double_sided = true
params = { rho_d = [0.8, 0.8, 0.8] }

[materials.lamp]
brdf = "lambert"
emissive = "factor"
vertex_color = true
params = { rho_d = [0.8, 0.8, 0.8], emissive = [1.0, 0.0, 0.0] }

[lights.below]
type = "directional"
params = { direction = [0.0, -1.0, 0.0], color = [1.0, 1.0, 1.0] }

[light_sets]
below = ["below"]
dark = []

[[objects]]
name = "cut"
material = "cut"
lights = "below"

[[objects]]
name = "kept"
material = "kept"
lights = "below"

[[objects]]
name = "one_sided"
material = "one_sided"
lights = "below"

[[objects]]
name = "two_sided"
material = "two_sided"
lights = "below"

[[objects]]
name = "lamp"
material = "lamp"
lights = "dark"
"""

PLACEMENT = """
[objects.cut]
translate = [-3.0, 1.5, 0.0]
[objects.kept]
translate = [0.0, 1.5, 0.0]
[objects.one_sided]
mesh = "plane"
translate = [-1.5, 0.0, 0.0]
scale = [0.7, 1.0, 0.7]
[objects.two_sided]
mesh = "plane"
translate = [1.5, 0.0, 0.0]
scale = [0.7, 1.0, 0.7]
[objects.lamp]
translate = [3.0, 1.5, 0.0]
[camera]
eye = [0.0, -4.0, 6.0]
target = [0.0, 0.5, 0.0]
"""


def test_toml_scenes_take_the_same_keys(tmp_path, lib):
    from generator.scene.load import load_scene
    path = tmp_path / "state.toml"
    path.write_text(TOML)
    scene = load_scene(path, lib)
    by = {o["name"]: scene.permutations[o["permutation"]] for o in scene.objects}
    assert by["cut"] == by["kept"]  # other base_alpha and cutoff: one shader
    assert by["one_sided"].canonical().endswith("precision=fp32") and by["two_sided"].surface.double_sided
    assert by["lamp"].surface.emissive == "factor" and by["lamp"].surface.vertex_color
    assert len(scene.permutations) == 4
    bad = TOML.replace('alpha = "mask"\nparams = { rho_d = [0.8, 0.8, 0.8], base_alpha = 0.2',
                       'alpha = "masked"\nparams = { rho_d = [0.8, 0.8, 0.8], base_alpha = 0.2')
    path.write_text(bad)
    with pytest.raises(SourceError) as e:
        load_scene(path, lib)
    assert (e.value.line, e.value.message) == (7, "'materials.cut.alpha' is 'masked', not one of opaque, mask, blend")
    text = TOML.replace('[materials.lamp]\nbrdf = "lambert"', '[materials.lamp]\nbrdf = "phong"')
    path.write_text(text.replace("rho_d = [0.8, 0.8, 0.8], emissive", "emissive"))
    with pytest.raises(SourceError) as e:
        load_scene(path, lib)
    line = text.splitlines().index("vertex_color = true") + 1
    assert "vertex_color multiplies rho_d" in e.value.message and e.value.line == line


TINTED = '''"""A packing with its own rho_d parameter and no get_rho_d (test)."""
BRICK = {
    "kind": "packing",
    "cite": "test",
    "params": {"rho_d": {"type": "vec3", "range": [0.0, 1.0], "default": [0.5, 0.5, 0.5], "doc": "unused tint"}},
    "slots": {"normal": {"kind": "normal", "default": "vertex"}},
}
'''


def test_vertex_colours_need_the_brdfs_rho_d_not_a_packings(tmp_path):
    """The scene check is the glue's (link/glue.py surface_inputs: the BRDF's parameters): a rho_d that only the
    packing declares is refused at the material's vertex_color key, not at link time."""
    from generator.library.bricks import load_library
    from generator.scene.load import load_scene
    (tmp_path / "bricks").mkdir()
    (tmp_path / "bricks" / "tinted.py").write_text(TINTED)
    lib = load_library([tmp_path / "bricks"])
    text = TOML.replace('[materials.lamp]\nbrdf = "lambert"', '[materials.lamp]\nbrdf = "phong"\npacking = "tinted"')
    path = tmp_path / "state.toml"
    path.write_text(text.replace("rho_d = [0.8, 0.8, 0.8], emissive", "emissive"))
    with pytest.raises(SourceError) as e:
        load_scene(path, lib)
    line = text.splitlines().index("vertex_color = true") + 1
    assert (e.value.path, e.value.line) == (str(path), line) and e.value.hint.startswith("use a BRDF with a diffuse")
    assert e.value.message == "material 'lamp': vertex_color multiplies rho_d, and this BRDF has no rho_d"


@pytest.mark.lavapipe
@pytest.mark.toolchain
def test_the_renderer_draws_the_state(tmp_path, lib):
    """One 96×64 render: the masked sphere is not drawn (base_alpha 0.2 < cutoff) and its twin is; seen from
    below with the light below, the single-sided plane is culled (its render_state's cull `back`: the clear colour
    shows) and the double-sided one lit; the lamp glows red without lights."""
    from generator.scene.load import load_scene
    from generator.runtime.placement import load_placement
    from generator.runtime.renderer import render_scene
    from generator.assemble.render_inputs import scene_textures
    path = tmp_path / "state.toml"
    path.write_text(TOML)
    (tmp_path / "state.placement.toml").write_text(PLACEMENT)
    scene = load_scene(path, lib)
    W, H = 96, 64
    render_scene(scene, lib, "specialized", 1, tmp_path / "out", size=(W, H), build=scene_textures(scene, tmp_path / "out"))
    from PIL import Image
    img = np.asarray(Image.open(tmp_path / "out" / "frame_0000.png").convert("RGB")).astype(int)
    placed = load_placement(scene)
    _, vp = placed.camera(W, H)

    def at(name):  # the 3×3 pixels around the object's centre
        o = next(p for p in placed.objects if p.name == name)
        c = vp @ np.append(o.translate, 1.0)
        x, y = int((c[0] / c[3] * 0.5 + 0.5) * W), int((c[1] / c[3] * 0.5 + 0.5) * H)
        return img[y - 1:y + 2, x - 1:x + 2].reshape(-1, 3)

    clear = np.round(np.array([0.06, 0.07, 0.09]) * 255)
    assert np.abs(at("cut") - clear).max() <= 1  # discarded: the clear colour shows
    assert np.abs(at("kept") - clear).max() > 1
    assert np.abs(at("one_sided") - clear).max() <= 1  # seen from behind: its back face is culled
    assert at("two_sided").min() > 40  # the back face, its normal reversed, faces the light
    lamp = at("lamp")
    assert lamp[:, 0].min() > 200 and lamp[:, 1:].max() <= 1  # emissive [1, 0, 0], no lights
