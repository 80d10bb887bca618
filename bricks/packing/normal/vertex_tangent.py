"""Shading normal = interpolated vertex normal, on a mesh that carries a tangent frame.

Phong 1975 (interpolated normals). The normal is the vertex normal, as in `vertex`;
reading T and B makes the mesh's tangent attribute part of the shader's interface, so
an anisotropic BRDF (which reads HdotT, HdotB, ...) can use the interpolated tangent
frame without a normal map (Lengyel 2001 for per-vertex tangents).
"""
BRICK = {
    "kind": "normal",
    "cite": "Phong 1975 interpolated normals; Lengyel 2001 per-vertex tangent frames",
}


def normal(N: vec3, T: vec3, B: vec3) -> vec3:
    return N
