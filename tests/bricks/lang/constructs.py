"""Every construct of the brick language, for the emitter tests (not a shading model)."""
BRICK = {
    "kind": "test",
    "params": {},
}

GAIN = 0.5
TAPS = 3
BIAS: float = -0.25


class Surface:
    """A struct with scalar, vector and matrix fields."""
    albedo: vec3
    rough: float
    layers: int
    basis: mat3


def make_surface(albedo: vec3, rough: float) -> Surface:
    frame = mat3(vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0), vec3(0.0, 0.0, 1.0))
    return Surface(albedo, rough, TAPS, frame)


def scalars(a: float, i: int, u: uint, flag: bool) -> float:
    """int, uint, bool, conversions, integer arithmetic, unary minus, and/or/not."""
    k = i * 2 + 1 - i / 3 + i % 2
    k -= 1
    w: uint = u * uint(2) + uint(k)
    neg = -a + -GAIN * BIAS
    on = (flag and a > 0.0) or not (i == 3) or (u != uint(4))
    off = not on
    b = 1.0 if on else 0.0
    if off:
        b = -b
    return b + neg + float(k) + float(w) + abs(a) + float(abs(-i)) + float(sign(i)) + float(min(i, 2)) + float(max(i, -2))


def vectors(v: vec4, n: ivec3, c: uvec2) -> vec3:
    """Swizzles (xyzw and rgba), component assignment, index, splat, int vectors."""
    rgb = v.rgb
    zyx = v.zyx
    p = vec2(v.x, v.w)
    q = vec3(p, 1.0)
    q.y = v.a
    q.x += 2.0
    q[2] = q[0] * 0.5
    m = ivec3(1, 2, 3) + n * 2
    m.z -= 1
    i = m[1] % 3
    s = vec3(0.5)
    bv = bvec2(v.x > 0.0, True)
    if bv.y and not bv.x:
        s = s * 2.0
    t = rgb + zyx * q + s / v.w - p.yxy + float(i) + float(m.x) + float(c.y)
    return t + vec3(float(max(n, ivec3(0)).x), float(abs(n).y), float(sign(n).z)) + vec3(float((c * uint(2) + uvec2(uint(3))).x))


def matrices(m3: mat3, m4: mat4, v: vec3, i: int) -> vec4:
    """mat*vec, vec*mat, mat*mat, scalar*mat, column index, column and element assignment."""
    a = m3 * v
    b = v * m3
    c = (m3 * m3) * a + (2.0 * m3) * b + (m3 + m3 - m3) * v
    col = m3[i]
    e = m3[1][2] + m3[i].y
    w = mat4(vec4(v, 1.0), vec4(b, 0.0), vec4(c, 0.0), vec4(0.0, 0.0, 0.0, 1.0))
    w[3] = vec4(col, e)
    w[0] *= 0.5
    w[1][2] = 4.0
    w[2].w = 1.0
    w *= m4
    h = vec4(a, 1.0) * w
    h *= m4
    neg = -m3
    return (w * h) + m4 * vec4(neg * col, e)


def surface_term(sfc: Surface, input: float) -> vec3:
    """Struct member read and write; a parameter and locals spelled like reserved words."""
    sampler = sfc.albedo * input
    texture = sfc.rough
    output = sampler * texture
    half = 0.5
    line = half * 2.0
    filter = line + half
    fn = filter * 2.0
    let = fn - 1.0
    sfc.rough = let
    sfc.albedo.x = 1.0
    input = input + sfc.rough + float(sfc.layers)
    return output + sfc.basis * sfc.albedo * input


def control(x: float, n: int) -> float:
    """if/elif/else, nested if, for over literal and constant counts, augmented assignment."""
    acc = 0.0
    if x < 0.0:
        acc = -x
    elif x < 1.0:
        if n > 2:
            acc = x * 2.0
        else:
            acc = x
    elif x < 2.0:
        acc = 1.0
    else:
        acc = 2.0
    for i in range(4):
        acc += float(i)
        acc *= 1.0001
        if i == n:
            acc -= 1.0
            acc /= 2.0
    for j in range(TAPS):
        acc += GAIN * float(j)
    return acc


def intrinsics(x: float, v: vec3, u: vec2) -> vec3:
    """Every intrinsic of the table except the texture ones."""
    d = dot(v, v) + length(v) + pow(x, 2.0) + exp(x) + exp2(x) + log(x + 2.0) + log2(x + 2.0)
    d += sqrt(x * x) + rsqrt(x * x + 1.0) + sin(x) + cos(x) + tan(x) + asin(saturate(x)) + acos(saturate(x))
    d += atan(x) + atan2(x, 1.0) + floor(x) + fract(x) + abs(x) + sign(x) + min(x, 1.0) + max(x, 0.0)
    d += clamp(x, 0.0, 1.0) + smoothstep(0.0, 1.0, x) + step(0.5, x) + mix(x, 1.0, 0.5) + select(x > 0.0, 1.0, 2.0)
    n = normalize(v) + cross(v, vec3(0.0, 1.0, 0.0)) + reflect(v, normalize(v))
    w = saturate(v) + clamp(v, 0.0, 1.0) + mix(v, n, 0.25) + mix(v, n, vec3(0.5)) + step(v, n) + smoothstep(0.0, 1.0, v)
    w += abs(v) + sign(v) + floor(v) + fract(v) + min(v, n) + max(v, 1.0) + sqrt(abs(v)) + rsqrt(abs(v) + 1.0)
    w += pow(abs(v), vec3(2.2)) + exp(v) + exp2(v) + log(abs(v) + 1.0) + log2(abs(v) + 1.0)
    w += sin(v) + cos(v) + tan(v) + asin(saturate(v)) + acos(saturate(v)) + atan(v) + atan2(v, n)
    w += select(x < PI, v, n) + vec3(length(u), dot(u, u), normalize(u).x)
    return w * d * INV_PI


def sample_albedo(albedo_map: texture2d, uv: vec2) -> vec4:
    """sample() first, outside any branch: WGSL needs uniform control flow for derivatives."""
    base = sample(albedo_map, uv)
    if uv.x > 0.5:
        base = base * 0.5
    return base


def sample_lod(albedo_map: texture2d, uv: vec2, lod: float) -> vec4:
    """sample_level() is allowed anywhere, also in branches and in compute shaders."""
    c = vec4(0.0)
    if lod > 0.0:
        c = sample_level(albedo_map, uv, lod)
    return c


def forward_texture(albedo_map: texture2d, uv: vec2) -> vec4:
    """A texture argument passed on to another function."""
    return sample_lod(albedo_map, uv, 1.0) * GAIN


def shade(x: float, v: vec3, uv: vec2, albedo_map: texture2d) -> vec3:
    """Calls between functions, a struct built and passed, and a parameter assigned."""
    sfc = make_surface(v, x)
    x = x * 2.0
    v.y = x
    m = sfc.basis
    r = intrinsics(x, v, uv) + surface_term(sfc, x) + matrices(m, mat4(vec4(1.0), vec4(0.0), vec4(0.0), vec4(1.0)), v, 1).xyz
    r += vectors(vec4(v, x), ivec3(1, 2, 3), uvec2(uint(1), uint(2))) + vec3(scalars(x, 2, uint(3), x > 0.0), control(x, 1), 0.0)
    return r + forward_texture(albedo_map, uv).rgb
