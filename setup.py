"""Which packages the wheel holds: the generator package, and the built-in bricks as package data.

Everything else (metadata, dependencies, package data globs) is in pyproject.toml; this file exists
only because pyproject.toml cannot map a folder outside the package into it: bricks/ stays at the
repository root, where brick authors look for it, and is installed as generator/library/bricks_data/
(read by generator.library.bricks; see the comment in pyproject.toml).
"""
from setuptools import find_namespace_packages, setup

BRICKS = "generator.library.bricks_data"

# Every brick folder is listed as a (namespace) package of BRICKS so that setuptools copies its files
# without warning that a folder of .py files is missing from `packages`; nothing imports them.
setup(packages=[*find_namespace_packages(include=["generator*"]),
                BRICKS, *(f"{BRICKS}.{p}" for p in find_namespace_packages(where="bricks"))],
      package_dir={BRICKS: "bricks"})
