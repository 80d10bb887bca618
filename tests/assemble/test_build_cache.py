"""The content-addressed compile cache: hits skip the compilers, output never changes, damage is rebuilt."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "scenes" / "example.toml"


def _tree(root: Path) -> dict[str, bytes]:
    return {str(p.relative_to(root)): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}


@pytest.fixture(scope="module")
def lib_scene():
    from generator.library.bricks import load_library
    from generator.scene.load import load_scene
    lib = load_library()
    return lib, load_scene(EXAMPLE, lib)


@pytest.mark.toolchain
def test_a_rebuild_from_the_cache_compiles_nothing_and_writes_the_same_bytes(lib_scene, tmp_path):
    from generator.assemble import BuildContext, build
    from generator.io import Store

    lib, scene = lib_scene
    store = Store(tmp_path / "cache")
    cold = build(scene, tmp_path / "a", BuildContext(lib, store=store))
    assert cold.ok and cold.compile.compiled == cold.compile.distinct - cold.compile.cached
    # identical shaders are compiled once: the vertex shaders differ only in their provenance header
    assert cold.compile.distinct < cold.compile.jobs
    warm = build(scene, tmp_path / "b", BuildContext(lib, store=Store(tmp_path / "cache")))
    assert warm.ok and warm.compile.compiled == 0 and warm.compile.cached == warm.compile.distinct
    plain = build(scene, tmp_path / "c", BuildContext(lib))  # no cache at all
    assert plain.ok
    assert _tree(tmp_path / "a") == _tree(tmp_path / "b") == _tree(tmp_path / "c")


@pytest.mark.toolchain
def test_a_damaged_entry_is_detected_dropped_and_rebuilt_never_served(lib_scene, tmp_path):
    from generator.assemble import BuildContext, build
    from generator.io import Store

    lib, scene = lib_scene
    build(scene, tmp_path / "a", BuildContext(lib, store=Store(tmp_path / "cache")))
    entries = sorted((tmp_path / "cache" / "compile-v1").glob("*/*"))
    victim = entries[len(entries) // 2]
    data = bytearray(victim.read_bytes())
    data[len(data) // 2] ^= 0xFF  # one flipped byte
    victim.write_bytes(bytes(data))
    store = Store(tmp_path / "cache")
    again = build(scene, tmp_path / "b", BuildContext(lib, store=store))
    assert again.ok and store.corrupt == 1 and again.compile.compiled == 1
    assert _tree(tmp_path / "a") == _tree(tmp_path / "b")
    assert victim.read_bytes() != bytes(data)  # replaced by the rebuilt entry


def test_every_input_of_a_compile_is_in_its_key(monkeypatch):
    import generator.toolchain as tc

    monkeypatch.setattr(tc, "tool_versions", lambda: {"glslc": "1", "naga": "30.0.1"})
    job = tc.CompileJob("k.frag.glsl", "glsl", "frag", "#version 450\n// header\nvoid main() {}\n")
    base = tc.cache_key(job)
    assert tc.cache_key(tc.CompileJob("other", "glsl", "frag", "#version 450\n// other header\nvoid main() {}\n")) == base
    different = [tc.CompileJob("k", "glsl", "frag", "#version 450\nvoid main() { }\n"),
                 tc.CompileJob("k", "hlsl", "frag", job.source), tc.CompileJob("k", "glsl", "vert", job.source),
                 tc.CompileJob("k", "glsl", "frag", job.source, entry="other"),
                 tc.CompileJob("k", "glsl", "frag", job.source, overrides=(("0", 1),))]
    assert len({tc.cache_key(j) for j in different} | {base}) == len(different) + 1
    assert tc.cache_key(job, optimize=False) != base and tc.cache_key(job, validate=False) != base
    monkeypatch.setattr(tc, "tool_versions", lambda: {"glslc": "2", "naga": "30.0.1"})  # a tool upgrade
    assert tc.cache_key(job) != base


def test_the_store_verifies_what_it_serves(tmp_path):
    from generator.io import Store
    s = Store(tmp_path)
    s.put("ns", "ab" * 32, b"payload")
    assert s.get("ns", "ab" * 32) == b"payload" and s.hits == 1
    path = tmp_path / "ns" / "ab" / ("ab" * 32)
    path.write_bytes(path.read_bytes()[:-1])  # truncated
    assert s.get("ns", "ab" * 32) is None and s.corrupt == 1 and not path.exists()
    assert s.get("ns", "cd" * 32) is None and s.misses == 2


@pytest.mark.toolchain
def test_cache_stats_and_clear(tmp_path):
    def cli(*args):
        return subprocess.run([sys.executable, "-m", "generator.cli", *map(str, args)], cwd=REPO,
                              capture_output=True, text=True, timeout=300)
    cache = tmp_path / "cache"
    r = cli("build", EXAMPLE, "--out", tmp_path / "out", "--cache-dir", cache)
    assert r.returncode == 0, r.stderr
    import re
    assert int(re.search(r"(\d+) compiled;", r.stdout)[1]) > 0 and "merged" in r.stdout
    distinct = int(re.search(r"(\d+) distinct", r.stdout)[1])
    r = cli("build", EXAMPLE, "--out", tmp_path / "fresh", "--cache-dir", cache)  # a new tree: the cache serves all
    assert f" {distinct} from the cache, 0 compiled;" in r.stdout, r.stdout
    stats = cli("cache", "stats", "--cache-dir", cache)
    assert stats.returncode == 0 and "compile-v1" in stats.stdout and "cost-v2" in stats.stdout
    cleared = cli("cache", "clear", "--cache-dir", cache)
    assert cleared.returncode == 0 and "entries removed" in cleared.stdout
    assert "0 entries" in cli("cache", "stats", "--cache-dir", cache).stdout
    r = cli("build", EXAMPLE, "--out", tmp_path / "out", "--no-cache", "--cache-dir", cache)
    assert r.returncode == 2 and "contradict" in r.stderr
