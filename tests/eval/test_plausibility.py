"""Plausibility from the bricks alone, and `accuracy` per material where a brick has no float64 reference.

An engine's brick directory (a cloth sheen written here: Charlie sheen, Estevez & Kulla 2017) in a scene
with built-in materials: every material is reported, the engine one with plausibility and its precision
error; implausible engine bricks fail naming the check and the material's scene line; `--reference` runs a
user's file of independent references. Every built-in brick passes plausibility (sampled; all under slow).
"""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

from generator.cli import main
from generator.eval import accuracy, plausibility
from generator.library.bricks import load_library
from generator.reference import REFERENCES
from tests.lavapipe import device  # noqa: F401 (fixture)

CHARLIE = '''"""Charlie sheen, a cloth lobe (Estevez & Kulla 2017, "Production Friendly Microfacet Sheen BRDF").

D = (2 + 1/alpha) sin(theta_h)^(1/alpha) / (2 pi) (their eq. 2) with Neubelt & Pettineo's visibility
V = 1 / (4 (n.l + n.v - n.l n.v)): f = sheen D V.
"""
BRICK = {
    "kind": "specular",
    "cite": "Estevez & Kulla 2017 eq. 2; Neubelt & Pettineo 2013 (visibility)",
    "params": {
        "alpha": {"type": "float", "range": [0.07, 1.0], "default": 0.5, "doc": "sheen roughness"},
        "sheen": {"type": "vec3", "range": [0.0, 1.0], "default": [0.5, 0.5, 0.5], "doc": "sheen colour"},
    },
    "needs": ["NdotL", "NdotV", "NxH2"],
}


def specular(NdotL: float, NdotV: float, NxH2: float, alpha: float, sheen: vec3) -> vec3:
    inv = 1.0 / alpha
    d = (2.0 + inv) * pow(NxH2, 0.5 * inv) * INV_TWO_PI
    v = 1.0 / (4.0 * (NdotL + NdotV - NdotL * NdotV))
    return sheen * (d * v)
'''

# Written from the paper with NumPy, not from the brick: the user's independent reference.
CHARLIE_REFERENCE = '''
import numpy as np
from generator.reference import reference


@reference("specular", "charlie_sheen")
def charlie_sheen(g, p, slots):
    """Estevez & Kulla 2017 eq. 2, sin(theta_h) = |n x h|; Neubelt & Pettineo's V."""
    a = p["alpha"][:, None] if np.ndim(p["alpha"]) else p["alpha"]
    d = (2.0 + 1.0 / a) * np.sqrt(g.NxH2)[:, None] ** (1.0 / a) / (2.0 * np.pi)
    v = 1.0 / (4.0 * (g.NdotL + g.NdotV - g.NdotL * g.NdotV))[:, None]
    return p["sheen"] * d * v
'''

DIFFUSE = '''"""{doc}"""
BRICK = {{
    "kind": "diffuse",
    "cite": "test brick",{extra}
    "params": {{"rho_d": {{"type": "vec3", "range": [0.0, 1.0], "default": [1.0, 1.0, 1.0]}}}},
    "needs": ["NdotL", "NdotV"],
}}


def diffuse(NdotL: float, NdotV: float, rho_d: vec3) -> vec3:
    return rho_d * ({expr})
'''
BRIGHT = DIFFUSE.format(doc="Reflects 1.5 times what it receives (a test probe).", extra="", expr="1.5 * INV_PI")
NEGATIVE = DIFFUSE.format(doc="A lobe that goes negative towards grazing light (a test probe).", extra="",
                          expr="INV_PI * (1.5 * NdotL * NdotV - 0.1)")
ONE_SIDED = DIFFUSE.format(doc="Brighter where the light is high: not reciprocal (a test probe).", extra="",
                           expr="INV_PI * (0.5 + 0.5 * NdotL)")
ONE_SIDED_DECLARED = DIFFUSE.format(
    doc="Brighter where the light is high: not reciprocal (a test probe).",
    extra='\n    "reciprocal": "no: the test probe reads n.l alone",', expr="INV_PI * (0.5 + 0.5 * NdotL)")

SCENE = '''[scene]
name = "cloth"

[materials.chalk]
brdf = "lambert"
params = {{ rho_d = [0.9, 0.8, 0.7] }}

[materials.velvet]
brdf = "{brdf}"
params = {{ {params} }}

[materials.gold]
brdf = "microfacet(ndf=ggx,fresnel=schlick,vis=smith_schlick)"
params = {{ alpha = 0.2, f0 = [1.0, 0.71, 0.29] }}

[lights.sun]
type = "directional"
params = {{ direction = [0.0, 1.0, 0.0], color = [1.0, 1.0, 1.0] }}

[light_sets]
day = ["sun"]

[[objects]]
name = "sofa"
material = "velvet"
lights = "day"

[[objects]]
name = "wall"
material = "chalk"
lights = "day"

[[objects]]
name = "ring"
material = "gold"
lights = "day"
'''
VELVET_LINE = 9  # `brdf = ...` of [materials.velvet] in SCENE


def _bricks(tmp_path, **files) -> str:
    d = tmp_path / "engine"
    d.mkdir(exist_ok=True)
    for name, text in files.items():
        (d / f"{name}.py").write_text(text)
    return str(d)


def _scene(tmp_path, brdf="lambert+charlie_sheen",
           params="rho_d = [0.3, 0.05, 0.1], alpha = 0.4, sheen = [0.9, 0.5, 0.6]") -> str:
    p = tmp_path / "cloth.toml"
    p.write_text(SCENE.format(brdf=brdf, params=params))
    return str(p)


def _accuracy(capsys, *argv):
    rc = main(["accuracy", *argv, "--samples", "3", "--format", "json"])
    cap = capsys.readouterr()
    return rc, (json.loads(cap.out) if cap.out.strip() else None), cap.err


@pytest.mark.lavapipe
@pytest.mark.toolchain  # compiles eval kernels
def test_engine_brick_without_reference_is_reported_with_the_other_materials(tmp_path, capsys, device):  # noqa: F811
    bricks = _bricks(tmp_path, charlie_sheen=CHARLIE)
    rc, rep, err = _accuracy(capsys, _scene(tmp_path), "--bricks", bricks, "--targets", "numpy,glsl",
                             "--dtypes", "float64,float32,float16")
    assert rc == 0, err
    by = {v["spec"]: v for v in rep["verdicts"]}
    assert list(by) == ["chalk: lambert", "velvet: lambert+charlie_sheen",
                        "gold: microfacet(ndf=ggx,fresnel=schlick,vis=smith_schlick)"]
    assert all(v["pass"] for v in by.values())
    velvet = by["velvet: lambert+charlie_sheen"]
    assert velvet["against"] == "precision error (no independent reference)"
    assert velvet["reference"]["missing"] == ["specular/charlie_sheen"] and velvet["plausibility"] == "pass"
    assert by["chalk: lambert"]["against"] == "float64 reference" and by["chalk: lambert"]["plausibility"] is None
    # the precision error: the GPU's float32 and float16 against the NumPy target at float64 (which is not a run)
    runs = {(r["target"], r["dtype"]) for r in rep["results"] if r["spec"] == velvet["spec"]}
    assert ("glsl", "float32") in runs and ("glsl", "float16") in runs and ("numpy", "float64") not in runs
    assert 0 < velvet["hemisphere_max_rel"] < 1e-4
    (plaus,) = rep["plausibility"]
    checks = {c["check"]: c for c in plaus["checks"]}
    assert list(checks) == ["non-negative", "reciprocity", "albedo", "float32 finite", "float16 finite"]
    assert all(c["pass"] for c in checks.values()) and checks["reciprocity"]["value"] < 1e-12
    assert 0.3 < checks["albedo"]["value"] < 1.0
    assert "no float64 reference for specular/charlie_sheen" in err and "3 of 3 specs pass" in err
    md = accuracy.markdown(rep)
    assert "## Plausibility" in md and "| `velvet: lambert+charlie_sheen` | pass |" in md


@pytest.mark.parametrize("probe,check,needle", [(BRIGHT, "albedo", "E = 1.5"),
                                                (NEGATIVE, "non-negative", "f = -")], ids=["albedo", "negative"])
def test_implausible_engine_brick_fails_at_the_material_line(tmp_path, capsys, probe, check, needle):
    bricks = _bricks(tmp_path, probe=probe)
    scene = _scene(tmp_path, brdf="probe", params="rho_d = [1.0, 1.0, 1.0]")
    rc, rep, err = _accuracy(capsys, scene, "--bricks", bricks, "--targets", "numpy", "--dtypes", "float32")
    assert rc == 1
    line = next(x for x in err.splitlines() if "plausibility check" in x)
    assert line.startswith(f"error: {scene}:{VELVET_LINE}:1: material 'velvet' (probe): "
                           f"plausibility check '{check}' fails: ") and needle in line and " — " in line
    by = {v["spec"]: v for v in rep["verdicts"]}
    assert by["velvet: probe"]["plausibility_failed"] == [check] and not by["velvet: probe"]["pass"]
    assert by["chalk: lambert"]["pass"] and "2 of 3 specs pass" in err  # the others keep their verdicts


def test_reciprocity_fails_unless_declared(tmp_path, capsys):
    lib = load_library([_bricks(tmp_path, one_sided=ONE_SIDED)])
    c = plausibility.reciprocity("one_sided", lib)
    assert not c.passed and c.value > 0.1 and "f(l, v) =" in c.detail
    (tmp_path / "engine" / "one_sided.py").write_text(ONE_SIDED_DECLARED)
    lib = load_library([str(tmp_path / "engine")])
    c = plausibility.reciprocity("one_sided", lib)
    assert c.passed and c.skipped == "one_sided: the test probe reads n.l alone" and "declared not reciprocal" in c.detail
    assert plausibility.check("one_sided", lib, mc=False)["pass"]
    # on the command line: the undeclared one exits 1 naming reciprocity
    (tmp_path / "engine" / "one_sided.py").write_text(ONE_SIDED)
    rc, _rep, err = _accuracy(capsys, "one_sided", "--bricks", str(tmp_path / "engine"), "--targets", "numpy",
                              "--dtypes", "float32")
    assert rc == 1 and "spec string 'one_sided':1:1: BRDF 'one_sided': plausibility check 'reciprocity'" in err


def test_reciprocal_key_is_checked_by_the_schema(tmp_path):
    from generator.lang import SourceError
    bad = ONE_SIDED_DECLARED.replace('"no: the test probe reads n.l alone"', "False")
    with pytest.raises(SourceError, match=r"one_sided.py:5:\d+: BRICK\['reciprocal'\] must be a string"):
        load_library([_bricks(tmp_path, one_sided=bad)])
    yes = ONE_SIDED_DECLARED.replace('"no: the test probe reads n.l alone"', '"yes"')
    with pytest.raises(SourceError, match=r"only a model that is not reciprocal says so — write \"reciprocal\": \"no"):
        load_library([_bricks(tmp_path, one_sided=yes)])


def test_user_reference_is_used_and_reported(tmp_path, capsys):
    bricks = _bricks(tmp_path, charlie_sheen=CHARLIE)
    ref = tmp_path / "cloth_references.py"
    ref.write_text(CHARLIE_REFERENCE)
    rc, rep, err = _accuracy(capsys, _scene(tmp_path), "--bricks", bricks, "--reference", str(ref),
                             "--targets", "numpy", "--dtypes", "float64,float32")
    assert rc == 0, err
    velvet = next(v for v in rep["verdicts"] if v["spec"].startswith("velvet"))
    assert velvet["against"] == "user's float64 reference" and velvet["reference"]["files"] == [str(ref)]
    assert velvet["plausibility"] is None and rep["plausibility"] == []
    assert rep["user_references"] == {"specular/charlie_sheen": str(ref)}
    # numpy float64 is measured against the user's reference: the brick and it agree to rounding
    f64 = [r for r in rep["results"] if r["spec"] == velvet["spec"] and r["dtype"] == "float64"]
    assert f64 and max(r["max_rel"] for r in f64 if r["set"] == "hemisphere") < 1e-12
    assert f"({ref})" in accuracy.markdown(rep)
    assert "charlie_sheen" not in REFERENCES["specular"]  # registered for that run alone


def test_user_reference_detects_a_wrong_brick(tmp_path, capsys):
    bricks = _bricks(tmp_path, charlie_sheen=CHARLIE.replace("(2.0 + inv)", "(2.5 + inv)"))
    ref = tmp_path / "cloth_references.py"
    ref.write_text(CHARLIE_REFERENCE)
    rc, rep, err = _accuracy(capsys, _scene(tmp_path), "--bricks", bricks, "--reference", str(ref),
                             "--targets", "numpy", "--dtypes", "float32")
    assert rc == 1 and "velvet: lambert+charlie_sheen numpy/float32: hemisphere max relative error" in err


def test_user_reference_file_errors_are_located(tmp_path, capsys):
    bricks = _bricks(tmp_path, charlie_sheen=CHARLIE)
    scene = _scene(tmp_path)
    broken = tmp_path / "broken.py"
    broken.write_text("import numpy as np\n\nraise RuntimeError('no data')\n")
    empty = tmp_path / "empty.py"
    empty.write_text("x = 1\n")
    twice = tmp_path / "twice.py"
    twice.write_text("from generator.reference import reference\n\n\n@reference('diffuse', 'lambert')\n"
                     "def f(g, p, slots):\n    return 0\n")
    cases = [(broken, f"{broken}:3:1: the reference file raised RuntimeError: no data — fix the file"),
             (empty, f"{empty}:1:1: registers no reference"),
             (twice, f"{twice}:4:1: the reference file raised ValueError: two references for diffuse brick 'lambert'"),
             (tmp_path / "absent.py", "absent.py:1:1: no such reference file")]
    for path, message in cases:
        rc, rep, err = _accuracy(capsys, scene, "--bricks", bricks, "--reference", str(path), "--targets", "numpy")
        assert rc == 1 and rep is None and message in err, err
    assert "lambert" in REFERENCES["diffuse"] and "f" not in [fn.__name__ for fn in REFERENCES["diffuse"].values()]


def test_furnace_quadrature_and_mc_agree_with_closed_forms():
    lib = load_library()
    # Lambert: E = rho_d at every view; normalized Phong at normal incidence: E = f0 (Hoffman & Baker 2006)
    for th in plausibility.FURNACE_VIEWS:
        np.testing.assert_allclose(plausibility.furnace("lambert", lib, {"rho_d": [1.0, 0.5, 0.2]}, th),
                                   [1.0, 0.5, 0.2], rtol=1e-10)
    e = plausibility.furnace("phong_normalized", lib, {"n": 1e5, "f0": 1.0}, 0.0)
    assert e[0] == pytest.approx(1.0, abs=1e-9)
    m, se = plausibility.furnace_mc("phong_normalized", lib, {"n": 10.0, "f0": 1.0}, 30.0)
    assert abs(m[0] - plausibility.furnace("phong_normalized", lib, {"n": 10.0, "f0": 1.0}, 30.0)[0]) < 4 * se[0]
    d = plausibility.cosine_directions(4096)
    assert np.all(d[:, 2] >= 0) and d[:, 2].mean() == pytest.approx(2 / 3, abs=2e-3)  # E[cos] = 2/3
    assert math.isclose(np.linalg.norm(d, axis=1).max(), 1.0)


LIB = load_library()
SAMPLED = ["lambert", "gotanda_fitted", "phong", "microfacet(ndf=ggx,fresnel=schlick,vis=smith_schlick)"]
ALL = SAMPLED + [pytest.param(s, marks=pytest.mark.slow) for s in accuracy.default_specs(LIB) if s not in SAMPLED]


@pytest.mark.parametrize("spec", ALL)
def test_every_builtin_brick_is_plausible(spec):
    r = plausibility.check(spec, LIB, mc=spec in SAMPLED)
    assert r["pass"], [c for c in r["checks"] if not c["pass"]]
