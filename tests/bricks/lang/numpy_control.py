"""Test brick for the numpy target: control flow, loops, structs, matrices, swizzles."""
BRICK = {"kind": "test"}

STEPS = 4
K = 0.5


class Surface:
    albedo: vec3
    rough: float
    count: int


def classify(x: float, y: float) -> float:
    """Early returns in if/elif/else branches, with code between them."""
    a = x * y
    if x > 0.5:
        if y > 0.0:
            return a + 1.0
        a = a * 2.0
    elif x < -0.5:
        b = x - y
        if b > 0.25:
            return b
        else:
            a = a + b
    else:
        a = a - 3.0
    if a > 0.0 and not (y < -0.75):
        return sqrt(a)
    a += 0.5 if y > 0.0 else -0.5
    return a * 10.0


def accumulate(x: float, v: vec3) -> vec3:
    acc = vec3(0.0)
    s = 0.0
    for i in range(STEPS):
        s += float(i) * K
        if x > s:
            acc.x += x
            acc[1] = acc[1] + s
        acc.z = acc.z + v[i % 3]
    return acc


def mutate(v: vec3, s: Surface, x: float) -> vec3:
    """Parameter reassignment and component assignment must not touch the caller's arrays."""
    v.x = 7.0
    s.albedo.y = x
    s.rough *= 2.0
    if x > 0.0:
        v = v * 2.0
        v.z = -1.0
    return v + s.albedo * s.rough


def make_surface(c: vec3, r: float, n: int) -> Surface:
    s = Surface(c, r, n)
    if r > 0.5:
        s.count = s.count * 2 + 1
    return s


def surface_sum(s: Surface) -> float:
    return s.albedo.x + s.albedo.y + s.albedo.z + s.rough + float(s.count)


def transform(c0: vec3, c1: vec3, c2: vec3, v: vec3) -> vec3:
    m = mat3(c0, c1, c2)
    w = m * v
    u = v * m
    p = m * m
    return w + u.zyx + p[1] + m[2] * 0.5


def swz(v: vec4, a: vec2) -> vec4:
    b = v.wzyx
    c = vec4(a, v.xy)
    d = vec3(a.y, v.zw)
    return b + c * d.x + vec4(d, a.x)


def choose(x: float, a: vec3, b: vec3) -> vec3:
    c = select(x > 0.0, a, b)
    d = a if x < 0.5 else b
    return c + d


def ints(i: int, j: int) -> int:
    k = i / j + i % j
    k -= abs(i) * 2
    return max(k, min(i, j)) + sign(j)
