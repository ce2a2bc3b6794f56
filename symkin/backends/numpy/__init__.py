"""The NumPy backend: one Python module per mechanism, imported from the build cache; needs
no compiler. Its pieces: ``printer`` (NumPy text; imported only when generating), ``naming``
(the Python names, signatures and literals of the template) and ``loader`` (the Kernel over
the module). Templates: ``templates/`` beside this
module.
"""

from __future__ import annotations

import platform
import sys
import sysconfig
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from symkin.codegen.target import Option, file_name, rendered_templates
from symkin.contract.manifest import MANIFEST_SUFFIX, manifest_name

if TYPE_CHECKING:
    from symkin.codegen.lower import Code
    from symkin.runtime.kernel import Kernel


class NumPyBackend:
    """The NumPy backend (see the module docstring)."""

    name = "numpy"
    title = "NumPy"
    options: tuple[Option, ...] = (
        Option("real", ("double",), "double", "NumPy computes in double"),)
    # its kernels evaluate the mass matrix and applied forces (build.motion integrates)
    equations_of_motion = True
    template_folder = "templates"

    @property
    def template_root(self) -> Path:
        # The backend's own folder: its templates ship inside it, with the package.
        return Path(__file__).resolve().parent

    def printer(self, options: Mapping[str, str]) -> Any:
        from symkin.backends.numpy.printer import PythonPrinter

        del options  # double only
        return PythonPrinter()

    def literal(self, options: Mapping[str, str]) -> Callable[[float], str]:
        del options
        return repr

    def precision(self, options: Mapping[str, str]) -> str:
        return options["real"]

    def templates(self, code: Code) -> list[str]:
        del code  # one module; the Python driver does the linear algebra
        return rendered_templates(self.template_root / self.template_folder)

    def output_name(self, template: str, prefix: str) -> str:
        return file_name(template, prefix, "kernel")

    def purpose(self, template: str) -> str:
        del template  # one file
        return "kinematic kernel of the mechanism {name}"

    def plans_lu(self, options: Mapping[str, str]) -> bool:
        del options
        return False

    def template_context(self, code: Code) -> dict[str, Any]:
        from symkin.backends.numpy import naming

        return naming.template_context(code)

    def routine_context(self, code: Code, routine: dict[str, Any]) -> dict[str, Any]:
        from symkin.backends.numpy import naming

        return naming.routine_context(code, routine)

    def unavailable(self) -> str | None:
        return None

    def require(self) -> None:
        return None

    def fingerprint(self) -> dict[str, Any]:
        return {"python": sys.version, "implementation": sys.implementation.cache_tag or "",
                "platform": sysconfig.get_platform(), "machine": platform.machine()}

    def build(self, files: dict[str, str], cache: Path) -> Kernel:
        from symkin.backends.numpy import loader

        return loader.build(files, _name(files), cache, self.name)

    def load(self, folder: Path, meta: Mapping[str, Any]) -> Kernel:
        from symkin.backends.numpy import loader

        return loader.load(folder, meta["name"], self.name)

    def loaded_files(self, folder: Path, name: str) -> list[str]:
        del folder
        return [manifest_name(name), f"{name}.py"]


def _name(files: Mapping[str, str]) -> str:
    """The mechanism of a generated folder: its manifest's prefix."""
    manifest = next(n for n in files if n.endswith(MANIFEST_SUFFIX))
    return manifest.removesuffix(MANIFEST_SUFFIX)


BACKEND = NumPyBackend()
