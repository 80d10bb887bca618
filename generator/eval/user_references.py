"""Independent float64 references an engine ships for its own bricks: Python files the user names.

`shadermatrix accuracy --reference FILE.py` (repeatable) runs FILE.py as Python before measuring. That is
user code, run with the user's rights: only a file named on the command line is ever run (nothing is
discovered beside a brick folder, nothing is imported from one). A file registers references the way
generator/reference/ does, with the same decorator and signatures (reference/models.py):

    from generator.reference import reference

    @reference("specular", "charlie_sheen")
    def charlie_sheen(g, p, slots):   # g: Geometry (the inputs table), p: {parameter: values}
        return ...                    # (N, 3) f_r in 1/sr

Registrations last for the run alone (user_references() restores the registry), so two runs in one process
see only the files each names; a file registering a brick that already has a reference is an error.
"""
from __future__ import annotations

import importlib.util
import sys
import traceback
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator

from ..lang import SourceError


def _located(path: Path, exc: BaseException) -> SourceError:
    """An exception raised while running the file, at the line of the file it came from."""
    frames = [f for f in traceback.extract_tb(exc.__traceback__) if Path(f.filename) == path.resolve()]
    line = frames[-1].lineno if frames and frames[-1].lineno else getattr(exc, "lineno", None) or 1
    col = getattr(exc, "offset", None) or 1 if isinstance(exc, SyntaxError) else 1
    what = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
    return SourceError(str(path), line, col, f"the reference file raised {type(exc).__name__}: {what}",
                       "fix the file (it is run as Python, as given with --reference)")


def _run_file(path: Path, n: int) -> None:
    spec = importlib.util.spec_from_file_location(f"shadermatrix_user_reference_{n}", path)
    if spec is None or spec.loader is None:
        raise SourceError(str(path), 1, 1, "is not a Python file", "name a .py file with --reference")
    module = importlib.util.module_from_spec(spec)
    try:
        spec.loader.exec_module(module)
    except Exception as exc:  # the user's code: any failure is theirs, located in their file
        raise _located(path, exc) from None


@contextmanager
def user_references(paths) -> Iterator[dict[str, str]]:
    """Run each file in turn; yield {"kind/id": file} of what they registered; restore the registry after."""
    from ..reference import REFERENCES

    saved = {k: dict(v) for k, v in REFERENCES.items()}
    registered: dict[str, str] = {}
    try:
        for n, p in enumerate(paths or ()):
            path = Path(p)
            if not path.is_file():
                raise SourceError(str(path), 1, 1, "no such reference file" if not path.exists() else
                                  "is not a file", "name a Python file that registers @reference(kind, id) functions")
            before = {(k, i) for k, v in REFERENCES.items() for i in v}
            _run_file(path, n)
            new = sorted({(k, i) for k, v in REFERENCES.items() for i in v} - before)
            if not new:
                raise SourceError(str(path), 1, 1, "registers no reference",
                                  "decorate a function with @reference(kind, brick_id) from generator.reference")
            registered.update({f"{k}/{i}": str(path) for k, i in new})
        yield registered
    finally:
        for k in REFERENCES:
            REFERENCES[k].clear()
            REFERENCES[k].update(saved.get(k, {}))
        for name in [m for m in sys.modules if m.startswith("shadermatrix_user_reference_")]:
            del sys.modules[name]
