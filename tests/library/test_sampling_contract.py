"""The sampling entries' contract at load time (library/kinds.py, library/sampling.py): located errors, and
sampling code kept out of the shading module."""
from __future__ import annotations

import re

import pytest

from generator.lang import SourceError
from generator.library.bricks import load_brick, load_library

HEAD = '''"""A test brick."""
BRICK = {"kind": "specular", "cite": "none", "params": {"n": {"type": "float", "default": 2.0}}}


def specular(NdotH: float, n: float) -> vec3:
    return vec3(pow(NdotH, n))
'''


def _load(tmp_path, body: str):
    path = tmp_path / "s.py"
    path.write_text(HEAD + body)
    return load_brick(path)


def test_sampling_entries_leave_the_shading_module_with_their_own_helpers(tmp_path):
    b = _load(tmp_path, '''

def lobe(c: float, n: float) -> float:
    return pow(c, n)


def sample(u: vec2, N: vec3) -> vec3:
    return N


def pdf(L: vec3, N: vec3, n: float) -> float:
    return lobe(dot(N, L), n)
''')
    assert sorted(b.module.functions) == ["specular"]
    assert sorted(b.sampling) == ["lobe", "pdf", "sample"]


@pytest.mark.parametrize("body, message", [
    ("\n\ndef pdf(L: vec3, NdotL: float) -> float:\n    return NdotL\n",
     "parameter 'NdotL' is neither an argument of the specular contract"),
    ("\n\ndef sample(u: vec2, N: vec3) -> float:\n    return u.x\n", "'sample' must return vec3, not float"),
])
def test_a_sampling_entry_reads_its_arguments_and_params_only_and_returns_the_contract_type(tmp_path, body, message):
    with pytest.raises(SourceError) as e:
        _load(tmp_path, body)
    assert message in str(e.value)
    assert re.search(r"s\.py:\d+:\d+: ", str(e.value))  # located: path:line:col


def test_shading_code_that_calls_a_sampling_entry_is_a_located_error(tmp_path):
    path = tmp_path / "s.py"
    path.write_text(HEAD.replace("return vec3(pow(NdotH, n))", "return vec3(pdf(vec3(0.0), vec3(0.0)))") +
                    "\n\ndef pdf(L: vec3, N: vec3) -> float:\n    return 1.0\n")
    with pytest.raises(SourceError) as e:
        load_brick(path)
    assert "'specular' calls the sampling entry 'pdf'" in str(e.value)


def test_every_shipped_ndf_with_a_sampler_has_both_entries():
    lib = load_library()
    for b in lib.of_kind("ndf") + lib.of_kind("specular") + lib.of_kind("diffuse"):
        names = set(b.sampling)
        pair = ("sample_h", "pdf_h") if b.kind == "ndf" else ("sample", "pdf")
        assert (pair[0] in names) == (pair[1] in names), b.id
