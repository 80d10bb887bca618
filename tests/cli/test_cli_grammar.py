"""One CLI grammar: the same brick-directory option everywhere, a subcommand's own usage on a usage
error, the exit codes in every --help and the same across commands (2 usage, 3 a missing tool or device, never a
silent skip), and a machine-readable build summary."""
from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "scenes" / "example.toml"
LOADS_BRICKS = ("bricks", "build", "costs", "eval", "accuracy", "render")


def run(*args, env=None):
    return subprocess.run([sys.executable, "-m", "generator.cli", *map(str, args)], cwd=REPO, capture_output=True,
                          text=True, timeout=300, env=env)


def _subparsers():
    from generator.cli import parser
    return next(a for a in parser()._actions if a.dest == "command").choices


def test_every_help_lists_the_same_exit_codes():
    from generator.cli import EXIT_CODES
    top = run("--help")
    assert top.returncode == 0 and EXIT_CODES.splitlines()[0] in top.stdout
    for name in _subparsers():
        r = run(name, "--help")
        assert r.returncode == 0, name
        text = " ".join(r.stdout.split())
        assert " ".join(EXIT_CODES.split()) in text, f"`{name} --help` does not list the exit codes"


def test_one_spelling_of_the_brick_directory_option():
    subs = _subparsers()
    for name in LOADS_BRICKS:
        actions = {o: a for a in subs[name]._actions for o in a.option_strings}
        a = actions.get("--bricks")
        assert a is not None and a.metavar == "DIR" and type(a).__name__ == "_AppendAction", name
        assert "--brick-dir" not in actions, name
    assert "--per-brick" in {o for a in subs["costs"]._actions for o in a.option_strings}


def test_an_unknown_option_prints_the_subcommands_usage_and_exits_2():
    r = run("costs", EXAMPLE, "--brick-dir", "x")
    assert r.returncode == 2
    assert r.stderr.startswith("usage: shadermatrix costs ") and "unrecognized arguments: --brick-dir x" in r.stderr
    r = run("accuracy", "lambert", "--targets", "numpy", "--samples", "0")  # a value out of range: one line
    assert r.returncode == 2 and r.stderr.startswith("error: --samples 0 is outside") and r.stderr.count("\n") == 1


def test_a_bad_option_value_is_a_usage_error_in_every_command(tmp_path):
    assert run("render", EXAMPLE, "--out", tmp_path, "--size", "big").returncode == 2
    assert run("eval", "lambert", "--input", tmp_path / "s.npy", "--out", tmp_path / "f.npy", "--target", "numpy",
               "--param", "rho_d").returncode == 2
    assert run("accuracy", "lambert", "--targets", "metal").returncode == 2
    assert run("costs").returncode == 2  # neither a scene nor --per-brick


@pytest.mark.lavapipe  # it asks the Vulkan loader for devices (and finds none)
def test_without_a_device_the_gpu_is_never_skipped_silently(tmp_path):
    env = {**os.environ, "VK_ICD_FILENAMES": str(tmp_path / "none.json"), "VK_DRIVER_FILES": str(tmp_path / "none.json")}
    env.pop("SHADERMATRIX_FORBID_DEVICE", None)
    r = run("accuracy", "lambert", "--samples", "2", env=env)
    assert r.returncode == 3 and "no lavapipe Vulkan device" in r.stderr and "--targets numpy" in r.stderr, r.stderr
    r = run("accuracy", "lambert", "--samples", "2", "--targets", "numpy", "--dtypes", "float64", env=env)
    assert r.returncode == 0, r.stderr  # the GPU left out on purpose


@pytest.mark.toolchain
def test_a_missing_tool_exits_3(tmp_path):
    env = {**os.environ, "PATH": str(tmp_path)}  # no glslc, no spirv-tools
    r = run("build", EXAMPLE, "--out", tmp_path / "out", "--no-cache", env=env)
    assert r.returncode == 3 and "not found" in r.stderr and "make setup" in r.stderr, r.stderr


@pytest.mark.toolchain
def test_build_json_is_the_summary_as_data(tmp_path):
    r = run("build", EXAMPLE, "--out", tmp_path / "out", "--cache-dir", tmp_path / "cache", "--json")
    assert r.returncode == 0, r.stderr
    s = json.loads(r.stdout)
    manifest = json.loads((tmp_path / "out" / "manifest.json").read_text())
    assert s["permutations"] == len(manifest["permutations"]) == s["built"] and s["ok"] and s["failures"] == []
    assert s["shaders"] == s["distinct"] + s["merged"] and s["distinct"] == s["from_cache"] + s["compiled"]
    again = json.loads(run("build", EXAMPLE, "--out", tmp_path / "out", "--cache-dir", tmp_path / "cache",
                           "--json").stdout)
    assert again["up_to_date"] == s["permutations"] and again["files_written"] == 0 and again["built"] == 0


@pytest.mark.toolchain
def test_a_cost_budget_lists_the_shaders_over_it_and_exits_1(tmp_path):
    """`costs SCENE --budget …`: a CI holds a per-shader budget; every shader over it is one line, located at the
    scene line of the material that asks for it."""
    cache = ("--cache-dir", tmp_path / "cache")
    roomy = run("costs", EXAMPLE, "--format", "json", "--budget", "alu=100000,texture=1000", *cache)
    assert roomy.returncode == 0, roomy.stderr
    assert roomy.stderr.splitlines()[-1].startswith("budget alu ≤ 100000, texture ≤ 1000: 0 of ")
    rows = [r for r in json.loads(roomy.stdout)["rows"] if r["alu"] is not None]
    alu = sorted(r["alu"] for r in rows)
    limit = alu[len(alu) // 2]  # about half the shaders are over it
    tight = run("costs", EXAMPLE, "--format", "json", "--budget", f"alu={limit}", *cache)
    assert tight.returncode == 1
    over = [line for line in tight.stderr.splitlines() if re.match(rf"error: {re.escape(str(EXAMPLE))}:\d+:\d+: ", line)]
    # one line per shader (a stage of a permutation, or of the ubershader), whichever of its languages are over
    assert len(over) == len({(r["subject"], r["stage"]) for r in rows if r["alu"] > limit}) > 0, tight.stderr
    assert all("alu " in line and f"> {limit}" in line for line in over)
    assert any("; objects " in line for line in over)  # a permutation's line names the objects drawn with it
    assert run("costs", EXAMPLE, "--budget", "alu=lots").returncode == 2
    assert run("costs", EXAMPLE, "--budget", "speed=3").returncode == 2


@pytest.mark.toolchain
def test_cost_rows_name_materials_and_objects_sort_and_mean_one_thing_per_column(tmp_path):
    import csv
    import io
    cache = ("--cache-dir", tmp_path / "cache")
    r = run("costs", EXAMPLE, "--format", "csv", "--sort", "alu", *cache)
    assert r.returncode == 0, r.stderr
    rows = list(csv.DictReader(io.StringIO(r.stdout)))
    shaders = [x for x in rows if x["table"] == "permutation"]
    assert all(x["kind"] == "" and x["measured"] == "" and x["key"].startswith("brdf=") for x in shaders)
    assert {x["materials"] for x in shaders if "statue" in x["objects"]} == {"polished_gold"}
    alu = [int(x["alu"]) for x in rows if x["alu"]]
    assert alu == sorted(alu, reverse=True)  # --sort alu: the costliest first
    md = run("costs", EXAMPLE, *cache)
    assert "| permutation | materials | objects | stage |" in md.stdout
    assert re.search(r"^Totals of the 5 frag shaders: tex \d+, ALU \d+, .*; the most registers: \d+ \(`\w{12}`, ",
                     md.stdout, re.M)
    assert run("costs", EXAMPLE, "--sort", "speed").returncode == 2


@pytest.mark.toolchain
def test_a_cost_diff_shows_what_a_change_cost_shader_by_shader(tmp_path):
    cache = ("--cache-dir", tmp_path / "cache")
    before = run("costs", EXAMPLE, "--format", "json", *cache)
    assert before.returncode == 0, before.stderr
    same = tmp_path / "same.json"
    same.write_text(before.stdout)
    r = run("costs", EXAMPLE, "--diff", same, *cache)
    assert r.returncode == 0 and "0 shaders changed, 0 new or gone" in r.stdout, r.stdout
    doc = json.loads(before.stdout)  # an earlier report in which one shader was cheaper and one did not exist
    rows = [x for x in doc["rows"] if x["table"] == "permutation"]
    rows[0]["alu"] -= 5
    gone = doc["rows"].pop(doc["rows"].index(rows[1]))
    doc["rows"].append({**rows[2], "subject": "0123456789ab"})
    old = tmp_path / "old.json"
    old.write_text(json.dumps(doc))
    r = run("costs", EXAMPLE, "--diff", old, *cache)
    assert r.returncode == 0, r.stderr
    assert "1 shaders changed, 2 new or gone" in r.stdout, r.stdout
    assert f"| {rows[0]['stage']} | {rows[0]['language']} | alu | {rows[0]['alu']} | {rows[0]['alu'] + 5} | +5 |" \
        in r.stdout
    assert f"- new: permutation `{gone['subject']}`" in r.stdout and "- gone: permutation `0123456789ab`" in r.stdout
    # shader-db's summary: the total over the shaders both have, the one it changed in, 0 helped and 1 hurt
    total = sum(x["alu"] for x in doc["rows"] if x["subject"] != "0123456789ab" and x["alu"] is not None)
    a = rows[0]["alu"]
    assert f"| alu | {total} → {total + 5} | {5 / total * 100:+.2f}% | {a} → {a + 5} | {5 / a * 100:+.2f}% | 0 | 1 |" \
        in r.stdout.split("## Helped and hurt")[1], r.stdout
    (tmp_path / "junk.json").write_text("{}")
    bad = run("costs", EXAMPLE, "--diff", tmp_path / "junk.json", *cache)
    assert bad.returncode == 1 and "not a `costs --format json` report" in bad.stderr


def _complete(script: str, *words: str) -> list[str]:
    """What bash offers for the last word of `shadermatrix WORDS...`, through the generated completion function."""
    line = " ".join(("shadermatrix",) + words)
    program = (f'source "$1"; COMP_WORDS=(shadermatrix {" ".join(words)}); COMP_CWORD={len(words)}; '
               f'COMP_LINE="{line}"; COMP_POINT=${{#COMP_LINE}}; _shtab_shadermatrix; printf "%s\\n" "${{COMPREPLY[@]}}"')
    r = subprocess.run(["bash", "-c", program, "bash", script], capture_output=True, text=True, timeout=30)
    assert r.returncode == 0, r.stderr
    return r.stdout.split()


def test_bash_completion_offers_every_command_and_option(tmp_path):
    r = run("completion", "bash")
    assert r.returncode == 0, r.stderr
    script = tmp_path / "shadermatrix.bash"
    script.write_text(r.stdout)
    assert _complete(str(script), "acc") == ["accuracy"]
    assert _complete(str(script), "costs", "--bu") == ["--budget"]
    assert set(_complete(str(script), "")) == set(_subparsers())  # every command, from the parser itself
    assert run("completion", "fish").returncode == 2
