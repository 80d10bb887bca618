"""`shadermatrix cache stats|clear`: the content-addressed compile cache that `build` reads and fills."""
from __future__ import annotations

from ...lang.errors import UsageError

HELP = "the content-addressed compile cache: what it holds (stats) or empty it (clear)"


def add_arguments(p) -> None:
    p.add_argument("action", choices=("stats", "clear"))
    p.add_argument("--cache-dir", metavar="DIR",
                   help="the cache (default: $SHADERMATRIX_CACHE_DIR, else $XDG_CACHE_HOME/shadermatrix, "
                        "else ~/.cache/shadermatrix)")


def run(args) -> int:
    from ...io import Store, default_cache_dir
    root = args.cache_dir or default_cache_dir()
    if root is None:
        raise UsageError("no cache directory: there is no home directory — give --cache-dir DIR")
    store = Store(root)
    if args.action == "clear":
        print(f"{store.clear()} entries removed from {store.root}")
        return 0
    entries = store.entries()
    total = sum(n for n, _ in entries.values()), sum(b for _, b in entries.values())
    print(f"{store.root}: {total[0]} entries, {total[1] / 1e6:.1f} MB")
    for ns, (n, size) in entries.items():
        print(f"  {ns:<12} {n:>8} entries {size / 1e6:>9.1f} MB")
    return 0
