"""pytest plugin: one test per permutation × language of a scene (compile + validate), for an engine's CI.

    pytest --shadermatrix-scene scenes/example.toml [--shadermatrix-bricks DIR] [--shadermatrix-golden DIR]

Registered through the `pytest11` entry point of the package, so installing
shadermatrix is enough. Each test is named `<scene>::<hash>-<language>`; a failure
reads as the brick line that caused it. With --shadermatrix-golden, a test also
fails when the permutation's emitted sources drift from the golden directory
(`shadermatrix check --golden DIR --update-golden` writes it).
"""
from __future__ import annotations

from pathlib import Path

import pytest


def pytest_addoption(parser):
    group = parser.getgroup("shadermatrix")
    group.addoption("--shadermatrix-scene", action="append", default=[], metavar="SCENE",
                    help="a scene file: one test per permutation × language (repeatable)")
    group.addoption("--shadermatrix-bricks", action="append", default=[], metavar="DIR",
                    help="an extra brick directory (repeatable)")
    group.addoption("--shadermatrix-golden", metavar="DIR", help="golden sources to compare with")
    group.addoption("--shadermatrix-languages", metavar="LIST",
                    help="comma-separated languages, from glsl, hlsl, wgsl (default all)")


class ShaderCheckFailed(Exception):
    pass


class PermutationItem(pytest.Item):
    def __init__(self, *, scene, lib, check, golden, **kw):
        super().__init__(**kw)
        self.scene, self.lib, self.check, self.golden = scene, lib, check, golden
        self.add_marker("shadermatrix")

    def runtest(self):
        from ..build.checks import default_store, golden_diff, run_check
        errors, sources = run_check(self.scene, self.lib, self.check, default_store())
        if errors:
            raise ShaderCheckFailed("\n".join(errors))
        if self.golden:
            diff = golden_diff(Path(self.golden), sources)
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

    def collect(self):
        from ..build.checks import checks
        from ..lang.errors import UserError
        from ..library.bricks import load_library
        from ..matrix.scene import load_scene
        from ..targets import LANGUAGES, parse_languages
        opt = self.config.getoption
        try:  # a bad scene, brick or option is the run's usage error, one line, not an INTERNALERROR
            langs = parse_languages(opt("--shadermatrix-languages")) if opt("--shadermatrix-languages") \
                else list(LANGUAGES)
            lib = load_library(opt("--shadermatrix-bricks"))
            scene = load_scene(self.scene_path, lib)
        except (UserError, ValueError) as e:
            raise pytest.UsageError(f"--shadermatrix-scene {self.scene_path}: {e}") from None
        for c in checks(scene, langs):
            yield PermutationItem.from_parent(self, name=c.id, scene=scene, lib=lib, check=c,
                                              golden=opt("--shadermatrix-golden"))


def pytest_configure(config):
    config.addinivalue_line("markers", "shadermatrix: a permutation × language compile check of a scene")


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
