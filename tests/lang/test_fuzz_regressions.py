"""Regression cases of the coverage-guided fuzzer, benchmarks/fuzz_parsers.py (results in
benchmarks/results/fuzz_parsers.md): each case is the exact input a campaign reported, and the message the
parser now gives for it — one line, `path: …` (the samples reader) or `path:line:col: …`, with ` — what to do`,
and nothing printed besides it."""
from __future__ import annotations

import base64
import re
import warnings

import pytest

LOCATED = re.compile(r"^[^\n]+:\d+:\d+: [^\n]+$")

# samples target, seed 1: numpy's .npy header parser tokenizes a header it cannot literal_eval, and its
# tokenize.TokenError ("EOF in multi-line statement") escaped load_samples as a traceback (found by the first
# campaign; fixed in generator/cli/commands/eval.py by aa8f717, which catches TokenError).
TOKEN_ERROR = base64.b64decode(
    "k05VTVBZAQB2AHsnZGVzY3InOiAnPGY0JywgJ2ZvcnRyYW5fb3JkZXInOiBGYWxzZSwgJ3NoYXBlJzogKDAsIDkpLCB9ICAgICAgICAgICAg"
    "/yB9ICAgICAgICAgICAgICAgICAgICAgICAgICAgIKQgICAgICAgICAgICAgICAgICAgICAgICAgICAgICAK")
# samples target: numpy's header parser makes Python print a warning before `shadermatrix eval`'s one-line error —
# "<unknown>:1: SyntaxWarning: invalid decimal literal" (twice) for a header numpy compiles, "UserWarning: Reading
# `.npy` or `.npz` file required additional header parsing as it was created on Python 2" for one it has to filter
# (both found by the campaign of benchmarks/results/fuzz_parsers.md: samples, seed 1), and "DeprecationWarning:
# invalid escape sequence '\['" (found while the harness counted every warning: Python 3.11 does not print it by
# default; 3.12 makes it a SyntaxWarning, printed). load_samples now reads the header and np.load under
# warnings.catch_warnings() with them ignored: its one-line error says what is wrong.
SYNTAX_WARNING = base64.b64decode(
    "k05VTVBZAQB2AHsnZGVzY3InOigwLCA5KSwgJ2ZvcnRyYW5fb3JkZXInOiBGYWxzZSwgJ3NoYXBlJzogKDEsIDlvcigzLCA5KSAgICAgICAg"
    "ICAgICAgICAgICA6KDAsIDkpLCAnZm9ydHJhbl9vcmRlcic6IEZhbHNlLCAnc2hhcGUnOiAoMSwgOW9ydH0gICAgICAgICAgICAgICAgICAg"
    "ICAgICAgICAgICAgICAgICAgICAgICAgICAgICAgICAgICAgICAgCiAgICAgICAgICAgICAgICAgICAgICAgICAgICAgICAgICAgCr/sHjUy"
    "KaB8")
PYTHON2_WARNING = base64.b64decode(
    "k05VTVBZAQB2AHsnZGVzY3InOiAnMGYoJywgJ2ZvcnRyYW5fb3Lu7u7u7u7u7u7u7u7u7u7u7u7u7u7u7u7u7u7u7u5kZXInOiBGYWxzZSwg"
    "J3NoYXBlJzogKDEsIDkpLCB9ICAgICAgICAgCiAgICAgICAgICAgICAgICAgICAgICAgICAgICAgICAgICAgICAgICAgICAgICAgICAKv+we"
    "NDYpoHy/aojAzxzo8D/ejYONEoG/TWiIJe3QUYvTcxpQehN/P9034Y63Zwm/i79NaIjacOdL2sq/24sFxrLcKg==")
ESCAPE_WARNING = base64.b64decode(
    "k05VTVBZAQB2AHsnZGVzY3InOiAnPGY4JywgJ2ZvcnRyMqSkpKRcW1tbW1tbZKSkpKSkpKSkpKSkpKSkpKSkpKSkpKSkpKSkpKSkpKSkpKSk"
    "pKSkpKSkpKSkpKSkpKSkpKSkYW5fb3JkZXInOiBGYWxzZSwgJ3NoYXBlJzogKCAgICAgICAgICAgICAgICAgICAgICAgICAgIKSkpKSkCg==")


def _samples_message(tmp_path, data: bytes) -> tuple[str, list]:
    from generator.cli.commands.eval import _BadInput, load_samples

    path = tmp_path / "case.npy"
    path.write_bytes(data)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with pytest.raises(_BadInput) as e:
            load_samples(str(path))
    text = str(e.value)
    assert text.startswith(f"{path}: ") and " — " in text and "\n" not in text, text
    return text, [f"{w.category.__name__}: {w.message}" for w in caught]


def test_a_header_numpy_cannot_tokenize_is_one_line(tmp_path):
    text, printed = _samples_message(tmp_path, TOKEN_ERROR)
    # numpy reads the header with tokenize on 3.11 ("EOF in multi-line statement"); 3.12's tokenizer lets it
    # through to ast.literal_eval, and numpy says "Cannot parse header": either way one line, with the reason
    assert "not a readable .npy array" in text, text
    assert "EOF in multi-line statement" in text or "Cannot parse header" in text, text
    assert not printed, printed


@pytest.mark.parametrize("data", [SYNTAX_WARNING, PYTHON2_WARNING, ESCAPE_WARNING],
                         ids=["SyntaxWarning", "Python-2-header", "invalid-escape"])
def test_a_header_numpy_compiles_prints_no_warning(data, tmp_path):
    text, printed = _samples_message(tmp_path, data)
    assert "not a readable .npy array" in text, text
    assert not printed, printed
