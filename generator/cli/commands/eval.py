"""`shadermatrix eval`: f_r of a BRDF spec for samples from a .npy file, on the CPU or on lavapipe.

    shadermatrix eval SPEC --input S.npy --output F.npy --target {reference,numpy,glsl,hlsl,wgsl}
                      [--param NAME=VALUE ...] [--dtype float64|float32|float16]

S.npy: float (N, 9) = [L, V, N] or (N, 12) = [L, V, N, T], unit vectors in one
frame (nothing is normalized unless a brick does). F.npy: float64 (N, 3), the
bare BRDF in 1/sr (no cosine, no π), written atomically.
"""
from __future__ import annotations

import io
import sys
from pathlib import Path

from ... import DTYPES, EVAL_TARGETS

HELP = "evaluate a BRDF spec on samples (.npy in, float64 f_r .npy out): reference, numpy or a GPU kernel"


def add_arguments(p) -> None:
    p.add_argument("spec", help="BRDF spec, e.g. 'lambert+microfacet(ndf=ggx)'")
    p.add_argument("--input", required=True, metavar="S.npy", help="samples: (N, 9) [L, V, N] or (N, 12) [L, V, N, T]")
    p.add_argument("--output", required=True, metavar="F.npy", help="f_r as float64 (N, 3)")
    p.add_argument("--target", required=True, choices=EVAL_TARGETS,
                   help="reference (float64), numpy (IR at --dtype), or a language's eval kernel on lavapipe")
    p.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                   help="a parameter (canonical name); RGB as f0=0.9,0.6,0.3; a scalar splats (repeatable)")
    p.add_argument("--dtype", choices=DTYPES,
                   help="numpy: float64 (default), float32 or float16; GPU targets: float32 only")
    p.add_argument("--bricks", action="append", metavar="DIR", help="an extra brick directory (repeatable)")


class _Usage(Exception):
    pass


def parse_params(items: list[str]) -> dict[str, list[float]]:
    """--param NAME=VALUE[,VALUE...] into {name: [floats]}."""
    out: dict[str, list[float]] = {}
    for item in items:
        name, eq, value = item.partition("=")
        name = name.strip()
        if not eq or not name or not value.strip():
            raise _Usage(f"--param {item!r} is not NAME=VALUE — write e.g. --param alpha=0.2 or --param f0=0.9,0.6,0.3")
        if name in out:
            raise _Usage(f"--param {name} is given twice — give each parameter once")
        try:
            out[name] = [float(v) for v in value.split(",")]
        except ValueError:
            raise _Usage(f"--param {item!r}: {value!r} is not a number or a comma-separated list of numbers — "
                         "write e.g. --param f0=0.9,0.6,0.3") from None
    return out


def load_samples(path: str):
    """The (N, 9|12) sample array of an .npy file, as float64."""
    import numpy as np

    p = Path(path)
    if not p.is_file():
        raise _Usage(f"{path}: no such file — pass an .npy file of samples with --input")
    try:
        a = np.load(p, allow_pickle=False)
    except (ValueError, OSError, EOFError) as exc:
        raise _Usage(f"{path}: not a readable .npy array ({exc}) — save the samples with numpy.save") from None
    if not isinstance(a, np.ndarray) or a.dtype.kind != "f":
        raise _Usage(f"{path}: dtype {getattr(a, 'dtype', type(a).__name__)} is not a float array — "
                     "save float32 or float64 samples")
    if a.ndim != 2 or a.shape[1] not in (9, 12):
        raise _Usage(f"{path}: shape {a.shape} — samples are (N, 9) = [L, V, N] or (N, 12) = [L, V, N, T]")
    return a.astype(np.float64)


def run(args) -> int:
    import numpy as np

    from ...library.bricks import load_library
    from ...io import atomic_write
    from ...eval.evaluate import EvalError, evaluate
    from ...matrix.permutation import SpecError
    from ...runtime.device import VulkanUnavailable

    try:
        params = parse_params(args.param)
        s = load_samples(args.input)
        lib = load_library(args.bricks or ())
        T = s[:, 9:12] if s.shape[1] == 12 else None
        f = evaluate(args.spec, s[:, 0:3], s[:, 3:6], s[:, 6:9], T=T, params=params,
                     target=args.target, dtype=args.dtype, lib=lib)
    except (_Usage, EvalError, SpecError, VulkanUnavailable) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    buf = io.BytesIO()
    np.save(buf, np.ascontiguousarray(f, dtype=np.float64))
    atomic_write(Path(args.output), buf.getvalue())
    print(f"{args.target}{'' if args.dtype is None else ' ' + args.dtype}: {len(f)} samples of "
          f"'{args.spec}' → {args.output}", file=sys.stderr)
    return 0
