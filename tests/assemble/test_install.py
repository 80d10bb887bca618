"""A non-editable install works on its own: the wheel carries every brick, template and data file the build
reads and the tool pins, so `shadermatrix build` run from another directory, with nothing of the clone on
sys.path, writes exactly what the clone's own build writes.

One wheel is built from a copy of the working tree's package sources (setuptools writes build/ and
*.egg-info beside pyproject.toml, and reuses a stale build/lib: neither may touch the clone) and installed
with pip, byte-compilation and all, into a fresh venv. The clone's build runs on that same copy (with
PYTHONPATH, as a clone runs), so an edit to the working tree while the test runs cannot tell them apart. The venv gets no dependencies of its own (the
tests may run without network): a .pth file makes this interpreter's site-packages visible to it, and
none of that folder's .pth files run there, so the clone's editable install does not leak in.
"""
from __future__ import annotations

import os
import shutil
import site
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from tests.conftest import in_ci, require, require_tool

REPO = Path(__file__).resolve().parents[2]
SOURCES = ("pyproject.toml", "setup.py", "README.md", "generator", "bricks")  # what the wheel is built from
SCENES = "scenes"  # copied too: what both builds read
TIMEOUT = 300


def _env(**extra) -> dict:
    env = {k: v for k, v in os.environ.items()
           if k not in ("PYTHONPATH", "PYTHONHOME", "PYTHONSTARTUP", "SHADERMATRIX_FORBID_TOOLS",
                        "SHADERMATRIX_TOOLS", "VIRTUAL_ENV")}
    env.update(PIP_NO_INDEX="1", PIP_DISABLE_PIP_VERSION_CHECK="1", **extra)
    return env


def _run(argv, cwd, env=None, check=True) -> subprocess.CompletedProcess:
    r = subprocess.run([str(a) for a in argv], cwd=cwd, env=env or _env(), capture_output=True, text=True,
                       timeout=TIMEOUT, stdin=subprocess.DEVNULL)
    if check:
        assert r.returncode == 0, f"{' '.join(map(str, argv))} exited {r.returncode}:\n{r.stdout[-3000:]}{r.stderr[-3000:]}"
    return r


def _make_venv(where: Path) -> Path:
    """A fresh venv without pip (this interpreter's pip installs into it); skipped where this Python
    cannot make one or its pip cannot install into another interpreter — a failure under CI=true."""
    try:
        import setuptools  # noqa: F401  (the wheel is built without build isolation: no network)
    except ImportError:
        require(False, "setuptools is not installed here — run `make setup`")
    made = subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(where)], capture_output=True, text=True)
    require(made.returncode == 0, f"`python -m venv` failed: {made.stderr.strip()[-500:]}")
    pip = subprocess.run([sys.executable, "-m", "pip", "--version"], capture_output=True, text=True)
    version = tuple(int(x) for x in pip.stdout.split()[1].split(".")[:2]) if pip.returncode == 0 else (0, 0)
    require(version >= (22, 3), f"pip >= 22.3 (for --python) is needed, this Python has {pip.stdout.strip() or 'none'}")
    return where / "bin" / "python"


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    """(the new venv's python, its site-packages, the copied sources) with the wheel installed."""
    tmp = tmp_path_factory.mktemp("install")
    src = tmp / "src"
    src.mkdir()
    for name in (*SOURCES, SCENES):
        if (REPO / name).is_dir():
            shutil.copytree(REPO / name, src / name, ignore=shutil.ignore_patterns("__pycache__", "*.egg-info"))
        elif (REPO / name).exists():
            shutil.copy2(REPO / name, src / name)
    python = _make_venv(tmp / "venv")
    _run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "--no-build-isolation", "-w", tmp / "wheels", "."],
         cwd=src)
    wheels = sorted((tmp / "wheels").glob("shadermatrix-*.whl"))
    assert len(wheels) == 1, wheels
    _run([sys.executable, "-m", "pip", "--python", python, "install", "-q", "--no-deps", wheels[0]], cwd=tmp)
    purelib = Path(_run([python, "-c", "import sysconfig; print(sysconfig.get_path('purelib'))"], cwd=tmp).stdout.strip())
    deps = [p for p in site.getsitepackages() if Path(p).is_dir()]
    (purelib / "_shadermatrix_test_deps.pth").write_text("".join(p + "\n" for p in deps))
    return python, purelib, src


def _elsewhere(tmp_path) -> Path:
    cwd = tmp_path / "elsewhere"
    cwd.mkdir(exist_ok=True)
    return cwd


@pytest.mark.toolchain
def test_the_installed_package_is_the_one_imported(installed, tmp_path):
    python, purelib, src = installed
    r = _run([python, "-c", "import generator, sys; print(generator.__file__); print(*sys.path, sep='\\n')"],
             cwd=_elsewhere(tmp_path))
    where, *path = r.stdout.splitlines()
    assert Path(where).is_relative_to(purelib), f"generator imported from {where}, not the install in {purelib}"
    others = [p for p in path if p and (Path(p) / "generator").is_dir() and Path(p).resolve() != purelib.resolve()]
    assert not others, f"another generator package is reachable on sys.path: {others}"  # the clone's, say
    files = {p.relative_to(purelib / "generator").as_posix() for p in (purelib / "generator").rglob("*")
             if p.is_file() and "__pycache__" not in p.parts}
    bricks = {f"library/bricks_data/{p.relative_to(src / 'bricks').as_posix()}" for p in (src / "bricks").rglob("*")
              if p.is_file() and "__pycache__" not in p.parts}
    assert bricks <= files, sorted(bricks - files)
    assert {"measure/course_costs.toml", "toolchain/pins.toml"} <= files
    # pip byte-compiled the bricks as any .py file it installs (harmless: they are parsed, never imported)
    assert list((purelib / "generator" / "library" / "bricks_data").rglob("*.pyc"))
    code = {p.relative_to(src / "generator").as_posix() for p in (src / "generator").rglob("*")
            if p.is_file() and "__pycache__" not in p.parts}
    assert code == files - bricks, f"only in the clone: {sorted(code - files)}; only installed: {sorted(files - bricks - code)}"


def _tree(root: Path) -> dict[str, bytes]:
    return {p.relative_to(root).as_posix(): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}


def _depfile(path: Path) -> tuple[str, set[str]]:
    rule = path.read_text().partition("\n\n")[0]  # the rule; an empty rule per dependency follows it
    target, _, deps = rule.replace("\\\n", " ").partition(":")
    return target.strip(), set(deps.split())


@pytest.mark.toolchain
def test_installed_build_is_byte_identical_to_the_clones(installed, tmp_path):
    python, purelib, src = installed
    scene = src / SCENES / "example.toml"
    cwd = _elsewhere(tmp_path)
    outs = {}
    # the install compiles every shader itself (a cache of its own, its tools found by its own find_tool);
    # the clone's build then reads the same cache: identical SPIR-V either way, and twice as fast
    cache = tmp_path / "cache"
    # the tools where the clone's build finds them (make setup puts naga in .venv/bin, not on PATH): the
    # installed package finds them through the documented setting
    tools = os.pathsep.join(sorted({str(Path(require_tool(t)).parent) for t in ("naga", "glslc", "spirv-val")}))
    for name, shadermatrix, env in (("installed", [python.parent / "shadermatrix"], {}),
                                    ("clone", [sys.executable, "-m", "generator.cli"], {"PYTHONPATH": str(src)})):
        out = tmp_path / name
        _run([*shadermatrix, "build", scene, "--out", out, "--depfile", tmp_path / f"{name}.d"], cwd=cwd,
             env=_env(SHADERMATRIX_CACHE_DIR=str(cache), SHADERMATRIX_TOOLS=tools, **env))
        outs[name] = _tree(out)
    installed_files, clone_files = outs["installed"], outs["clone"]
    assert sorted(installed_files) == sorted(clone_files)
    assert len(clone_files) > 50 and "manifest.json" in clone_files  # every platform's sources, SPIR-V, tables
    # the manifest and the state file carry each permutation's input key, which hashes the generator's own
    # code: equal bytes there also say that the install runs the clone's code, and no file differs at all
    differ = [f for f in clone_files if installed_files[f] != clone_files[f]]
    assert not differ, f"the installed build differs from the clone's in {differ}"
    for text in (clone_files["manifest.json"], clone_files[".shadermatrix-state.json"]):
        assert str(src).encode() not in text and str(purelib).encode() not in text

    # the depfiles name the same files, the install's own copies where the clone names its sources
    target, deps = _depfile(tmp_path / "installed.d")
    clone_target, clone_deps = _depfile(tmp_path / "clone.d")
    assert (target, clone_target) == (str(tmp_path / "installed" / "manifest.json"),
                                      str(tmp_path / "clone" / "manifest.json"))
    assert all(Path(d).exists() for d in deps), deps  # files, the brick folders and OUT/.shadermatrix-versions
    assert not [d for d in deps if Path(d).is_relative_to(src) and not Path(d).is_relative_to(scene.parent)], deps
    in_clone = {d.replace(f"{purelib}/generator/library/bricks_data", f"{src}/bricks")
                 .replace(f"{purelib}/generator/", f"{src}/generator/")
                 .replace(str(tmp_path / "installed"), str(tmp_path / "clone")) for d in deps}
    assert in_clone == clone_deps, (sorted(in_clone - clone_deps), sorted(clone_deps - in_clone))
    assert any("/bricks/" in d for d in clone_deps) and any(d.endswith(".j2") for d in clone_deps)


@pytest.mark.toolchain
@pytest.mark.lavapipe  # doctor also looks for the lavapipe device
def test_installed_doctor_reads_its_pins_and_finds_tools_by_the_setting(installed, tmp_path):
    python, _, src = installed
    pins = tomllib.loads((src / "generator" / "toolchain" / "pins.toml").read_text())
    naga = require_tool("naga")
    # a PATH holding every tool but naga (links to the real ones), and naga in a folder of its own
    tools, own = tmp_path / "tools", tmp_path / "naga-only"
    tools.mkdir(), own.mkdir()
    for tool in ("glslc", "glslangValidator", "spirv-val", "spirv-opt", "spirv-as"):
        (tools / tool).symlink_to(require_tool(tool))
    (own / "naga").symlink_to(naga)
    doctor = [python.parent / "shadermatrix", "doctor"]
    r = _run(doctor, cwd=_elsewhere(tmp_path), env=_env(PATH=str(tools)), check=False)
    row = next((line for line in r.stdout.splitlines() if " naga " in line), "")
    assert r.returncode == 3 and row.split()[0] == "MISSING", r.stdout + r.stderr
    assert f"cargo install naga-cli --locked --version {pins['naga']}" in row, row
    r = _run(doctor, cwd=_elsewhere(tmp_path), env=_env(PATH=str(tools), SHADERMATRIX_TOOLS=str(own)), check=False)
    row = next((line for line in r.stdout.splitlines() if " naga " in line), "")
    assert row.split()[:4] == ["ok", "naga", pins["naga"], pins["naga"]] and str(own) in row, r.stdout + r.stderr
    assert "glslc" in r.stdout and pins["glslc"] in r.stdout


def test_a_venv_that_cannot_be_made_skips_but_fails_under_ci(monkeypatch, tmp_path):
    taken = tmp_path / "a-file"  # `python -m venv` cannot make a venv where a file is
    taken.write_text("")
    monkeypatch.setenv("CI", "")
    with pytest.raises(pytest.skip.Exception, match="venv"):
        _make_venv(taken)
    monkeypatch.setenv("CI", "true")
    assert in_ci()
    with pytest.raises(pytest.fail.Exception, match="venv"):
        _make_venv(taken)
