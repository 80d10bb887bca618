"""Test brick for the numpy target: every intrinsic except texture sampling, returned as one struct."""
BRICK = {"kind": "test"}


class Results:
    f_abs: float
    f_sign: float
    f_floor: float
    f_fract: float
    f_saturate: float
    f_sqrt: float
    f_rsqrt: float
    f_exp: float
    f_exp2: float
    f_log: float
    f_log2: float
    f_sin: float
    f_cos: float
    f_tan: float
    f_asin: float
    f_acos: float
    f_atan: float
    f_atan2: float
    f_pow: float
    f_step: float
    f_min: float
    f_max: float
    f_clamp: float
    f_smooth: float
    f_mix: float
    f_select: float
    v_dot: float
    v_length: float
    v_cross: vec3
    v_normalize: vec3
    v_reflect: vec3
    v_mix: vec3
    v_clamp: vec3
    v_step: vec3
    v_smooth: vec3
    v_select: vec3
    v_abs: vec3
    v_max: vec3
    v_pow: vec3
    i_abs: int
    i_sign: int
    i_min: int
    i_max: int
    iv_max: ivec3


def intrinsics(x: float, y: float, a: vec3, b: vec3, i: int, j: int) -> Results:
    ax = abs(x)
    n = normalize(b)
    return Results(
        abs(x), sign(x), floor(x * 3.0), fract(x * 3.0), saturate(x * 2.0),
        sqrt(ax), rsqrt(ax + 0.1), exp(x), exp2(x), log(ax + 0.01), log2(ax + 0.01),
        sin(x), cos(x), tan(x), asin(x), acos(x), atan(x), atan2(y, x),
        pow(ax, y), step(0.1, x), min(x, y), max(x, y), clamp(x, -0.25, 0.5),
        smoothstep(-0.5, 0.5, x), mix(x, y, 0.25), select(x > y, x, y),
        dot(a, b), length(a), cross(a, b), normalize(a), reflect(a, n),
        mix(a, b, x), clamp(a, 0.0, 0.5), step(b, a), smoothstep(0.0, 1.0, a),
        select(x > 0.0, a, b), abs(a), max(a, b), pow(abs(a), b),
        abs(i), sign(i), min(i, j), max(i, j), max(ivec3(i, j, 3), ivec3(j)))


def blinn_phong(NdotH: float, n: float, f0: vec3) -> vec3:
    """Normalized Blinn-Phong (Hoffman & Baker 2006)."""
    return f0 * ((n + 4.0) / (8.0 * PI)) * pow(max(NdotH, 0.0), n)


def overflow(x: float) -> float:
    """Overflows in float16 (65504) but not in float32."""
    return x * 1000.0 * 1000.0 / 1000.0 / 1000.0


def divide(x: float, y: float) -> float:
    return x / y


def lanes(v: vec4, m: mat4, i: int) -> vec4:
    """Per-lane int indices into vectors and matrix columns, reads and writes."""
    w = v
    w[i] = v[3 - i] * 2.0
    c = m[i]
    m[i] = c * 3.0
    return w + c + m[i] * 0.5 + m * v


def reserved_names(np: float, F: vec3) -> vec3:
    return F * np
