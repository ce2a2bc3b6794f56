"""``symkin cache info|clear``: see and empty the kernel cache.

``clear`` removes only what symkin puts there (kernel folders ``_symkin_*``, the warm-run
index, temporaries of builds); any other file in the folder is left alone.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from symkin.cli import messages
from symkin.cli.exits import EXIT_OK


def handle(args: argparse.Namespace) -> int:
    """Run the subcommand; returns the exit status."""
    import shutil

    from symkin.build import cache, index  # not at import: `symkin --help` builds the parser

    root = cache.cache_root()
    owned = _symkins(root)
    if args.action == "clear":
        for path in owned:
            if path.is_dir():
                shutil.rmtree(path, ignore_errors=True)
            else:
                path.unlink(missing_ok=True)
        print(messages.printable(f"removed {len(owned)} item(s) from {root}"))
        return EXIT_OK
    kernels = [p for p in owned if p.name.startswith(cache.KERNEL_PREFIX)]
    entries = [p for p in owned if p.name == index.INDEX_FOLDER]
    temporaries = [p for p in owned if p.name.startswith(".")]
    size = sum(f.stat().st_size for p in owned for f in _files(p))
    problem = cache.unusable(root) if root.exists() else None
    print(messages.printable(
        f"cache: {root}\n"
        f"kernels: {len(kernels)}\n"
        f"warm-run index entries: {sum(len(list(_files(p))) for p in entries)}\n"
        f"temporaries of builds: {len(temporaries)}\n"
        f"size: {size / 1e6:.1f} MB"
        + (f"\nnot used: {problem}" if problem else "")))
    return EXIT_OK


def _symkins(root: Path) -> list[Path]:
    """What symkin wrote into ``root``: kernel folders, the index, build temporaries."""
    from symkin.build import cache, index

    try:
        entries = sorted(root.iterdir())
    except OSError:
        return []
    return [p for p in entries
            if p.name.startswith((cache.KERNEL_PREFIX, f".{cache.KERNEL_PREFIX}",
                                  ".discarded."))
            or (p.name == index.INDEX_FOLDER and p.is_dir())]


def _files(path: Path) -> list[Path]:
    if path.is_file():
        return [path]
    return [f for f in path.rglob("*") if f.is_file()]
