"""Scenes (TOML, glTF) and the permutations they use; explain."""
