"""Permutation keys and spec strings, their constraints, and the parameter policy: what one permutation is."""
