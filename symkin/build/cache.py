"""The build cache: content-addressed folders of built kernels, verified before every load.

A folder's name carries the sha256 of everything that decides its contents. It is filled under
a private temporary name (``.<folder>.<pid>.<random>``) and renamed into place in one step, so
concurrent builds of the same kernel all succeed and none sees half a folder; the sha256 of
every file it holds is recorded in it (:data:`RECORD`) before the rename.

Nothing found in the cache is trusted by its name alone: before a kernel is loaded, every
recorded file must still have its recorded hash, and the sources must be the ones this symkin
would generate now. A folder that fails (planted, truncated, edited) is moved aside and
rebuilt, never imported. The cache itself is private: created 0700, and a folder that another
user owns or that others may write is not used (symkin falls back to a private temporary
cache, with one note). Temporaries left by a killed build are removed when their process is
gone.
"""

from __future__ import annotations

import atexit
import contextlib
import functools
import hashlib
import json
import os
import shutil
import stat
import tempfile
import warnings
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from symkin.contract.manifest import MANIFEST_SUFFIX, manifest_name
from symkin.errors import BuildError, SymkinWarning

RECORD = ".symkin-files.json"
"""Inside each kernel folder: {file name: sha256} of everything the build wrote."""

KERNEL_PREFIX = "_symkin_"
"""Every kernel folder's name starts with this; nothing else in a cache is symkin's."""


def cache_root() -> Path:
    """``$SYMKIN_CACHE_DIR``, else the user cache folder: one folder for kernels and index."""
    explicit = os.environ.get("SYMKIN_CACHE_DIR")
    if explicit:
        return Path(explicit)
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "symkin"


def open_cache(folder: str | Path | None = None) -> Path:
    """The cache folder to use: ``folder`` (default :func:`cache_root`) when it is private and
    writable, else a private temporary one (with one note per process and folder)."""
    wanted = Path(folder) if folder is not None else cache_root()
    problem = unusable(wanted)
    if problem is None:
        _clean_stale(wanted)
        return wanted
    return _fallback(str(wanted), problem)


def unusable(folder: Path) -> str | None:
    """Why ``folder`` cannot serve as a private cache, or None when it can."""
    try:
        folder.mkdir(mode=0o700, parents=True, exist_ok=True)
        info = folder.stat()
    except OSError as error:
        return f"it cannot be created ({error.strerror or error})"
    if not stat.S_ISDIR(info.st_mode):
        return "it is not a folder"
    if hasattr(os, "getuid") and info.st_uid != os.getuid():
        return "another user owns it, so a kernel in it could have been planted"
    if info.st_mode & (stat.S_IWGRP | stat.S_IWOTH):
        return "others may write to it, so a kernel in it could have been planted"
    if not os.access(folder, os.W_OK | os.X_OK):
        return "it is not writable"
    return None


@functools.cache
def _fallback(wanted: str, problem: str) -> Path:
    private = Path(tempfile.mkdtemp(prefix="symkin-cache-"))
    atexit.register(shutil.rmtree, private, ignore_errors=True)  # nothing left behind
    warnings.warn(f"the cache folder {wanted} is not used: {problem}. Kernels are built in "
                  f"{private} for this run; set SYMKIN_CACHE_DIR to a private folder.",
                  SymkinWarning, stacklevel=3)
    return private


@functools.cache
def _clean_stale(cache: Path) -> None:
    """Remove temporaries of builds whose process is gone (killed mid-build)."""
    try:
        entries = list(cache.iterdir())
    except OSError:
        return
    for entry in entries:
        pid = _owner(entry.name)
        if pid is not None and not _alive(pid):
            shutil.rmtree(entry, ignore_errors=True)


def _owner(name: str) -> int | None:
    """The process id in a temporary's name ``.<folder>.<pid>.<random>``, else None."""
    parts = name.split(".")
    if len(parts) >= 4 and name.startswith(f".{KERNEL_PREFIX}") and parts[-2].isdigit():
        return int(parts[-2])
    if name.startswith(".discarded.") and len(parts) >= 4 and parts[2].isdigit():
        return int(parts[2])
    return None


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:
        return True  # it exists, but is not ours to signal
    return True


def publish(cache: Path, folder: Path, fill: Callable[[Path], Any]) -> None:
    """Fill a private temporary folder, record its files' hashes, and rename it to ``folder``.

    When another process published the same folder first, the rename fails; its result is
    the same (same key, same inputs), so this build is discarded.
    """
    cache.mkdir(mode=0o700, parents=True, exist_ok=True)
    build = Path(tempfile.mkdtemp(dir=cache, prefix=f".{folder.name}.{os.getpid()}."))
    try:
        fill(build)
        record = {path.name: sha256_of(path) for path in sorted(build.iterdir())
                  if path.is_file()}
        (build / RECORD).write_text(json.dumps(record, indent=1, sort_keys=True),
                                    encoding="utf-8")
        try:
            os.replace(build, folder)
        except OSError:
            if not folder.is_dir():
                raise
    finally:
        if build.exists():
            shutil.rmtree(build, ignore_errors=True)


def verified(folder: Path, expected: Mapping[str, str]) -> bool:
    """Whether ``folder`` is a kernel symkin built and nobody changed: every file in its record
    has the recorded hash, and the files of ``expected`` ({name: text}) are exactly those
    texts. A folder that fails is moved aside, so the caller rebuilds it."""
    if not folder.is_dir():
        return False
    try:
        record = json.loads((folder / RECORD).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        record = None
    good = isinstance(record, dict) and all(
        isinstance(name, str) and Path(name).name == name and sha256_of(folder / name) == digest
        for name, digest in record.items()) and all(
        record.get(name) == hashlib.sha256(text.encode()).hexdigest()
        for name, text in expected.items())
    if not good:
        discard(folder)
    return good


def build_unless_verified(cache: Path, folder: Path, expected: dict[str, str],
                          build: Callable[[Path], Any]) -> None:
    """Publish a fresh build unless ``folder`` holds a verified one; a folder that fails
    verification, whoever put it there, is never loaded."""
    if verified(folder, expected):
        return
    publish(cache, folder, build)
    if not verified(folder, expected):
        raise BuildError(f"the kernel folder {folder} changed while it was being built; "
                         "run again, and make sure no other user can write to the cache")


def checked_manifest(files: Mapping[str, str]) -> dict[str, Any]:
    """The manifest of a generated folder given as text (``{file name: text}``), after
    checking that the names, the manifest and its file list agree.

    Raises:
        BuildError: the files are not one generated symkin folder.
    """
    manifests = [name for name in files if name.endswith(MANIFEST_SUFFIX)]
    if len(manifests) != 1:
        raise BuildError(f"expected one symkin manifest among the files, found {len(manifests)}")
    meta: dict[str, Any] = json.loads(files[manifests[0]])
    name = meta.get("name")
    plain = all(isinstance(n, str) and Path(n).name == n and not n.startswith(".")
                for n in files)
    if not (isinstance(name, str) and name.isidentifier() and plain
            and manifests[0] == manifest_name(name)
            and set(files) == {*meta.get("files", {}), manifests[0]}):
        raise BuildError("the files are not one generated symkin folder (names, manifest and "
                         "file list must agree); send the folder symkin.compile built")
    return meta


def discard(folder: Path) -> None:
    """Move a kernel folder out of the way in one atomic step, then delete it."""
    if not folder.is_dir():
        return
    trash = Path(tempfile.mkdtemp(dir=folder.parent, prefix=f".discarded.{os.getpid()}."))
    with contextlib.suppress(OSError):  # already gone: nothing to move
        os.replace(folder, trash / folder.name)
    shutil.rmtree(trash, ignore_errors=True)


def sha256_of(path: Path) -> str | None:
    """The sha256 of a file's bytes, or None when it cannot be read."""
    try:
        return hashlib.sha256(path.read_bytes()).hexdigest()
    except OSError:
        return None


def content_key(inputs: dict[str, Any]) -> str:
    """The sha256 of a JSON-able description of a build's inputs."""
    return hashlib.sha256(json.dumps(inputs, sort_keys=True).encode()).hexdigest()
