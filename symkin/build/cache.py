"""The build cache: content-addressed folders of built kernels, published atomically.

A folder's name carries the sha256 of everything that decides its contents, so a folder that
exists is the right one; it is filled under a private temporary name and renamed into place in
one step, so concurrent builds of the same kernel all succeed and none sees half a folder.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any


def cache_root() -> Path:
    """``$SYMKIN_CACHE_DIR``, else the user cache folder: one folder for kernels and index."""
    explicit = os.environ.get("SYMKIN_CACHE_DIR")
    if explicit:
        return Path(explicit)
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "symkin"


def publish(cache: Path, folder: Path, fill: Callable[[Path], Any]) -> None:
    """Fill a private temporary folder and rename it to ``folder`` in one atomic step.

    When another process published the same folder first, the rename fails; its result is
    the same (same key, same inputs), so this build is discarded.
    """
    cache.mkdir(parents=True, exist_ok=True)
    build = Path(tempfile.mkdtemp(dir=cache, prefix=f".{folder.name}."))
    try:
        fill(build)
        try:
            os.replace(build, folder)
        except OSError:
            if not folder.is_dir():
                raise
    finally:
        if build.exists():
            shutil.rmtree(build, ignore_errors=True)


def content_key(inputs: dict[str, Any]) -> str:
    """The sha256 of a JSON-able description of a build's inputs."""
    return hashlib.sha256(json.dumps(inputs, sort_keys=True).encode()).hexdigest()
