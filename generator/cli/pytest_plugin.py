"""pytest plugin: one test per permutation × platform of a scene (compile + validate), for an engine's CI.

    pytest --shadermatrix-scene scenes/example.toml [--shadermatrix-platforms LIST] [--shadermatrix-bricks DIR]
           [--shadermatrix-golden DIR]

Registered through the `pytest11` entry point of the package, so installing
shadermatrix is enough. A scene is a file pytest collects (a SceneFile), its tests the
items under it, named `<hash>-<platform>` (vulkan, d3d12, gl, webgpu: what each validates
is assemble/checks.py's table): the node id `scenes/example.toml::<hash>-vulkan` runs one
again, alone (`--shadermatrix-scene` not needed then), and `--lf` and `-k` work as on any
test. Given scenes and no paths, a run collects the scenes alone, not the tests of the
directory it runs in; `pytest tests/ --shadermatrix-scene S` runs both. A failure reads as
the brick line that caused it. With --shadermatrix-golden, a test also fails when the
permutation's emitted sources drift from the golden directory
(`shadermatrix check --golden DIR --update-golden` writes it). A gl test whose GLSL ES
3.10 does not validate passes, with the note in its report section and
`user_properties` (a JUnit XML property), as `build` ships GLSL 4.50 core alone for it.

The checks of a scene's collected tests are compiled in one batch when the first of
them runs (identical shaders once, the tool processes in parallel, as `shadermatrix
check` does); each test then reports its own part.
"""
from __future__ import annotations

from pathlib import Path

import pytest


def pytest_addoption(parser):
    group = parser.getgroup("shadermatrix")
    group.addoption("--shadermatrix-scene", action="append", default=[], metavar="SCENE",
                    help="a scene file: one test per permutation × platform (repeatable)")
    group.addoption("--shadermatrix-bricks", action="append", default=[], metavar="DIR",
                    help="an extra brick directory (repeatable)")
    group.addoption("--shadermatrix-golden", metavar="DIR", help="golden sources to compare with")
    group.addoption("--shadermatrix-platforms", metavar="LIST",
                    help="comma-separated platforms, from vulkan, d3d12, gl, webgpu (default all)")
    group.addoption("--shadermatrix-languages", metavar="LIST",
                    help="comma-separated languages, from glsl, hlsl, wgsl (default all): the platforms made "
                         "from them (vulkan: from any, compiling only these)")


class ShaderCheckFailed(Exception):
    pass


class PermutationItem(pytest.Item):
    def __init__(self, *, scene, lib, check, golden, **kw):
        super().__init__(**kw)
        self.scene, self.lib, self.check, self.golden = scene, lib, check, golden
        self.add_marker("shadermatrix")

    def runtest(self):
        from ..assemble.checks import check_notes, golden_diff
        res = self.parent.outcome(self)
        notes = [*res.notes, *check_notes([self.check.platform])]
        for note in filter(None, notes):
            self.user_properties.append(("shadermatrix-note", note))
            self.add_report_section("call", "shadermatrix", note)
        if res.errors:
            raise ShaderCheckFailed("\n".join(res.errors))
        if self.golden:
            diff = golden_diff(Path(self.golden), res.sources)
            if diff:
                raise ShaderCheckFailed("emitted sources drift from the golden ones:\n" + "".join(diff))

    def repr_failure(self, excinfo):
        from ..lang.errors import UserError
        if isinstance(excinfo.value, (ShaderCheckFailed, UserError)):  # a missing tool too: one message, no trace
            return f"{self.check.id} ({', '.join(self.check.objects)}):\n{excinfo.value}"
        return super().repr_failure(excinfo)

    def reportinfo(self):
        return self.path, None, f"{self.scene.name}::{self.check.id}"


class SceneFile(pytest.File):
    """A scene file as pytest collects it: its items are the scene's checks, so a node id
    (`scenes/example.toml::<hash>-<platform>`) names one and runs it again."""

    def __init__(self, **kw):
        super().__init__(**kw)
        self.outcomes: dict = {}  # check -> Outcome (or the batch's error), once a test of it has run

    def outcome(self, item):
        """The item's Outcome: every check of this scene the session runs is compiled in one batch, the first
        time one is asked for; an error of the batch (a missing tool: one line) fails each of its tests."""
        from ..assemble.checks import default_store, run_checks
        if item.check not in self.outcomes:
            mine = [i.check for i in self.session.items if isinstance(i, PermutationItem) and i.parent is self]
            todo = [c for c in mine if c not in self.outcomes] or [item.check]
            try:
                self.outcomes.update(zip(todo, run_checks(item.scene, item.lib, todo, default_store())))
            except Exception as e:  # noqa: BLE001 — raised again by each test of the batch, not retried
                self.outcomes.update((c, e) for c in todo)
        res = self.outcomes[item.check]
        if isinstance(res, Exception):
            raise res
        return res

    def collect(self):
        from ..assemble.checks import checks
        scene, lib, plats, langs = self.config.stash[_LOADED][self.path.resolve()]
        for c in checks(scene, plats, langs):
            yield PermutationItem.from_parent(self, name=c.id, scene=scene, lib=lib, check=c,
                                              golden=self.config.getoption("--shadermatrix-golden"))


_LOADED = pytest.StashKey[dict]()  # resolved scene path -> (Scene, Library, platforms, languages)


def pytest_configure(config):
    """Given scenes, the run collects them, and not the tests of the directory it runs in unless paths are named
    too (`pytest tests/ --shadermatrix-scene S` runs both); a scene under a named path is found there, and a
    scene named by a node id (`S::<hash>-vulkan`, with or without --shadermatrix-scene) runs only that test."""
    config.addinivalue_line("markers", "shadermatrix: a permutation × platform compile check of a scene")
    scenes = list(dict.fromkeys(Path(p).resolve() for p in config.getoption("--shadermatrix-scene")))
    named = config.args_source == pytest.Config.ArgsSource.ARGS
    given = [Path(a.split("::", 1)[0]).resolve() for a in config.args] if named else []
    if scenes:
        extra = [str(s) for s in scenes if not any(s == g or g in s.parents for g in given)]
        config.args = [*config.args, *extra] if named else extra
    on_line = [g for g in given if g not in scenes and _is_scene(g) and g.is_file()]
    if scenes or on_line:
        config.stash[_LOADED] = _load(config, scenes, on_line)


def _load(config, scenes, on_line) -> dict:
    """Every scene of the run loaded before collection: a bad scene, brick or option is the run's usage error
    (exit 4, one line), not a collection error or an INTERNALERROR."""
    from ..lang.errors import UserError
    from ..library.bricks import load_library
    from ..scene.load import load_scene
    from .commands.check import selection
    opt = config.getoption
    shown = {Path(p).resolve(): p for p in opt("--shadermatrix-scene")}
    path = (scenes or on_line)[0]
    try:
        plats, langs = selection(opt("--shadermatrix-platforms"), opt("--shadermatrix-languages"), "--shadermatrix-")
        lib = load_library(opt("--shadermatrix-bricks"))
        out = {}
        for path in [*scenes, *on_line]:
            out[path] = (load_scene(path, lib), lib, plats, langs)
    except (UserError, ValueError) as e:
        raise pytest.UsageError(f"--shadermatrix-scene {shown[path]}: {e}" if path in shown else f"{path}: {e}") \
            from None
    return out


def pytest_collect_file(file_path: Path, parent):
    """A scene the run loaded (given by --shadermatrix-scene, or named on the command line) is a SceneFile."""
    loaded = parent.config.stash.get(_LOADED, None)
    if loaded and file_path.resolve() in loaded:
        return SceneFile.from_parent(parent, path=file_path)
    return None


# scene/load.py's SCENE_SUFFIXES, spelled here: importing the scene loader takes ~0.4 s, and every pytest run on a
# machine with shadermatrix installed loads this plugin (tests/cli/test_pytest_plugin.py keeps the two equal)
SCENE_SUFFIXES = (".toml", ".gltf", ".glb")


def _is_scene(path: Path) -> bool:
    return path.name.lower().endswith(SCENE_SUFFIXES)
