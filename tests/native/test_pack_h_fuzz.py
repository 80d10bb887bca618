"""A bounded libFuzzer run of include/shadermatrix/pack.h (tests/native/fuzz_pack.c) under AddressSanitizer and
UndefinedBehaviorSanitizer, seeded with real packs: any report, crash, leak or timeout fails it. Slow (about
70 s): `pytest -m slow tests/native/test_pack_h_fuzz.py`."""
from __future__ import annotations

import re
import subprocess

import pytest

from .packs import layout
from .conftest import HERE, INCLUDE, SANITIZE, WARNINGS, compile_c, compiler
from .test_pack_h_checks import small_pack

pytestmark = [pytest.mark.toolchain, pytest.mark.slow]

SECONDS = 60
MAX_LEN = 8192  # small inputs run fast: a real pack is re-encoded from its smallest modules to fit
DICTIONARY = ['"SMPACK\\x0d\\x0a"', '"\\x01\\x00\\x00\\x00"', '"format"', '"smpack"', '"vert"', '"frag"',
              '"ubershader"', '"\\\\u00"', '"{\\"format\\":\\"smpack\\"}"', '"\\x00\\x00\\x00\\x00\\x00\\x00\\x00\\x00"']


def seeds(example_packs) -> dict[str, bytes]:
    """The format-only pack of the pack tests, each example pack's metadata (the harness also opens an input as
    the metadata of a pack), and a pack of the vulkan pack's real metadata and its smallest modules."""
    from generator.assemble.pack import encode_pack, read_pack
    out = {"format.smpack": small_pack()}
    for p in example_packs:
        data = p.read_bytes()
        out[p.name + ".meta"] = data[56:56 + layout(data)["meta_len"]]
    pack = read_pack(example_packs[0])
    small = sorted(pack["entries"].values(), key=lambda e: e.length)[:3]
    out["vulkan-small.smpack"] = encode_pack(pack["meta"], [(e.permutation, e.stage, e.input_key, e.data)
                                                             for e in small])[0]
    assert all(len(d) <= MAX_LEN for d in out.values()), {k: len(d) for k, d in out.items()}
    return out


def test_libfuzzer_finds_nothing_in_a_bounded_run(tmp_path, example_packs, sanitizer_env):
    fuzzer = tmp_path / "fuzz_pack"
    compile_c([compiler("clang-14"), "-std=c11", "-g", "-O1", *WARNINGS, "-fsanitize=fuzzer,address,undefined",
               *SANITIZE[1:], f"-I{INCLUDE}", str(HERE / "fuzz_pack.c"), "-o", str(fuzzer)],
              "the libFuzzer harness does not build")
    corpus = tmp_path / "corpus"
    corpus.mkdir()
    for name, data in seeds(example_packs).items():
        (corpus / name).write_bytes(data)
    (tmp_path / "pack.dict").write_text("\n".join(DICTIONARY) + "\n")
    r = subprocess.run([str(fuzzer), f"-max_total_time={SECONDS}", f"-max_len={MAX_LEN}", "-timeout=10", "-rss_limit_mb=2048",
                        "-print_final_stats=1", f"-dict={tmp_path / 'pack.dict'}", f"-artifact_prefix={tmp_path}/",
                        str(corpus)], capture_output=True, text=True, env=sanitizer_env, timeout=SECONDS + 60)
    out = r.stderr
    crashes = sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(("crash-", "leak-", "timeout-", "oom-")))
    assert r.returncode == 0 and not crashes, f"libFuzzer exited {r.returncode}, left {crashes}:\n{out[-6000:]}"
    runs = int(re.search(r"stat::number_of_executed_units: (\d+)", out).group(1))
    assert runs >= 20000, f"only {runs} inputs in {SECONDS} s:\n{out[-3000:]}"
