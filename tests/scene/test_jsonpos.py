"""scene/jsonpos.py: the offset it gives for a JSON pointer is where that pointer's value starts, on any text
json.loads reads, and the scan stays bounded on text it does not."""
from __future__ import annotations

import json

import pytest

from generator.lang.errors import position
from generator.scene.jsonpos import GLB_JSON_START, Lines, locate, origins, pointer

DOC = {"asset": {"version": "2.0"}, "a/b": {"~x": [1, -2.5e3, True, None, "q\"]}[{"]},
       "materials": [{"name": "brace } [ \\ in a string"}, {}, {"pbr": {"base": [1, 0.5, 0.25, 1]}}],
       "ünï": "ü", "esc\"aped": {"k": []}, "empty": {},
       "backslashes": ["\\", "\\\\\"", "\\\"\\", "]"]}


def _pointers(value, here=""):
    yield here, value
    items = value.items() if isinstance(value, dict) else enumerate(value) if isinstance(value, list) else ()
    for k, v in items:
        yield from _pointers(v, here + pointer(k))


@pytest.mark.parametrize("indent", [None, 0, 2, "\t"])
@pytest.mark.parametrize("ascii", [True, False])
def test_every_pointer_starts_at_its_value(indent, ascii):
    text = json.dumps(DOC, indent=indent, ensure_ascii=ascii)
    want = dict(_pointers(DOC))
    found = locate(text, want)
    assert set(found) == set(want)
    for ptr, value in want.items():
        assert json.JSONDecoder().raw_decode(text, found[ptr])[0] == value, ptr


def test_only_the_wanted_pointers_and_missing_ones_are_absent():
    text = json.dumps(DOC)
    found = locate(text, ["/materials/2/pbr/base/3", "/materials/7", "/asset/nothing", "/a~1b/~0x/4"])
    assert set(found) == {"/materials/2/pbr/base/3", "/a~1b/~0x/4"}
    assert text[found["/a~1b/~0x/4"]:].startswith('"q\\"]}[{"')


def test_a_repeated_key_is_the_last_one_as_json_loads_reads_it():
    text = '{"m": {"x": {"deep": 1}}, "m": {"y": 2}}'
    found = locate(text, ["/m", "/m/x/deep", "/m/y"])
    assert found == {"/m": text.rindex('{"y"'), "/m/y": text.rindex("2")}


def test_deep_nesting_is_scanned_without_recursion():
    depth = 20_000  # far past Python's recursion limit, and json.loads's
    text = '{"skip": ' + "[" * depth + "]" * depth + ', "keep": ' + '{"a": ' * depth + "1" + "}" * depth + "}"
    deep = "/keep" + "/a" * depth
    found = locate(text, [deep, "/keep"])
    assert text[found[deep]] == "1" and found["/keep"] == text.index('{"a"')


@pytest.mark.parametrize("cut", range(0, 120, 3))
def test_cut_or_broken_text_stops_with_what_it_found(cut):
    text = json.dumps(DOC, indent=1)[:cut]
    for broken in (text, text + ",,]", text.replace(":", " ")):
        found = locate(broken, dict(_pointers(DOC)))
        assert all(0 <= off < len(broken) for off in found.values())


def test_lines_count_as_editors_do():
    text = 'a\r\nb\rc\nd\u2028e\x0cf'  # CR LF, CR, LF are line breaks; U+2028 and form feed are not
    lines = Lines(text)
    for i in range(len(text)):
        if text[i] not in "\r\n":  # a value never starts inside a line break
            assert lines.position(i) == position(text, i), i


def test_origins_give_lines_in_a_gltf_and_file_bytes_in_a_glb():
    text = '{\n  "materials": [\n    {"name": "ä"},\n    {"name": "b"}\n  ]\n}'
    asks = {"h": (("brdf", "/materials/1"), ("light0", "/nowhere"))}
    o = origins("m.gltf", text, asks)["h"]
    assert (o.at("brdf").line, o.at("brdf").col) == (4, 5)
    assert str(o.at("brdf").error("bad", "fix it")) == "m.gltf:4:5: /materials/1: bad — fix it"
    assert (o.at("light0").line, o.at("light0").col, o.at("light0").pointer) == (1, 1, "/nowhere")
    g = origins("m.glb", text, asks, glb=True)["h"].at("brdf")
    byte = GLB_JSON_START + text.encode().index(b'{"name": "b"}')  # after the two-byte "ä"
    assert (g.line, g.col, g.pointer) == (1, 1, f"/materials/1 (byte {byte})")
