"""Cost stand-in packing: every material input from constants, the normal from its slot.

Not a model: the baseline a packing brick is measured against.
"""
BRICK = {
    "kind": "packing",
    "cite": "shadermatrix cost baseline (no model)",
    "slots": {"normal": {"kind": "normal", "default": "standin_normal"}},
}
