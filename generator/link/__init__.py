"""The link stage: resolved brick nodes → one IR program and its typed Interface; the glue, built as IR."""
