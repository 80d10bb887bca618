"""A scene's environments baked for image-based lighting: SH9 values, the prefiltered radiance cube, the
AmbientBRDF table of each BRDF an environment lights (eval/ibl_env.py, eval/ibl_tables.py), deterministic.

- `values(scene)`: {environment: {sh0 … sh8}}, the SH9 coefficients of its radiance (R&H 2001; Â not folded:
  bricks/environment/split_sum.py), which link/values.uploads writes into the Lights block beside the scene's
  intensity and the cube's level count. Cheap (the projection of a 512 × 256 image: ~0.1 s).
- `bake(scene, lib)`: an `EnvironmentInputs` (runtime/environment.py) for the renderer: per environment its SH9
  values and its GGX-prefiltered cube (size² faces, the full chain, level k at α = (k/(L − 1))²), per BRDF key
  the AmbientBRDF texels. The cube and the tables are kept in the per-user store (namespace "ibl") by input key:
  the source image's bytes (or the sky's name), the rotation, the size, and the modules and bricks they are
  computed from.

The image is turned by `rotation` degrees about +Y when loaded, so the SH9 values and the cube are in world
space; `intensity` is not baked in (the brick multiplies by it: changing it is a value, not a bake).
"""
from __future__ import annotations

import hashlib
import math
from pathlib import Path

import numpy as np

from ..io import Store, content_key, default_cache_dir

SKY_WIDTH = 512  # the default sky's equirectangular width (eval/ibl_env.sky)
_MEMO: dict = {}


def _image(env):
    """The eval Environment of a scene Environment, turned by its rotation; intensity 1."""
    from ..eval import ibl_env
    key = ("image", env.source, str(env.image), env.rotation)
    if key not in _MEMO:
        e = ibl_env.sky(SKY_WIDTH) if env.image is None else ibl_env.load(env.image)
        e.rotation = math.radians(env.rotation)
        _MEMO[key] = e
    return _MEMO[key]


def _source_key(env) -> str:
    """What determines an environment's image: the file's bytes or the sky's name, and the rotation."""
    h = hashlib.sha256(env.image.read_bytes()).hexdigest() if env.image is not None else env.source
    return content_key("environment", h, env.rotation)


def sh_values(env) -> dict:
    """{sh0 … sh8: [r, g, b]} of a scene Environment (its image at intensity 1, turned by its rotation)."""
    from ..eval import ibl_env
    key = ("sh", _source_key(env))
    if key not in _MEMO:
        coeffs = ibl_env.sh9(_image(env))
        _MEMO[key] = {f"sh{k}": [float(x) for x in coeffs[k]] for k in range(9)}
    return _MEMO[key]


def values(scene) -> dict:
    """{environment name: {sh0 … sh8}} of the environments that light a light set of the scene."""
    used = sorted(set(scene.environment_of.values()))
    return {name: sh_values(scene.environments[name]) for name in used}


def budget(size: int) -> int:
    """The prefilter's samples per level (eval/ibl_env.prefilter): 2^20, fewer for cubes below 32² (a test's)."""
    return min(1 << 20, 1024 * size * size)


def cube(env, lib=None) -> list[np.ndarray]:
    """The prefiltered radiance chain of a scene Environment: levels (6, s, s, 3) float64, cached by input key."""
    from ..eval import ibl_env, ibl_tables
    key = content_key("radiance_cube", _source_key(env), env.size, budget(env.size),
                      ibl_tables.input_key("prefilter", ibl_env.GGX_TERM, (env.size, env.size), 0, lib))
    if ("cube", key) in _MEMO:
        return _MEMO[("cube", key)]
    shapes = [(6, max(1, env.size >> k), max(1, env.size >> k), 3) for k in range(env.levels)]
    total = sum(int(np.prod(s)) for s in shapes)
    root = default_cache_dir()
    store = Store(root) if root is not None else None
    data = store.get(ibl_tables.NAMESPACE, key) if store is not None else None
    if data is not None and len(data) == 8 * total:
        flat, levels, at = np.frombuffer(data, "<f8"), [], 0
        for s in shapes:
            n = int(np.prod(s))
            levels.append(flat[at:at + n].reshape(s).copy())
            at += n
    else:
        levels = ibl_env.prefilter(_image(env), env.size, lib=lib, budget=budget(env.size))
        if store is not None:
            store.put(ibl_tables.NAMESPACE, key, b"".join(np.asarray(x, "<f8").tobytes() for x in levels))
    _MEMO[("cube", key)] = levels
    return levels


def lit_brdfs(scene) -> list[str]:
    """The BRDF keys of the materials drawn under a light set with an environment, sorted."""
    return sorted({scene.materials[o["material"]].brdf for o in scene.objects if o["light_set"] in scene.environment_of})


def bake(scene, lib=None):
    """The renderer's EnvironmentInputs of `scene`: every environment a light set uses, every lit BRDF's table."""
    from ..eval import ibl_tables
    from ..runtime.environment import BakedEnvironment, EnvironmentInputs
    envs = {}
    for name in sorted(set(scene.environment_of.values())):
        env = scene.environments[name]
        envs[name] = BakedEnvironment(name, sh_values(env), cube(env, lib))
    tables = {brdf: ibl_tables.ambient_brdf(brdf, lib=lib, where=_where(scene, brdf)).texels
              for brdf in lit_brdfs(scene)}
    return EnvironmentInputs(envs, tables)


def _where(scene, brdf: str) -> str:
    """path:line:col of the first material with this BRDF (an AmbientBRDF refusal is located there)."""
    from ..scene.locate import Locator
    name = next(m for m, x in scene.materials.items() if x.brdf == brdf)
    try:
        loc = Locator(str(scene.path), Path(scene.path).read_text(encoding="utf-8"))
        line, col = loc.find(f"materials.{name}", "brdf")
    except (OSError, UnicodeDecodeError):
        line, col = 1, 1
    return f"{scene.path}:{line}:{col}"
