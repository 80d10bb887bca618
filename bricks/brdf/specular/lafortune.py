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



# Sampling (the contract: library/kinds.py). Lobe j is K_j (l.w_j)^n_j with w_j = (C_x v_x, C_y v_y, C_z v_z)
# in the local frame (t, b, n), i.e. |w_j|^n_j times a cosine lobe about w_j / |w_j| (Lafortune et al. 1997
# §4; Lafortune & Willems 1994): one lobe is picked with probability proportional to its integral over the
# sphere, lum(K_j) |w_j|^n_j 2 pi / (n_j + 1) (lum: the mean of K's channels), by the first uniform, which is
# then rescaled to [0, 1) within the lobe's share, and the cos^n_j sampler draws about w_j (Bikker 2017). The
# density is the mixture: sum_j p_j (n_j + 1)/(2 pi) max(0, l.w_j/|w_j|)^n_j (the course's multi-layer rule).
def lobe_axis(c: vec4, V: vec3, N: vec3, T: vec3, B: vec3) -> vec3:
    return T * (c.x * dot(V, T)) + B * (c.y * dot(V, B)) + N * (c.z * clamp(dot(V, N), 0.0001, 1.0))


def lobe_weight(c: vec4, k: vec3, w: vec3) -> float:
    return (k.x + k.y + k.z) * pow(length(w), c.w) * TWO_PI / (c.w + 1.0) if dot(w, w) > 0.0 else 0.0


def sample(u: vec2, V: vec3, N: vec3, T: vec3, B: vec3, lobes: array[vec4, 4], lobes_count: int,
           K: array[vec3, 4]) -> vec3:
    total = 0.0
    for j in range(lobes_count):
        total += lobe_weight(lobes[j], K[j], lobe_axis(lobes[j], V, N, T, B))
    t = u.x * total
    below = 0.0
    axis = N
    ux = u.x
    n = 1.0
    for j in range(lobes_count):
        w = lobe_axis(lobes[j], V, N, T, B)
        p = lobe_weight(lobes[j], K[j], w)
        if p > 0.0 and t >= below and t < below + p:
            axis = normalize(w)
            ux = min((t - below) / p, 1.0)
            n = lobes[j].w
        below += p
    c = pow(ux, 1.0 / (n + 1.0))
    s = sqrt(max(1.0 - c * c, 0.0))
    phi = TWO_PI * u.y
    sg = 1.0 if axis.z >= 0.0 else -1.0
    # an orthonormal frame about the axis (Duff et al. 2017, listing 3)
    kk = -1.0 / (sg + axis.z)
    bb = axis.x * axis.y * kk
    e1 = vec3(1.0 + sg * axis.x * axis.x * kk, sg * bb, -sg * axis.x)
    e2 = vec3(bb, sg + axis.y * axis.y * kk, -axis.y)
    return e1 * (s * cos(phi)) + e2 * (s * sin(phi)) + axis * c


def pdf(L: vec3, V: vec3, N: vec3, T: vec3, B: vec3, lobes: array[vec4, 4], lobes_count: int,
        K: array[vec3, 4]) -> float:
    total = 0.0
    acc = 0.0
    for j in range(lobes_count):
        w = lobe_axis(lobes[j], V, N, T, B)
        p = lobe_weight(lobes[j], K[j], w)
        d = dot(L, w) * rsqrt(max(dot(w, w), 1e-30))
        lobe = pow(d, lobes[j].w) if d > 0.0 else 0.0
        total += p
        acc += p * (lobes[j].w + 1.0) * INV_TWO_PI * lobe
    return acc / total if total > 0.0 and dot(N, L) > 0.0 else 0.0
