"""What every step of a build reads, in one value: the bricks, what to build, where compiles run and what to show.

A build is given a BuildContext instead of loose parameters, process globals and environment variables: the
library it composes from, the languages and platforms it builds, the compile cache, whether it draws a progress
bar, how many processes it may use and the executor its compiles may run on. Worker processes get the same
value (BuildContext.for_workers), so they compose from exactly what the build does.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace

from ..backends import LANGUAGES
from ..library.bricks import Library
from ..toolchain import Gate
from .platforms import PLATFORMS, dialects_of


@dataclass(frozen=True)
class BuildContext:
    library: Library
    languages: tuple[str, ...] = tuple(LANGUAGES)
    platforms: tuple[str, ...] = PLATFORMS  # what to write besides every language's SPIR-V checks (platforms.py)
    store: object = None  # the content-addressed compile cache (io.Store), or None: compile everything
    progress: bool = False  # draw progress bars (on stderr)
    jobs: int | None = None  # worker processes (from MIN_PERMUTATIONS), else tool processes; None: the core count
    executor: object = None  # a Dask cluster the chunks run on (toolchain/dask.py, assemble/cluster.py), or None
    # this build's switch for its tools (toolchain.Gate): the build's signal handler stops it, which kills them
    gate: Gate = field(default_factory=Gate, compare=False, repr=False)

    def __post_init__(self):
        object.__setattr__(self, "languages", tuple(self.languages))
        object.__setattr__(self, "platforms", tuple(self.platforms))

    @property
    def dialects(self) -> tuple[str, ...]:
        """The platform dialects composed beside the languages (compose.Composed.dialects)."""
        return tuple(dialects_of(self.platforms))

    def for_workers(self) -> BuildContext:
        """This context as it is sent to worker processes (pickled): the bricks without what this process derived
        from them (each worker links its own), no executor (the workers are where compiles run), no progress bar,
        no store (it holds a lock: a worker opens its own at the store's root, parallel.py) and a gate of their
        own (this one holds a lock and this process's tools; the build ends its workers by killing them)."""
        return replace(self, library=Library(bricks=self.library.bricks, errors=self.library.errors),
                       executor=None, progress=False, store=None, gate=Gate())
