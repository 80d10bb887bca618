"""Shading normal = interpolated vertex normal.

Phong 1975 (interpolated normals); the default normal source of every packing.
"""
BRICK = {
    "kind": "normal",
    "cite": "Phong 1975, interpolated vertex normals",
}


def normal(N: vec3) -> vec3:
    return N
