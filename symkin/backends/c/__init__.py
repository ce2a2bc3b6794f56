"""The C99 backend: a self-contained C folder per mechanism, built with cffi.

Its pieces, each imported only when needed (loading a built kernel never imports SymPy):
``printer`` (C99 text), ``lu_code``, ``norm_code``, ``inverse_code`` and ``context`` (the
solver's template data), ``cdef`` (cffi declarations from the headers), ``toolchain`` (the
compiler), ``cffi_build`` (the build), ``loader`` (the CKernel), ``csolver`` and ``batch``
(the generated grid and batch solvers through cffi). Templates: ``templates/`` beside this
module. Its options (:data:`OPTIONS`): the real type and the LU behind the solver.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from symkin.codegen.target import Option, file_name, rendered_templates
from symkin.contract.manifest import MANIFEST_SUFFIX, manifest_name

if TYPE_CHECKING:
    from symkin.codegen.lower import Code
    from symkin.runtime.kernel import Kernel

PURPOSES = {
    "kernel": "kinematic kernel of the mechanism {name}: Phi, Phi_q, Phi_t, Gamma, points",
    "solver": "position, velocity and acceleration analysis of {name}, one call a step",
    "linalg": "the solver's linear algebra on the dense LU",
    "sparse_lu": "sparse LU of Phi_q with its pivot order fixed at generation time",
    "dense_lu": "dense LU with partial pivoting (also the sparse LU's fall-back)",
    "dynamics": "forward dynamics of {name}: one integrator step a call",
    "README": "how to build and call the solver of {name} in a controller loop",
}
# linalg.*.j2 (on the dense LU) and sparse_lu.*.j2 define the same functions: only the chosen
# one is rendered; dense_lu.*.j2, which both use, always is.
_LINALG_TEMPLATES = {"dense": "linalg", "sparse": "sparse_lu"}

REAL = Option("real", ("double", "float"), "double", "C real type (default double)")
LINALG = Option("linalg", ("sparse", "dense"), "sparse",
                "LU behind the C solver: generated sparse LU with run-time pivot checks and a "
                "dense fall-back (default), or dense partial pivoting")
OPTIONS = (REAL, LINALG)


class CBackend:
    """The C99 backend (see the module docstring)."""

    name = "c"
    title = "C"
    options: tuple[Option, ...] = OPTIONS
    # its kernels evaluate the mass matrix and applied forces (build.motion integrates)
    equations_of_motion = True
    template_folder = "templates"

    @property
    def template_root(self) -> Path:
        # The backend's own folder: its templates ship inside it, with the package.
        return Path(__file__).resolve().parent

    def printer(self, options: Mapping[str, str]) -> Any:
        from symkin.backends.c.printer import CPrinter

        return CPrinter(options[REAL.name])

    def literal(self, options: Mapping[str, str]) -> Callable[[float], str]:
        from symkin.backends.c.printer import literal

        return literal(options[REAL.name])

    def precision(self, options: Mapping[str, str]) -> str:
        return options[REAL.name]

    def templates(self, code: Code) -> list[str]:
        left_out = _LINALG_TEMPLATES["sparse" if linalg(code) == "dense" else "dense"]
        return [name for name in rendered_templates(self.template_root / self.template_folder)
                if name.split(".")[0] != left_out]

    def output_name(self, template: str, prefix: str) -> str:
        return file_name(template, prefix, "kernel")

    def purpose(self, template: str) -> str:
        return PURPOSES[template.split(".")[0]]

    def plans_lu(self, options: Mapping[str, str]) -> bool:
        return options[LINALG.name] == "sparse"

    def template_context(self, code: Code) -> dict[str, Any]:
        from symkin.backends.c import context

        return context.template_context(code)

    def routine_context(self, code: Code, routine: dict[str, Any]) -> dict[str, Any]:
        from symkin.backends.c import context

        return context.routine_context(code, routine)

    def unavailable(self) -> str | None:
        from symkin.backends.c import toolchain

        return toolchain.missing()

    def require(self) -> None:
        from symkin.backends.c import toolchain

        toolchain.require()

    def fingerprint(self) -> dict[str, Any]:
        from symkin.backends.c import toolchain

        return toolchain.fingerprint(toolchain.c_compiler())

    def build(self, files: dict[str, str], cache: Path) -> Kernel:
        from symkin.backends.c import cffi_build, toolchain

        toolchain.require()
        compiler = toolchain.c_compiler()
        assert compiler is not None  # require() raised otherwise
        names = [n for n in files if n.endswith(MANIFEST_SUFFIX)]
        return cffi_build.build(files, names[0].removesuffix(MANIFEST_SUFFIX), cache,
                                compiler)

    def load(self, folder: Path, meta: Mapping[str, Any]) -> Kernel:
        from symkin.backends.c import loader

        return loader.load(folder, meta)

    def loaded_files(self, folder: Path, name: str) -> list[str]:
        from symkin.backends.c import loader

        return [manifest_name(name), loader.extension_file(folder).name]


def real(code: Code) -> str:
    """The real type ``code`` is generated in (its ``real`` option)."""
    return code.options[REAL.name]


def linalg(code: Code) -> str:
    """The LU the solver of ``code`` runs on: the sparse one where lowering planned it (the
    ``linalg`` option, for a mechanism with a kinematic solve), else the dense one."""
    return "sparse" if code.lu_plan is not None else "dense"


BACKEND = CBackend()
