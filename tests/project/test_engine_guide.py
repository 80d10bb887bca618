"""docs/guide/engine-integration.md is true of a real build, and enough to read one without our code.

- Every excerpt on the page (a ```text block right after a ```sh block) is what the block's last command prints
  now: the page's commands are run in order, as the docs test runs them, against builds in a temporary folder.
- tests/project/engine_reader.py, a loader written from the page alone with the standard library, reads the
  example and the textured builds: every object's permutation and uploaded blocks decode to the scene's TOML
  values, every KTX2 header and level index is the manifest's. It imports nothing of the generator, and it
  fails on a damaged build (a flipped upload byte, a wrong texture size, a cut KTX2 file, a changed scene).
"""
from __future__ import annotations

import ast
import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from tests.project import engine_reader
from tests.project.test_docs import _env, commands_of

REPO = Path(__file__).resolve().parents[2]
PAGE = REPO / "docs" / "guide" / "engine-integration.md"
OUT = "out/engine"  # the page's build folders (out/engine, out/engine-pack, out/engine-textured)
READER_IMPORTS = {"__future__", "hashlib", "json", "pathlib", "struct", "sys", "tomllib"}


def excerpts(text: str) -> dict[int, str]:
    """{line of a ```sh block's last command: the ```text block right after that block}."""
    lines = text.splitlines()
    out, i = {}, 0
    while i < len(lines):
        if lines[i].strip() != "```sh":
            i += 1
            continue
        end = next(j for j in range(i + 1, len(lines)) if lines[j].strip() == "```")
        cmds = commands_of("page", "\n".join(["```sh", *lines[i + 1:end], "```"]))
        k = end + 1
        while k < len(lines) and not lines[k].strip():
            k += 1
        if cmds and k < len(lines) and lines[k].strip() == "```text":
            stop = next(j for j in range(k + 1, len(lines)) if lines[j].strip() == "```")
            out[i + cmds[-1].line] = "\n".join(lines[k + 1:stop])
        i = end + 1
    return out


def _tidy(s: str) -> str:
    return "\n".join(ln.rstrip() for ln in s.strip("\n").splitlines())


@pytest.fixture(scope="module")
def page_run(tmp_path_factory):
    """The page's commands run in order against a temporary folder: {line: stdout}, and that folder."""
    tmp = tmp_path_factory.mktemp("engine-guide")
    text = PAGE.read_text(encoding="utf-8")
    printed = {}
    for c in commands_of(str(PAGE.relative_to(REPO)), text):
        cmd = c.text.replace(OUT, str(tmp / "engine"))
        r = subprocess.run(["bash", "-c", cmd], cwd=REPO, env=_env(tmp), capture_output=True, text=True, timeout=600)
        assert r.returncode == c.exit, f"{c.id}: `{c.text}` exited {r.returncode}\n{r.stderr[-3000:]}"
        printed[c.line] = r.stdout
    return printed, tmp


def test_the_page_pairs_commands_with_excerpts():
    found = excerpts(PAGE.read_text(encoding="utf-8"))
    assert len(found) >= 12, f"the page shows {len(found)} excerpts under their commands"
    sample = "\n".join(["x", "```sh", "echo a", "echo b", "```", "", "```text", "b", "```", "```sh", "ls", "```"])
    assert excerpts(sample) == {4: "b"}


@pytest.mark.toolchain
def test_every_excerpt_is_what_its_command_prints(page_run):
    printed, tmp = page_run
    stale = []
    for line, shown in excerpts(PAGE.read_text(encoding="utf-8")).items():
        got = _tidy(printed[line].replace(str(tmp / "engine"), OUT))
        if got != _tidy(shown):
            stale.append(f"docs/guide/engine-integration.md:{line}: the page shows\n{shown}\nthe command prints\n{got}")
    assert not stale, "excerpts that went stale (paste what the command prints):\n\n" + "\n\n".join(stale)


@pytest.mark.toolchain
@pytest.mark.parametrize("build, scene", [("engine", "example.toml"), ("engine-textured", "textured.toml")])
def test_the_second_reader_reads_the_build(page_run, build, scene):
    _, tmp = page_run
    said, errors = engine_reader.read(tmp / build, REPO / "scenes" / scene)
    assert errors == []
    m = json.loads((tmp / build / "manifest.json").read_text())
    assert len(said) == len(m["objects"]) + len(m["textures"]), said
    if scene == "textured.toml":  # real images, and a sampler of each kind the page names
        states = {(s["wrap_u"], s["mipmap"], s["mag_filter"], s["anisotropy"]) for s in m["samplers"]}
        assert {("mirrored", "linear", "linear", 1), ("clamp", "none", "nearest", 1),
                ("repeat", "linear", "linear", 8)} <= states


def test_the_second_reader_imports_only_the_standard_library():
    tree = ast.parse(Path(engine_reader.__file__).read_text(encoding="utf-8"))
    imported = {a.name.split(".")[0] for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names}
    imported |= {n.module.split(".")[0] for n in ast.walk(tree) if isinstance(n, ast.ImportFrom) and n.module}
    assert all(not (isinstance(n, ast.ImportFrom) and n.level) for n in ast.walk(tree)), "a relative import"
    assert imported <= READER_IMPORTS, f"the reader imports {sorted(imported - READER_IMPORTS)}"


def _damaged(tmp: Path, name: str) -> Path:
    d = tmp / f"damaged-{name}"
    shutil.rmtree(d, ignore_errors=True)
    shutil.copytree(tmp / "engine", d)
    return d


@pytest.mark.toolchain
def test_the_second_reader_fails_on_a_damaged_build(page_run, tmp_path):
    _, tmp = page_run
    scene = REPO / "scenes" / "example.toml"

    d = _damaged(tmp, "upload")  # the Material block's n (offset 12 of painted_wood's) is no longer 16.0
    m = json.loads((d / "manifest.json").read_text())
    p = next(p for p in m["permutations"] if p["hash"] == "fa18c646f579")
    p["uploads"][0]["Material"] = p["uploads"][0]["Material"][:24] + "00004040" + p["uploads"][0]["Material"][32:]
    (d / "manifest.json").write_text(json.dumps(m))
    errors = engine_reader.read(d, scene)[1]
    assert any("painted_wood n at offset 12 reads [3.0]" in e for e in errors), errors

    d = _damaged(tmp, "size")  # the manifest says 17 texels wide, the file 16
    m = json.loads((d / "manifest.json").read_text())
    m["textures"][0]["width"] += 1
    (d / "manifest.json").write_text(json.dumps(m))
    assert any("the header says" in e for e in engine_reader.read(d, scene)[1])

    d = _damaged(tmp, "cut")  # a KTX2 file cut short: its sha256 and its level 0 fail
    path = d / m["textures"][0]["path"]
    path.write_bytes(path.read_bytes()[:-16])
    errors = engine_reader.read(d, scene)[1]
    assert any("sha256" in e for e in errors) and any("level 0" in e for e in errors), errors

    edited = tmp_path / "example.toml"  # the scene says another colour than the build holds
    edited.write_text(re.sub(r"rho_d = \[0\.8, 0\.05, 0\.05\]", "rho_d = [0.7, 0.05, 0.05]", scene.read_text()))
    assert edited.read_text() != scene.read_text()
    errors = engine_reader.read(tmp / "engine", edited)[1]
    assert any("red_plastic rho_d" in e for e in errors), errors


@pytest.mark.toolchain
def test_the_reader_exits_1_naming_the_mismatch(page_run, tmp_path):
    _, tmp = page_run
    edited = tmp_path / "example.toml"
    edited.write_text((REPO / "scenes" / "example.toml").read_text().replace("n = 16.0", "n = 17.0"))
    r = subprocess.run([sys.executable, str(Path(engine_reader.__file__)), str(tmp / "engine"), str(edited)],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 1 and "error: object bench: Material material painted_wood n" in r.stderr, r.stderr
