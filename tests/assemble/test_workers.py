"""The build's worker pool (generator/assemble/workers.py) reports what a worker could not send as what it is: a
result that does not pickle is the pickling error (its type and message), an exception that does not make the
trip arrives as its type and message, and the workers stay usable; none of them reads as a worker that died."""
from __future__ import annotations

import threading

import pytest

from generator.assemble.workers import ReplyNotSent, WorkerDied, Workers
from generator.lang.errors import SourceError, UserError


class Locked(Exception):
    """An exception that does not pickle: it holds a lock."""

    def __init__(self, message: str):
        super().__init__(message)
        self.lock = threading.Lock()


class Unreadable:
    """A result that pickles in the worker and cannot be unpickled by the build."""

    def __reduce__(self):
        return _explode, ("made in a worker",)


def _explode(text):
    raise ValueError(f"cannot rebuild what was {text}")


def _init():
    pass


def _run(kind: str):
    if kind == "lock":
        return {"result": threading.Lock()}
    if kind == "locked":
        raise Locked("the brick is held")
    if kind == "located":  # pickles, but SourceError(message) cannot make it again: it takes path, line, col, …
        raise SourceError("scene.toml", 3, 7, "unknown brick 'x'", "fix it")
    if kind == "unreadable":
        return Unreadable()
    return kind * 2


@pytest.fixture(scope="module")
def pool():
    with Workers(2, _init, (), _run) as p:
        yield p


def _one(pool, kind):
    return dict(pool.unordered([(kind,)]))[0]


def test_a_result_that_does_not_pickle_is_the_pickling_error(pool):
    with pytest.raises(ReplyNotSent) as e:
        _one(pool, "lock")
    assert not isinstance(e.value, WorkerDied)
    assert str(e.value) == ("a worker's result (dict) cannot be sent to the build: TypeError: cannot pickle "
                            "'_thread.lock' object")
    assert "TypeError: cannot pickle '_thread.lock' object" in str(e.value.__cause__)  # the worker's traceback
    assert _one(pool, "ok") == "okok"  # the worker is alive and takes the next task


def test_an_exception_that_does_not_pickle_arrives_with_its_type_and_message(pool):
    with pytest.raises(RuntimeError, match=r"^Locked: the brick is held$"):
        _one(pool, "locked")
    assert _one(pool, "again") == "againagain"


def test_a_located_error_arrives_as_a_user_error_with_its_position(pool):
    with pytest.raises(UserError) as e:
        _one(pool, "located")
    assert str(e.value) == "scene.toml:3:7: unknown brick 'x' — fix it"


def test_a_result_the_build_cannot_unpickle_is_named(pool):
    with pytest.raises(ReplyNotSent, match=r"cannot be read by the build: ValueError: cannot rebuild what was "
                                           r"made in a worker"):
        _one(pool, "unreadable")
    assert sorted(v for _, v in pool.unordered([("a",), ("b",), ("c",)])) == ["aa", "bb", "cc"]
