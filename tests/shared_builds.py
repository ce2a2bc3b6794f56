"""Derived Systems and generated sources kept on disk for every process of one test run.

pytest-xdist runs the test files in several processes, and each would derive the same example
again (SymPy: seconds to a minute for the spatial ones) and generate its code again (as long
again) before the kernel cache finds the compiled library. Here the first process to need a
System or a folder of sources stores it, pickled, in a folder of this run (conftest's
``shared_builds``); the others load it. A System pickles faithfully
(``symkin.symbolic.pickling``): the copy generates the same bytes, which
tests/symbolic/test_system_pickle.py checks.

Keys hold the mechanism file's path and bytes and a digest of symkin's own sources and SymPy's
version, so nothing derived by other code is ever taken. Outside a test run (no folder set)
everything is computed in the process.
"""

from __future__ import annotations

import functools
import hashlib
import os
import pickle
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

import sympy

import symkin

T = TypeVar("T")
FOLDER: list[Path] = []
"""The run's folder, set by conftest once the session starts (empty: no sharing)."""


@functools.cache
def _sources_digest() -> str:
    """sha256 of every file of the symkin package (code and templates), SymPy's and Python's
    versions: a change to any of them makes every key new."""
    digest = hashlib.sha256(f"{sympy.__version__} {sys.version}".encode())
    package = Path(symkin.__file__).resolve().parent
    for path in sorted(package.rglob("*")):
        if path.is_file() and "__pycache__" not in path.parts:
            digest.update(str(path.relative_to(package)).encode() + b"\0" + path.read_bytes())
    return digest.hexdigest()


def file_key(path: Path) -> tuple[str, str]:
    """A mechanism file by its place and its bytes."""
    return str(path), hashlib.sha256(path.read_bytes()).hexdigest()


def stored(kind: str, key: tuple[Any, ...], make: Callable[[], T]) -> T:
    """What ``make()`` returns, loaded from the run's folder when a process stored it first."""
    if not FOLDER:
        return make()
    name = hashlib.sha256(repr((kind, key, _sources_digest())).encode()).hexdigest()
    path = FOLDER[0] / f"{kind}-{name}.pickle"
    try:
        value: T = pickle.loads(path.read_bytes())  # written by this run, below
        return value
    except FileNotFoundError:
        pass
    value = make()
    partial = path.with_name(f".{path.name}.{os.getpid()}")
    partial.write_bytes(pickle.dumps(value, protocol=pickle.HIGHEST_PROTOCOL))
    os.replace(partial, path)  # whole or absent: a reader never sees half a file
    return value


def text_file(name: str, text: str) -> Path:
    """A file of ``text`` called ``name`` at a place that depends on both alone, in the run's
    folder: every test and every worker that writes the same file gets the same path, so
    ``codegen_support.derived`` and ``compiled`` (keyed by path and bytes) derive and generate
    it once per run. Outside a run, in the system's temporary folder."""
    digest = hashlib.sha256(f"{name}\0{text}".encode()).hexdigest()[:20]
    root = FOLDER[0] if FOLDER else Path(tempfile.gettempdir())
    path = root / "files" / digest / name
    if not path.is_file():
        path.parent.mkdir(parents=True, exist_ok=True)
        partial = path.with_name(f".{name}.{os.getpid()}")
        partial.write_text(text, encoding="utf-8")
        os.replace(partial, path)  # whole or absent for a worker reading it at once
    return path
