"""The shader matrix: spec strings, permutation keys, scenes (TOML) and the permutations they use."""
