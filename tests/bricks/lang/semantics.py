"""Functions whose meaning the three languages (and NumPy) must agree on (a test brick).

Each takes and returns one float; tests/lang/test_semantics.py runs them in GLSL, HLSL
and WGSL on lavapipe (optimized SPIR-V, so constant folding is included) and in
the NumPy target, and compares.
"""
BRICK = {"kind": "test"}


def signed_mod(x: float) -> float:
    # The truncated remainder (sign of the dividend) everywhere, also when folded.
    a = int(x)
    return float(a % 3) + 10.0 * float(a % -4) + 100.0 * float(-7 % 3)


def signed_div(x: float) -> float:
    return float(int(x) / 3) + 10.0 * float(-7 / 2)


def unsigned_ops(x: float) -> float:
    u = uint(abs(x) * 10.0)
    return float(u / uint(3)) + 0.5 * float(u % uint(7))


def reserved_names(x: float) -> float:
    # `point`, `sampler` and `filter` are reserved somewhere and get renamed; a brick name
    # that looks like a renamed one must stay a different variable.
    point = x
    point_r = 2.0
    sampler = 3.0
    filter = point * point_r + sampler
    return filter


def select_order(x: float) -> float:
    y = x if x > 0.0 else -2.0 * x
    return select(x < 1.0, y, 10.0 + y)


def matrices(x: float) -> float:
    m = mat3(vec3(x, 1.0, 2.0), vec3(3.0, x, 5.0), vec3(6.0, 7.0, x))
    v = m * vec3(1.0, 2.0, 3.0)
    w = vec3(1.0, 0.0, 2.0) * m
    c = m[1]
    return v.x + 10.0 * v.y + 100.0 * w.z + 1000.0 * m[1][2] + c.z


def early_return(x: float) -> float:
    acc = 0.0
    for i in range(4):
        if float(i) > x:
            return acc
        acc += float(i) * x
    return acc - 1.0
