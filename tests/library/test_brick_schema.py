"""BRICK metadata against its schema: every case here was a traceback or an invalid brick accepted;
each is now one line at the offending key of the BRICK literal (generator/library/schema.py)."""
from __future__ import annotations

import pytest

from generator.lang import SourceError

GOOD = '''"""Test brick."""
BRICK = {
    "kind": "specular",
    "cite": "test",
    "params": {"n": {"type": "float", "range": [1.0, 100.0], "default": 8.0}},
}


def specular(NdotH: float, n: float) -> vec3:
    return vec3(pow(NdotH, n))
'''

CASES = [  # (id, replace, with, line, words)
    ("range-of-strings", '"range": [1.0, 100.0]', '"range": ["a", "b"]', 5, "BRICK['params']['n']['range'][0] must be a number"),
    ("range-of-three", '"range": [1.0, 100.0]', '"range": [1.0, 2.0, 3.0]', 5, "has 3 items", "[low, high]"),
    ("cite-is-a-number", '"cite": "test"', '"cite": 5', 4, "BRICK['cite'] must be a string, not an integer"),
    ("kind-is-a-list", '"kind": "specular"', '"kind": ["specular"]', 3, "BRICK['kind'] must be a string, not a list"),
    ("param-name-with-a-space", '"n": {', '"a b": {', 5, "'a b' is not a name of the brick language"),
    ("param-name-empty", '"n": {', '"": {', 5, "is not a name of the brick language"),
    ("param-key-not-a-string", '"n": {', '1: {', 5, "a key that is not a string"),
    ("typo-in-param", '"default": 8.0', '"defualt": 8.0', 5, "unknown key 'defualt'", "did you mean 'default'?"),
    ("typo-at-top", '"cite": "test"', '"cite": "test", "slot": {}', 4, "unknown key 'slot' in BRICK", "did you mean 'slots'?"),
    ("texture-not-a-dict", '"cite": "test"', '"cite": "test", "textures": {"t": 1}', 4,
     "BRICK['textures']['t'] must be a dict, not an integer"),
    ("srgb-not-a-boolean", '"cite": "test"', '"cite": "test", "textures": {"t": {"srgb": "yes"}}', 4,
     "BRICK['textures']['t']['srgb'] must be True or False, not a string"),
    ("slot-default-not-an-id", '"cite": "test"', '"cite": "test", "slots": {"ndf": {"kind": "ndf", "default": "a-b"}}',
     4, "'a-b' is not a name of the brick language"),
    ("slot-name-a-list", '"cite": "test"', '"cite": "test", "slots": {"ndf": {"kind": ["ndf"], "default": "ggx"}}',
     4, "BRICK['slots']['ndf']['kind'] must be a string, not a list"),
    ("second-brick", 'def specular', 'BRICK = {"kind": "diffuse"}\n\n\ndef specular', 9, "a second BRICK",
     "the first is at line 2"),
    ("count-not-an-integer", '"default": 8.0', '"default": 8.0, "count": 2.5', 5,
     "BRICK['params']['n']['count'] must be an integer, not a number"),
    # non-finite (1e400 is inf to literal_eval) or past float32: parameters are float32 in every shader
    ("default-inf", '"range": [1.0, 100.0], "default": 8.0', '"default": 1e400', 5,
     "BRICK['params']['n']['default'] holds inf, outside the float32 range", "write a finite number"),
    ("default-minus-inf", '"range": [1.0, 100.0], "default": 8.0', '"default": -1e400', 5, "holds -inf"),
    ("default-past-float32", '"range": [1.0, 100.0], "default": 8.0', '"default": 1e39', 5, "holds 1e+39"),
    ("vector-default-inf", '"type": "float", "range": [1.0, 100.0], "default": 8.0',
     '"type": "vec3", "default": [0.5, 1e400, 0.5]', 5, "BRICK['params']['n']['default'] holds inf"),
    ("array-default-inf", '"range": [1.0, 100.0], "default": 8.0', '"count": 2, "default": [1.0, -1e400]', 5,
     "holds -inf"),
    ("range-bound-inf", '"range": [1.0, 100.0]', '"range": [1.0, 1e400]', 5,
     "BRICK['params']['n']['range'][1] holds inf, outside the float32 range"),
    ("range-bound-minus-inf", '"range": [1.0, 100.0]', '"range": [-1e400, 100.0]', 5, "['range'][0] holds -inf"),
]


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_a_malformed_brick_is_one_error_at_its_key(case, tmp_path):
    from generator.library.bricks import load_brick

    _, old, new, line, *words = case
    assert old in GOOD
    path = tmp_path / "test_brick.py"
    path.write_text(GOOD.replace(old, new, 1))
    with pytest.raises(SourceError) as e:
        load_brick(path)
    text = str(e.value)
    assert f":{line}:" in text.split(" ")[0] and " — " in text, text
    assert all(w in text for w in words), text


def test_the_good_brick_and_every_shipped_brick_pass_the_schema(tmp_path):
    from generator.library.bricks import load_brick, load_library
    (tmp_path / "test_brick.py").write_text(GOOD)
    assert load_brick(tmp_path / "test_brick.py").params["n"].default == 8.0
    assert load_library().bricks  # every shipped brick loads through the schema


BODY = '''"""T."""
BRICK = {"kind": "diffuse", "cite": "x"}
PRE


def diffuse(NdotL: float) -> vec3:
    BODY
'''

LIMITS = [  # (id, module-level text, body, line, words) — each was a traceback or an emitter assertion
    ("constant-out-of-fp32", "K = -1e400", "return vec3(NdotL * K)", 3, "constant K = -inf is outside the fp32 range"),
    ("constant-out-of-int32", "N = 3000000000", "return vec3(NdotL)", 3, "constant N = 3000000000 does not fit in 32 bits"),
    ("loop-count-past-int32", "", "s = 0.0\n    for i in range(3000000000):\n        s = s + NdotL\n    return vec3(s)", 8,
     "the loop count 3000000000 does not fit in 32 bits"),
    ("a-500-term-sum", "", "return vec3(" + " + ".join(["NdotL"] * 500) + ")", 7, "nested more than 100 deep"),
    # Python's own parser gives up (RecursionError): located at the logical line with the most tokens
    ("a-10000-term-sum", "", "return vec3(" + " + ".join(["NdotL"] * 10000) + ")", 7, "too long or too deeply nested"),
]


@pytest.mark.parametrize("case", LIMITS, ids=[c[0] for c in LIMITS])
def test_a_brick_past_a_limit_is_one_located_error(case, tmp_path):
    from generator.library.bricks import load_brick

    _, pre, body, line, words = case
    path = tmp_path / "t.py"
    path.write_text(BODY.replace("PRE", pre).replace("BODY", body))
    with pytest.raises(SourceError) as e:
        load_brick(path)
    text = str(e.value)
    assert text.split(" ")[0].split(":")[1] == str(line) and words in text, text


def test_a_brick_id_that_is_not_a_name_and_a_packing_without_a_normal_slot(tmp_path):
    from generator.library.bricks import load_brick

    (tmp_path / "a-b.py").write_text(BODY.replace("PRE", "").replace("BODY", "return vec3(NdotL)"))
    with pytest.raises(SourceError, match=r"a-b\.py:1:1: the brick id 'a-b' \(its file name\) is not a name"):
        load_brick(tmp_path / "a-b.py")
    (tmp_path / "pk.py").write_text('"""P."""\nBRICK = {"kind": "packing", "cite": "x"}\n\n\n'
                                    "def get_rho_d(rho_d: vec3) -> vec3:\n    return rho_d\n")
    with pytest.raises(SourceError, match=r"pk\.py:2:1: a packing brick needs a 'normal' slot"):
        load_brick(tmp_path / "pk.py")


def test_slot_defaults_that_form_a_cycle_are_one_error(tmp_path):
    from generator.library.bricks import load_library
    from generator.spec.permutation import SpecError, parse_brdf

    (tmp_path / "sp.py").write_text('"""S."""\nBRICK = {"kind": "specular", "cite": "x", '
                                    '"slots": {"ndf": {"kind": "ndf", "default": "cyc"}}}\n\n\n'
                                    "def specular(NdotH: float, NxH2: float) -> vec3:\n"
                                    "    return vec3(ndf(NdotH, NxH2, 0.5))\n")
    (tmp_path / "cyc.py").write_text('"""C."""\nBRICK = {"kind": "ndf", "cite": "x", '
                                     '"slots": {"x": {"kind": "specular", "default": "sp"}}}\n\n\n'
                                     "def ndf(NdotH: float, NxH2: float, alpha: float) -> float:\n    return NdotH\n")
    with pytest.raises(SpecError, match="the slot defaults form a cycle"):
        parse_brdf("sp", load_library([tmp_path]))


def test_a_default_of_inf_is_at_its_key(tmp_path):
    from generator.library.bricks import load_brick

    path = tmp_path / "t.py"
    path.write_text(GOOD.replace('"range": [1.0, 100.0], "default": 8.0', '"default": 1e400'))
    with pytest.raises(SourceError, match=r"t\.py:5:39: BRICK\['params'\]\['n'\]\['default'\] holds inf"):
        load_brick(path)


GLUE_CLASH = '''"""A diffuse term whose helper is named like the glue's functions once linked."""
BRICK = {"kind": "diffuse", "cite": "test", "params": {"rho_d": {"type": "vec3", "default": [0.5, 0.5, 0.5]}}}


def HELPER(x: float) -> float:
    return 0.5 * x


def diffuse(NdotL: float, rho_d: vec3) -> vec3:
    return rho_d * HELPER(NdotL)
'''


@pytest.mark.parametrize("helper", ["lit", "switch", "lit_0"])
def test_a_brick_whose_functions_link_as_the_glues_is_one_error_at_load(helper, tmp_path):
    """A brick brdf.py with a helper `lit` was linked as `brdf_lit`, the glue's function: composing it
    failed at `<glue>:1:1` ("generated twice when linking"), with a hint about bricks of different kinds."""
    from generator.library.bricks import load_library

    (tmp_path / "brdf.py").write_text(GLUE_CLASH.replace("HELPER", helper))
    with pytest.raises(SourceError) as e:
        load_library([tmp_path])
    text = str(e.value)
    assert text.startswith(f"{tmp_path.name}/brdf.py:5:1: function '{helper}' of brick 'brdf' would be linked as "
                           f"'brdf_{helper}', a function of the generated glue — "), text


def test_a_brick_named_brdf_with_other_helpers_composes(tmp_path):
    from generator.compose import compose_eval
    from generator.library.bricks import load_library

    (tmp_path / "brdf.py").write_text(GLUE_CLASH.replace("HELPER", "half"))
    composed = compose_eval("brdf", load_library([tmp_path]))
    assert all("brdf_half(" in s.text for s in composed.sources)


def test_the_glue_and_templates_generate_only_the_names_bricks_are_kept_from():
    """GLUE_FUNCTIONS and TEMPLATE_STRUCTS (what a brick's function and struct names are checked against) cover
    every function the link stage generates and every block or struct the templates declare."""
    import re

    from generator.lang.parse import TEMPLATE_STRUCTS, _TEMPLATE_STRUCT_FAMILIES
    from generator.library.bricks import GLUE_FUNCTIONS, REPO, load_library
    from generator.link import link_permutation, switch_program
    from generator.link.uber import link_ubershader
    from generator.scene.load import load_scene

    lib = load_library()
    perms = list(load_scene(REPO / "scenes" / "example.toml", lib).permutations.values())
    programs = [switch_program(["lambert", "microfacet(ndf=beckmann)", "lambert+phong_normalized"], lib).program,
                link_permutation(perms[0], lib).program, link_ubershader(perms, lib).program]
    brick_structs = {n for b in lib.bricks.values() for n in b.module.structs}
    for prog in programs:
        glue = {f.name for f in prog.functions if f.loc.path == "<glue>"}
        assert glue and all(GLUE_FUNCTIONS.fullmatch(n) for n in glue), glue
        made = {st.name for st in prog.structs} - brick_structs
        assert all(n in TEMPLATE_STRUCTS or _TEMPLATE_STRUCT_FAMILIES.fullmatch(n) for n in made), made
    declared = {m[1] for t in (REPO / "generator" / "backends").glob("*/templates/*.j2") for m in re.finditer(
        r"\b(?:struct|uniform|buffer|cbuffer)\s+([A-Z]\w*)", t.read_text())}
    assert declared and declared <= TEMPLATE_STRUCTS, declared - TEMPLATE_STRUCTS


LONGEST = '''"""The longest names a brick may have: 64-character id, function, parameter, local, struct and field."""
BRICK = {"kind": "specular", "cite": "test", "slots": {"ndf": {"kind": "ndf", "default": "ggx"}},
         "params": {"PPPP": {"type": "float", "range": [0.0, 1.0], "default": 0.5}}}


class SSSS:
    FFFF: float


def HHHH(NdotH: float, NxH2: float, PPPP: float) -> float:
    LLLL = SSSS(ndf(NdotH, NxH2, 0.3))
    return LLLL.FFFF * PPPP


def specular(NdotH: float, NxH2: float, PPPP: float) -> vec3:
    return vec3(HHHH(NdotH, NxH2, PPPP))
'''


def _longest(tmp_path):
    from generator.compose import compose_eval
    from generator.library.bricks import load_library

    text = LONGEST
    for short, ch in (("PPPP", "p"), ("SSSS", "S"), ("FFFF", "f"), ("HHHH", "h"), ("LLLL", "l")):
        text = text.replace(short, ch * 64)
    (tmp_path / f"{'b' * 64}.py").write_text(text)
    return compose_eval("b" * 64, load_library([tmp_path]))


def test_the_longest_names_stay_far_below_the_compilers_limits(tmp_path):
    """64 characters per identifier: the longest generated name, `<id>_<6 hex>_<function>`, is 136 characters
    (glslang takes 1,024, GLSL and HLSL alike); a 1,023-character struct name used to fail in glslang."""
    import re

    for src in _longest(tmp_path).sources:
        longest = max(re.findall(r"[A-Za-z_][A-Za-z0-9_]*", src.text), key=len)
        assert len(longest) == 64 + 1 + 6 + 1 + 64 and longest.endswith("_" + "h" * 64), (src.language, longest)


@pytest.mark.toolchain
def test_the_longest_names_compile_in_every_language(tmp_path, require_tool):
    from generator.toolchain import CompileJob, compile_many

    for tool in ("glslc", "naga", "spirv-val", "spirv-opt"):
        require_tool(tool)
    jobs = [CompileJob(f"longest.comp.{s.language}", s.language, "comp", s.text, line_map=tuple(s.line_map))
            for s in _longest(tmp_path).sources]
    results = compile_many(jobs)
    assert all(r.ok for r in results.values()), [e for r in results.values() for e in r.errors()]
