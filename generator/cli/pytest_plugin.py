"""pytest plugin: one test per permutation × platform of a scene (compile + validate), for an engine's CI.

    pytest --shadermatrix-scene scenes/example.toml [--shadermatrix-platforms LIST] [--shadermatrix-bricks DIR]
           [--shadermatrix-golden DIR]

Registered through the `pytest11` entry point of the package, so installing
shadermatrix is enough. Each test is named `<scene>::<hash>-<platform>` (vulkan, d3d12,
gl, webgpu: what each validates is assemble/checks.py's table); a failure reads as the
brick line that caused it. With --shadermatrix-golden, a test also fails when the
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


class SceneCollector(pytest.Collector):
    def __init__(self, *, scene_path, **kw):
        super().__init__(**kw)
        self.scene_path = scene_path
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
        from ..lang.errors import UserError
        from ..library.bricks import load_library
        from ..scene.load import load_scene
        from .commands.check import selection
        opt = self.config.getoption
        try:  # a bad scene, brick or option is the run's usage error, one line, not an INTERNALERROR
            plats, langs = selection(opt("--shadermatrix-platforms"), opt("--shadermatrix-languages"),
                                     "--shadermatrix-")
            lib = load_library(opt("--shadermatrix-bricks"))
            scene = load_scene(self.scene_path, lib)
        except (UserError, ValueError) as e:
            raise pytest.UsageError(f"--shadermatrix-scene {self.scene_path}: {e}") from None
        for c in checks(scene, plats, langs):
            yield PermutationItem.from_parent(self, name=c.id, scene=scene, lib=lib, check=c,
                                              golden=opt("--shadermatrix-golden"))


def pytest_configure(config):
    config.addinivalue_line("markers", "shadermatrix: a permutation × platform compile check of a scene")


def pytest_collection_modifyitems(session, config, items):
    seen = set()
    for path in config.getoption("--shadermatrix-scene"):
        p = Path(path).resolve()
        if p in seen:
            continue
        seen.add(p)
        try:  # the node id names the scene by its path from the rootdir: two scene.toml files stay apart
            name = p.relative_to(config.rootpath).as_posix()
        except ValueError:
            name = p.as_posix()
        items.extend(SceneCollector.from_parent(session, name=name, path=p, scene_path=p).collect())
