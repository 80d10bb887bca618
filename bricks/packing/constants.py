"""Constant packing: every material parameter comes from the material's constants.

Hoffman & Baker 2006, "shift-invariant" BRDFs: parameters constant over the surface.
"""
BRICK = {
    "kind": "packing",
    "cite": "Hoffman & Baker 2006, shift-invariant BRDF parameters",
    "slots": {"normal": {"kind": "normal", "default": "vertex"}, "uv": {"kind": "uv", "optional": True}},
}
