"""The real compilers and validators, no mocks: glslc, naga, spirv-val, spirv-opt."""
from __future__ import annotations

import os
import struct
import subprocess

import pytest

from tests.conftest import require_tool
from generator import toolchain
from generator.backends import FRONT_ENDS
from generator.toolchain import CompileJob, Diagnostic, ToolMissing, compile_many, tool_versions
from generator.toolchain.spirv import spirv_steps

pytestmark = pytest.mark.toolchain

LINE_EXT = "#extension GL_GOOGLE_cpp_style_line_directive : require\n"

GLSL_FRAG = """#version 450
layout(location = 0) in vec3 v_normal;
layout(location = 0) out vec4 o_color;
void main() { o_color = vec4(max(dot(normalize(v_normal), vec3(0.0, 0.0, 1.0)), 0.0) / 3.14159265); }
"""
GLSL_COMP = """#version 450
layout(local_size_x = 64) in;
layout(std430, binding = 0) buffer Data { float v[]; } data;
void main() { uint i = gl_GlobalInvocationID.x; data.v[i] = pow(data.v[i], 2.0); }
"""
HLSL_FRAG = """float4 main(float3 n : NORMAL) : SV_Target {
    return float4((float3)(max(dot(normalize(n), float3(0, 0, 1)), 0.0) / 3.14159265), 1.0);
}
"""
HLSL_COMP = """RWStructuredBuffer<float> data : register(u0);
[numthreads(64, 1, 1)]
void main(uint3 id : SV_DispatchThreadID) { data[id.x] = pow(data[id.x], 2.0); }
"""
WGSL_FRAG = """@fragment
fn main(@location(0) n: vec3<f32>) -> @location(0) vec4<f32> {
    return vec4<f32>(vec3<f32>(max(dot(normalize(n), vec3<f32>(0.0, 0.0, 1.0)), 0.0) / 3.14159265), 1.0);
}
"""
WGSL_COMP = """@group(0) @binding(0) var<storage, read_write> data: array<f32>;
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) { data[id.x] = pow(data[id.x], 2.0); }
"""

SOURCES = {("glsl", "frag"): GLSL_FRAG, ("glsl", "comp"): GLSL_COMP, ("hlsl", "frag"): HLSL_FRAG,
           ("hlsl", "comp"): HLSL_COMP, ("wgsl", "frag"): WGSL_FRAG, ("wgsl", "comp"): WGSL_COMP}


def _front_end(language: str) -> str:
    return FRONT_ENDS[language].tool


def _spirv_val_ok(tmp_path, blob: bytes) -> None:
    path = tmp_path / "check.spv"
    path.write_bytes(blob)
    proc = subprocess.run([require_tool("spirv-val"), "--target-env", "vulkan1.1", str(path)],
                          capture_output=True, text=True)
    assert proc.returncode == 0, proc.stdout + proc.stderr


def _errors(result) -> list[Diagnostic]:
    return [d for d in result.diagnostics if d.severity == "error"]


def _glsl_brick(body: str, brick: str, line: int) -> str:
    return f'#version 450\n{LINE_EXT}layout(location = 0) out vec4 o_color;\n#line {line} "{brick}"\n{body}\n'


@pytest.mark.parametrize("language,stage", sorted(SOURCES))
@pytest.mark.parametrize("optimize", [True, False])
def test_valid_shader_compiles_and_validates(language, stage, optimize, tmp_path):
    for tool in (_front_end(language), "spirv-val", "spirv-opt"):
        require_tool(tool)
    key = f"ok.{stage}.{language}"
    res = compile_many([CompileJob(key, language, stage, SOURCES[language, stage])], optimize=optimize)[key]
    assert res.ok, [str(d) for d in res.diagnostics]
    assert _errors(res) == []
    for blob in (res.spirv, res.spirv_unopt):
        magic, version = struct.unpack_from("<II", blob)
        assert magic == toolchain.SPIRV_MAGIC
        assert version == 0x00010300, hex(version)  # SPIR-V 1.3 = vulkan1.1, every front end
        _spirv_val_ok(tmp_path, blob)
    if not optimize:
        assert res.spirv == res.spirv_unopt


def test_glsl_batch_with_one_broken_shader():
    require_tool("glslc"), require_tool("spirv-val"), require_tool("spirv-opt")
    jobs = [CompileJob(f"p{i:02d}.frag.glsl", "glsl", "frag",
                       _glsl_brick(f"void main() {{ o_color = vec4({i}.0 / 10.0); }}", "bricks/output/plain.py", 3))
            for i in range(10)]
    broken = _glsl_brick("float unused() { return 1.0; }\nvoid main() { o_color = vec4(rho_d, 1.0); }",
                         "bricks/brdf/lambert.py", 12)
    jobs[6] = CompileJob("broken.frag.glsl", "glsl", "frag", broken)
    results = compile_many(jobs)
    assert list(results) == [j.key for j in jobs]
    for key, res in results.items():
        if key == "broken.frag.glsl":
            continue
        assert res.ok and res.spirv is not None and _errors(res) == [], key
    bad = results["broken.frag.glsl"]
    assert not bad.ok and bad.spirv is None
    errs = _errors(bad)
    assert errs and all(d.tool == "glslc" for d in errs)
    assert (errs[0].path, errs[0].line) == ("bricks/brdf/lambert.py", 13)
    assert "rho_d" in errs[0].message
    assert str(errs[0]).startswith("bricks/brdf/lambert.py:13:")


def test_errors_are_given_to_the_right_job_in_a_batch():
    """Two broken jobs naming the same brick path, one broken without #line, one HLSL."""
    require_tool("glslc"), require_tool("spirv-val"), require_tool("spirv-opt")
    ok = _glsl_brick("void main() { o_color = vec4(1.0); }", "bricks/a.py", 1)
    jobs = [
        CompileJob("a.frag.glsl", "glsl", "frag", ok),
        CompileJob("b.frag.glsl", "glsl", "frag", _glsl_brick("void main() { o_color = vec4(xb); }", "bricks/same.py", 40)),
        CompileJob("c.frag.glsl", "glsl", "frag", ok.replace("1.0", "0.5")),
        CompileJob("d.frag.glsl", "glsl", "frag", _glsl_brick("\n\nvoid main() { o_color = vec4(xd); }", "bricks/same.py", 70)),
        CompileJob("e.frag.glsl", "glsl", "frag", "#version 450\nlayout(location = 0) out vec4 o;\nvoid main() { o = vec4(1.0) }\n"),
        CompileJob("f.frag.hlsl", "hlsl", "frag", '#line 9 "bricks/h.py"\nfloat4 main() : SV_Target { return yh; }\n'),
        CompileJob("g.comp.hlsl", "hlsl", "comp", HLSL_COMP),
    ]
    results = compile_many(jobs)
    assert [k for k, r in results.items() if r.ok] == ["a.frag.glsl", "c.frag.glsl", "g.comp.hlsl"]
    first = {k: _errors(r)[0] for k, r in results.items() if not r.ok}
    assert (first["b.frag.glsl"].path, first["b.frag.glsl"].line) == ("bricks/same.py", 40)
    assert "xb" in first["b.frag.glsl"].message
    assert (first["d.frag.glsl"].path, first["d.frag.glsl"].line) == ("bricks/same.py", 72)
    assert "xd" in first["d.frag.glsl"].message
    assert (first["e.frag.glsl"].path, first["e.frag.glsl"].line) == ("e.frag.glsl", 3)  # no #line: the job key
    assert (first["f.frag.hlsl"].path, first["f.frag.hlsl"].line) == ("bricks/h.py", 9)
    assert "yh" in first["f.frag.hlsl"].message
    for res in results.values():  # nothing leaks into another job
        assert all(d.severity != "error" for d in res.diagnostics) == res.ok


def test_broken_wgsl_maps_line_through_line_map():
    require_tool("naga")
    source = ("// generated\n"                       # 1
              "@fragment\n"                           # 2
              "fn main() -> @location(0) vec4<f32> {\n"  # 3
              "    let k = 0.5;\n"                    # 4  <- bricks/brdf/phong.py:20
              "    return vec4<f32>(k, k, undefined_q, 1.0);\n"  # 5 -> phong.py:21
              "}\n")
    line_map = ((4, "bricks/brdf/phong.py", 20), (6, "templates/wgsl/fragment.wgsl.j2", 30))
    res = compile_many([CompileJob("w.frag.wgsl", "wgsl", "frag", source, line_map=line_map)])["w.frag.wgsl"]
    assert not res.ok and res.spirv is None
    err = _errors(res)[0]
    assert (err.path, err.line, err.tool) == ("bricks/brdf/phong.py", 21, "naga")
    assert err.col > 1 and "undefined_q" in err.message


def test_wgsl_line_before_line_map_is_the_generated_file():
    require_tool("naga")
    source = "fn f() -> f32 { return nope; }\n@compute @workgroup_size(1)\nfn main() { }\n"
    res = compile_many([CompileJob("x.comp.wgsl", "wgsl", "comp", source,
                                   line_map=((3, "bricks/b.py", 5),))])["x.comp.wgsl"]
    assert (res.ok, _errors(res)[0].path, _errors(res)[0].line) == (False, "x.comp.wgsl", 1)


def test_wgsl_validation_error_has_location():
    require_tool("naga")
    source = "fn f(a: f32) -> f32 { return a + vec3<f32>(1.0); }\n@compute @workgroup_size(1)\nfn main() { let y = f(1.0); }\n"
    res = compile_many([CompileJob("v.comp.wgsl", "wgsl", "comp", source)])["v.comp.wgsl"]
    err = _errors(res)[0]
    assert not res.ok and (err.path, err.line) == ("v.comp.wgsl", 1)
    assert "\x1b[" not in err.message  # colour codes stripped


def test_tool_versions_are_stable():
    for tool in ("glslc", "glslangValidator", "spirv-val", "spirv-opt", "naga"):
        require_tool(tool)
    first = tool_versions()
    toolchain.tool_versions.cache_clear()
    second = tool_versions()
    assert first == second
    assert set(first) == {"glslc", "glslang", "spirv-tools", "naga"}
    assert all(v and v != "missing" and "\n" not in v for v in first.values()), first
    assert first["naga"] == "30.0.1"


def test_no_temp_files_left(tmp_path, monkeypatch):
    require_tool("glslc"), require_tool("naga")
    monkeypatch.setattr("tempfile.tempdir", str(tmp_path))
    compile_many([CompileJob("a.frag.glsl", "glsl", "frag", GLSL_FRAG),
                  CompileJob("b.frag.glsl", "glsl", "frag", "#version 450\nvoid main() { x }\n"),
                  CompileJob("c.comp.wgsl", "wgsl", "comp", WGSL_COMP)])
    assert list(tmp_path.iterdir()) == []


def test_missing_tool_raises_clear_error(tmp_path, monkeypatch):
    monkeypatch.setenv("SHADERMATRIX_TOOLS", str(tmp_path))
    monkeypatch.setattr("sysconfig.get_path", lambda name: str(tmp_path))
    monkeypatch.setenv("PATH", str(tmp_path))
    with pytest.raises(ToolMissing, match=r"glslc not found — run `make setup`"):
        compile_many([CompileJob("a.frag.glsl", "glsl", "frag", GLSL_FRAG)])


def _fake_tool(folder, name="naga"):
    folder.mkdir(exist_ok=True)
    fake = folder / name
    fake.write_text("#!/bin/sh\necho 0.0.0\n")
    fake.chmod(0o755)
    return str(fake)


def test_tools_setting_comes_before_the_environment_and_path(tmp_path, monkeypatch):
    on_path, in_env, in_setting = (_fake_tool(tmp_path / d) for d in ("path", "venv", "setting"))
    monkeypatch.delenv("SHADERMATRIX_TOOLS", raising=False)
    monkeypatch.setenv("PATH", str(tmp_path / "path"))
    monkeypatch.setattr("sysconfig.get_path", lambda name: str(tmp_path / "venv"))
    assert toolchain.find_tool("naga") == in_env  # the venv's bin/ (where `make setup` links naga) before PATH
    monkeypatch.setenv("SHADERMATRIX_TOOLS", os.pathsep.join([str(tmp_path / "none"), str(tmp_path / "setting")]))
    assert toolchain.find_tool("naga") == in_setting
    monkeypatch.delenv("SHADERMATRIX_TOOLS")
    monkeypatch.setattr("sysconfig.get_path", lambda name: str(tmp_path / "none"))
    assert toolchain.find_tool("naga") == on_path
    (tmp_path / "path" / "naga").chmod(0o644)  # not executable: not a tool
    assert toolchain.find_tool("naga") is None


def test_bad_jobs_are_rejected():
    with pytest.raises(ValueError, match="duplicate"):
        compile_many([CompileJob("k", "glsl", "frag", GLSL_FRAG), CompileJob("k", "glsl", "frag", GLSL_FRAG)])
    with pytest.raises(ValueError, match="unknown language"):
        compile_many([CompileJob("k", "msl", "frag", "")])


def test_warning_of_a_good_shader_stays_with_it_in_a_batch():
    require_tool("glslc"), require_tool("spirv-val"), require_tool("spirv-opt")
    plain = _glsl_brick("void main() { o_color = vec4(1.0); }", "bricks/a.py", 1)
    warned = plain.replace(LINE_EXT, LINE_EXT + "#extension GL_EXT_shadermatrix_nonexistent : enable\n")
    jobs = [CompileJob(f"{name}.frag.glsl", "glsl", "frag", src)
            for name, src in (("p", plain), ("w", warned), ("q", plain.replace("1.0", "0.25")))]
    results = compile_many(jobs)
    assert all(r.ok for r in results.values())
    assert results["p.frag.glsl"].diagnostics == [] and results["q.frag.glsl"].diagnostics == []
    (warning,) = results["w.frag.glsl"].diagnostics
    assert (warning.severity, warning.path, warning.line) == ("warning", "w.frag.glsl", 3)
    assert "GL_EXT_shadermatrix_nonexistent" in warning.message


INVALID_SPVASM = """OpCapability Shader
OpMemoryModel Logical GLSL450
OpEntryPoint Fragment %main "main"
OpExecutionMode %main OriginUpperLeft
%void = OpTypeVoid
%fn = OpTypeFunction %void
%float = OpTypeFloat 32
%main = OpFunction %void None %fn
%label = OpLabel
%sum = OpFAdd %float %label %label
OpReturn
OpFunctionEnd
"""


def test_an_invalid_front_end_module_fails_in_spirv_opt_with_the_validator_message(tmp_path):
    """compile_many runs no spirv-val before spirv-opt, because spirv-opt validates its input: shown here."""
    spirv_as = require_tool("spirv-as")
    bad = tmp_path / "bad.spv"
    subprocess.run([spirv_as, "--target-env", "vulkan1.1", "-", "-o", str(bad)], input=INVALID_SPVASM.encode(),
                   check=True)
    job = CompileJob("bad.frag.glsl", "glsl", "frag", "")
    res = spirv_steps({"spirv-opt": require_tool("spirv-opt"), "spirv-val": require_tool("spirv-val")},
                      str(tmp_path), 0, job, bad.read_bytes(), [], optimize=True, validate=True)
    assert not res.ok and res.spirv is None
    assert any("requires a type" in d.message and d.tool == "spirv-opt" for d in res.diagnostics), res.diagnostics
