"""`build --explain` names the input that changed and how far it reaches; the compile cache records each shader's
time; `matrix --explain` counts what each axis value adds and costs."""
from __future__ import annotations

import hashlib
import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.toolchain
PLATFORMS = ("vulkan",)

LAM_A = '''"""A Lambert copy (test)."""
BRICK = {"kind": "diffuse", "cite": "test",
         "params": {"rho_d": {"type": "vec3", "range": [0.0, 1.0], "default": [0.5, 0.5, 0.5]}}}


def diffuse(rho_d: vec3) -> vec3:
    return rho_d * INV_PI
'''
# three permutations: two read lam_a (one with a specular lobe), one the built-in lambert
SCENE = '''[scene]
name = "tiny"

[materials.a]
brdf = "lam_a"

[materials.b]
brdf = "lam_a+blinn_phong_normalized"
params = { n = 32.0 }

[materials.c]
brdf = "lambert"

[lights.sun]
type = "directional"

[lights.lamp]
type = "point"

[light_sets]
day = ["sun"]
night = ["lamp"]

[[objects]]
name = "one"
material = "a"
lights = "day"

[[objects]]
name = "two"
material = "b"
lights = "day"

[[objects]]
name = "three"
material = "c"
lights = "night"
'''


def _load(root: Path):
    from generator.library.bricks import load_library
    from generator.scene.load import load_scene
    lib = load_library([root / "engine_bricks"])
    return lib, load_scene(root / "tiny.toml", lib)


def _build(root: Path, cache: Path):
    from generator.assemble import BuildContext, build
    from generator.io import Store
    lib, scene = _load(root)
    res = build(scene, root / "out", BuildContext(lib, platforms=PLATFORMS, store=Store(cache)))
    assert res.ok, res.failures
    return scene, res


@pytest.fixture(scope="module")
def first(tmp_path_factory):
    """A built tree of the tiny scene, the first build's explanation and the shared compile cache."""
    root = tmp_path_factory.mktemp("explain")
    (root / "engine_bricks").mkdir()
    (root / "engine_bricks" / "lam_a.py").write_text(LAM_A)
    (root / "tiny.toml").write_text(SCENE)
    scene, res = _build(root, root / "cache")
    return root, root / "cache", res.explain.explained()


@pytest.fixture
def tree(first, tmp_path):
    """A copy of the first build's tree, bricks and scene, to change and rebuild."""
    root, cache, _ = first
    for name in ("engine_bricks", "out"):
        shutil.copytree(root / name, tmp_path / name)
    shutil.copy(root / "tiny.toml", tmp_path / "tiny.toml")
    return tmp_path, cache


def _sha12(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()[:12]


def test_a_first_build_says_there_was_no_earlier_build(first):
    why = first[2]
    assert why.first and why.lines() == ["explain: no earlier build — all 3 permutations and the ubershader built"]


def test_a_touched_brick_is_named_with_its_hashes_and_its_fan_out(tree):
    root, cache = tree
    brick = root / "engine_bricks" / "lam_a.py"
    old = _sha12(brick)
    brick.write_text(LAM_A.replace("rho_d * INV_PI", "rho_d * (0.5 * INV_PI)"))
    scene, res = _build(root, cache)
    why = res.explain.explained()
    readers = {h for h, p in scene.permutations.items() if "lam_a" in p.brdf}
    assert len(readers) == 2 and set(why.rebuilt) == readers  # the lambert permutation was kept
    for h in readers:
        assert [str(c) for c in why.rebuilt[h]] == \
            [f"engine_bricks/lam_a.py changed (sha256 {old} → sha256 {_sha12(brick)})"]
    assert [str(c) for c in why.ubershader] == [str(why.rebuilt[min(readers)][0])]
    lines = why.lines()
    assert lines[0] == "explain: 2 of 3 permutations rebuilt, and the ubershader"
    assert lines[-2:] == ["fan-out:", "  engine_bricks/lam_a.py changed → 2 of 3 permutations and the ubershader"]


def test_a_changed_scene_value_is_named(tree):
    root, cache = tree
    scene_file = root / "tiny.toml"
    scene_file.write_text(SCENE.replace("n = 32.0", "n = 8.0"))
    scene, res = _build(root, cache)
    why = res.explain.explained()
    (h, changes), = why.rebuilt.items()
    assert scene.permutations[h].brdf == "lam_a+blinn_phong_normalized" and why.ubershader is None  # reads no value
    assert [str(c) for c in changes] == [f"{scene_file}: materials.b.params.n changed (32.0 → 8.0)"]
    assert why.lines()[-1] == f"  {scene_file}: materials.b.params.n changed → 1 of 3 permutations"


def test_a_changed_tool_version_is_named(tree, monkeypatch):
    import generator.assemble as assemble
    root, cache = tree
    real = assemble.tool_versions()
    monkeypatch.setattr(assemble, "tool_versions", lambda: {**real, "spirv-tools": real["spirv-tools"] + "-upgraded"})
    _, res = _build(root, cache)
    why = res.explain.explained()
    tool = f"tool spirv-tools changed ({real['spirv-tools']} → {real['spirv-tools']}-upgraded)"
    assert len(why.rebuilt) == 3 and all([str(c) for c in cs] == [tool] for cs in why.rebuilt.values())
    assert [str(c) for c in why.ubershader] == [tool]
    assert why.lines()[-1] == "  tool spirv-tools changed → 3 of 3 permutations and the ubershader"


def test_a_changed_template_is_named_with_its_hashes(tree, monkeypatch):
    import generator.assemble.keys as keys
    root, cache = tree
    real = keys.source_files()
    template = "generator/backends/glsl/templates/fragment.glsl.j2"
    assert template in real  # as if it had been edited: the build keys it by its sha256
    monkeypatch.setattr(keys, "source_files", lambda: {**real, template: "0" * 64})
    _, res = _build(root, cache)
    why = res.explain.explained()
    change = f"{template} changed (sha256 {real[template][:12]} → sha256 000000000000)"
    assert len(why.rebuilt) == 3 and all([str(c) for c in cs] == [change] for cs in why.rebuilt.values())
    assert why.lines()[-1] == f"  {template} changed → 3 of 3 permutations and the ubershader"


def test_a_damaged_output_and_a_no_op_say_so_on_the_command_line(tree):
    root, cache = tree
    m = json.loads((root / "out" / "manifest.json").read_text())
    entry = m["permutations"][0]
    (root / "out" / entry["languages"]["glsl"]["frag"]["spirv"]).write_bytes(b"damaged")
    cli = [sys.executable, "-m", "generator.cli", "build", root / "tiny.toml", "--out", root / "out", "--bricks",
           root / "engine_bricks", "--cache-dir", cache, "--platform", ",".join(PLATFORMS), "--explain", "-q"]
    r = subprocess.run(cli, cwd=REPO, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert lines[0].startswith("explain: ") and any(
        line.startswith(f"  {entry['hash']}  {entry['id']}: its files were missing or damaged") for line in lines)
    again = subprocess.run([*cli, "--json"], cwd=REPO, capture_output=True, text=True, timeout=300)
    explain = json.loads(again.stdout)["explain"]
    assert explain["rebuilt"] == [] and explain["ubershader"] is None and not explain["first_build"]


def test_the_cache_records_each_shader_s_compile_time(first):
    from generator.io import Store
    from generator.toolchain import COMPILE_NAMESPACE
    from generator.toolchain.cache import decode
    _, cache, _ = first
    entries = sorted((cache / COMPILE_NAMESPACE).glob("*/*"))
    assert entries
    store = Store(cache)
    for e in entries:
        r = decode(store.get(COMPILE_NAMESPACE, e.name), "x")
        assert r is not None and r.seconds is not None and 0 < r.seconds < 60


def test_a_batch_time_is_apportioned_by_source_size_and_an_untimed_record_reads():
    import base64
    from generator.toolchain import CompileJob
    from generator.toolchain.cache import apportion, decode
    jobs = [CompileJob("a", "glsl", "frag", "x" * 300), CompileJob("b", "glsl", "frag", "x" * 100)]
    assert apportion(2.0, jobs) == {"a": 1.5, "b": 0.5}
    assert apportion(1.0, [CompileJob("e", "glsl", "frag", ""), CompileJob("f", "glsl", "frag", "")]) == \
        {"e": 0.5, "f": 0.5}
    old = json.dumps({"spirv": base64.b64encode(b"\x03\x02\x23\x07").decode(), "spirv_unopt": "",
                      "diagnostics": [], "key": "k"}).encode()  # stored before times were recorded
    assert decode(old, "k").seconds is None


def test_matrix_explain_counts_what_each_value_adds_and_costs(first):
    from generator.cli.commands.matrix import spirv_identities
    from generator.scene.explain import markdown, report
    root, cache, _ = first
    lib, scene = _load(root)
    spirv, failures, shaders = spirv_identities(scene, lib, cache)
    assert not failures
    rep = report(scene, lib, spirv, shaders)
    adds = {(v["axis"], v["value"]): v["adds"] for v in rep["axes"]}
    # by hand: objects one (a: lam_a, day), two (b: lam_a+blinn_phong_normalized, day), three (c: lambert, night)
    assert adds == {("brdf", "lam_a"): 1, ("brdf", "lam_a+blinn_phong_normalized"): 1, ("brdf", "lambert"): 1,
                    ("packing", "constants(normal=vertex)"): 3, ("surface", "default"): 3,
                    ("lights", "directional/none"): 2, ("lights", "point/none"): 1,
                    ("output", "linear"): 3, ("precision", "fp32"): 3}
    records = rep["compile_records"]
    assert records["shaders"] == records["timed"] > 0  # every shader of the cache has its time
    value = {(v["axis"], v["value"]): v for v in rep["axes"]}
    assert value[("output", "linear")]["compile_seconds"] == pytest.approx(records["seconds"], abs=0.002)
    assert 0 < value[("brdf", "lam_a")]["compile_seconds"] < value[("lights", "directional/none")]["compile_seconds"]
    assert "| brdf | `lam_a` | yes | 1 | " in markdown(rep, True)
    blind = markdown(report(scene, lib), True)  # --no-compile: no build, so no records to read
    assert "not known without a build" in blind and "| brdf | `lam_a` | yes | 1 | — |" in blind
