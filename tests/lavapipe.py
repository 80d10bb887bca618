"""Shared lavapipe fixtures: a validated device, and a check after every test that it said nothing.

Import the fixtures into a test module (`from tests.lavapipe import device, no_validation_messages`).
Without a Vulkan device the tests skip with the reason; under CI=true they fail.
"""
from __future__ import annotations

import pytest

from tests.conftest import require, require_tool

COMPILERS = ("glslc", "naga", "spirv-val", "spirv-opt")


def open_device():
    """A new lavapipe Device with the Khronos validation layer on (skip/fail without one)."""
    from generator.runtime.device import Device, VulkanUnavailable

    try:
        return Device(validation=True)
    except VulkanUnavailable as exc:
        require(False, str(exc))


def _report(messages) -> str:
    return "validation messages:\n" + "\n".join(map(str, messages))


@pytest.fixture(scope="module")
def device(eval_session):
    """The device of the test session's EvalSession (tests/conftest.py: validation on), which the tests pass to
    what they evaluate; at the module's end its kernels free their buffers and the layer has said nothing."""
    for t in COMPILERS:
        require_tool(t)
    from generator.runtime.device import VulkanUnavailable

    try:
        dev = eval_session.device
    except VulkanUnavailable as exc:
        require(False, str(exc))
    yield dev
    eval_session.release()
    found, dev.messages[:] = list(dev.messages), []
    assert found == [], "at the module's end: " + _report(found)


@pytest.fixture(autouse=True)
def no_validation_messages(request):
    """Fail a test that uses `device` if the validation layer reported anything during it."""
    yield
    if "device" in request.fixturenames:
        dev = request.getfixturevalue("device")
        found, dev.messages[:] = list(dev.messages), []
        assert found == [], _report(found)
