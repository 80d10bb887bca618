"""Evaluating a BRDF spec on samples (reference, NumPy, eval kernels) and measuring its accuracy."""
