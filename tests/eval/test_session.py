"""The eval kernels' device and what is compiled for it belong to an EvalSession its caller makes and closes: no
device outlives its session, a call given none opens one of its own and closes it, and a session that runs
nothing on the GPU opens none."""
from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import require, require_tool

L = V = N = np.tile([0.0, 0.0, 1.0], (4, 1))


def test_a_session_opens_no_device_until_a_gpu_target_needs_one():
    """(Not a lavapipe test: a device opened here would raise, test tiers.)"""
    from generator.eval.evaluate import evaluate
    from generator.runtime.eval_kernel import EvalSession

    with EvalSession() as session:
        evaluate("lambert", L, V, N, target="numpy", session=session)
        assert not session.opened and session.kernels == {}
    with pytest.raises(RuntimeError, match="closed"):
        session.device


def _open_devices() -> set[int]:
    from generator.runtime import device
    return set(device._DEVICES)


@pytest.mark.lavapipe
@pytest.mark.toolchain
def test_devices_live_exactly_as_long_as_their_session():
    for t in ("glslc", "spirv-val", "spirv-opt"):
        require_tool(t)
    from generator.eval.evaluate import evaluate
    from generator.runtime.eval_kernel import EvalSession
    from generator.runtime.probe import lavapipe_present

    require(lavapipe_present(), "no lavapipe Vulkan device")
    before = _open_devices()
    alone = evaluate("lambert", L, V, N, target="glsl")  # a session of its own, closed when the call returns
    assert _open_devices() == before
    with EvalSession() as session:
        got = evaluate("lambert", L, V, N, target="glsl", session=session)
        kernel = next(iter(session.kernels.values()))
        evaluate("lambert", L, V, N, target="glsl", session=session)
        assert list(session.kernels.values()) == [kernel]  # compiled once, kept by the session
        assert _open_devices() - before == {id(session.device)}
    assert _open_devices() == before and session.kernels == {}
    np.testing.assert_array_equal(got, alone)
    np.testing.assert_allclose(got, 0.5 / np.pi, rtol=1e-6)
