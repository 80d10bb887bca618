"""A brick that does not load fails only what reaches it (library/bricks.py, load_library(strict=False)).

The library keeps its located error and leaves it out; resolving a scene that names it (a BRDF term, a slot
filler, a light type, the output) raises that error, at the brick's line; a scene that does not name it loads.
The strict loader (the default) still fails on the first such brick.
"""
from __future__ import annotations

from pathlib import Path

import pytest

from generator.lang import SourceError
from generator.library.bricks import load_library
from generator.scene.load import load_scene

REPO = Path(__file__).resolve().parents[2]
SCENE = """[scene]
name = "tiny"
output = "{output}"

[materials.red]
brdf = "{brdf}"
params = {{ rho_d = [0.8, 0.05, 0.05] }}

[lights.lamp]
type = "point"
params = {{ position = [1.0, 2.5, 0.0], color = [4.0, 3.2, 2.0] }}

[light_sets]
room = ["lamp"]

[[objects]]
name = "box"
material = "red"
lights = "room"
"""


@pytest.fixture
def engine(tmp_path) -> Path:
    """An engine's brick directory: a good output brick (`tinted`), one with a syntax error in its code at line 9
    (`broken`, an output brick) and one whose BRICK names no kind (`kindless`)."""
    d = tmp_path / "engine"
    d.mkdir()
    good = (REPO / "bricks" / "output" / "linear.py").read_text()
    (d / "tinted.py").write_text(good)
    lines = good.splitlines()
    at = next(i for i, ln in enumerate(lines) if ln.startswith("def "))
    lines[at] = lines[at].replace("def ", "def def ", 1)
    (d / "broken.py").write_text("\n".join(lines) + "\n")
    (d / "kindless.py").write_text('"""A brick without a kind."""\nBRICK = {"cite": "nobody"}\n')
    return d


def _scene(tmp_path: Path, output: str = "tinted", brdf: str = "lambert") -> Path:
    p = tmp_path / "scene.toml"
    p.write_text(SCENE.format(output=output, brdf=brdf))
    return p


def test_the_strict_loader_fails_on_the_first_broken_brick(engine):
    with pytest.raises(SourceError, match=r"^engine/broken\.py:\d+:\d+: "):
        load_library([engine])


def test_unreached_broken_bricks_are_kept_as_errors_and_a_scene_without_them_loads(engine, tmp_path):
    lib = load_library([engine], strict=False)
    assert [Path(e.path).name for e in lib.errors] == ["broken.py", "kindless.py"]
    assert all(e.line >= 1 and e.col >= 1 for e in lib.errors)
    assert lib.get("output", "tinted") is not None and lib.get("output", "nothing_of_that_name") is None
    scene = load_scene(_scene(tmp_path), lib)
    assert len(scene.permutations) == 1


@pytest.mark.parametrize("where", ["output", "brdf"])
def test_a_scene_that_reaches_a_broken_brick_fails_with_the_bricks_own_located_error(engine, tmp_path, where):
    lib = load_library([engine], strict=False)
    strict = None
    try:
        load_library([engine])
    except SourceError as e:
        strict = str(e)
    scene = _scene(tmp_path, output="broken") if where == "output" else _scene(tmp_path, brdf="lambert+broken")
    with pytest.raises(SourceError) as got:
        load_scene(scene, lib)
    assert str(got.value) == strict  # what the strict loader said of it, at the brick's line
