"""A switch, runtime loops, a local array and both buffer kinds, run on lavapipe against NumPy."""
BRICK = {
    "kind": "test",
    "params": {},
}


class Light:
    """color.rgb, position.xyz, kind.x selects the formula."""
    color: vec4
    position: vec4
    kind: ivec4


class Lobe:
    C: vec4
    K: vec4


lights: storage_buffer[Light]
lobes_ub: uniform_buffer[Lobe, 4]


def lobe_sum(lobes: array[Lobe, 3], n: int, x: float) -> vec3:
    acc = vec3(0.0)
    for i in range(n):
        lb = lobes[i % 3]
        acc += lb.C.xyz * pow(x, lb.K.x)
    return acc


def eval_sample(k: int, x: float) -> vec4:
    lobes: array[Lobe, 3] = [lobes_ub[0], lobes_ub[1], lobes_ub[3]]
    n = k % 5
    acc = lobe_sum(lobes, n, x)
    for j in range(buffer_length(lights)):
        light = lights[j]
        match light.kind.x:
            case 0:
                acc += light.color.rgb
            case 1 | 2:
                d = light.position.xyz - vec3(x, 0.0, 1.0)
                acc += light.color.rgb * (x / max(dot(d, d), 0.01))
            case _:
                acc -= light.position.xyz * 0.5
    w: array[float, 4] = [1.0, x, x * x, -x]
    for i in range(uint(max(n, 0))):
        w[i % uint(4)] = w[i % uint(4)] * 0.5 + float(i)
    match k:
        case 3:
            return vec4(acc, w[1])
        case 7 | 8 | 9:
            return vec4(-acc, w[2] + w[3])
        case -1:
            return vec4(0.0)
        case _:
            pass
    return vec4(acc, w[0] + w[3] + float(lobes_ub[k % 4].K.y))
