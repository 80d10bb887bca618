"""Lafortune generalized cosine lobes: f_r = sum_j K_j max(0, C_x,j l_x v_x + C_y,j l_y v_y + C_z,j l_z v_z)^n_j.

Lafortune, Foo, Torrance & Greenberg 1997, "Non-Linear Approximation of Reflectance
Functions", eq. 4 (one lobe per term, summed), as Hoffman & Baker 2006 print it: "one
spectral (RGB) constant K_j and four scalar constants (C_x,j, C_y,j, C_z,j, n_j) per term".
x, y, z are the local frame (t, b, n): l_x = l.t, l_y = l.b, l_z = n.l (and the same for v,
with n.v under the shading policy's clamp). The lobe (C_x, C_y, C_z) = (-1, -1, 1) is
exactly (r.v)^n, Phong (ACCURACY-FACTS §4.10); the course's cases: Phong K = R_F(0),
-C_x = -C_y = C_z = ((n+2)/(2 pi))^(1/n); Lambertian K = rho_d/pi, n = 0; off-specular
C_z < -C_x = -C_y; retro-reflection C_x, C_y, C_z > 0; anisotropy C_x != C_y.
Parameters: `lobes`, array of vec4 (C_x, C_y, C_z, n) per lobe, and `K`, array of RGB;
the number of lobes summed is the key constant of `lobes`: lafortune(lobes=2). `K` has a
count of its own in the key (every array parameter has one), which this brick does not
read: K[j] is read for the lobes summed, whatever K's count. The tangent frame is read
(LdotT, VdotT, LdotB, VdotB) because anisotropic lobes (C_x != C_y) need it; an isotropic
lobe could do without (l_x v_x + l_y v_y = l.v - (n.l)(n.v)) but one brick reads one set of
inputs. A lobe is max(0, d)^n with 0^0 = 1 (the n = 0 Lambertian lobe is constant).
Reciprocal (every lobe is symmetric in l and v).
"""
BRICK = {
    "kind": "specular",
    "cite": "Lafortune et al. 1997 eq. 4; Hoffman & Baker 2006 (K_j, C_x, C_y, C_z, n_j per lobe)",
    "params": {
        "lobes": {"type": "vec4", "count": 4, "range": [-100.0, 100000.0],
                  "default": [[-1.0, -1.0, 1.0, 32.0], [-1.0, -0.6, 0.8, 8.0], [0.5, 0.5, 0.5, 4.0],
                              [0.0, 0.0, 0.5, 1.0]],
                  "doc": "per lobe (C_x, C_y, C_z, n): the local-frame weights and the exponent"},
        "K": {"type": "vec3", "count": 4, "range": [0.0, 1000.0],
              "default": [[0.2, 0.2, 0.2], [0.1, 0.1, 0.1], [0.05, 0.05, 0.05], [0.3, 0.3, 0.3]],
              "doc": "per lobe the RGB scale K_j"},
    },
    "needs": ["NdotL", "NdotV", "LdotT", "VdotT", "LdotB", "VdotB"],
}


def specular(NdotL: float, NdotV: float, LdotT: float, VdotT: float, LdotB: float, VdotB: float,
             lobes: array[vec4, 4], lobes_count: int, K: array[vec3, 4]) -> vec3:
    f = vec3(0.0)
    for j in range(lobes_count):
        c = lobes[j]
        d = c.x * LdotT * VdotT + c.y * LdotB * VdotB + c.z * NdotL * NdotV
        # pow of a negative base is undefined and pow(0, 0) too (GLSL: exp2(0 * -inf)):
        # a lobe is max(0, d)^n with 0^0 = 1, written as a select. Cost: none.
        t = pow(d, c.w) if d > 0.0 else (1.0 if c.w == 0.0 else 0.0)
        f += K[j] * t
    return f
