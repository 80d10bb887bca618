"""`shadermatrix eval`: f_r of a BRDF spec for samples from a .npy file, on the CPU or on lavapipe.

    shadermatrix eval SPEC --input S.npy --out F.npy --target {reference,numpy,glsl,hlsl,wgsl}
                      [--param NAME=VALUE ...] [--dtype float64|float32|float16]

S.npy: float (N, 9) = [L, V, N] or (N, 12) = [L, V, N, T], unit vectors in one
frame (nothing is normalized unless a brick does). F.npy: float64 (N, 3), the
bare BRDF in 1/sr (no cosine, no π), written atomically.

Samples are checked before any target sees them: a non-finite component or a vector whose length is
not 1 within UNIT_TOL is an error naming the first such row (every target would treat it its own way:
the float64 reference, NumPy and the GPU kernels disagree on NaN). --unchecked passes them through
unchanged, identically to every target. The .npy header is read first: an array larger than
MAX_SAMPLES rows is refused before anything is allocated.
"""
from __future__ import annotations

import io
import sys
import warnings
from tokenize import TokenError
from pathlib import Path

from ... import DTYPES, EVAL_TARGETS
from ...lang.errors import UsageError

HELP = "evaluate a BRDF spec on samples (.npy in, float64 f_r .npy out): reference, numpy or a GPU kernel"


def add_arguments(p) -> None:
    p.add_argument("spec", help="BRDF spec, e.g. 'lambert+microfacet(ndf=ggx)'")
    p.add_argument("--input", required=True, metavar="S.npy", help="samples: (N, 9) [L, V, N] or (N, 12) [L, V, N, T]")
    p.add_argument("--out", required=True, metavar="F.npy", help="f_r as float64 (N, 3), written atomically")
    p.add_argument("--target", required=True, choices=EVAL_TARGETS,
                   help="reference (float64), numpy (IR at --dtype), or a language's eval kernel on lavapipe")
    p.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                   help="a parameter (canonical name); RGB as f0=0.9,0.6,0.3; a scalar splats (repeatable)")
    p.add_argument("--dtype", choices=DTYPES,
                   help="numpy: float64 (default), float32 or float16; GPU targets: float32, or float16 where the device "
                        "reports shaderFloat16")
    p.add_argument("--bricks", action="append", metavar="DIR", help="an extra brick directory (repeatable)")
    p.add_argument("--unchecked", action="store_true",
                   help="pass non-finite and non-unit sample vectors through as they are (default: an error)")


class _BadInput(Exception):
    """A sample file that cannot be evaluated (exit 1; a malformed option is a UsageError, exit 2)."""


def parse_params(items: list[str]) -> dict[str, list[float]]:
    """--param NAME=VALUE[,VALUE...] into {name: [floats]}."""
    out: dict[str, list[float]] = {}
    for item in items:
        name, eq, value = item.partition("=")
        name = name.strip()
        if not eq or not name or not value.strip():
            raise UsageError(f"--param {item!r} is not NAME=VALUE — write e.g. --param alpha=0.2 or --param f0=0.9,0.6,0.3")
        if name in out:
            raise UsageError(f"--param {name} is given twice — give each parameter once")
        try:
            out[name] = [float(v) for v in value.split(",")]
        except ValueError:
            raise UsageError(f"--param {item!r}: {value!r} is not a number or a comma-separated list of numbers — "
                         "write e.g. --param f0=0.9,0.6,0.3") from None
    return out


UNIT_TOL = 1e-3  # |length - 1| a sample vector may have (float16 inputs round to ~5e-4)
MAX_SAMPLES = 50_000_000  # rows of an input (12 float64 columns: 4.8 GB)


def _one_line(exc: Exception) -> str:
    return " ".join(str(exc).split())


def load_samples(path: str, checked: bool = True):
    """The (N, 9|12) sample array of an .npy file, as float64 (checked: finite unit vectors)."""
    import numpy as np

    p = Path(path)
    if not p.is_file():
        raise _BadInput(f"{path}: no such file — pass an .npy file of samples with --input")
    try:
        # numpy compiles a malformed header dict, and Python warns of what it finds (SyntaxWarning, numpy's
        # Python-2 header note): the one-line error below says it all, so nothing else is printed
        with warnings.catch_warnings(), open(p, "rb") as f:  # the header first: a shape past the limit allocates nothing
            warnings.simplefilter("ignore")
            version = np.lib.format.read_magic(f)
            read = np.lib.format.read_array_header_1_0 if version == (1, 0) else np.lib.format.read_array_header_2_0
            shape, _, dtype = read(f)
            start = f.tell()
    except (ValueError, OSError, EOFError, SyntaxError, TokenError) as exc:  # numpy tokenizes the header dict
        raise _BadInput(f"{path}: not a readable .npy array ({_one_line(exc)}) — save the samples with numpy.save") from None
    # everything the header declares is checked before np.load allocates a byte
    if dtype.kind != "f":
        raise _BadInput(f"{path}: dtype {dtype} is not a float array — save float32 or float64 samples")
    if len(shape) != 2 or shape[1] not in (9, 12):
        raise _BadInput(f"{path}: shape {shape} — samples are (N, 9) = [L, V, N] or (N, 12) = [L, V, N, T]")
    if shape[0] > MAX_SAMPLES:
        raise _BadInput(f"{path}: {shape[0]} samples declared, more than the {MAX_SAMPLES} allowed — split the file")
    if p.stat().st_size - start < shape[0] * shape[1] * dtype.itemsize:
        raise _BadInput(f"{path}: the header declares {shape[0]} samples, but the file is shorter — save it again")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            a = np.load(p, allow_pickle=False)
    except (ValueError, OSError, EOFError) as exc:
        raise _BadInput(f"{path}: not a readable .npy array ({_one_line(exc)}) — save the samples with numpy.save") from None
    if not isinstance(a, np.ndarray) or a.dtype.kind != "f":
        raise _BadInput(f"{path}: dtype {getattr(a, 'dtype', type(a).__name__)} is not a float array — "
                     "save float32 or float64 samples")
    if a.ndim != 2 or a.shape[1] not in (9, 12):
        raise _BadInput(f"{path}: shape {a.shape} — samples are (N, 9) = [L, V, N] or (N, 12) = [L, V, N, T]")
    with np.errstate(invalid="ignore", over="ignore"):  # a float128 past float64: inf/nan, caught by the check below
        a = a.astype(np.float64)
    if checked and len(a):
        bad = ~np.isfinite(a).all(axis=1)
        if bad.any():
            row = int(np.argmax(bad))
            raise _BadInput(f"{path}: row {row} holds a NaN or infinity ({a[row].tolist()}) — fix the samples, or pass "
                         "--unchecked to evaluate them as they are")
        names = ["L", "V", "N", "T"][:a.shape[1] // 3]
        with np.errstate(over="ignore", invalid="ignore"):  # huge finite values: an overflowed length is "not 1"
            lengths = np.linalg.norm(a.reshape(len(a), -1, 3), axis=2)
        off = np.abs(lengths - 1.0) > UNIT_TOL
        if off.any():
            row, col = (int(x) for x in np.argwhere(off)[0])
            raise _BadInput(f"{path}: row {row}: {names[col]} has length {lengths[row, col]:.6g}, not 1 — normalize the "
                         "sample vectors, or pass --unchecked to evaluate them as they are")
    return a


def run(args) -> int:
    import numpy as np

    from ...library.bricks import load_library
    from ...io import atomic_write
    from ...eval.evaluate import EvalError, evaluate
    from ...runtime.eval_kernel import EvalSession
    from ...spec.permutation import SpecError

    params = parse_params(args.param)  # a usage error: the CLI's exit 2
    try:
        s = load_samples(args.input, checked=not args.unchecked)
        lib = load_library(args.bricks or ())
        T = s[:, 9:12] if s.shape[1] == 12 else None
        with EvalSession() as session:  # the device, opened only for a GPU target, closed before the output is written
            f = evaluate(args.spec, s[:, 0:3], s[:, 3:6], s[:, 6:9], T=T, params=params,
                         target=args.target, dtype=args.dtype, lib=lib, session=session)
    except (_BadInput, EvalError, SpecError) as exc:  # in the inputs: exit 1 (no device: the CLI's exit 3)
        print(f"error: {exc}", file=sys.stderr)
        return 1
    buf = io.BytesIO()
    np.save(buf, np.ascontiguousarray(f, dtype=np.float64))
    atomic_write(Path(args.out), buf.getvalue())
    print(f"{args.target}{'' if args.dtype is None else ' ' + args.dtype}: {len(f)} samples of "
          f"'{args.spec}' → {args.out}", file=sys.stderr)
    return 0
