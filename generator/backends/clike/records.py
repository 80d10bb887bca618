"""The C-like emitters' record of what they emitted for each linked function, held by whoever emits.

Linked brick functions are shared by every program of a library and never change once linked
(link/program.py), so an emitter that meets one again from the same writer state replays its lines
instead of walking it. The caller owns the store and passes it to CLikeTarget.emit (composition keeps one
per library: compose.Composing), so a replay never crosses from one library, or one build, into another.
The record is kept here, keyed by the function's identity, not written into the IR node: IR stays the link stage's value (a copy of a node copies no emitter state, a validator or a dump
sees only IR), and an entry goes when its function is collected. IR nodes compare by value and are not
hashable, hence identity keys and a weak reference that checks the identity is still that function's.
"""
from __future__ import annotations

import weakref


class FunctionRecords:
    """Per linked function (by identity): a dict the emitter fills with what it emitted, keyed as it likes."""

    def __init__(self):
        self._by_id: dict[int, tuple[weakref.ref, dict]] = {}

    def of(self, f) -> dict:
        """The record of function `f` (empty the first time), dropped when `f` is collected."""
        key = id(f)
        held = self._by_id.get(key)
        if held is not None and held[0]() is f:
            return held[1]
        record: dict = {}
        self._by_id[key] = (weakref.ref(f, self._forget(key)), record)
        return record

    def __len__(self) -> int:
        return len(self._by_id)

    def _forget(self, key: int):
        by_id = self._by_id

        def forget(ref: weakref.ref) -> None:
            held = by_id.get(key)
            if held is not None and held[0] is ref:  # not a later function that reused the id
                del by_id[key]
        return forget
