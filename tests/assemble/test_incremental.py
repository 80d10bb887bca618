"""Incremental builds: a no-op rebuild composes, compiles and writes nothing; a change rebuilds
only the permutations it reaches."""
from __future__ import annotations

import copy
import json
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "scenes" / "example.toml"
pytestmark = pytest.mark.toolchain


def _stamps(root: Path) -> dict:
    return {str(p.relative_to(root)): (p.stat().st_mtime_ns, p.read_bytes()) for p in sorted(root.rglob("*"))
            if p.is_file()}


@pytest.fixture
def built(tmp_path):
    from generator.assemble import BuildContext, build
    from generator.library.bricks import load_library
    from generator.scene.load import load_scene
    lib = load_library()
    scene = load_scene(EXAMPLE, lib)
    out = tmp_path / "out"
    first = build(scene, out, BuildContext(lib))
    assert first.ok and first.kept == 0
    return lib, scene, out


def test_a_no_op_rebuild_composes_compiles_and_writes_nothing(built, monkeypatch):
    import generator.compose as compose
    import generator.compose.uber as uber
    from generator.assemble import BuildContext, build

    lib, scene, out = built
    before = _stamps(out)

    def refuse(*a, **k):
        raise AssertionError("composed on a no-op rebuild")
    monkeypatch.setattr(compose, "compose_permutation", refuse)
    monkeypatch.setattr(uber, "compose_ubershader", refuse)
    again = build(scene, out, BuildContext(lib))
    assert again.ok and again.up_to_date and again.kept == len(scene.permutations) and again.compile.jobs == 0
    assert again.written == 0 and _stamps(out) == before  # not one file rewritten, timestamps too
    assert again.manifest["permutations"]  # read from disk when asked for


def test_a_changed_brick_rebuilds_only_the_permutations_that_read_it(built):
    from generator.assemble import BuildContext, build

    lib, scene, out = built
    key = ("ndf", "beckmann")
    readers = {h for h, p in scene.permutations.items() if "ndf=beckmann" in p.brdf}
    assert 0 < len(readers) < len(scene.permutations)
    edited = copy.copy(lib.bricks[key])
    edited.module = copy.copy(edited.module)
    edited.module.source_hash = "0" * 64  # as if the file had been edited
    lib.bricks[key] = edited
    again = build(scene, out, BuildContext(lib))
    assert again.ok and again.kept == len(scene.permutations) - len(readers)


def test_a_changed_material_value_rebuilds_only_its_permutations(built):
    from generator.assemble import BuildContext, build

    lib, scene, out = built
    name = next(iter(scene.materials))
    users = {o["permutation"] for o in scene.objects if o["material"] == name}
    scene.materials[name].params = {**scene.materials[name].params, "rho_d": [0.1, 0.2, 0.3]}
    again = build(scene, out, BuildContext(lib))
    assert again.ok and again.kept == len(scene.permutations) - len(users)
    import json
    m = json.loads((out / "manifest.json").read_text())
    assert m["materials"][name]["params"]["rho_d"] == [0.1, 0.2, 0.3]


def test_a_damaged_output_is_rebuilt(built):
    from generator.assemble import BuildContext, build

    lib, scene, out = built
    victim = sorted((out / "vulkan" / "glsl").glob("*.frag.spv"))[0]
    victim.write_bytes(b"garbage")
    again = build(scene, out, BuildContext(lib))
    users = {e["hash"] for e in json.loads((out / "manifest.json").read_text())["permutations"]
             for st in e["languages"].values() for it in st.values() if it["spirv"] == f"vulkan/glsl/{victim.name}"}
    assert again.ok and again.kept == len(scene.permutations) - len(users) and users  # every one naming it
    assert victim.read_bytes()[:4] == b"\x03\x02\x23\x07"  # SPIR-V again
