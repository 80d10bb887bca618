"""Edge cases of switches, runtime loops, arrays and textures for the NumPy target tests."""
BRICK = {
    "kind": "test",
    "params": {},
}


class Bag:
    """A struct with an array field."""
    w: array[vec2, 3]
    n: int


def masked_writes(x: float, k: int) -> vec2:
    """Element and element-component writes under a mask, with a per-lane index."""
    a: array[vec2, 3] = [vec2(x, 0.0), vec2(1.0, x), vec2(-x, 2.0)]
    if x > 0.0:
        a[k].y = 10.0 * x
        a[2] = vec2(a[k].x, 7.0)
    return a[0] + a[1] * 2.0 + a[2] * 3.0


def first_over(vals: array[float, 4], n: int, limit: float) -> int:
    """A return inside a runtime loop: the first index whose value passes limit, else -1."""
    for i in range(n):
        if vals[i] > limit:
            return i
    return -1


def nested(n: int, m: uint) -> float:
    """A switch inside nested runtime loops."""
    acc = 0.0
    for i in range(n):
        for j in range(m):
            match i:
                case 0:
                    acc += 1.0
                case 1 | 3:
                    acc += float(j)
                case _:
                    acc -= 0.5
    return acc


def bag_sum(b: Bag) -> vec2:
    """A loop bounded by a struct field over the struct's array field."""
    acc = vec2(0.0)
    for i in range(b.n):
        acc += b.w[i]
    return acc


def make_bag(x: float) -> Bag:
    w: array[vec2, 3] = [vec2(x), vec2(2.0 * x), vec2(3.0 * x)]
    return Bag(w, 2)


def sampled(t: texture2d, uv: vec2, lod: float) -> vec4:
    """Both sampling intrinsics read mip level 0 in the NumPy target."""
    return sample_level(t, uv, lod) * 0.25 + sample(t, uv) * 0.75


def env(t: texturecube, dir: vec3) -> vec4:
    return sample_level(t, dir, 0.0)
