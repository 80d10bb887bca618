"""Test brick for the numpy target: corner cases of masking, nesting and constants."""
BRICK = {"kind": "test"}


class Inner:
    v: vec3
    k: float


class Outer:
    inner: Inner
    flag: bool


def constant() -> vec3:
    return vec3(0.25, 0.5, 1.0) * PI


def nested_store(o: Outer, x: float) -> Outer:
    if x > 0.0:
        o.inner.v.y = x
        if o.flag == True:
            o.inner.k = -x
    o.flag = not o.flag
    return o


def loop_return(x: float) -> float:
    """A return inside a loop inside a branch, and a branch where every path returns."""
    acc = 0.0
    for i in range(5):
        acc += x
        if acc > 2.0:
            return acc + float(i) * 100.0
        if i == 3:
            acc = acc * 0.5
    if x < 0.0:
        return -1.0
    elif x < 0.25:
        return acc
    else:
        return acc * 2.0


def first_iteration(x: float) -> float:
    for i in range(3):
        return x + float(i)
    return 99.0


def matrices(m: mat3, s: float, v: vec3) -> vec3:
    a = m * s + s * m - m
    b = -v
    return a * b + (m * m) * v


def uints(a: uint, b: uint) -> uint:
    c = a - b
    return c / uint(2) + a % b


def choose_struct(x: float, p: Inner, q: Inner) -> Inner:
    # WGSL select() takes no structs, so the language asks for an if/else here.
    if x > 0.0:
        return p
    return q
