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
from typing import Any

from symkin import resources


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
