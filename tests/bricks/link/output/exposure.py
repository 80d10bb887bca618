"""Test brick: an output transform with a parameter, exposure in stops: color · 2^ev.

Reinhard et al. 2002 (exposure as a scale of scene-referred radiance).
"""
BRICK = {
    "kind": "output",
    "cite": "Reinhard et al. 2002, exposure",
    "params": {"ev": {"type": "float", "range": [-20.0, 20.0], "default": 0.0, "doc": "exposure in stops"}},
}


def output(color: vec3, ev: float) -> vec4:
    return vec4(color * exp2(ev), 1.0)
