"""Switch, runtime loops, fixed arrays, read-only buffers and cube textures (for the emitter tests)."""
BRICK = {
    "kind": "test",
    "params": {},
}

LOBES = 4
POINT = 1


class Lobe:
    """A Lafortune-style lobe: C (rgb, w unused), n in K.x."""
    C: vec4
    K: vec4


class Light:
    """A buffer element: every member is 16 bytes."""
    color: vec4
    position: vec4
    kind: ivec4


class Table:
    """A buffer element with a nested struct and a fixed array."""
    lobe: Lobe
    taps: array[vec4, 2]


lights: storage_buffer[Light]
table: uniform_buffer[Table, 8]


def classify(k: int, x: float) -> float:
    """match with alternatives, a negative case, a default, and returns inside cases."""
    y = x
    match k:
        case 0:
            y = x * 2.0
        case 1 | 2:
            return x + 10.0
        case -3:
            y = -x
            if x > 0.0:
                return 100.0
        case _:
            y = x - 1.0
    return y


def pick(k: uint) -> float:
    """A uint selector and a switch whose every case returns ends the function."""
    match k:
        case 0:
            return 1.0
        case 7 | 9:
            return 2.0
        case _:
            return 3.0


def no_default(k: int) -> float:
    acc = 0.5
    match k + 1:
        case 2:
            acc = 4.0
    return acc


def sum_lobes(lobes: array[Lobe, LOBES], n: int, cos_t: float) -> vec3:
    """A runtime loop over a parameter array of structs; member access of an element."""
    acc = vec3(0.0)
    for i in range(n):
        lobe = lobes[i]
        acc += lobe.C.xyz * pow(max(cos_t, 0.0), lobes[i].K.x)
    return acc


def weights(m: uint, x: float) -> float:
    """A uint-bounded loop, a local array literal, element writes and reads by index."""
    w: array[float, 3] = [x, 2.0 * x, 0.5]
    acc = 0.0
    for i in range(m):
        w[i % uint(3)] = w[i % uint(3)] + 1.0
        acc += w[i % uint(3)]
    return acc + w[0] + w[2]


def shade_lights(p: vec3) -> vec3:
    """Read a storage buffer: its runtime length, element fields, a switch on a field."""
    acc = vec3(0.0)
    for i in range(buffer_length(lights)):
        light = lights[i]
        match light.kind.x:
            case 1:
                d = light.position.xyz - p
                acc += light.color.rgb / max(dot(d, d), 0.0001)
            case _:
                acc += light.color.rgb
    return acc


def read_table(j: int) -> vec4:
    """Read a uniform buffer's nested struct and array fields; its length is its capacity."""
    e = table[j]
    return e.lobe.C + e.taps[1] + table[0].taps[0] * float(buffer_length(table))


def env_light(env: texturecube, dir: vec3, lod: float) -> vec4:
    """Cube texture with an explicit level (valid in compute shaders)."""
    return sample_level(env, dir, lod)


def env_sample(env: texturecube, dir: vec3) -> vec4:
    """Cube texture with implicit derivatives (fragment shaders only)."""
    return sample(env, dir) * 0.5
