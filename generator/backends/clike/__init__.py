"""The tree walk the C-like back ends share (GLSL, HLSL, WGSL and the GL dialects): walk.py drives it from
per-language tables, control.py spells switches and runtime-bounded loops, resources.py buffers, global
declarations and arrays; reserved.py holds the names every C-like back end renames brick identifiers against.

Kept free of imports: a language package's keyword table is read from here while this package initialises."""
