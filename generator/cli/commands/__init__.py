"""Subcommands of the `shadermatrix` CLI: one module each.

A command module defines HELP (one line), `add_arguments(parser)` and
`run(args) -> int` (the exit code). The CLI lists the modules of this package
in ORDER (then any others alphabetically), so a new command is one new file.
"""
ORDER = ("bricks", "build", "matrix", "check", "cache", "render", "costs", "eval", "accuracy", "tables", "doctor",
         "completion")
