"""`build --pack`: one shader pack per platform, its documented format, its reader."""
from __future__ import annotations

import hashlib
import json
import struct
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "scenes" / "example.toml"


# ------------------------------------------------------------------ an independent minimal reader

def minimal_read(data: bytes) -> dict:
    """The layout of generator/assemble/pack.py's docstring, read with struct alone (no package code)."""
    magic, version, count, key, meta_len, reserved = struct.unpack_from("<8sII32sII", data, 0)
    assert magic == b"SMPACK\r\n" and version == 1 and reserved == 0
    meta = json.loads(data[56:56 + meta_len])
    index_at = 56 + meta_len + (-(56 + meta_len) % 8)
    entries, rows, end = {}, [], index_at + 104 * count
    for i in range(count):
        perm, stage, input_key, sha, offset, length = struct.unpack_from("<16s8s32s32sQQ", data, index_at + 104 * i)
        perm, stage = perm.rstrip(b"\0").decode(), stage.rstrip(b"\0").decode()
        blob = data[offset:offset + length]
        assert hashlib.sha256(blob).digest() == sha
        entries[(perm, stage)] = blob
        rows.append([perm, stage, input_key.hex(), sha.hex()])
        end = max(end, offset + length)
    assert end == len(data)  # nothing after the last blob
    doc = json.dumps(["smpack", 1, meta, rows], sort_keys=True, separators=(",", ":")).encode()
    assert hashlib.sha256(doc).digest() == key
    return {"key": key.hex(), "meta": meta, "entries": entries, "input_keys": {(r[0], r[1]): r[2] for r in rows}}


def expected_entries(out: Path, manifest: dict, platform: str) -> dict:
    """{(permutation, stage): bytes} the pack of `platform` must hold: every ok entry's artifact, the depth
    units' under their hash (and the ubershader's GLSL SPIR-V in vulkan's)."""
    from generator.assemble.platforms import PLATFORM_TABLE
    want = {}
    for e in [*manifest["permutations"], *(manifest.get("depth_shaders") or {}).values()]:
        if e.get("status") == "ok":
            for stage, item in e["platforms"][platform]["stages"].items():
                kind = "dxil" if "dxil" in item else PLATFORM_TABLE[platform].blob  # no dxc: d3d12 packs HLSL
                want[(e["hash"], stage)] = (out / item[kind]["path"]).read_bytes()
    if platform == "vulkan" and manifest["ubershader"].get("status") == "ok":
        for stage, item in manifest["ubershader"]["languages"]["glsl"].items():
            want[("ubershader", stage)] = (out / item["spirv"]).read_bytes()
    return want


# ------------------------------------------------------------------ builds of the example scene

@pytest.fixture(scope="module")
def lib_scene():
    from generator.library.bricks import load_library
    from generator.scene.load import load_scene
    lib = load_library()
    return lib, load_scene(EXAMPLE, lib)


@pytest.fixture(scope="module")
def packed(lib_scene, tmp_path_factory):
    from generator.assemble import BuildContext, build
    lib, scene = lib_scene
    out = tmp_path_factory.mktemp("packed")
    res = build(scene, out, BuildContext(lib), pack=True)
    assert res.ok
    return out, json.loads((out / "manifest.json").read_text())


@pytest.mark.toolchain
def test_build_pack_on_the_command_line_writes_one_pack_per_platform_listed_in_the_manifest(tmp_path):
    out = tmp_path / "out"
    r = subprocess.run([sys.executable, "-m", "generator.cli", "build", str(EXAMPLE), "--out", str(out), "--pack",
                        "--json"], capture_output=True, text=True, cwd=REPO)
    assert r.returncode == 0, r.stderr
    manifest = json.loads((out / "manifest.json").read_text())
    packs = manifest["packs"]
    assert [p["platform"] for p in packs] == manifest["platforms"] == ["vulkan", "d3d12", "gl", "webgpu"]
    assert json.loads(r.stdout)["packs"] == [p["path"] for p in packs]
    for p in packs:
        data = (out / p["path"]).read_bytes()
        assert p["path"] == f"packs/{p['platform']}.{p['key'][:16]}.smpack"
        assert hashlib.sha256(data).hexdigest() == p["sha256"] and len(data) == p["size"]
        uber = 1 if p["platform"] == "vulkan" else 0  # the ubershader is built for vulkan only
        depth = sum(len(u["platforms"][p["platform"]]["stages"]) for u in manifest["depth_shaders"].values())
        assert depth >= 1  # the example's sun is shadowed: its depth pass's units are packed too
        assert p["entries"] == len(expected_entries(out, manifest, p["platform"])) == \
            2 * (len(manifest["permutations"]) + uber) + depth
    assert sorted(x.name for x in (out / "packs").iterdir()) == sorted(Path(p["path"]).name for p in packs)


@pytest.mark.toolchain
def test_the_package_reader_and_an_independent_reader_agree_with_the_manifests_spirv(packed):
    from generator.assemble.pack import lookup, read_pack
    out, manifest = packed
    keys = {p["hash"]: p["input_key"] for p in [*manifest["permutations"], *manifest["depth_shaders"].values()]} | \
        {"ubershader": manifest["ubershader"]["input_key"]}
    for p in manifest["packs"]:
        want = expected_entries(out, manifest, p["platform"])
        data = (out / p["path"]).read_bytes()
        mine = minimal_read(data)
        pack = read_pack(out / p["path"])
        assert mine["key"] == pack["key"] == p["key"]
        assert mine["meta"] == pack["meta"] and pack["language"] == p["language"] and pack["platform"] == p["platform"]
        assert pack["tools"] == {**manifest["permutations"][0]["platforms"][p["platform"]]["tools"], **manifest["tools"]}
        assert pack["generator"] == manifest["generator"]
        assert mine["entries"] == {k: e.data for k, e in pack["entries"].items()} == want
        assert mine["input_keys"] == {k: e.input_key for k, e in pack["entries"].items()} == \
            {(h, s): keys[h] for h, s in want}
        for (h, stage), spirv in want.items():
            assert lookup(pack, h, stage) == spirv
        perm = manifest["permutations"][0]
        assert lookup(pack, perm["id"], "frag") == want[(perm["hash"], "frag")]  # by canonical id too
        # identical modules (the vertex shaders) are one blob
        assert len({(e.offset, e.length) for e in pack["entries"].values()}) == len(set(want.values()))


@pytest.mark.toolchain
def test_packs_are_deterministic_and_a_rebuild_writes_nothing(packed, lib_scene, tmp_path):
    from generator.assemble import BuildContext, build
    out, manifest = packed
    lib, scene = lib_scene
    again = build(scene, tmp_path / "b", BuildContext(lib), pack=True)
    assert again.ok
    for p in manifest["packs"]:
        assert (tmp_path / "b" / p["path"]).read_bytes() == (out / p["path"]).read_bytes()
    assert (tmp_path / "b" / "manifest.json").read_bytes() == (out / "manifest.json").read_bytes()
    same = build(scene, tmp_path / "b", BuildContext(lib), pack=True)
    assert same.up_to_date and same.written == 0
    (tmp_path / "b" / manifest["packs"][0]["path"]).unlink()  # a pack gone: the no-op check notices
    fixed = build(scene, tmp_path / "b", BuildContext(lib), pack=True)
    assert not fixed.up_to_date and fixed.written == 1 and fixed.compile.compiled == 0
    assert (tmp_path / "b" / manifest["packs"][0]["path"]).read_bytes() == (out / manifest["packs"][0]["path"]).read_bytes()


@pytest.mark.toolchain
def test_without_pack_the_manifest_is_what_it_was_and_no_pack_is_left(packed, lib_scene, tmp_path):
    from generator.assemble import BuildContext, build
    out, manifest = packed
    lib, scene = lib_scene
    plain = tmp_path / "plain"
    assert build(scene, plain, BuildContext(lib)).ok
    text = (plain / "manifest.json").read_text()
    assert "packs" not in json.loads(text) and not (plain / "packs").exists()
    without = {k: v for k, v in manifest.items() if k != "packs"}
    assert text == json.dumps(without, indent=2) + "\n"  # byte for byte the manifest minus its "packs"
    # --pack then a build without it: the packs leave with the manifest's list; and back
    assert build(scene, plain, BuildContext(lib), pack=True).ok and (plain / "packs").is_dir()
    assert build(scene, plain, BuildContext(lib)).ok
    assert (plain / "manifest.json").read_text() == text and not (plain / "packs").exists()


@pytest.mark.toolchain
def test_a_changed_tool_version_changes_the_pack_key(packed, lib_scene, tmp_path, monkeypatch):
    import generator.assemble as assemble
    from generator.assemble.pack import read_pack
    out, manifest = packed
    lib, scene = lib_scene
    real = assemble.tool_versions()
    monkeypatch.setattr(assemble, "tool_versions", lambda: {**real, "spirv-tools": real["spirv-tools"] + "-upgraded"})
    assert assemble.build(scene, tmp_path / "up", assemble.BuildContext(lib), pack=True).ok
    upgraded = json.loads((tmp_path / "up" / "manifest.json").read_text())
    for old, new in zip(manifest["packs"], upgraded["packs"]):
        assert new["key"] != old["key"] and new["path"] != old["path"]
        pack_old, pack_new = read_pack(out / old["path"]), read_pack(tmp_path / "up" / new["path"])
        assert pack_new["tools"]["spirv-tools"].endswith("-upgraded")
        # every entry's input key moved with it: no entry of the old pack answers for the new inputs
        assert not {e.input_key for e in pack_old["entries"].values()} & {e.input_key for e in pack_new["entries"].values()}


@pytest.mark.toolchain
def test_a_damaged_built_pack_is_refused_naming_the_file(packed, tmp_path):
    from generator.assemble.pack import PackError, read_pack
    out, manifest = packed
    data = bytearray((out / manifest["packs"][0]["path"]).read_bytes())
    data[-100] ^= 0x01  # one bit of the last blob
    bad = tmp_path / "bad.smpack"
    bad.write_bytes(bytes(data))
    with pytest.raises(PackError, match=r"bad\.smpack: not a valid shader pack — sha256 mismatch in the blob of "):
        read_pack(bad)


# ------------------------------------------------------------------ the format alone (no tools)

META = {"format": "smpack", "generator": "shadermatrix test", "language": "glsl", "platform": None,
        "spirv_version": "1.3", "target_env": "vulkan1.1", "tools": {"glslc": "1"}}
SPV = [b"\x03\x02\x23\x07" + bytes([i]) * (4 * (i + 3)) for i in range(3)]


def _entries():
    return [("bbbbbbbbbbbb", "frag", "11" * 32, SPV[0]), ("aaaaaaaaaaaa", "vert", "22" * 32, SPV[1]),
            ("aaaaaaaaaaaa", "frag", "33" * 32, SPV[2]), ("bbbbbbbbbbbb", "vert", "44" * 32, SPV[1]),
            ("ubershader", "frag", "55" * 32, SPV[0])]


def _write(tmp_path, data: bytes) -> Path:
    p = tmp_path / "x.smpack"
    p.write_bytes(data)
    return p


def test_a_pack_round_trips(tmp_path):
    from generator.assemble.pack import PackError, encode_pack, lookup, read_pack
    data, key = encode_pack(META, _entries())
    assert encode_pack(META, list(reversed(_entries()))) == (data, key)  # sorted: order-independent bytes
    pack = read_pack(_write(tmp_path, data))
    assert pack["key"] == key == minimal_read(data)["key"] and pack["meta"] == META
    assert {k: e.data for k, e in pack["entries"].items()} == {(p, s): spv for p, s, _, spv in _entries()}
    assert lookup(pack, "ubershader", "frag") == SPV[0]
    meta_len = len(json.dumps(META, sort_keys=True, separators=(",", ":")))
    assert len(data) == 56 + meta_len + (-(56 + meta_len) % 8) + 5 * 104 + sum(map(len, SPV))  # SPV[1] once
    assert len(data) == max(e.offset + e.length for e in pack["entries"].values())
    with pytest.raises(PackError, match=r"x\.smpack: no entry for permutation cccccccccccc stage frag"):
        lookup(pack, "cccccccccccc", "frag")
    assert encode_pack({**META, "tools": {"glslc": "2"}}, _entries())[1] != key  # tool versions are in the key


def _corrupt(data: bytes, how: str) -> bytes:
    b = bytearray(data)
    meta_len = struct.unpack_from("<I", data, 48)[0]
    index_at = 56 + meta_len + (-(56 + meta_len) % 8)
    if how == "magic":
        b[0:8] = b"NOTAPACK"
    elif how == "version":
        struct.pack_into("<I", b, 8, 2)
    elif how == "truncated":
        del b[len(b) - 7:]
    elif how == "truncated_index":
        del b[index_at + 50:]
    elif how == "blob":
        b[-3] ^= 0x80
    elif how == "trailing":
        b += b"\0\0\0\0"
    elif how == "offset":
        struct.pack_into("<Q", b, index_at + 88, len(data) + 8)
    elif how == "key":
        b[20] ^= 0x01
    elif how == "input_key":
        b[index_at + 30] ^= 0x01
    return bytes(b)


@pytest.mark.parametrize("how,message", [
    ("magic", r"bad magic b'NOTAPACK' \(expected b'SMPACK\\r\\n'\)"),
    ("version", r"format version 2, this reader reads version 1"),
    ("truncated", r"index entry \d \(\w+ \w+\) points at bytes \d+\.\.\d+, outside the blobs \(\d+\.\.\d+\): "
                  r"the file is truncated or its index damaged"),
    ("truncated_index", r"truncated: the header announces 5 entries"),
    ("blob", r"sha256 mismatch in the blob of "),
    ("trailing", r"4 bytes of trailing garbage after the last blob"),
    ("offset", r"index entry 0 \(aaaaaaaaaaaa frag\) points at bytes \d+\.\.\d+, outside the blobs"),
    ("key", r"the pack key does not match its metadata and index"),
    ("input_key", r"the pack key does not match its metadata and index"),
])
def test_a_corrupt_or_truncated_pack_is_refused_with_what_is_wrong(tmp_path, how, message):
    from generator.assemble.pack import PackError, encode_pack, read_pack
    from generator.lang.errors import UserError
    data, _ = encode_pack(META, _entries())
    path = _write(tmp_path, _corrupt(data, how))
    with pytest.raises(PackError, match=r"^" + str(path).replace(".", r"\.") + r": not a valid shader pack — " + message) as e:
        read_pack(path)
    assert isinstance(e.value, UserError) and "shadermatrix build --pack" in str(e.value)


def test_an_empty_file_and_a_directory_are_refused(tmp_path):
    from generator.assemble.pack import PackError, read_pack
    with pytest.raises(PackError, match="bad magic b''"):
        read_pack(_write(tmp_path, b""))
    with pytest.raises(PackError, match="not a regular file"):
        read_pack(tmp_path)
    with pytest.raises(PackError, match="cannot read the shader pack"):
        read_pack(tmp_path / "missing.smpack")


def test_only_ok_entries_are_packed_and_a_damaged_tree_is_refused(tmp_path):
    from generator.assemble.pack import PackError, read_pack, write_packs

    def entry(h, status, spv):
        (tmp_path / "glsl").mkdir(exist_ok=True)
        (tmp_path / "glsl" / f"{h}.spv").write_bytes(spv)
        item = {"spirv": {"path": f"glsl/{h}.spv", "sha256": hashlib.sha256(spv).hexdigest()}}
        return {"hash": h, "input_key": "ab" * 32, "status": status,
                "platforms": {"vulkan": {"stages": {"frag": item}}}}

    manifest = {"generator": "shadermatrix test", "tools": {"glslc": "1"}, "platforms": ["vulkan"], "ubershader": {},
                "permutations": [entry("aaaaaaaaaaaa", "ok", SPV[0]), entry("bbbbbbbbbbbb", "stale", SPV[1])]}
    [listed] = write_packs(tmp_path, manifest)
    pack = read_pack(tmp_path / listed["path"])
    assert list(pack["entries"]) == [("aaaaaaaaaaaa", "frag")] and listed["entries"] == 1  # a stale entry is older inputs
    (tmp_path / "glsl" / "aaaaaaaaaaaa.spv").write_bytes(SPV[2])
    with pytest.raises(PackError, match=r"aaaaaaaaaaaa\.spv: its sha256 is not the manifest's"):
        write_packs(tmp_path, manifest)


@pytest.mark.parametrize("text,why", [(b" 12 ", "not canonical JSON"), (b"1.00", "not JSON"), (b"[[[]", "not JSON")])
def test_metadata_not_exactly_as_the_encoder_writes_it_is_refused(tmp_path, text, why):
    """The key is hashed over the metadata's bytes as they are by the C reader (include/shadermatrix/pack.h),
    which cannot re-encode JSON: both readers take only the canonical form (no spaces, no floats)."""
    from generator.assemble.pack import PackError, encode_pack, read_pack
    data, _ = encode_pack(META, _entries())
    assert data.count(b":null,") == 1  # META's "platform", the same length as each replacement
    with pytest.raises(PackError, match=f"the metadata is {why}"):
        read_pack(_write(tmp_path, data.replace(b":null,", b":" + text + b",")))
