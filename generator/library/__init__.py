"""Brick library: discovery and parsing of bricks, kind contracts, the shading-inputs table, the parameter policy."""
