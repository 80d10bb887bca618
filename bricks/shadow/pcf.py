"""Percentage-closer filtering: k × k depth compares around the projected point, averaged.

Reeves, Salesin & Cook 1987, "Rendering antialiased shadows with depth maps": filter the results of
the depth comparisons, never the depths. Each tap is the shadow_map brick's test, (depth of P in light
space - bias <= stored depth), at an offset of (i - (k-1)/2, j - (k-1)/2) · pcf_texel in shadow-map uv;
the k² results are averaged, so visibility takes the values n / k² and a shadow edge gets k² - 1
intermediate steps (k = 1 is shadow_map's one tap).

The kernel size k is the parameter `pcf_taps` (a float uniform, rounded down and clamped to [1, 8] in
the loop bound `range(int(...))`, which the brick language allows with a runtime bound): one compiled
shader serves every k, at the cost of a loop the compiler cannot unroll. `pcf_texel` is the tap spacing
in uv: one texel is 1 / the shadow map's side, and the renderer writes exactly that when the scene leaves
it unset (the default, 1/512, is the renderer's default map).

The compares are made in the shader on the depth texture as the renderer binds it (bilinear sampler,
sample_level at LOD 0: valid in non-uniform control flow), so each tap compares against depth averaged
over 2 × 2 texels — not the hardware 2 × 2 compare of a comparison sampler (sampler2DShadow /
SamplerComparisonState / sampler_comparison), which `pcf_hardware` uses (a texture2d_shadow read by
sample_compare: each tap filters four compares instead of comparing one filtered depth). Both are kept:
this one runs on any sampleable depth copy (the renderer's R32_SFLOAT fallback where a device cannot
filter D32_SFLOAT) and, comparing against the interpolated depth of a plane, needs less bias on tilted
receivers; pcf_hardware gives a visibility continuous in P from one tap on. Measured on the tilted floor
of tests/scenes/shadow.toml (256² map, lavapipe), the least bias that leaves the lit floor unshadowed:
pcf 0.003 at k = 1 (as shadow_map), 0.006 at k = 3; pcf_hardware 0.006 at k = 1, 0.01 at k = 3. Offset
taps reach texels nearer the light, so the bias must cover the depth slope over the kernel in both.
"""
BRICK = {
    "kind": "shadow",
    "cite": "Reeves, Salesin & Cook 1987 (percentage-closer filtering), k x k taps",
    "params": {
        "shadow_matrix": {"type": "mat4", "default": [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0], "doc": "world to light clip space, column-major"},
        "shadow_bias": {"type": "float", "range": [0.0, 1.0], "default": 0.002, "doc": "depth bias against self-shadowing acne"},
        "pcf_taps": {"type": "float", "range": [1.0, 8.0], "default": 3.0, "doc": "kernel side k: k x k compares (rounded down)"},
        "pcf_texel": {"type": "float", "range": [0.0, 1.0], "default": 0.001953125, "doc": "tap spacing in shadow-map uv (1 / map side)"},
    },
    "textures": {"shadow_map": {"srgb": False, "doc": "light-space depth in .x"}},
}


def shadow(P: vec3, shadow_matrix: mat4, shadow_bias: float, pcf_taps: float, pcf_texel: float,
           shadow_map: texture2d) -> float:
    c = shadow_matrix * vec4(P, 1.0)
    # w is floored so that points behind the light's near plane do not divide by zero.
    p = c.xyz / max(c.w, 0.000001)
    uv = p.xy * 0.5 + vec2(0.5)
    k = int(clamp(floor(pcf_taps), 1.0, 8.0))
    centre = 0.5 * float(k - 1)
    lit = 0.0
    for i in range(k):
        for j in range(k):
            o = vec2(float(i) - centre, float(j) - centre) * pcf_texel
            stored = sample_level(shadow_map, uv + o, 0.0).x
            lit += 1.0 if p.z - shadow_bias <= stored else 0.0
    return lit / float(k * k)
