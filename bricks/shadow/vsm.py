"""Variance shadow map: visibility from the filtered first two moments of light-space depth.

Donnelly & Lauritzen 2006, "Variance shadow maps". The map holds (E[d], E[d²]) over a filter region;
for a receiver at depth t > E[d], Chebyshev's one-tailed inequality bounds the lit fraction,
p_max = σ² / (σ² + (t - E[d])²) with σ² = E[d²] - E[d]², and t <= E[d] is lit (1). Because moments
(unlike depth compares) filter linearly, the map can be blurred once and sampled bilinearly: soft
edges at one tap. The depth pass writes the moments for the texture `shadow_moments`
(RGBA32F: d, d², 0, 1, the moments stage of the generated depth shaders, box-filtered over 5 × 5 texels
by their blur pass; generator/runtime/shadow_pass.py), declared as an ordinary filterable float texture2d
in every language (GLSL texture2D + sampler, HLSL Texture2D + SamplerState, WGSL texture_2d<f32> +
sampler) and sampled bilinearly. Vulkan filters R32G32B32A32_SFLOAT linearly on lavapipe; WebGPU
needs the float32-filterable feature for it (16-bit moments would lose E[d²] - E[d]² to rounding;
not measured here).

σ² is floored at `vsm_min_variance`: in float32, E[d²] - E[d]² cancels for a flat receiver (its
d² carries ~1e-7 relative error), which can flicker into acne; the floor plays the part of
shadow_map's bias (the test scene shows no acne even at 0).

Light bleeding, the trade-off: Chebyshev's bound is tight only for one occluder and one receiver in
the filter region. With occluders at depths d_a < d_b both inside the region, a receiver at t behind
them is lit by p_max > 0 although it is fully shadowed, the more the closer d_b is to t: e.g. a filter
region half at d_a = 0.2, half at d_b = 0.5, receiver t = 0.6 -> E[d] = 0.35, σ² = 0.0225,
p_max = 0.0225 / (0.0225 + 0.0625) = 0.265 — a quarter lit inside a full shadow (with the default
vsm_bleed = 0.2: 0.081; tests/runtime/test_shadows_filtered.py computes both with this brick's formula).
A curved occluder does it alone: its depths vary across the filter region, so σ² > 0 over the
whole umbra and the bound is never 0 there. Measured on lavapipe (tests/scenes/shadow.toml, a ball
over a floor, 256² map, 5 × 5 moments box, 96 × 64 frame, linear output): with vsm_bleed = 0 the
umbra (floor within 0.85 r of the shadow ray's closest approach) is lit up to 6 of the lit 124
(4.8 %); with the default 0.2 it is black.
`vsm_bleed` ∈ [0, 1) trades it away: p_max is remapped by linstep(vsm_bleed, 1, p_max), which removes
every bleed below vsm_bleed at the cost of darkening (hardening) the penumbra: of the 153 floor
pixels between 0.85 r and 1.3 r, 0 are black with vsm_bleed = 0, 20 with 0.2 and 44 with 0.5
(intermediate: 99, 79, 55). 0 keeps Chebyshev's bound as it is. A point light's map holds
perspective (non-linear) depth, compressed toward 1, so the ball's depth spread weighs more against
the floor's distance behind it: with the default 0.2, 9 of 164 umbra pixels keep up to 9 of their
8-bit value; vsm_bleed = 0.5 makes them black (moments of linear depth would be the cure; the
renderer writes the depth buffer's).
"""
BRICK = {
    "kind": "shadow",
    "cite": "Donnelly & Lauritzen 2006 (variance shadow maps)",
    "params": {
        "shadow_matrix": {"type": "mat4", "default": [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0], "doc": "world to light clip space, column-major"},
        "shadow_bias": {"type": "float", "range": [0.0, 1.0], "default": 0.002, "doc": "depth bias subtracted from the receiver"},
        "vsm_min_variance": {"type": "float", "range": [0.0, 1.0], "default": 0.00002, "doc": "floor of the variance against float32 cancellation"},
        "vsm_bleed": {"type": "float", "range": [0.0, 0.99], "default": 0.2, "doc": "light-bleeding reduction: p_max below this is cut to 0"},
    },
    "textures": {"shadow_moments": {"srgb": False, "doc": "filtered light-space depth moments: .x = E[d], .y = E[d^2]"}},
}


def shadow(P: vec3, shadow_matrix: mat4, shadow_bias: float, vsm_min_variance: float, vsm_bleed: float,
           shadow_moments: texture2d) -> float:
    c = shadow_matrix * vec4(P, 1.0)
    # w is floored so that points behind the light's near plane do not divide by zero.
    p = c.xyz / max(c.w, 0.000001)
    uv = p.xy * 0.5 + vec2(0.5)
    m = sample_level(shadow_moments, uv, 0.0).xy
    t = p.z - shadow_bias
    variance = max(m.y - m.x * m.x, vsm_min_variance)
    d = t - m.x
    p_max = variance / (variance + d * d)
    # linstep(vsm_bleed, 1, p_max); the denominator is >= 0.01 (vsm_bleed <= 0.99)
    reduced = clamp((p_max - vsm_bleed) / max(1.0 - vsm_bleed, 0.01), 0.0, 1.0)
    return 1.0 if t <= m.x else reduced
