"""A backend as the build stage and the warm-run index see it: a code-generation Target plus
how its rendered folder becomes a loaded runtime Kernel.

The build stage never names a backend: ``compile``, ``index`` and the registry of
:mod:`symkin.backends` hand one of these objects down, and every decision that differs between
backends (whether it can build here, what identifies its toolchain, how files are built and
loaded) is a method of it.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

from symkin.codegen.target import Target

if TYPE_CHECKING:  # the registry imports this module: no NumPy at CLI start-up
    from symkin.runtime.kernel import Kernel


class Backend(Target, Protocol):
    """A code-generation target that can also be built and loaded."""

    def unavailable(self) -> str | None:
        """Why it cannot build on this machine (e.g. no compiler), or None when it can."""
        ...

    def require(self) -> None:
        """Raise the error that says how to make it available (``NoCompilerError`` where it
        needs a compiler);
        nothing when :meth:`unavailable` is None."""
        ...

    def fingerprint(self) -> dict[str, Any]:
        """Everything besides the sources that decides a built kernel (interpreter,
        compiler): part of the warm-run index key."""
        ...

    def build(self, files: dict[str, str], cache: Path) -> Kernel:
        """Build (or find verified in ``cache``) and load the kernel of a rendered folder,
        given as ``{file name: text}`` with its manifest."""
        ...

    def load(self, folder: Path, meta: Mapping[str, Any]) -> Kernel:
        """Load a built kernel from ``folder``; ``meta`` is its manifest."""
        ...

    def loaded_files(self, folder: Path, name: str) -> list[str]:
        """The files :meth:`load` reads (the warm-run index records their hashes)."""
        ...
