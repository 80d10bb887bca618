"""Baked lookup tables (generator/reference/tables.py): declarations, baking, and the bricks that sample them."""
from __future__ import annotations

import numpy as np
import pytest

from generator.lang import SourceError
from generator.reference import tables

TABLE_BRICK = '''"""A diffuse term scaled by a baked table."""
BRICK = {
    "kind": "diffuse",
    "cite": "test",
    "textures": {"t": TEX},
}


def diffuse(NdotL: float, t: texture2d) -> vec3:
    return vec3(sample_level(t, vec2(NdotL, 0.5), 0.0).x)
'''


@pytest.mark.parametrize("tex, words", [
    ('{"table": "oren_nayar_sin_sin", "format": "fp16"}', "without its 'size'"),
    ('{"table": "oren_nayar_sin_sin", "size": [8, 8]}', "without its 'format'"),
    ('{"size": [8, 8], "format": "fp16"}', "has a 'size' but no 'table'"),
    ('{"table": "oren_nayar_sin_sin", "size": [8, 8], "format": "fp16", "srgb": True}', "is marked sRGB"),
    ('{"table": "oren_nayar_sin_sin", "size": [8, 8], "format": "half"}', "format"),
])
def test_a_table_declaration_is_checked_where_it_is_written(tex, words, tmp_path):
    from generator.library.bricks import load_brick

    path = tmp_path / "tb.py"
    path.write_text(TABLE_BRICK.replace("TEX", tex))
    with pytest.raises(SourceError, match=words) as e:
        load_brick(path)
    assert str(e.value).startswith(f"{path}:") or "tb.py:" in str(e.value)


def test_an_unknown_table_is_an_error_that_names_the_closest_one(tmp_path):
    from generator.eval.evaluate import EvalError, evaluate
    from generator.library.bricks import load_library

    (tmp_path / "tb.py").write_text(TABLE_BRICK.replace(
        "TEX", '{"table": "oren_nayar_sin_sn", "size": [8, 8], "format": "fp16"}'))
    lib = load_library([tmp_path])
    L = V = N = np.array([[0.0, 0.0, 1.0]])
    with pytest.raises(EvalError, match="did you mean 'oren_nayar_sin_sin'"):
        evaluate("tb", L, V, N, target="numpy", lib=lib)


def test_baking_is_deterministic_and_quantizes_to_the_declared_format():
    a = tables.baked("oren_nayar_sin_sin", (16, 8), "unorm8")
    assert a.dtype == np.uint8 and a.shape == (8, 16, 4) and not a.flags.writeable
    tables._BAKED.clear()
    assert tables.sha256(tables.baked("oren_nayar_sin_sin", (16, 8), "unorm8")) == tables.sha256(a)
    f = tables.baked("oren_nayar_sin_sin", (16, 8), "fp16")
    assert f.dtype == np.float16
    assert np.abs(tables.decoded(a) - tables.decoded(f)).max() <= 0.5 / 255 + 1e-3
    assert tables.texel_coordinate(np.array([0.0, 1.0]), 64).tolist() == [0.5 / 64, 63.5 / 64]


def test_every_registered_table_bakes_and_its_error_shrinks_with_size():
    for name, d in tables.all_tables().items():
        if d.exact is None:
            continue
        coarse = tables.table_error(name, (16, 16), "fp32")
        fine = tables.table_error(name, (128, 128), "fp32")
        assert fine["max_abs"] < coarse["max_abs"], (name, coarse, fine)


def test_every_table_a_brick_declares_is_registered_and_bakes_at_its_size():
    from generator.library.bricks import load_library

    for b in load_library().bricks.values():
        for tname, t in b.textures.items():
            if "table" in t:
                stored = tables.baked(t["table"], t["size"], t["format"])
                assert stored.shape[-3:-1] == (t["size"][1], t["size"][0]), (b.id, tname)


SCENE = '''[scene]
name = "tables"
[materials.m]
brdf = "BRDF"
[lights.sun]
type = "directional"
[light_sets]
all = ["sun"]
[[objects]]
name = "o"
material = "m"
lights = "all"
'''


@pytest.mark.toolchain
def test_a_build_writes_the_tables_its_shaders_sample_as_ktx2_listed_in_the_manifest(tmp_path):
    import hashlib
    import json
    import subprocess
    import sys

    from generator.io.ktx2 import decode

    def build(brdf, extra=""):
        scene = tmp_path / "s.toml"
        scene.write_text(SCENE.replace("BRDF", brdf) + extra)
        r = subprocess.run([sys.executable, "-m", "generator.cli", "build", str(scene), "--out", str(tmp_path / "out"),
                            "--no-cache"], capture_output=True, text=True, timeout=300)
        assert r.returncode == 0, r.stderr
        return json.loads((tmp_path / "out" / "manifest.json").read_text())

    m = build("oren_nayar_factored")
    (row,) = m["tables"]
    assert row["texture"] == "on_sin_sin" and row["table"] == "oren_nayar_sin_sin" and row["format"] == "unorm8"
    data = (tmp_path / "out" / row["path"]).read_bytes()
    assert hashlib.sha256(data).hexdigest() == row["sha256"] and row["path"].endswith(f".{row['sha256'][:12]}.ktx2")
    texels, fmt, cube = decode(data, row["path"])
    assert fmt == "unorm8" and not cube
    assert np.array_equal(texels, tables.baked("oren_nayar_sin_sin", (64, 64), "unorm8"))
    assert row["error"]["max_rel"] < 0.05 and "Oren & Nayar" in row["reference"]
    assert set(row["used_by"]) == {m["permutations"][0]["hash"], "ubershader"}
    # read as the brick's texel-centre arithmetic assumes: bilinear, level 0, clamped; its row of samplers,
    # which every platform reflection's sampler of the table names too
    index = row["sampler"]["index"]
    assert {k: v for k, v in row["sampler"].items() if k != "index"} == {
        "mag_filter": "linear", "min_filter": "linear", "mipmap": "none", "wrap_u": "clamp", "wrap_v": "clamp",
        "anisotropy": 1, "lod_bias": 0.0, "compare": None}
    vk = m["samplers"][index]["platforms"]["vulkan"]
    assert vk["maxLod"] == 0.25 and vk["addressModeU"] == "VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE"
    for platform, p in m["permutations"][0]["platforms"].items():
        refl = p["reflection"]
        rows = [*refl.get("descriptors", []), *refl.get("resources", []), *refl.get("samplers", []),
                *refl.get("bind_groups", [])]
        assert [d.get("sampler_state") for d in rows if "on_sin_sin" in d["name"] and (
            "sampler" in d or d.get("type") in ("sampler", "Sampler", "sampler2D"))] == [index], platform
    # a rebuild (another object, so not up to date) keeps the row whose input key and file are intact, and
    # bakes again a table whose file was damaged
    (tmp_path / "out" / row["path"]).write_bytes(b"damaged")
    m2 = build("oren_nayar_factored", '[[objects]]\nname = "o2"\nmaterial = "m"\nlights = "all"\n')
    (row2,) = m2["tables"]
    assert row2["input_key"] == row["input_key"] and row2["sha256"] == row["sha256"]
    assert hashlib.sha256((tmp_path / "out" / row2["path"]).read_bytes()).hexdigest() == row["sha256"]
    # an intact row is kept, not baked and measured again: a mark put into it (a value the schema allows, so
    # the build's own check of its manifest passes) survives the next build
    mf = tmp_path / "out" / "manifest.json"
    marked = json.loads(mf.read_text())
    marked["tables"][0]["error"]["max_abs"] = -1.0
    mf.write_text(json.dumps(marked))
    m3 = build("oren_nayar_factored", '[[objects]]\nname = "o3"\nmaterial = "m"\nlights = "all"\n')
    assert m3["tables"][0]["error"]["max_abs"] == -1.0
    # a scene that no longer samples it: no table in the manifest, and the file is gone
    m = build("oren_nayar")
    assert "tables" not in m and not any((tmp_path / "out" / "tables").iterdir())


def test_the_tables_command_lists_and_bakes(tmp_path):
    import json
    import subprocess
    import sys

    from generator.io.ktx2 import decode

    def cli(*a):
        return subprocess.run([sys.executable, "-m", "generator.cli", "tables", *a], capture_output=True, text=True,
                              timeout=120)

    r = cli("--format", "json")
    assert r.returncode == 0, r.stderr
    rows = {x["texture"]: x for x in json.loads(r.stdout)}
    assert rows["on_sin_sin"]["table"] == "oren_nayar_sin_sin" and rows["on_sin_sin"]["error"]["max_rel"] > 0
    r = cli("--bake", "oren_nayar_sin_sin", "--out", str(tmp_path / "t.ktx2"), "--size", "8x4", "--texel-format", "fp16")
    assert r.returncode == 0, r.stderr
    texels, fmt, _ = decode((tmp_path / "t.ktx2").read_bytes())
    assert fmt == "fp16" and texels.shape == (4, 8, 4)
    r = cli("--bake", "oren_nayar_sin_sn", "--out", str(tmp_path / "u.ktx2"))
    assert r.returncode == 2 and "did you mean 'oren_nayar_sin_sin'" in r.stderr and not (tmp_path / "u.ktx2").exists()
    r = cli("--bake", "oren_nayar_sin_sin", "--out", str(tmp_path / "v.ktx2"), "--image", str(tmp_path / "none.png"))
    assert r.returncode == 2 and "not painted" in r.stderr
    assert cli("--out", "x.ktx2").returncode == 2
    # a painted table from the artist's image: the shipped example gives the default table's texels
    r = cli("--bake", "ndf_map", "--image", "bricks/brdf/painted/ndf_map.png", "--out", str(tmp_path / "n.ktx2"))
    assert r.returncode == 0, r.stderr
    texels, fmt, _ = decode((tmp_path / "n.ktx2").read_bytes())
    assert np.array_equal(texels, tables.baked("ndf_map", (64, 1), "fp16"))
    r = cli("--bake", "ndf_map", "--image", "bricks/brdf/painted/ndf_map_anisotropic.png", "--out", str(tmp_path / "m.ktx2"))
    assert r.returncode == 1 and r.stderr.startswith("error: bricks/brdf/painted/ndf_map_anisotropic.png:1:1: ")
    assert not (tmp_path / "m.ktx2").exists()


def test_two_bricks_may_not_declare_different_tables_under_one_texture_name(tmp_path):
    from generator.library.bricks import load_library

    a = TABLE_BRICK.replace("TEX", '{"table": "oren_nayar_sin_sin", "size": [8, 8], "format": "fp16"}')
    (tmp_path / "ta.py").write_text(a)
    (tmp_path / "tb.py").write_text(a.replace('[8, 8]', '[16, 16]'))
    with pytest.raises(SourceError, match=r"texture 't' of diffuse brick 'tb' is table 'oren_nayar_sin_sin' 16x16 fp16, "
                                          r"but diffuse brick 'ta'"):
        load_library([tmp_path])
    (tmp_path / "tb.py").write_text(a)  # the same table at the same size and format: one texture, fine
    assert set(load_library([tmp_path]).tables()) >= {"t"}


def test_table_error_checks_between_the_centres_of_a_fine_table():
    """A fixed 257-point grid lands on the texel centres of a 256-texel axis and saw none of the filter's error
    (1.7e-4 reported for sin θ_i sin θ_r at 256², 2.2e-2 in truth: its square-root edge)."""
    coarse = tables.table_error("oren_nayar_sin_sin", (128, 128), "fp32")["max_rel"]
    fine = tables.table_error("oren_nayar_sin_sin", (256, 256), "fp32")["max_rel"]
    assert 0.5 * coarse < fine < coarse, (coarse, fine)  # O(√h) at the edge: a factor √2 per doubling


def test_bakers_refuse_what_they_cannot_bake_with_a_message(tmp_path):
    from PIL import Image

    from generator.reference import tables_painted as tp

    with pytest.raises(ValueError, match="beyond the dense solve"):  # refused before a 19 GB matrix is made
        tables.lookup("homomorphic_p").bake(64, 64)
    with pytest.raises(ValueError, match="faces are square"):
        tables.lookup("homomorphic_q").bake(16, 8)
    spike = np.zeros((1, 2048, 3), np.uint8)
    spike[0, 0] = 255  # one painted pixel: K_N p overflows half's 65504
    Image.fromarray(spike, "RGB").save(tmp_path / "spike.png")
    with pytest.raises(SourceError, match="does not fit fp16") as e:
        tp.bake_painted("ndf_map", tmp_path / "spike.png", (2048, 1))
    assert str(e.value).startswith(f"{tmp_path / 'spike.png'}:1:1: ")
