"""Shared test helpers.

``require_tool(name)`` (plain function, and a fixture of the same name that
returns it): skips the test when an external tool is missing, but under
``CI=true`` a missing tool FAILS the test, so CI can never pass by skipping.
"""
from __future__ import annotations

import os

import pytest


def in_ci() -> bool:
    return os.environ.get("CI", "").strip().lower() in ("1", "true", "yes")


def require(condition: bool, reason: str) -> None:
    """Skip unless ``condition``; under CI=true, fail instead of skipping."""
    if condition:
        return
    if in_ci():
        pytest.fail(f"{reason} (CI=true: missing prerequisites fail instead of skipping)", pytrace=False)
    pytest.skip(reason)


def require_tool(name: str) -> str:
    """Path of an external tool, found as the build finds it (generator.toolchain.find_tool)."""
    from generator.toolchain import find_tool

    path = find_tool(name)
    require(path is not None, f"{name} not found — run `make setup` (scripts/setup.sh)")
    return path


@pytest.fixture(name="require_tool")
def _require_tool_fixture():
    return require_tool


@pytest.fixture(scope="session", autouse=True)
def _own_compile_cache(tmp_path_factory):
    """Every test session starts with an empty compile cache of its own (never the user's ~/.cache):
    `shadermatrix build` run by a test, in this process or a child, reads and fills only this one."""
    os.environ["SHADERMATRIX_CACHE_DIR"] = str(tmp_path_factory.mktemp("compile-cache"))


@pytest.fixture(scope="session")
def eval_session():
    """The EvalSession GPU evaluations of this test session run on (pass it as `session=`), with the validation
    layer on; its device opens when a lavapipe test first uses it (tests/lavapipe.py: `device`), and closes
    when the session ends, saying nothing then too."""
    from generator.runtime.eval_kernel import EvalSession

    session = EvalSession(validation=True)
    yield session
    dev = session.device if session.opened else None
    session.close()
    if dev is not None:
        assert dev.messages == [], "while closing: " + "\n".join(map(str, dev.messages))


# Every manifest a test's build writes is validated against the shipped schema first (generator/assemble/manifest.py
# reads this variable), in this process and in the commands a test starts: a field a build writes that the schema
# does not describe fails the test that wrote it. tests/assemble/test_manifest_schema.py checks it is set.
CHECK_MANIFEST_ENV = "SHADERMATRIX_CHECK_MANIFEST"


@pytest.fixture(scope="session", autouse=True)
def _check_manifests():
    os.environ[CHECK_MANIFEST_ENV] = "1"


@pytest.fixture(autouse=True)
def _test_tier(request, monkeypatch):
    """Tiers do not leak: only `toolchain` tests run external tools, only `lavapipe` ones open a device.

    The generator refuses (tools: generator.toolchain.find_tool; devices: runtime.device.Device) while
    SHADERMATRIX_FORBID_* is set, in this process and in the CLI subprocesses a test starts, so
    `pytest -m "not toolchain"` provably runs no tool and `-m "not lavapipe"` opens no device.
    """
    marks = {m.name for m in request.node.iter_markers()}
    if "toolchain" not in marks:
        monkeypatch.setenv("SHADERMATRIX_FORBID_TOOLS", f"{request.node.nodeid} is not marked toolchain")
    if "lavapipe" not in marks:
        monkeypatch.setenv("SHADERMATRIX_FORBID_DEVICE", f"{request.node.nodeid} is not marked lavapipe")
