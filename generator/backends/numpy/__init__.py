"""The NumPy back end: brick functions run on the CPU, vectorized over samples (emit.py: NumpyTarget;
control.py, resources.py and runtime.py: switches and loops, and the helpers the emitted code calls).

Kept free of imports: NumPy is loaded only when this back end is asked for
(generator.backends.get_target("numpy")), which the shader back ends do not need."""
