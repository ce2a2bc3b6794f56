"""The C toolchain: which compiler, and what identifies it in a cache key.

One place for compiler detection, so the build cache and the warm-run index can never disagree
about which compiler a kernel was built with.
"""

from __future__ import annotations

import functools
import os
import platform
import shlex
import shutil
import subprocess
import sys
import sysconfig
import warnings
from typing import Any

from symkin import resources
from symkin.errors import NoCompilerError, SymkinWarning


def c_compiler() -> list[str] | None:
    """The C compiler command (``$CC``, else Python's, else ``cc``), or None when missing."""
    if os.name != "posix":
        return None
    command = shlex.split(os.environ.get("CC") or sysconfig.get_config_var("CC") or "cc")
    return command if command and shutil.which(command[0]) else None


@functools.cache
def compiler_version(command: tuple[str, ...]) -> str:
    """What ``CC --version`` prints (first line): a new compiler must mean a new cache key."""
    try:
        result = subprocess.run([*command, "--version"], capture_output=True, text=True,
                                timeout=30, check=False)
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    lines = result.stdout.strip().splitlines()
    return lines[0] if lines else "unknown"


def fingerprint(compiler: list[str] | None) -> dict[str, Any]:
    """Everything besides the sources that decides a built extension: interpreter, cffi,
    platform and the compiler with its path and version."""
    import cffi

    found: dict[str, Any] = {
        "cffi": cffi.__version__, "python": sys.version,
        "implementation": sys.implementation.cache_tag or "",
        "platform": sysconfig.get_platform(), "machine": platform.machine(),
        "suffix": resources.extension_suffix()}
    if compiler:
        found["compiler"] = [shutil.which(compiler[0]), *compiler]
        found["compiler_version"] = compiler_version(tuple(compiler))
    return found


BACKENDS = ("auto", "c", "numpy")


def resolve_backend(backend: str) -> str:
    """The backend to build: ``"auto"`` is C when a compiler is found, else NumPy with a
    one-line note; an explicit ``"c"`` without a compiler is an error, never a silent NumPy.

    Raises:
        NoCompilerError: ``"c"`` was asked for and no C compiler is found.
    """
    if backend not in ("auto", "c"):
        return backend
    if c_compiler() is not None:
        return "c"
    looked_for = os.environ.get("CC") or "cc"
    if backend == "c":
        raise NoCompilerError(
            f"the C backend needs a C compiler and none was found (looked for {looked_for}). "
            "Install one (Debian/Ubuntu: apt install gcc; macOS: xcode-select --install; "
            "or conda install c-compiler), set CC to it, or use backend 'numpy' or 'auto'.")
    warnings.warn(f"no C compiler found (looked for {looked_for}): using the NumPy backend, "
                  "which gives the same results, more slowly. Install gcc or clang, or set "
                  "CC, for the C backend.", SymkinWarning,
                  stacklevel=3)
    return "numpy"
