"""Coverage-guided fuzzing of the input parsers with atheris: hostile and malformed inputs.

    .venv/bin/python benchmarks/fuzz_parsers.py TARGET [--seconds S | --runs N] [--seed N] [--keep-going]
        [--all-warnings] [--artifacts DIR] [--corpus DIR] [-- LIBFUZZER_ARGS]

TARGET is one of
  brick    generator.library.bricks.load_brick on a file holding the fuzzed bytes, and the language alone
           (generator.lang.parse_module) on the same text
           (seeds: every shipped brick, bricks/**/*.py, and the test bricks under tests/);
  scene    generator.scene.load.load_scene with the built-in library (seeds: scenes/*.toml, tests/scenes/*.toml);
  samples  the eval samples reader, load_samples of generator/cli/commands/eval.py, checked and unchecked
           (seeds: small valid .npy files of (N, 9) and (N, 12) float32/float64 samples).

The property, per input: the call returns, or raises SourceError/UserError whose message is one line
`path:line:col: what is wrong — what to do` naming the fuzzed file (the samples reader, which reads a binary
file, says `path: what is wrong — what to do` and raises its own usage error). Anything else — another
exception, a message of several lines or without its hint, a warning Python prints besides the message — is a
finding: it is raised, and atheris (libFuzzer) reports it with the input (saved as crash-<sha1> under
--artifacts) and stops. --keep-going records each distinct finding (by exception type and raising line) under --artifacts instead and goes on.
An input that takes longer than --timeout seconds is a finding too (libFuzzer's -timeout).

--seed is libFuzzer's -seed (the mutation sequence); --runs / --seconds bound the run (-runs,
-max_total_time); arguments after `--` go to libFuzzer unchanged. The corpus grows in a temporary directory
unless --corpus DIR keeps it. The last line printed is a summary: runs, execs/s, coverage (libFuzzer's
`cov:` edges and `ft:` features), corpus size, findings. Results of a campaign: benchmarks/results/fuzz_parsers.md.
"""
from __future__ import annotations

import argparse
import hashlib
import io
import json
import re
import shutil
import subprocess
import sys
import tempfile
import time
import traceback
import types
import warnings
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))

TARGETS = ("brick", "scene", "samples")
LOCATED = re.compile(r"^[^\n]+:\d+:\d+: [^\n]+$")
SAMPLES_MESSAGE = re.compile(r"^[^\n]+: [^\n]+$")


class Finding(AssertionError):
    """An input that broke the property (raised so that atheris reports it)."""


def seeds(target: str) -> list[tuple[str, bytes]]:
    """(name, bytes) of the seed corpus of a target."""
    if target == "brick":  # the shipped bricks, and the test bricks (loops, match, arrays, buffers, textures)
        paths = sorted((REPO / "bricks").rglob("*.py")) + sorted(
            p for d in ("bricks", "link_bricks", "eval_bricks", "fixtures/cost_bricks")
            for p in (REPO / "tests" / d).rglob("*.py"))
        return [(p.relative_to(REPO).as_posix().replace("/", "_"), p.read_bytes()) for p in paths]
    if target == "scene":
        paths = sorted((REPO / "scenes").glob("*.toml")) + sorted((REPO / "tests" / "scenes").glob("*.toml"))
        return [(p.relative_to(REPO).as_posix().replace("/", "_"), p.read_bytes()) for p in paths]
    import numpy as np

    rng = np.random.default_rng(0)
    out = []
    for n, cols, dtype in ((3, 9, "<f8"), (2, 12, "<f4"), (1, 9, ">f8"), (0, 9, "<f8")):
        v = rng.normal(size=(n, cols // 3, 3))
        v /= np.linalg.norm(v, axis=2, keepdims=True)
        buf = io.BytesIO()
        np.save(buf, v.reshape(n, cols).astype(dtype))
        out.append((f"samples_{n}x{cols}_{dtype[1:]}.npy", buf.getvalue()))
    return out


def dictionary(target: str) -> list[bytes]:
    """Tokens libFuzzer may insert whole (-dict): the words of the format, so mutations reach past the lexer."""
    if target == "brick":
        import keyword

        from generator.lang.intrinsics import CONSTANTS, INTRINSICS
        from generator.lang.types import BUILTIN_TYPES
        from generator.library.bricks import META_KEYS, PARAM_KEYS, PARAM_TYPES
        from generator.library.inputs import BY_NAME
        from generator.library.kinds import KINDS
        words = [*keyword.kwlist, *INTRINSICS, *CONSTANTS, *BUILTIN_TYPES, *BY_NAME, *PARAM_TYPES,
                 "array", "storage_buffer", "uniform_buffer", "range", "match", "case", "->", "BRICK", "srgb",
                 *(f'"{k}"' for k in (*META_KEYS, *PARAM_KEYS, *KINDS)), "1e400", "3000000000", "    ", "\n", "__"]
        for k in KINDS.values():
            words += [e.name for e in k.entries]
    elif target == "scene":
        from generator.library.bricks import load_library
        lib = load_library()
        words = ["[scene]", "[materials.", "[lights.", "[light_sets]", "[[objects]]", "name", "output", "precision",
                 "brdf", "packing", "params", "type", "shadow", "material", "lights", "fp32", "fp16", "inf", "nan",
                 "1e400", "true", "1979-05-27", "{ ", " }", '"""', "'''", "\\u", "+", "(", ")", ",", "=", "\n",
                 *sorted({b.id for b in lib.bricks.values()}),
                 *sorted({p for b in lib.bricks.values() for p in b.params}),
                 *sorted({s for b in lib.bricks.values() for s in b.slots})]
    else:
        words = ["\x93NUMPY", "\x01\x00", "\x02\x00", "\x03\x00", "{'descr': ", "'fortran_order': ", "'shape': ",
                 "'<f8'", "'>f8'", "'<f4'", "'<f2'", "'<f16'", "'|O'", "'<c16'", "'|V8'", "[('a', '<f8')]", "True",
                 "False", "(0, 9)", "(1, 12)", "(3, 9)", "(-1, 9)", "(99999999999, 9)", "(9,)", "()", "}", "\n"]
    return [w.encode("latin-1") if target == "samples" else w.encode() for w in words]


def _dict_line(word: bytes) -> str:
    """One entry of a libFuzzer dictionary file: the word quoted, every other byte as \\xNN."""
    return '"' + "".join(chr(c) if 32 <= c < 127 and c not in b'"\\' else f"\\x{c:02x}" for c in word) + '"\n'


def _message_ok(text: str, shown: str, located: bool) -> str:
    """'' when an error message keeps the rule, else what is wrong with it."""
    if "\n" in text or "\r" in text:
        return "the message has more than one line"
    if located and not LOCATED.match(text):
        return "the message is not `path:line:col: what`"
    if not located and not SAMPLES_MESSAGE.match(text):
        return "the message is not `path: what`"
    if " — " not in text:
        return "the message has no ' — what to do'"
    if not text.startswith(shown + ":"):
        return f"the message does not name the file ({shown})"
    return ""


def make_target(target: str, workdir: Path, all_warnings: bool = False):
    """The one-input test function of a target: raises Finding (or lets an unexpected exception through).
    A warning Python would print with its default filters (numpy's header parser compiles the header:
    SyntaxWarning) is a finding too: the user would see lines besides the one message. Deprecation, import and
    resource warnings are not printed by default (an invalid escape in a header is a DeprecationWarning in 3.11,
    a SyntaxWarning from 3.12: --all-warnings counts them as well)."""
    one = _target(target, workdir)
    quiet_by_default = () if all_warnings else (DeprecationWarning, PendingDeprecationWarning, ImportWarning,
                                                ResourceWarning)

    def quiet(data: bytes) -> None:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")  # every occurrence, not once per location
            for category in quiet_by_default:
                warnings.simplefilter("ignore", category)
            one(data)
        if caught:
            w = caught[0]
            raise Finding(f"a warning is printed besides the message: {w.category.__name__}: {w.message}")
    return quiet


def _target(target: str, workdir: Path):
    from generator.lang.errors import SourceError, UserError

    if target == "brick":
        from generator.library.bricks import load_brick

        path = workdir / "fz.py"  # the brick id is the file stem: a valid one, so the stem is not what is fuzzed
        shown = str(path)

        from generator.lang import parse_module

        def one(data: bytes) -> None:
            path.write_bytes(data)
            try:
                load_brick(path, shown=shown)
            except (SourceError, UserError) as e:
                problem = _message_ok(str(e), shown, located=True)
                if problem:
                    raise Finding(f"{problem}: {str(e)!r}") from e
            try:  # the language alone, whatever BRICK says (the test bricks' kind "test" stops load_brick early)
                parse_module(data.decode("utf-8"), shown)
            except UnicodeDecodeError:
                pass  # load_brick has had these bytes (a located error)
            except (SourceError, UserError) as e:
                problem = _message_ok(str(e), shown, located=True)
                if problem:
                    raise Finding(f"{problem}: {str(e)!r}") from e
        return one

    if target == "scene":
        from generator.library.bricks import load_library
        from generator.scene.load import load_scene

        lib = load_library()
        path = workdir / "fz.toml"
        shown = str(path)

        def one(data: bytes) -> None:
            path.write_bytes(data)
            try:
                load_scene(path, lib)
            except (SourceError, UserError) as e:
                problem = _message_ok(str(e), shown, located=True)
                if problem:
                    raise Finding(f"{problem}: {str(e)!r}") from e
        return one

    import numpy as np
    from generator.cli.commands import eval as eval_command

    usage = getattr(eval_command, "_Usage")
    path = workdir / "fz.npy"
    shown = str(path)

    def one(data: bytes) -> None:
        path.write_bytes(data)
        for checked in (True, False):
            try:
                a = eval_command.load_samples(shown, checked=checked)
            except (usage, UserError) as e:
                problem = _message_ok(str(e), shown, located=isinstance(e, SourceError))
                if problem:
                    raise Finding(f"{problem}: {str(e)!r}") from e
                continue
            if not (isinstance(a, np.ndarray) and a.dtype == np.float64 and a.ndim == 2 and a.shape[1] in (9, 12)):
                raise Finding(f"returned {type(a).__name__} {getattr(a, 'dtype', '')} {getattr(a, 'shape', '')}, "
                              "not float64 (N, 9|12) samples")
            if checked and not np.isfinite(a).all():
                raise Finding("a checked read returned non-finite samples")
    return one


def _signature(exc: BaseException) -> str:
    """A finding's identity: exception type and the innermost frame of the repository that raised it."""
    tb = traceback.extract_tb(exc.__traceback__)
    ours = [f for f in tb if f.filename.startswith(str(REPO / "generator"))] or tb
    f = ours[-1] if ours else None
    where = f"{Path(f.filename).relative_to(REPO) if str(REPO) in f.filename else f.filename}:{f.lineno}" if f else "?"
    inner = exc.__cause__ if isinstance(exc, Finding) and exc.__cause__ is not None else exc
    if isinstance(exc, Finding) and exc.__cause__ is None:  # a broken rule with no exception: what broke it
        where = re.sub(r"['\"].*", "", str(exc))[:100]
    return f"{type(exc).__name__}({type(inner).__name__}) at {where}"


def child(args) -> None:
    """Runs inside libFuzzer: instrument the generator, then fuzz one target."""
    import atheris
    import numpy.lib.format as npy_format  # numpy itself is not instrumented: only the .npy header parser below

    # not tomllib or jsonschema: instrumented, tomllib segfaults under Python 3.11
    with atheris.instrument_imports(include=["generator"]):
        import generator.lang  # noqa: F401
        import generator.library.bricks  # noqa: F401
        import generator.library.schema  # noqa: F401
        import generator.scene.load  # noqa: F401
        import generator.scene.schema  # noqa: F401
        import generator.spec.permutation  # noqa: F401
        import generator.cli.commands.eval  # noqa: F401
    if args.target == "samples":  # the samples reader relies on it: its branches are coverage too
        for fn in vars(npy_format).values():
            if isinstance(fn, types.FunctionType) and fn.__module__ == npy_format.__name__:
                atheris.instrument_func(fn)
    work = Path(tempfile.mkdtemp(prefix="fuzz_parsers_"))
    one = make_target(args.target, work, args.all_warnings)
    artifacts = Path(args.artifacts)
    seen: set[str] = set()

    def test(data: bytes) -> None:
        try:
            one(data)
        except Exception as e:  # noqa: BLE001 — every other exception is what the fuzzer is looking for
            if not args.keep_going:
                raise
            sig = _signature(e)
            if sig not in seen:
                seen.add(sig)
                name = f"finding-{hashlib.sha1(data).hexdigest()}"
                (artifacts / name).write_bytes(data)
                with open(artifacts / "findings.jsonl", "a") as f:
                    f.write(json.dumps({"target": args.target, "signature": sig, "input": name,
                                        "error": f"{type(e).__name__}: {e}"[:2000]}) + "\n")
                print(f"FINDING {sig}: {type(e).__name__}: {str(e)[:300]!r} -> {artifacts / name}", file=sys.stderr,
                      flush=True)

    atheris.Setup([sys.argv[0], *args.libfuzzer], test)
    atheris.Fuzz()


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("target", choices=TARGETS)
    p.add_argument("--seconds", type=int, help="stop after this many seconds (libFuzzer -max_total_time)")
    p.add_argument("--runs", type=int, help="stop after this many inputs (libFuzzer -runs)")
    p.add_argument("--seed", type=int, default=1, help="libFuzzer's -seed (default 1)")
    p.add_argument("--timeout", type=int, default=10, help="seconds one input may take (default 10)")
    p.add_argument("--keep-going", action="store_true", help="record each distinct finding and go on")
    p.add_argument("--all-warnings", action="store_true",
                   help="count every warning as a finding, also those Python does not print by default")
    p.add_argument("--corpus", help="keep the corpus in this directory (default: a temporary one)")
    p.add_argument("--artifacts", default=".", help="where failing inputs are written (default: .)")
    p.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    argv = list(sys.argv[1:] if argv is None else argv)
    cut = argv.index("--") if "--" in argv else len(argv)
    args = p.parse_args(argv[:cut])
    args.libfuzzer = argv[cut + 1:]  # after --: arguments for libFuzzer
    if args.child:
        child(args)
        return 0
    if args.seconds is None and args.runs is None:
        p.error("give --seconds S or --runs N")
    artifacts = Path(args.artifacts).resolve()
    artifacts.mkdir(parents=True, exist_ok=True)
    corpus = Path(args.corpus) if args.corpus else Path(tempfile.mkdtemp(prefix=f"fuzz_{args.target}_corpus_"))
    corpus.mkdir(parents=True, exist_ok=True)
    for name, data in seeds(args.target):
        (corpus / name).write_bytes(data)
    dict_file = corpus.parent / f"{corpus.name}.dict"
    dict_file.write_text("".join(_dict_line(w) for w in dictionary(args.target)))
    lf = [f"-seed={args.seed}", f"-dict={dict_file}", f"-timeout={args.timeout}", "-print_final_stats=1",
          "-rss_limit_mb=4096", f"-artifact_prefix={artifacts}/"]
    if args.seconds is not None:
        lf.append(f"-max_total_time={args.seconds}")
    if args.runs is not None:
        lf.append(f"-runs={args.runs}")
    cmd = [sys.executable, str(Path(__file__).resolve()), args.target, "--child", "--artifacts", str(artifacts),
           *(["--keep-going"] if args.keep_going else []), *(["--all-warnings"] if args.all_warnings else []),
           "--", *lf, *args.libfuzzer, str(corpus)]
    findings_file = artifacts / "findings.jsonl"
    before = findings_file.read_text().count("\n") if findings_file.exists() else 0
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, stderr=subprocess.PIPE, text=True, errors="replace")
    cov = ft = corp = None
    stats: dict[str, str] = {}
    crashed = []
    for line in proc.stderr:
        if not line.startswith("INFO: Instrumenting "):  # one line per module atheris instruments
            sys.stderr.write(line)
        m = re.search(r"\bcov: (\d+) ft: (\d+) corp: (\d+)", line)
        if m:
            cov, ft, corp = (int(x) for x in m.groups())
        m = re.match(r"stat::(\w+):\s+(\d+)", line)
        if m:
            stats[m[1]] = m[2]
        m = re.search(r"Test unit written to (\S+)", line)
        if m:
            crashed.append(m[1])
    rc = proc.wait()
    wall = time.perf_counter() - t0
    dict_file.unlink(missing_ok=True)
    if not args.corpus:
        shutil.rmtree(corpus, ignore_errors=True)
    after = findings_file.read_text().count("\n") if findings_file.exists() else 0
    found = (after - before) + len(crashed)
    runs = int(stats.get("number_of_executed_units", 0))
    summary = {"target": args.target, "seed": args.seed, "runs": runs, "seconds": round(wall, 1),
               "execs_per_s": max(int(stats.get("average_exec_per_sec", 0)), round(runs / wall)),
               "cov": cov, "ft": ft, "corpus": corp, "findings": found, "exit": rc}
    print(json.dumps(summary))
    return 0 if found == 0 and rc == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
