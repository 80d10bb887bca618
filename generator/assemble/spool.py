"""`build --pack-only`: the packs and the manifest without the loose artifacts (10,000 permutations are ~90,000
files otherwise).

The build runs as it always does — every language composed, compiled and validated, every platform's artifacts
made, the manifest entries complete with every path and sha256 a loose build would write — but the Writer hands
the artifacts to a Spool instead of the output tree. Of each unit's artifacts, those a pack holds (pack.py: what
each platform loads) go to one temporary file beside the outputs (``.spool.<pid>-<random>.tmp``: an interrupted
build's leftover, removed by the next one) and the rest, already validated, are dropped; the packs are written
from it, and it is removed. The manifest says ``"artifacts": "packs"``: its entries' paths name no file of the
tree, and each platform's artifact is in ``packs`` under its entry's hash and stage. A failing unit's sources are
still written beside (``failed_sources``): they are for reading.

A later build keeps a unit whose input key is unchanged when the last build's packs hold every artifact of it
with the manifest's sha256 (``Packed.intact``; or its loose files, after a loose build), and the new packs take
those bytes from the old packs (``Packed.fetch``), so a rebuild from a pack-only tree is byte-identical to a loose
build's packs.
"""
from __future__ import annotations

import hashlib
import os
from pathlib import Path

from .pack import PackError, read_pack, rows_of


class Spool:
    """The artifacts of one pack-only build that its packs hold, in one temporary file of the output tree."""

    def __init__(self, out: Path):
        self.path = os.path.join(os.fspath(out), f".spool.{os.getpid()}-{os.urandom(4).hex()}.tmp")
        self._file = open(self.path, "w+b")
        self.at: dict[str, tuple[int, int]] = {}  # rel -> (offset, length)
        self.pending: dict[str, bytes] = {}  # what the unit being written has made so far
        self.shared: dict[str, bytes] = {}  # shared modules (put_shared) no pack holds: a later unit may name them

    def stash(self, rel: str, data: bytes | None, shared: bool = False) -> None:
        """One artifact of the unit being written (data None: a shared module already stashed)."""
        if data is None or rel in self.at:
            return
        (self.shared if shared else self.pending)[rel] = data

    def settle(self, entry: dict, name: str, platforms) -> None:
        """The unit `name` (its manifest entry complete): what a pack of `platforms` holds of it is spooled, the
        rest dropped."""
        for platform in platforms:
            for _, _, _, _, rel, _ in rows_of(entry, name, platform):
                data = self.pending.get(rel) or self.shared.pop(rel, None)
                if data is not None and rel not in self.at:
                    self._file.seek(0, os.SEEK_END)
                    self.at[rel] = (self._file.tell(), len(data))
                    self._file.write(data)
        self.pending.clear()

    def get(self, rel: str) -> bytes | None:
        where = self.at.get(rel)
        if where is None:
            return None
        self._file.seek(where[0])
        return self._file.read(where[1])

    def close(self) -> None:
        if not self._file.closed:
            self._file.close()
        try:
            os.unlink(self.path)
        except FileNotFoundError:
            pass


class Packed:
    """What the last build's packs hold, for a pack-only build: whether a unit it keeps is there whole (intact) and
    its bytes (fetch), read from each old pack once, checked whole (pack.read_pack)."""

    def __init__(self, out: Path, previous: dict):
        self.out, self.previous = Path(out), previous
        self._where: dict[str, tuple[str, str, str, str]] | None = None  # rel -> (platform, name, stage, sha256)
        self._index: dict[str, dict] = {}  # platform -> {(name, stage): sha256} of its old pack
        self._pack: tuple[str, dict] | None = None  # the one old pack whose blobs are in memory

    def _rels(self) -> dict:
        if self._where is None:
            self._where, m = {}, self.previous
            units = [*((e, e.get("hash")) for e in m.get("permutations", [])),
                     *((e, e.get("hash")) for e in (m.get("depth_shaders") or {}).values()),
                     ((m.get("ubershader") or {}), "ubershader")]
            for p in m.get("platforms", []):
                for e, name in units:
                    for n, stage, _, _, rel, sha in rows_of(e, name, p, ok_only=True):
                        self._where[rel] = (p, n, stage, sha)
        return self._where

    def _read(self, platform: str) -> dict | None:
        listed = next((p for p in self.previous.get("packs", []) if p.get("platform") == platform), None)
        if listed is None:
            return None
        try:
            pack = read_pack(self.out / listed["path"])
        except PackError:
            return None
        return pack if pack["key"] == listed.get("key") else None

    def intact(self, entry: dict, name: str) -> bool:
        """Whether every artifact of the last build's `entry` is in its platform's old pack with its sha256."""
        rels = self._rels()
        for p in self.previous.get("platforms", []):
            if p not in self._index:
                pack = self._read(p)
                self._index[p] = {} if pack is None else {k: e.sha256 for k, e in pack["entries"].items()}
            for n, stage, _, _, rel, sha in rows_of(entry, name, p, ok_only=True):
                if rels.get(rel, (None,) * 4)[3] != sha or self._index[p].get((n, stage)) != sha:
                    return False
        return True

    def fetch(self, rel: str) -> bytes | None:
        """A kept unit's artifact from the old pack that holds it (sha256 checked), or None."""
        found = self._rels().get(rel)
        if found is None:
            return None
        platform, name, stage, sha = found
        if self._pack is None or self._pack[0] != platform:
            self._pack = None  # one old pack in memory at a time: the new packs are written platform by platform
            pack = self._read(platform)
            if pack is None:
                return None
            self._pack = (platform, pack)
        entry = self._pack[1]["entries"].get((name, stage))
        if entry is None or hashlib.sha256(entry.data).hexdigest() != sha:
            return None
        return entry.data
