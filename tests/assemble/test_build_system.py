"""The build as a build system calls it: depfiles, one build at a time, kill -9 loses nothing,
failures keep the last good outputs, removed permutations leave the tree, no machine paths in outputs."""
from __future__ import annotations

import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "scenes" / "example.toml"
pytestmark = pytest.mark.toolchain


def _cli(*args, cwd=REPO, **kw):
    return subprocess.run([sys.executable, "-m", "generator.cli", *map(str, args)], cwd=cwd, capture_output=True,
                          text=True, timeout=600, **kw)


def _consistent(out: Path, exact: bool = True) -> dict:
    """The manifest, after checking that every file it names is there and intact, and (exact) that the language
    directories hold nothing else. An interrupted build may leave new, not yet named files: never a named one
    changed or missing."""
    import hashlib
    from generator.assemble.outputs import named
    m = json.loads((out / "manifest.json").read_text())
    files = {str(p.relative_to(out)) for p in out.rglob("*") if p.is_file() and p.parent != out}  # the trees
    assert named(m) <= files, sorted(named(m) - files)[:5]
    if exact:
        assert files == named(m), sorted(files - named(m))[:5]
    for e in [*m["permutations"], m["ubershader"]]:
        for stages in e.get("languages", {}).values():
            for item in stages.values():
                assert hashlib.sha256((out / item["spirv"]).read_bytes()).hexdigest() == item["spirv_sha256"]
    return m


def test_the_depfile_lists_the_scene_the_bricks_its_permutations_read_and_every_template_read(tmp_path):
    dep = tmp_path / "out.d"
    r = _cli("build", EXAMPLE, "--out", tmp_path / "out", "--depfile", dep)
    assert r.returncode == 0, r.stderr
    text = dep.read_text()
    rule, _, phony = text.partition("\n\n")  # the rule, then an empty rule per dependency (gcc's -MP)
    target, _, rest = rule.partition(":")
    assert target == str(tmp_path / "out" / "manifest.json")
    deps = [d.strip().rstrip("\\").strip() for d in rest.splitlines() if d.strip().rstrip("\\").strip()]
    assert phony.split() == [f"{d}:" for d in deps]
    assert "scenes/example.toml" in deps  # relative to the working directory, as the build system sees it
    m = json.loads((tmp_path / "out" / "manifest.json").read_text())
    read = {b for e in m["permutations"] for b in e["bricks"]}  # what the composed permutations read
    assert {d for d in deps if d.endswith(".py")} == read
    unused = {str(p.relative_to(REPO)) for p in (REPO / "bricks").rglob("*.py")} - read
    assert unused and not unused & set(deps)  # editing a brick no permutation uses reruns nothing
    folders = {str(p.relative_to(REPO)) for p in [REPO / "bricks", *(REPO / "bricks").rglob("*")]
               if p.is_dir() and p.name != "__pycache__"}
    assert folders <= set(deps)  # a brick added to one is a change
    assert str(tmp_path / "out" / ".shadermatrix-versions") in deps
    templates = {d for d in deps if d.endswith(".j2")}
    for lang in ("glsl", "hlsl", "wgsl"):  # what was composed with: vertex, fragment, the ubershader, macros
        assert {f"generator/backends/{lang}/templates/{stage}.{lang}.j2"
                for stage in ("vertex", "fragment", "macros")} <= templates
    assert all(Path(REPO / d).exists() for d in deps)
    again = _cli("build", EXAMPLE, "--out", tmp_path / "out", "--depfile", tmp_path / "again.d")
    assert "up to date" in again.stdout and (tmp_path / "again.d").read_text() == text  # composed nothing, same deps


def test_a_second_build_into_the_same_directory_waits_for_the_first(tmp_path):
    from generator.assemble.outputs import locked
    out = tmp_path / "out"
    with locked(out):  # a build holds the directory ...
        p = subprocess.Popen([sys.executable, "-m", "generator.cli", "build", str(EXAMPLE), "--out", str(out)],
                             cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        deadline = time.time() + 60
        while not (out / "manifest.json").exists() and time.time() < deadline and p.poll() is None:
            time.sleep(0.2)
            if time.time() > deadline - 55:
                break
        assert not (out / "manifest.json").exists() and p.poll() is None  # ... and the other one waits
    stdout, stderr = p.communicate(timeout=300)
    assert p.returncode == 0, stderr
    assert "waiting: another build into" in stderr
    _consistent(out)


def test_kill_9_at_any_moment_loses_nothing_and_the_next_build_cleans_up(tmp_path):
    out, cache = tmp_path / "out", tmp_path / "cache"
    r = _cli("build", EXAMPLE, "--out", out, "--cache-dir", cache)
    assert r.returncode == 0
    before = _consistent(out)
    engine = tmp_path / "engine"
    engine.mkdir()
    # an engine brick changes (a new output brick used by every permutation): every file is rebuilt
    shutil.copy(REPO / "bricks" / "output" / "linear.py", engine / "tinted.py")
    text = (engine / "tinted.py").read_text()
    assert "return vec4(color, 1.0)" in text
    (engine / "tinted.py").write_text(text.replace("return vec4(color, 1.0)", "return vec4(color * 0.5, 1.0)"))
    scene = tmp_path / "scene.toml"
    scene.write_text(EXAMPLE.read_text().replace('output = "linear"', 'output = "tinted"'))
    t0 = time.perf_counter()  # how long the rebuild takes here, so that the kills land inside it
    assert _cli("build", scene, "--out", tmp_path / "timing", "--bricks", engine, "--no-cache").returncode == 0
    took = time.perf_counter() - t0
    landed = 0
    for delay in (took * f for f in (0.35, 0.5, 0.6, 0.7, 0.8, 0.9)):
        # no cache: every shader is compiled, so the build is still running when the signal comes
        p = subprocess.Popen([sys.executable, "-m", "generator.cli", "build", str(scene), "--out", str(out),
                              "--bricks", str(engine), "--no-cache"], cwd=REPO,
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        time.sleep(delay)
        landed += p.poll() is None
        p.send_signal(signal.SIGKILL)
        p.wait()
        _consistent(out, exact=False)  # whatever the moment: the manifest (old or new) and the files it names agree
    assert landed >= 3, f"only {landed} of the kills found the build running (a build takes {took:.2f} s)"
    from generator.assemble.outputs import STALE_S
    _orphans_done()
    for d in Path(tempfile.gettempdir()).glob("shadermatrix-*"):  # let the killed builds' temp dirs be old
        old = time.time() - STALE_S - 1
        os.utime(d, (old, old))
    r = _cli("build", scene, "--out", out, "--bricks", engine, "--cache-dir", cache)
    assert r.returncode == 0, r.stderr
    m = _consistent(out)
    assert m["permutations"][0]["input_key"] != before["permutations"][0]["input_key"]
    assert all(p["status"] == "ok" for p in m["permutations"])
    assert not list(out.rglob("*.tmp"))
    from generator.assemble.outputs import TEMP_DIR, _alive
    left = [d for d in Path(tempfile.gettempdir()).glob("shadermatrix-*")
            if (m := TEMP_DIR.match(d.name)) and not _alive(int(m[1]))]
    assert left == []  # what the killed builds left in the temp dir went with the next build


def _orphans_done(bound_s: float = 60.0) -> None:
    """Wait until no compiler a killed build started is still running: an orphaned glslc or naga goes on writing
    into its temp dir after the build is gone, which makes the dir new again (and not a leftover yet)."""
    end = time.monotonic() + bound_s
    while time.monotonic() < end:
        running = []
        for p in Path("/proc").glob("[0-9]*"):  # the tools run with the build's temp dir as their cwd
            try:
                if Path(os.readlink(p / "cwd")).name.startswith("shadermatrix-"):
                    running.append(p.name)
            except OSError:
                continue
        if not running:
            return
        time.sleep(0.2)


def test_a_failing_permutation_keeps_its_last_good_outputs_marked_stale(tmp_path):
    engine = tmp_path / "engine"
    engine.mkdir()
    good = (REPO / "bricks" / "output" / "linear.py").read_text()
    (engine / "tinted.py").write_text(good)
    scene = tmp_path / "scene.toml"
    scene.write_text(EXAMPLE.read_text().replace('output = "linear"', 'output = "tinted"'))
    out = tmp_path / "out"
    assert _cli("build", scene, "--out", out, "--bricks", engine).returncode == 0
    first = _consistent(out)
    # an edit that type-checks but that naga refuses (division by a constant zero), so every permutation fails
    assert "return vec4(color, 1.0)" in good
    (engine / "tinted.py").write_text(good.replace("return vec4(color, 1.0)", "k = 1\n    q = k / 0\n"
                                                   "    return vec4(color * float(q), 1.0)"))
    r = _cli("build", scene, "--out", out, "--bricks", engine)
    assert r.returncode == 1 and "Division by zero" in r.stderr
    # every failure is located at the scene position that asks for it: its first object's material key
    # (the ubershader's at [scene]), then the brick line the compiler refused
    heads = [line for line in r.stderr.splitlines() if line.startswith("error: ")]
    text = scene.read_text().splitlines()
    assert len(heads) == len(first["permutations"]) + 1
    for line in heads:
        m = re.match(rf"error: {re.escape(str(scene))}:(\d+):1: (permutation \w+ \(material '(\w+)'|the scene's "
                     r"ubershader).* does not build — fix the errors below \(its last good outputs stay", line)
        assert m, line
        assert text[int(m[1]) - 1] == (f'material = "{m[3]}"' if m[3] else "[scene]")
    assert re.search(r"^  engine/tinted\.py:\d+:\d+: error: .*Division by zero", r.stderr, re.M)
    m = _consistent(out)  # the last good set, whole
    for old, new in zip(first["permutations"], m["permutations"]):
        assert new["status"] == "stale" and new["errors"]
        assert new["languages"] == old["languages"] and new["input_key"] == old["input_key"]
        assert set(new["failed_sources"]) == {"wgsl.frag"}
    (engine / "tinted.py").write_text(good)  # fixed: the next build is the first one's again
    assert _cli("build", scene, "--out", out, "--bricks", engine).returncode == 0
    assert _consistent(out)["permutations"] == first["permutations"]


def test_permutations_that_leave_the_scene_leave_the_tree(tmp_path):
    out = tmp_path / "out"
    assert _cli("build", EXAMPLE, "--out", out).returncode == 0
    first = {e["hash"] for e in _consistent(out)["permutations"]}
    n = len(first)
    fewer = tmp_path / "fewer.toml"
    text = EXAMPLE.read_text()
    fewer.write_text(text[:text.index("[[objects]]")] + '[[objects]]\nname = "only"\nmaterial = "red_plastic"\n'
                     'lights = "indoor"\n')
    assert _cli("build", fewer, "--out", out, "--keep-removed").returncode == 0  # kept, and listed as removed
    m = _consistent(out)
    assert len(m["permutations"]) == 1
    assert {e["hash"] for e in m["removed"]} == first - {m["permutations"][0]["hash"]}
    assert all(e["status"] == "removed" for e in m["removed"])
    assert _cli("build", fewer, "--out", out).returncode == 0
    m = _consistent(out)
    assert len(m["permutations"]) == 1 < n and "removed" not in m


def test_moving_an_engine_brick_directory_changes_no_output_and_no_output_names_this_machine(tmp_path):
    trees = []
    for where in ("a/deep/place", "elsewhere"):
        engine = tmp_path / where / "engine_bricks"
        engine.mkdir(parents=True)
        shutil.copy(REPO / "bricks" / "output" / "linear.py", engine / "tinted.py")
        scene = tmp_path / where / "scene.toml"
        scene.write_text(EXAMPLE.read_text().replace('output = "linear"', 'output = "tinted"'))
        out = tmp_path / where / "out"
        assert _cli("build", scene, "--out", out, "--bricks", engine, "--no-cache").returncode == 0
        trees.append({str(p.relative_to(out)): p.read_bytes() for p in sorted(out.rglob("*")) if p.is_file()
                      and p.name != ".shadermatrix-lock"})
    assert trees[0] == trees[1]
    for data in trees[0].values():
        assert str(tmp_path).encode() not in data and str(REPO).encode() not in data
