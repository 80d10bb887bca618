"""Fixtures of the C reader's tests: the compilers, the driver built under the sanitizers, the example's packs.

A missing compiler skips these tests, and fails them under CI=true (tests/conftest.py `require`)."""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import require

REPO = Path(__file__).resolve().parents[2]
INCLUDE = REPO / "include"
HEADER = INCLUDE / "shadermatrix" / "pack.h"
HERE = Path(__file__).resolve().parent
EXAMPLE = REPO / "scenes" / "example.toml"
WARNINGS = ["-Wall", "-Wextra", "-Werror", "-pedantic"]
SANITIZE = ["-fsanitize=address,undefined", "-fno-sanitize-recover=all", "-fno-omit-frame-pointer"]
# Any report ends the process with a status of its own and a text on stderr; the tests require neither.
SANITIZER_ENV = {"ASAN_OPTIONS": "detect_leaks=1:detect_stack_use_after_return=1:strict_string_checks=1:exitcode=97",
                 "UBSAN_OPTIONS": "print_stacktrace=1:halt_on_error=1:exitcode=98"}


def compiler(name: str) -> str:
    path = shutil.which(name)
    require(path is not None, f"{name} not found — run `make setup` (scripts/setup.sh installs gcc, g++ and clang-14)")
    return path


def compile_c(args: list[str], what: str) -> None:
    r = subprocess.run(args, capture_output=True, text=True, timeout=180)
    assert r.returncode == 0, f"{what}: {' '.join(args)}\n{r.stderr[-6000:]}"


@pytest.fixture(scope="session")
def sanitizer_env() -> dict:
    return {**os.environ, **SANITIZER_ENV}


@pytest.fixture(scope="session")
def pack_check(tmp_path_factory) -> Path:
    """tests/native/pack_check.c built with clang-14 under AddressSanitizer and UndefinedBehaviorSanitizer."""
    out = tmp_path_factory.mktemp("pack-check") / "pack_check"
    compile_c([compiler("clang-14"), "-std=c11", "-g", "-O1", *WARNINGS, *SANITIZE, f"-I{INCLUDE}",
               str(HERE / "pack_check.c"), "-o", str(out)], "the sanitized driver does not build")
    return out


@pytest.fixture(scope="session")
def example_packs(tmp_path_factory) -> list[Path]:
    """The four packs of `shadermatrix build scenes/example.toml --pack`, vulkan's first."""
    out = tmp_path_factory.mktemp("example-packs")
    r = subprocess.run([sys.executable, "-m", "generator.cli", "build", str(EXAMPLE), "--out", str(out), "--pack"],
                       capture_output=True, text=True, cwd=REPO, timeout=600)
    assert r.returncode == 0, r.stderr[-4000:]
    return [out / p["path"] for p in json.loads((out / "manifest.json").read_text())["packs"]]
