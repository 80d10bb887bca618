"""A second reader of a build: an engine's loader written from docs/guide/engine-integration.md alone.

It imports nothing of the generator (the standard library only: json, struct, tomllib, hashlib), so what it
reads is what the page states, not what our code happens to do: each object's permutation, its Material and
Lights blocks decoded parameter by parameter (`parameters[].offset`, little-endian float32) and compared with
the scene's TOML values (a value the scene leaves out: the parameter's `default`), the Vulkan descriptors of
its material textures, and each KTX2 file's header and level index against the manifest.

    python tests/project/engine_reader.py BUILD_DIR SCENE.toml

prints one line per object and texture and exits 1, naming each mismatch, when the build and the page
disagree. tests/project/test_engine_guide.py runs it on the example build and on damaged copies of it.
"""
from __future__ import annotations

import hashlib
import json
import struct
import sys
import tomllib
from pathlib import Path

KTX2_IDENTIFIER = b"\xabKTX 20\xbb\r\n\x1a\n"
VK_FORMATS = {37: "R8G8B8A8_UNORM", 43: "R8G8B8A8_SRGB", 97: "R16G16B16A16_SFLOAT", 109: "R32G32B32A32_SFLOAT"}
TEXEL_BYTES = {"R8G8B8A8_UNORM": 4, "R8G8B8A8_SRGB": 4, "R16G16B16A16_SFLOAT": 8, "R32G32B32A32_SFLOAT": 16}
# the page's Vulkan spellings of the neutral sampler words (engine-integration.md, "Samplers")
VK_ADDRESS = {"repeat": "VK_SAMPLER_ADDRESS_MODE_REPEAT", "mirrored": "VK_SAMPLER_ADDRESS_MODE_MIRRORED_REPEAT",
              "clamp": "VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE"}
VK_FILTER = {"linear": "VK_FILTER_LINEAR", "nearest": "VK_FILTER_NEAREST"}


def f32(x: float) -> float:
    """x rounded to float32, as the blocks hold it."""
    return struct.unpack("<f", struct.pack("<f", x))[0]


def flat(value) -> list[float]:
    """A TOML or manifest value (a number, a vector, a list of vectors) as the float32 numbers a block holds."""
    if isinstance(value, (int, float)):
        return [f32(value)]
    return [x for v in value for x in flat(v)]


def decode(hex_bytes: str, parameters: list[dict]) -> dict[tuple, list[float]]:
    """{(light index or None, name): its float32 numbers} of one uploaded block."""
    raw = bytes.fromhex(hex_bytes)
    return {(q.get("light"), q["name"]): list(struct.unpack_from(f"<{q['size'] // 4}f", raw, q["offset"]))
            for q in parameters}


def scene_value(params: dict, name: str, default):
    """The scene's value of parameter `name` (`name[i]`: element i of an array parameter), else the default."""
    base, _, index = name.partition("[")
    if base not in params:
        return default
    return params[base][int(index[:-1])] if index else params[base]


def block(entry: dict, name: str) -> dict | None:
    for stage in ("frag", "vert"):
        for b in entry["interface"].get(stage, {}).get("uniform_blocks", []):
            if b["name"] == name:
                return b
    return None


def check_object(m: dict, scene: dict, obj: dict, errors: list[str]) -> str:
    """Check one object's permutation and its uploaded blocks against the scene; a line saying what was read."""
    entry = next((p for p in m["permutations"] if p["hash"] == obj["permutation"]), None)
    if entry is None:
        errors.append(f"object {obj['name']}: no permutation {obj['permutation']}")
        return ""
    upload = next((u for u in entry["uploads"] if (u["material"], u["light_set"]) == (obj["material"], obj["light_set"])),
                  None)
    if upload is None or obj["name"] not in upload["objects"]:
        errors.append(f"object {obj['name']}: no upload for ({obj['material']}, {obj['light_set']})")
        return ""
    lights = scene["light_sets"][obj["light_set"]]
    counted = 0
    for name, of in (("Material", lambda q: scene["materials"][obj["material"]].get("params", {})),
                     ("Lights", lambda q: scene["lights"][lights[q["light"]]].get("params", {}))):
        b = block(entry, name)
        if b is None:
            continue
        if len(upload[name]) // 2 != b["size"]:
            errors.append(f"object {obj['name']}: {name} upload is {len(upload[name]) // 2} bytes, the block {b['size']}")
        got = decode(upload[name], b["parameters"])
        for q in b["parameters"]:
            want = flat(scene_value(of(q), q["name"], q["default"]))
            if got[(q.get("light"), q["name"])] != want:
                who = f"light {lights[q['light']]}" if "light" in q else f"material {obj['material']}"
                errors.append(f"object {obj['name']}: {name} {who} {q['name']} at offset {q['offset']} reads "
                              f"{got[(q.get('light'), q['name'])]}, the scene says {want}")
            counted += 1
    check_descriptors(m, entry, obj, errors)
    return f"{obj['name']}: permutation {entry['hash']}, {counted} parameters as the scene says"


def check_descriptors(m: dict, entry: dict, obj: dict, errors: list[str]) -> None:
    """Each material texture is a sampled image at its binding and a sampler at sampler_binding (Vulkan)."""
    vk = entry.get("platforms", {}).get("vulkan")
    if vk is None:
        return
    kinds = {(d["set"], d["binding"]): d["type"] for d in vk["reflection"]["descriptors"]}
    for tname, t in m["materials"][obj["material"]].get("textures", {}).items():
        if kinds.get((t["set"], t["binding"])) != "sampled_image" or kinds.get((t["set"], t["sampler_binding"])) != "sampler":
            errors.append(f"object {obj['name']}: texture {tname} is not a sampled image at ({t['set']}, "
                          f"{t['binding']}) and a sampler at ({t['set']}, {t['sampler_binding']})")


def check_sampler(m: dict, scene: dict, mname: str, tname: str, t: dict, errors: list[str]) -> None:
    """The binding's sampler row against the scene's `samplers` entry (defaults: linear, linear mipmaps, repeat,
    anisotropy 1, LOD bias 0) and its Vulkan spelling."""
    s = scene["materials"][mname].get("samplers", {}).get(tname, {})
    want = {"mag_filter": s.get("mag_filter", s.get("filter", "linear")),
            "min_filter": s.get("min_filter", s.get("filter", "linear")), "mipmap": s.get("mipmap", "linear"),
            "wrap_u": s.get("wrap_u", s.get("wrap", "repeat")), "wrap_v": s.get("wrap_v", s.get("wrap", "repeat")),
            "anisotropy": s.get("anisotropy", 1), "lod_bias": s.get("lod_bias", 0.0)}
    row = m["samplers"][t["sampler"]["index"]]
    got = {k: row[k] for k in want}
    if got != want:
        errors.append(f"material {mname} texture {tname}: sampler {got}, the scene says {want}")
    vk = row["platforms"].get("vulkan")
    if vk is not None:
        spelled = {"magFilter": VK_FILTER[want["mag_filter"]], "minFilter": VK_FILTER[want["min_filter"]],
                   "addressModeU": VK_ADDRESS[want["wrap_u"]], "addressModeV": VK_ADDRESS[want["wrap_v"]],
                   "maxLod": 0.25 if want["mipmap"] == "none" else 1000.0,
                   "anisotropyEnable": want["anisotropy"] > 1}
        if {k: vk[k] for k in spelled} != spelled:
            errors.append(f"material {mname} texture {tname}: Vulkan sampler {vk}, the page's spelling {spelled}")


def check_render_state(toml: dict, mname: str, state: dict, errors: list[str]) -> None:
    """The material's render state as the page derives it from `alpha` and `double_sided`."""
    alpha = toml.get("alpha", "opaque")
    want = {"alpha_mode": alpha, "cull": "none" if toml.get("double_sided", False) else "back",
            "depth": {"test": True, "write": alpha != "blend", "compare": "less"}}
    got = {k: state[k] for k in want}
    if got != want or (state["blend"] is None) != (alpha != "blend"):
        errors.append(f"material {mname}: render state {state}, the page derives {want}")
    if alpha == "mask" and f32(state.get("alpha_cutoff", -1.0)) != f32(toml.get("params", {}).get("alpha_cutoff", 0.5)):
        errors.append(f"material {mname}: alpha_cutoff {state.get('alpha_cutoff')}")


def check_ktx2(build: Path, t: dict, errors: list[str]) -> str:
    """The KTX2 file's sha256, header and level index against the manifest's texture entry."""
    data = (build / t["path"]).read_bytes()
    if hashlib.sha256(data).hexdigest() != t["sha256"] or len(data) != t["bytes"]:
        errors.append(f"{t['path']}: its sha256 or size is not the manifest's")
    if data[:12] != KTX2_IDENTIFIER:
        errors.append(f"{t['path']}: not a KTX2 file")
        return ""
    vk_format, _type_size, width, height, depth, layers, faces, levels, scheme = struct.unpack_from("<9I", data, 12)
    header = {"format": VK_FORMATS.get(vk_format, vk_format), "width": width, "height": height, "levels": levels}
    want = {k: t[k] for k in header}
    if header != want or (depth, layers, faces, scheme) != (0, 0, 1, 0):
        errors.append(f"{t['path']}: the header says {header} (depth {depth}, layers {layers}, faces {faces}, "
                      f"supercompression {scheme}), the manifest {want}")
        return ""
    if levels != max(width, height).bit_length():
        errors.append(f"{t['path']}: {levels} levels, a full chain of {width} x {height} has "
                      f"{max(width, height).bit_length()}")
    for i in range(levels):
        offset, length, _ = struct.unpack_from("<3Q", data, 80 + 24 * i)
        expect = max(1, width >> i) * max(1, height >> i) * TEXEL_BYTES[header["format"]]
        if length != expect or offset + length > len(data):
            errors.append(f"{t['path']}: level {i} is {length} bytes at {offset}, expected {expect} within the file")
    return f"{t['path']}: {header['format']} {width} x {height}, {levels} levels, as the manifest says"


def read(build: Path, scene_path: Path) -> tuple[list[str], list[str]]:
    """(what was read, the mismatches) of a build against its TOML scene."""
    m = json.loads((build / "manifest.json").read_text(encoding="utf-8"))
    scene = tomllib.loads(scene_path.read_text(encoding="utf-8"))
    errors: list[str] = []
    if m.get("format_version") != 1:
        return [], [f"manifest format {m.get('format_version')}: this reader reads format 1"]
    said = [check_object(m, scene, o, errors) for o in m["objects"]]
    files = {t["path"]: t for t in m.get("textures", [])}
    for mname, mat in sorted(m["materials"].items()):
        for tname, t in sorted(mat.get("textures", {}).items()):
            listed = files.get(t["path"])
            if listed is None or {k: listed[k] for k in ("sha256", "format", "width", "height", "levels")} != \
                    {k: t[k] for k in ("sha256", "format", "width", "height", "levels")}:
                errors.append(f"material {mname} texture {tname}: {t['path']} is not the top level's entry")
            want_path = scene["materials"][mname].get("textures", {}).get(tname, "generated")
            if t["source"] != want_path:
                errors.append(f"material {mname} texture {tname}: source {t['source']}, the scene names {want_path}")
            check_sampler(m, scene, mname, tname, t, errors)
        check_render_state(scene["materials"][mname], mname, mat["render_state"], errors)
    said += [check_ktx2(build, t, errors) for t in files.values()]
    return [s for s in said if s], errors


def main(argv: list[str]) -> int:
    if len(argv) != 2:
        print("usage: engine_reader.py BUILD_DIR SCENE.toml", file=sys.stderr)
        return 2
    said, errors = read(Path(argv[0]), Path(argv[1]))
    for line in said:
        print(line)
    for e in errors:
        print(f"error: {e}", file=sys.stderr)
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
