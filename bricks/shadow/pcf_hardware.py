"""Percentage-closer filtering in hardware: k × k taps, each a 2 × 2 depth compare of a comparison sampler.

Reeves, Salesin & Cook 1987, "Rendering antialiased shadows with depth maps": filter the results of the
depth comparisons, never the depths. Here the texture unit does it over 2 × 2 texels (Everitt, Rege &
Cebenoyan 2001, "Hardware Shadow Mapping"): `sample_compare` compares (depth of P in light space - bias)
with each texel of the bilinear footprint (lit where ref <= stored depth: compareOp LESS_OR_EQUAL) and
weights the four results by the bilinear weights — GLSL sampler2DShadow, HLSL SamplerComparisonState
(SampleCmpLevelZero), WGSL texture_depth_2d + sampler_comparison (textureSampleCompareLevel), on a
depth-format image (the renderer binds its D32_SFLOAT depth pass). Level 0 is read explicitly, so the
taps are valid in non-uniform control flow (inside the light loop's `NdotL > 0` branch).

The k × k taps sit at offsets (i - (k-1)/2, j - (k-1)/2) · pcf_texel in shadow-map uv and are averaged,
as in `pcf`; with pcf_texel one texel, k taps of a 2 × 2 filter cover (k+1) × (k+1) texels, a tent-like
kernel whose visibility varies continuously with P (k = 1 is already the bilinear 2 × 2 PCF of the
hardware, which `shadow_map`'s one compare is not). `pcf_taps` and `pcf_texel` mean what they mean in
`pcf` (the renderer writes 1 / shadow-map side into an unset `pcf_texel`), so a scene swaps one for the
other.

Why both bricks: `pcf` compares in the shader against a bilinearly sampled depth (each tap compares one
depth averaged over 2 × 2 texels: k² compares, visibility in steps of 1/k²), `pcf_hardware` filters four
compares per tap in the sampler (4k² compares for k² fetches, visibility continuous). The texture is
named `shadow_depth`, not `shadow_map`, because it is another resource: a depth image read through a
comparison sampler, where `shadow_map` is read through the project's plain bilinear sampler (an
ubershader holding both binds both).

Bias: each compare reaches texels up to one texel (plus the tap offset) from P, nearer the light on a
tilted receiver, so the bias must cover the depth slope over that footprint. Measured on the tilted floor
of tests/scenes/shadow.toml (256² map, lavapipe), the least bias that leaves the lit floor unshadowed is
0.006 at k = 1 and 0.01 at k = 3 (pcf: 0.003 and 0.006); the default 0.002 suits receivers facing the
light. The edge band of that scene (98 floor pixels) holds 22 intermediate pixels at k = 1 and 65 at
k = 3 (pcf: 0 and 43, bias 0.01; tests/backends/test_shadow_compare.py).
"""
BRICK = {
    "kind": "shadow",
    "cite": "Reeves, Salesin & Cook 1987 (percentage-closer filtering); Everitt, Rege & Cebenoyan 2001 "
            "(hardware 2 x 2 depth compare), k x k taps",
    "params": {
        "shadow_matrix": {"type": "mat4", "default": [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0], "doc": "world to light clip space, column-major"},
        "shadow_bias": {"type": "float", "range": [0.0, 1.0], "default": 0.002, "doc": "depth bias against self-shadowing acne"},
        "pcf_taps": {"type": "float", "range": [1.0, 8.0], "default": 3.0, "doc": "kernel side k: k x k hardware 2 x 2 compares (rounded down)"},
        "pcf_texel": {"type": "float", "range": [0.0, 1.0], "default": 0.001953125, "doc": "tap spacing in shadow-map uv (1 / map side)"},
    },
    "textures": {"shadow_depth": {"srgb": False, "doc": "light-space depth (a depth image, comparison sampler)"}},
}


def shadow(P: vec3, shadow_matrix: mat4, shadow_bias: float, pcf_taps: float, pcf_texel: float,
           shadow_depth: texture2d_shadow) -> float:
    c = shadow_matrix * vec4(P, 1.0)
    # w is floored so that points behind the light's near plane do not divide by zero.
    p = c.xyz / max(c.w, 0.000001)
    uv = p.xy * 0.5 + vec2(0.5)
    ref = p.z - shadow_bias
    # k clamped to the parameter's range [1, 8]: a loop bound the scene cannot make 0 or huge
    k = int(clamp(floor(pcf_taps), 1.0, 8.0))
    centre = 0.5 * float(k - 1)
    lit = 0.0
    for i in range(k):
        for j in range(k):
            o = vec2(float(i) - centre, float(j) - centre) * pcf_texel
            lit += sample_compare(shadow_depth, uv + o, ref)
    return lit / float(k * k)
