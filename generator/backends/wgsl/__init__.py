"""WGSL as naga accepts it: the emitter (emit.py: WgslTarget, WgslHalfTarget) and the words a brick identifier is renamed away from
(keywords.py).

Kept free of imports, so that the shared C-like walk can read keywords.py while the emitter that
subclasses it is still being imported."""
