"""The C toolchain: which compiler, what identifies it in a cache key, and running it.

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
from pathlib import Path
from typing import Any

from symkin import resources
from symkin.errors import BuildError, NoCompilerError


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


def missing() -> str | None:
    """Why C cannot be built here (no compiler), or None when a compiler is found."""
    if c_compiler() is not None:
        return None
    return (f"no C compiler found (looked for {os.environ.get('CC') or 'cc'}): install gcc "
            "or clang, or set CC, for the C backend")


def require() -> None:
    """Raise NoCompilerError, saying how to install one, when no C compiler is found."""
    if c_compiler() is None:
        raise NoCompilerError(
            "the C backend needs a C compiler and none was found (looked for "
            f"{os.environ.get('CC') or 'cc'}). Install one (Debian/Ubuntu: apt install gcc; "
            "macOS: xcode-select --install; or conda install c-compiler), set CC to it, or "
            "use backend 'numpy' or 'auto'.")


class CompilerError(BuildError):
    """The C compiler failed: ``command`` is what ran, ``stderr`` what it said."""

    def __init__(self, command: list[str], returncode: int, stderr: str) -> None:
        self.command = command
        self.returncode = returncode
        self.stderr = stderr
        super().__init__(f"the C compiler failed (exit status {returncode}):\n"
                         f"  {shlex.join(command)}\n{stderr.strip()}")


def run(command: list[str], cwd: Path) -> None:
    """Run a compiler command; on failure raise CompilerError with the command and its output."""
    try:
        result = subprocess.run(command, cwd=cwd, capture_output=True, text=True, check=False)
    except OSError as error:
        raise BuildError(f"could not run {shlex.join(command)}: {error}") from None
    if result.returncode != 0:
        raise CompilerError(command, result.returncode, result.stderr)
