"""`render --export DIR`: the frame export holds what the render drew with — its meshes byte for byte, the
placement's matrices, the camera, each shadowed light's fitted matrix — in the layout its schema states, the
same bytes on every run, and a bad --export is refused before anything is lost."""
from __future__ import annotations

import hashlib
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "scenes" / "example.toml"


def _render(tmp_path, name: str, *extra: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "generator.cli", "render", str(EXAMPLE), "--mode", "specialized",
                           "--frames", "1", "--size", "64x40", "--out", str(tmp_path / name), *extra],
                          capture_output=True, text=True, cwd=REPO)


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("export")
    r = _render(tmp, "out", "--export", str(tmp / "frame"))
    assert r.returncode == 0, r.stderr
    return tmp


@pytest.mark.lavapipe
@pytest.mark.toolchain
def test_the_export_holds_what_the_render_drew_with(exported):
    from generator.library.bricks import load_library
    from generator.runtime.camera import column_major
    from generator.runtime.frame_export import check_document
    from generator.runtime.placement import load_placement, make_mesh
    from generator.scene.load import load_scene

    doc = json.loads((exported / "frame" / "frame.json").read_text())
    check_document(doc)
    scene = load_scene(EXAMPLE, load_library())
    placed = load_placement(scene)
    assert doc["scene"] == scene.name and doc["size"] == [64, 40] and doc["color_attachment"] == "srgb"
    assert [o["name"] for o in doc["objects"]] == [o["name"] for o in scene.objects] == [p.name for p in placed.objects]
    eye, vp = placed.camera(64, 40)
    assert doc["camera"]["eye"] == [float(x) for x in eye] and doc["camera"]["view_proj"] == column_major(vp)
    for o, p in zip(doc["objects"], placed.objects):
        assert o["model"] == column_major(p.model) and o["mirrored"] == p.mirrored
        mesh, row = make_mesh(p.mesh, p.mirrored), doc["meshes"][o["mesh"]]
        data = (exported / "frame" / row["path"]).read_bytes()
        assert hashlib.sha256(data).hexdigest() == row["sha256"] and len(data) == row["bytes"]
        assert row["vertex_count"] == mesh.vertex_count and row["indices"]["count"] == mesh.index_count
        for name, arr in mesh.attributes().items():  # each attribute's array, where the row says it is
            a, n = row["attributes"][name], np.asarray(arr).shape[1]
            got = np.frombuffer(data, "<f4", mesh.vertex_count * n, a["offset"]).reshape(-1, n)
            assert a["stride"] == 4 * n and np.array_equal(got, np.asarray(arr, np.float32)), name
        idx = np.frombuffer(data, "<u4", mesh.index_count, row["indices"]["offset"])
        assert np.array_equal(idx, mesh.indices) and row["indices"]["offset"] + 4 * mesh.index_count == len(data)
    report = json.loads((exported / "out" / "report.json").read_text())
    assert sorted(doc["lights"]) == sorted(report["shadow_maps"]) == ["sun"]
    sun = doc["lights"]["sun"]
    assert sun["shadow_matrix"] == report["shadow_maps"]["sun"]["shadow_matrix"]
    assert sun["size"] == report["shadow_maps"]["sun"]["size"] and sun["pcf_texel"] is None  # shadow_map: no taps
    assert sorted(doc["draw_order"]) == list(range(len(scene.objects)))
    # no absolute path anywhere: the export moves with its folder
    assert str(exported) not in (exported / "frame" / "frame.json").read_text()


@pytest.mark.lavapipe
@pytest.mark.toolchain
def test_the_export_is_the_same_bytes_every_time(exported, tmp_path):
    r = _render(tmp_path, "again", "--export", str(tmp_path / "frame"))
    assert r.returncode == 0, r.stderr
    first = {p.relative_to(exported / "frame"): p.read_bytes() for p in (exported / "frame").rglob("*") if p.is_file()}
    again = {p.relative_to(tmp_path / "frame"): p.read_bytes() for p in (tmp_path / "frame").rglob("*") if p.is_file()}
    assert first == again and len(first) == 4  # frame.json and the example's three meshes


def test_an_export_onto_a_file_is_refused_and_the_file_kept(tmp_path):
    there = tmp_path / "frame"
    there.write_text("keep me\n")
    r = _render(tmp_path, "out", "--export", str(there))
    assert r.returncode != 0 and "give --export a directory" in r.stderr, r.stderr
    assert there.read_text() == "keep me\n"


def test_the_schema_is_closed():
    from generator.runtime.frame_export import FrameExport, check_document, frame_document

    doc = frame_document(FrameExport("s", (4, 4), "srgb", (0, 0, 0, 1), [0, 0, 1], [0.0] * 16), [])
    check_document(doc)
    with pytest.raises(ValueError, match="extra"):
        check_document({**doc, "extra": 1})
    with pytest.raises(ValueError, match="/camera"):
        check_document({**doc, "camera": {"eye": [0, 0, 1]}})


def test_an_export_the_schema_refuses_writes_nothing_and_a_new_one_drops_stale_meshes(tmp_path):
    from generator.runtime.frame_export import FrameExport, write_export
    from generator.runtime.placement import make_mesh

    def export(attachment, mesh):
        return FrameExport("s", (4, 4), attachment, (0, 0, 0, 1), [0, 0, 1], [0.0] * 16, meshes=[("m", mesh)],
                           objects=[{"name": "o", "mesh": 0, "model": [0.0] * 16, "mirrored": False}], draw_order=[0])
    write_export(tmp_path, export("srgb", make_mesh("plane")))
    before = {p: p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()}
    with pytest.raises(ValueError, match="color_attachment"):
        write_export(tmp_path, export("bogus", make_mesh("box")))
    assert {p: p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()} == before
    write_export(tmp_path, export("srgb", make_mesh("box")))
    doc = json.loads((tmp_path / "frame.json").read_text())
    assert sorted(p.name for p in (tmp_path / "meshes").iterdir()) == [Path(doc["meshes"][0]["path"]).name]
