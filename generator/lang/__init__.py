"""The brick language: Python syntax parsed with ast into a typed IR (never imported or executed)."""
from .errors import SourceError
from .parse import Signature, parse_module, read_meta

__all__ = ["SourceError", "Signature", "parse_module", "read_meta"]
