"""The build as a rule of GNU Make, Ninja and CMake, driven by the real tools with the snippets of
docs/guide/build.md taken from the page (so the page cannot drift from what is tested).

Each build system, on a one-permutation scene whose output brick lives in a brick directory of copies here:
touching that brick reruns the build once and then nothing; touching a brick no permutation uses reruns nothing;
editing the scene, adding a brick file to the directory and a changed versions file each rerun it; and what
reads the manifest reruns only when the manifest changed (the build leaves an unchanged manifest's mtime alone).
The builds are counted by a wrapper that logs each `shadermatrix` command a rule ran. It runs a copy of the
generator taken when the module starts: the versions file holds the hash of the generator's code, and an edit
of the working tree during the test would rightly rerun the build.
"""
from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import require

REPO = Path(__file__).resolve().parents[2]
PAGE = REPO / "docs" / "guide" / "build.md"
pytestmark = pytest.mark.toolchain

SCENE = """[scene]
name = "tiny"
output = "tinted"
precision = "fp32"

[materials.red]
brdf = "lambert"
params = { rho_d = [0.8, 0.05, 0.05] }

[lights.lamp]
type = "point"
params = { position = [1.0, 2.5, 0.0], color = [4.0, 3.2, 2.0] }

[light_sets]
room = ["lamp"]

[[objects]]
name = "box"
material = "red"
lights = "room"
"""
FLAGS = "--bricks bricks --platform vulkan"  # and the module's compile cache (SHADERMATRIX_CACHE_DIR)


def snippet(lang: str) -> str:
    """The page's one ```<lang> block."""
    found = re.findall(rf"^```{lang}\n(.*?)^```$", PAGE.read_text(encoding="utf-8"), re.S | re.M)
    assert len(found) == 1, f"{PAGE.name} has {len(found)} ```{lang} blocks, the test runs one"
    return found[0]


@pytest.fixture(scope="module")
def snapshot(tmp_path_factory) -> Path:
    """This generator and its built-in bricks, copied: what the builds of this module run (their compile cache
    beside, warm after the first build)."""
    root = tmp_path_factory.mktemp("generator")
    for part in ("generator", "bricks"):
        shutil.copytree(REPO / part, root / part, ignore=shutil.ignore_patterns("bricks_data"))
    (root / "cache").mkdir()
    return root


class Project:
    """A folder with the scene, a brick directory of copies (the scene's output brick `tinted`, an unused `spare`
    and an unused `broken`, with a syntax error) and a `shadermatrix` that logs what it is asked to do."""

    def __init__(self, root: Path, generator: Path):
        self.root = root
        (root / "bricks").mkdir(parents=True)
        shutil.copy(REPO / "bricks" / "output" / "linear.py", root / "bricks" / "tinted.py")
        shutil.copy(REPO / "bricks" / "output" / "srgb.py", root / "bricks" / "spare.py")
        good = (root / "bricks" / "tinted.py").read_text()
        (root / "bricks" / "broken.py").write_text(good.replace("def ", "def def ", 1))  # a syntax error, unused
        (root / "scene.toml").write_text(SCENE)
        (root / "bin").mkdir()
        self.tool = root / "bin" / "shadermatrix"
        self.tool.write_text(f'#!/bin/sh\necho "$1" >> "$SHADERMATRIX_TEST_LOG"\nexec "{sys.executable}" -m generator.cli "$@"\n')
        self.tool.chmod(0o755)
        self.env = {k: v for k, v in os.environ.items() if not k.startswith("SHADERMATRIX_FORBID")}
        self.env["PYTHONPATH"] = str(generator)
        self.env["SHADERMATRIX_TEST_LOG"] = str(root / "log")
        self.env["SHADERMATRIX_CACHE_DIR"] = str(generator / "cache")

    def call(self, *cmd, cwd: Path | None = None) -> subprocess.CompletedProcess:
        return subprocess.run(list(map(str, cmd)), cwd=cwd or self.root, env=self.env, capture_output=True,
                              text=True, timeout=300)

    def run(self, *cmd, cwd: Path | None = None) -> str:
        r = self.call(*cmd, cwd=cwd)
        assert r.returncode == 0, f"{' '.join(map(str, cmd))}: exit {r.returncode}\n{r.stdout[-3000:]}\n{r.stderr[-3000:]}"
        return r.stdout + r.stderr

    def builds(self, invoke) -> int:
        """How many builds one invocation of the build system ran."""
        log = self.root / "log"
        before = log.read_text().split().count("build") if log.exists() else 0
        self.output = invoke()
        return log.read_text().split().count("build") - before


def _steps(p: Project, invoke, shaders: Path, downstream: Path | None = None, every: bool = True) -> None:
    """The cases of the module docstring, in order; `downstream`: a file a rule copies from the manifest. Not
    `every`: the brick touched (used, unused) and the versions file only."""
    def runs(why: str, n: int) -> None:
        assert p.builds(invoke) == n, f"{why}: the build did not run {n} times"

    runs("the first build", 1)
    warned = [line for line in p.output.splitlines() if line.startswith("warning:")]
    assert len(warned) == 1 and re.match(r"warning: bricks/broken\.py:\d+:\d+: .*no permutation of this scene uses "
                                         r"the brick", warned[0]), p.output  # an unused broken brick fails nothing
    assert (shaders / "manifest.json").is_file() and (shaders / ".shadermatrix-versions").is_file()
    copied = downstream.stat().st_mtime_ns if downstream else None
    manifest = (shaders / "manifest.json").stat().st_mtime_ns
    files = {f: f.stat().st_mtime_ns for f in shaders.rglob("*") if f.is_file()}
    os.utime(p.root / "bricks" / "tinted.py")  # a used brick, touched: its bytes are the same
    runs("a used brick touched", 1)
    # nothing changed: the manifest, every artifact and the build's records keep their mtimes
    assert {f: f.stat().st_mtime_ns for f in shaders.rglob("*") if f.is_file()} == files
    if downstream:
        assert downstream.stat().st_mtime_ns == copied, "what reads the manifest reran, and it had not changed"
    runs("nothing changed since", 0)
    os.utime(p.root / "bricks" / "spare.py")
    runs("an unused brick touched", 0)
    if every:
        _changes(p, runs, shaders, manifest, downstream, copied)
    (shaders / ".shadermatrix-versions").write_text("{}\n")  # as after an upgrade: the next check rewrites it
    runs("a changed versions file", 1)
    runs("nothing changed since", 0)


def _changes(p: Project, runs, shaders: Path, manifest: int, downstream: Path | None, copied: int | None) -> None:
    """The scene edited, then a brick file added."""
    scene = p.root / "scene.toml"
    scene.write_text(scene.read_text().replace("color = [4.0, 3.2, 2.0]", "color = [4.0, 3.2, 2.5]"))
    runs("the scene edited", 1)
    assert (shaders / "manifest.json").stat().st_mtime_ns != manifest  # a new light colour: new uploads
    if downstream:
        assert downstream.stat().st_mtime_ns != copied, "the manifest changed and what reads it did not rerun"
    shutil.copy(REPO / "bricks" / "output" / "sqrt_gamma.py", p.root / "bricks" / "added.py")
    runs("a brick file added", 1)


def _require(tool: str) -> None:
    require(shutil.which(tool) is not None, f"{tool} not found — run `make setup` (scripts/setup.sh pins it)")


def test_gnu_make_reruns_the_build_exactly_when_an_input_changed(tmp_path, snapshot):
    _require("make")
    p = Project(tmp_path, snapshot)
    (tmp_path / "Makefile").write_text(snippet("make") + "\nout/copied.json: out/shaders/manifest.json\n\tcp $< $@\n")
    variables = [f"SHADERMATRIX={p.tool}", "SCENE=scene.toml", "SHADERS=out/shaders", f"SHADERFLAGS={FLAGS}"]
    _steps(p, lambda: p.run("make", "-s", *variables, "shaders", "out/copied.json"), tmp_path / "out" / "shaders",
           tmp_path / "out" / "copied.json")
    text = (tmp_path / "out" / "shaders.d").read_text()
    assert text.startswith("out/shaders.stamp: \\\n")  # the stamp's rule, named as Make names the target


def test_ninja_reruns_the_build_exactly_when_an_input_changed(tmp_path, snapshot):
    _require("ninja")
    p = Project(tmp_path, snapshot)
    text = snippet("ninja")
    values = {"shadermatrix": str(p.tool), "scene": "scene.toml", "shaders": "out/shaders", "shaderflags": FLAGS}
    for name, value in values.items():
        text, n = re.subn(rf"^{name} =.*$", f"{name} = {value}", text, flags=re.M)
        assert n == 1, f"the ninja snippet sets no variable '{name}'"
    (tmp_path / "build.ninja").write_text(text + "rule copy\n  command = cp $in $out\n"
                                          "build out/copied.json: copy out/shaders/manifest.json\n")
    _steps(p, lambda: p.run("ninja", "out/shaders.stamp", "out/copied.json"), tmp_path / "out" / "shaders",
           tmp_path / "out" / "copied.json")
    deps = p.run("ninja", "-t", "deps", "out/shaders.stamp")
    assert "bricks/tinted.py" in deps and "bricks/spare.py" not in deps  # the depfile, as Ninja read it


@pytest.mark.parametrize("generator,every", [("Ninja", False), pytest.param("Ninja", True, marks=pytest.mark.slow),
                                             pytest.param("Unix Makefiles", True, marks=pytest.mark.slow)])
def test_cmake_reruns_the_build_exactly_when_an_input_changed(tmp_path, generator, every, snapshot):
    """Every case with the Ninja and the Makefile generators in the slow tier; in the default one (each build costs
    a second here) the bricks touched and the versions file, with Ninja."""
    _require("cmake")
    _require("ninja" if generator == "Ninja" else "make")
    p = Project(tmp_path, snapshot)
    (tmp_path / "CMakeLists.txt").write_text(snippet("cmake"))
    flags = f"--bricks {tmp_path / 'bricks'} --platform vulkan"
    p.run("cmake", "-S", ".", "-B", "build", "-G", generator, f"-DSHADERMATRIX={p.tool}",
          f"-DSCENE={tmp_path / 'scene.toml'}", f"-DSHADERFLAGS={flags}")
    _steps(p, lambda: p.run("cmake", "--build", "build"), tmp_path / "build" / "shaders", every=every)


def test_the_depfile_escapes_spaces_dollars_hashes_and_colons_as_make_and_ninja_read_them(tmp_path, snapshot):
    """A build of a scene and bricks whose folder is named `a b$c#d:e`: Make and Ninja read its depfile back as
    those files (Make reruns its rule once the used brick is touched; Ninja's deps log names the files)."""
    _require("make")
    _require("ninja")
    from generator.assemble.depfile import escape
    from generator.lang.errors import UserError
    p = Project(tmp_path / "a b$c#d:e", snapshot)
    p.run(p.tool, "build", p.root / "scene.toml", "--out", tmp_path / "out", "--bricks", p.root / "bricks",
          "--platform", "vulkan", "--stamp", "x", "--depfile", tmp_path / "x.d", cwd=tmp_path)
    text = (tmp_path / "x.d").read_text()
    assert "a\\ b$$c\\#d\\:e/bricks/tinted.py \\\n" in text  # relative to the working directory
    (tmp_path / "Makefile").write_text("x:\n\ttouch $@\n-include x.d\n")

    def make() -> str:
        r = subprocess.run(["make", "x"], cwd=tmp_path, capture_output=True, text=True, timeout=60)
        assert r.returncode == 0, r.stdout + r.stderr
        return r.stdout

    assert "up to date" in make()
    os.utime(p.root / "bricks" / "tinted.py")
    assert "touch x" in make() and "up to date" in make()
    (tmp_path / "build.ninja").write_text("rule w\n  command = touch $out\n  depfile = x.d\n  deps = gcc\n"
                                          "build x: w\n")
    r = subprocess.run(["ninja", "x"], cwd=tmp_path, capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stdout + r.stderr
    deps = subprocess.run(["ninja", "-t", "deps", "x"], cwd=tmp_path, capture_output=True, text=True).stdout
    assert "    a b$c#d:e/bricks/tinted.py\n" in deps and "    a b$c#d:e/scene.toml\n" in deps, deps
    for bad in ("a\nb", "a\\ b", "a\\"):
        with pytest.raises(UserError, match="--depfile: the path"):
            escape(bad)
    assert escape("a\\b") == "a\\b"  # a backslash before an ordinary character is itself to both tools


def test_a_broken_brick_fails_the_builds_that_reach_it_and_a_failed_build_writes_no_stamp(tmp_path, snapshot):
    p = Project(tmp_path, snapshot)
    build = [p.tool, "build", "scene.toml", "--out", "out", "--bricks", "bricks", "--platform", "vulkan", "-q",
             "--stamp", "out.stamp"]
    check = p.call(p.tool, "bricks", "--check", "--bricks", "bricks")
    assert check.returncode == 1 and re.fullmatch(r"error: bricks/broken\.py:\d+:\d+: .*\n", check.stderr), check.stderr
    assert p.call(p.tool, "bricks", "--check").returncode == 0  # the built-in bricks
    scene = p.root / "scene.toml"
    scene.write_text(SCENE.replace('output = "tinted"', 'output = "broken"'))
    r = p.call(*build)
    assert r.returncode == 1 and re.search(r"^error: bricks/broken\.py:\d+:\d+: ", r.stderr, re.M), r.stderr
    assert not (p.root / "out.stamp").exists()
    scene.write_text(SCENE)  # a build that fails in the compiler (naga refuses a division by zero)
    tinted = p.root / "bricks" / "tinted.py"
    tinted.write_text(tinted.read_text().replace("return vec4(color, 1.0)", "k = 1\n    q = k / 0\n"
                                                 "    return vec4(color * float(q), 1.0)"))
    r = p.call(*build)
    assert r.returncode == 1 and "Division by zero" in r.stderr, r.stderr
    assert not (p.root / "out.stamp").exists()
