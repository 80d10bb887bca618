"""Argument types the benchmark scripts share: a bad value is argparse's usage error (exit 2), never a traceback
or a silent reinterpretation."""
from __future__ import annotations

import argparse
import re
from pathlib import Path


def positive(text: str) -> int:
    """A whole number of at least 1."""
    if not re.fullmatch(r"[0-9]+", text) or int(text) < 1:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number of at least 1")
    return int(text)


def size(text: str) -> str:
    """WxH, each 1 to 4096."""
    m = re.fullmatch(r"([0-9]+)x([0-9]+)", text)
    if not m or not all(1 <= int(v) <= 4096 for v in m.groups()):
        raise argparse.ArgumentTypeError(f"{text!r} is not WxH (each 1 to 4096), e.g. 320x160")
    return text


def folder(text: str) -> str:
    """An output folder: not an existing file, and not a name that reads as one (`sheet.png`)."""
    p = Path(text)
    if p.is_file() or p.suffix.lower() in (".png", ".md", ".json", ".txt", ".svg", ".pdf"):
        raise argparse.ArgumentTypeError(f"{text!r} is a file name; give the folder the results go into")
    return text


def languages(text: str) -> list[str]:
    """A comma-separated list of GPU languages (glsl, hlsl, wgsl), each once."""
    allowed = ("glsl", "hlsl", "wgsl")
    items = [x.strip() for x in text.split(",") if x.strip()]
    if not items or any(x not in allowed for x in items) or len(set(items)) != len(items):
        raise argparse.ArgumentTypeError(f"{text!r} is not a comma-separated list from {', '.join(allowed)} "
                                         "(each once)")
    return items
