"""The brick language: Python syntax parsed with ast into a typed IR (never imported or executed)."""
from .errors import SourceError, UserError
from .parse import Signature, parse_module, read_meta

__all__ = ["SourceError", "UserError", "Signature", "parse_module", "read_meta"]
