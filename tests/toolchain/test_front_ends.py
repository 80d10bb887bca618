"""Each back end declares how its text becomes SPIR-V, and the toolchain reads that declaration: it has no branch
on a language's name, so a language is added by adding its package."""
from __future__ import annotations

import ast
from dataclasses import replace
from pathlib import Path

import pytest

from generator.backends import FRONT_ENDS, LANGUAGES, FrontEnd, language
from generator.toolchain import CompileJob, cache_key, compile_many
from generator.toolchain.frontends import DRIVERS

TOOLCHAIN = Path(__file__).resolve().parents[2] / "generator" / "toolchain"
HLSL_FRAG = "float4 main(float3 n : NORMAL) : SV_Target { return float4(n, 1.0); }\n"
GLSL_FRAG = "#version 450\nlayout(location = 0) out vec4 o;\nvoid main() { o = vec4(0.5); }\n"


def test_every_shading_language_declares_a_front_end_the_toolchain_drives():
    for name in LANGUAGES:
        fe = language(name).front_end
        assert isinstance(fe, FrontEnd) and FRONT_ENDS[name] is fe, name
        assert fe.tool in DRIVERS, f"{name}: no driver for {fe.tool!r}"
        if DRIVERS[fe.tool].most > 1:  # batched: its messages are split by the language's sentinel
            assert "{message}" in fe.sentinel, name
    assert language("gl").front_end is None and language("essl").front_end is None  # validated, not compiled


def test_the_toolchain_names_no_language():
    """No string in the toolchain's code is a language's name (docstrings may describe them)."""
    found = []
    for path in sorted(TOOLCHAIN.glob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        docs = {id(node.body[0].value) for node in ast.walk(tree)
                if isinstance(node, (ast.Module, ast.FunctionDef, ast.ClassDef)) and node.body
                and isinstance(node.body[0], ast.Expr) and isinstance(node.body[0].value, ast.Constant)}
        found += [f"{path.name}:{node.lineno}: {node.value!r}" for node in ast.walk(tree)
                  if isinstance(node, ast.Constant) and id(node) not in docs and isinstance(node.value, str)
                  and node.value.strip().lower() in LANGUAGES]
    assert not found, found


@pytest.mark.toolchain  # a cache key holds the tools' versions
def test_a_front_ends_flags_are_part_of_the_cache_key(monkeypatch):
    job = CompileJob("a.frag.hlsl", "hlsl", "frag", HLSL_FRAG)
    before, declared = cache_key(job), FRONT_ENDS["hlsl"]
    monkeypatch.setitem(FRONT_ENDS, "hlsl", replace(declared, process_flags=()))
    assert cache_key(job) != before
    monkeypatch.setitem(FRONT_ENDS, "hlsl", replace(declared, sentinel="#error other {message}\n"))
    assert cache_key(job) == before  # the sentinel splits messages: it changes no module


def test_a_front_end_without_a_driver_is_refused(monkeypatch):
    monkeypatch.setitem(FRONT_ENDS, "msl", FrontEnd("metal"))
    with pytest.raises(ValueError, match="names the tool 'metal', which .* has no driver"):
        compile_many([CompileJob("a.frag.msl", "msl", "frag", "")])


@pytest.mark.toolchain
def test_a_language_is_compiled_as_its_declaration_says(monkeypatch, require_tool):
    """A language registered with HLSL's declaration under another name compiles HLSL, in a batch with GLSL, its
    errors split by its sentinel; and GLSL declared with HLSL's flags is read as HLSL (and fails)."""
    for tool in ("glslc", "spirv-val", "spirv-opt"):
        require_tool(tool)
    monkeypatch.setitem(FRONT_ENDS, "hlsl6", FRONT_ENDS["hlsl"])
    jobs = [CompileJob("ok.frag.hlsl6", "hlsl6", "frag", HLSL_FRAG),
            CompileJob("bad.frag.hlsl6", "hlsl6", "frag", HLSL_FRAG.replace("return", "retrun")),
            CompileJob("ok.frag.glsl", "glsl", "frag", GLSL_FRAG)]
    res = compile_many(jobs)
    assert res["ok.frag.hlsl6"].ok and res["ok.frag.glsl"].ok, {k: r.errors() for k, r in res.items()}
    assert not res["bad.frag.hlsl6"].ok
    assert all(d.path == "bad.frag.hlsl6" for d in res["bad.frag.hlsl6"].diagnostics if d.severity == "error")
    assert res["ok.frag.hlsl6"].diagnostics == []  # the sentinel's own error is no job's

    monkeypatch.setitem(FRONT_ENDS, "glsl", replace(FRONT_ENDS["glsl"], flags=("-x", "hlsl")))
    assert not compile_many([CompileJob("g.frag.glsl", "glsl", "frag", GLSL_FRAG)])["g.frag.glsl"].ok
