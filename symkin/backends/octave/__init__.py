"""The MATLAB/Octave backend: one .m function per file, for people who read the chapter's
program (``Wiezy``, ``Jakobian``, ``NewRaph``) and for running in GNU Octave.

Everything of the language is here: ``printer`` (MATLAB text, 1-based elements), the
templates in ``templates/`` beside this module, the file layout (``<prefix>_<what>.m``), and
``session`` (a running ``octave-cli`` the Kernel evaluates in) with ``loader``. symkin runs
the generated functions in Octave, found on PATH; the same files run unchanged in MATLAB.
"""

from __future__ import annotations

import platform
import shutil
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from symkin.codegen.target import Option, rendered_templates
from symkin.errors import MissingToolError

if TYPE_CHECKING:
    from symkin.codegen.lower import Code
    from symkin.runtime.kernel import Kernel

OCTAVE = "octave-cli"
"""The program symkin runs the generated functions with (Octave's command-line build)."""

PURPOSES = {
    "phi": "Phi(q, t, p) of {name}: the constraint equations, one row per joint or driver row",
    "phi_q": "Phi_q(q, t, p) of {name}: the Jacobian of Phi (sparse), and its non-zeros",
    "phi_t": "Phi_t(q, t, p) of {name}: the partial derivative of Phi with respect to t",
    "gamma": "Gamma(q, dq, t, p) of {name}: the right-hand side of Phi_q ddq = Gamma",
    "phi_p": "Phi_p(q, t, p) of {name}: d Phi / d p (sparse), and its non-zeros",
    "points": "the named points' local vectors of {name}, one row a point",
    "point_kinematics": "the named points' global positions, velocities and accelerations of "
                        "{name}",
    "removed": "the rows of {name} removed as dependent at t0, for the check along the motion",
    "senses": "the senses of {name}: each positive only at the configuration the file means",
    "dynamics_rhs": "Q - M ddq - h(q, dq) of {name}: the right-hand side of Phi_q' lam = rhs",
    "loads": "the efforts and joint reactions of {name} from the multipliers lam",
    "removed_q": "the Jacobian of the rows of {name} removed as dependent at t0",
    "loads_full": "the efforts and joint reactions of {name} from the multipliers of every row",
    "multipliers": "the multipliers lam of Phi_q' lam = Q - M ddq - h of {name}",
    "data": "the nominal parameters, starting point and time grid of {name}, with their names",
    "solve": "position, velocity and acceleration of {name} over a time grid",
    "README": "how to call the MATLAB/Octave functions of {name}",
}


class OctaveBackend:
    """The MATLAB/Octave backend (see the module docstring)."""

    name = "octave"
    title = "MATLAB/Octave"
    options: tuple[Option, ...] = (
        Option("real", ("double",), "double", "MATLAB and Octave compute in double"),)
    template_folder = "templates"

    @property
    def template_root(self) -> Path:
        # The backend's own folder: its templates ship inside it, with the package.
        return Path(__file__).resolve().parent

    def printer(self, options: Mapping[str, str]) -> Any:
        from symkin.backends.octave.printer import MatlabPrinter

        del options  # double only
        return MatlabPrinter()

    def literal(self, options: Mapping[str, str]) -> Callable[[float], str]:
        from symkin.octave_process import number

        del options
        return number

    def precision(self, options: Mapping[str, str]) -> str:
        return options["real"]

    def templates(self, code: Code) -> list[str]:
        del code  # MATLAB's backslash does the linear algebra
        return rendered_templates(self.template_root / self.template_folder)

    def output_name(self, template: str, prefix: str) -> str:
        # One function per file, named as the function: kernel names never clash between
        # mechanisms in one folder, which MATLAB's path would not tell apart.
        stem, suffix = template.removesuffix(".j2").rsplit(".", 1)
        return f"{prefix}_{stem}.{suffix}"

    def purpose(self, template: str) -> str:
        return PURPOSES[template.split(".")[0]]

    def plans_lu(self, options: Mapping[str, str]) -> bool:
        del options
        return False

    def template_context(self, code: Code) -> dict[str, Any]:
        from symkin.backends.octave.context import template_context

        return template_context(code)

    def routine_context(self, code: Code, routine: dict[str, Any]) -> dict[str, Any]:
        del code, routine  # the templates name each function after its file
        return {}

    def unavailable(self) -> str | None:
        if shutil.which(OCTAVE) is None:
            return (f"GNU Octave ({OCTAVE}) is not on PATH; install it (Debian/Ubuntu: "
                    "apt-get install octave) to run the MATLAB/Octave backend")
        return None

    def require(self) -> None:
        note = self.unavailable()
        if note is not None:
            raise MissingToolError(f"{note}; `symkin generate --backend octave` writes the "
                                   ".m files without it")

    def fingerprint(self) -> dict[str, Any]:
        return {"octave": shutil.which(OCTAVE) or "", "machine": platform.machine()}

    def build(self, files: dict[str, str], cache: Path) -> Kernel:
        from symkin.backends.octave import loader

        return loader.build(files, cache, self.name)

    def load(self, folder: Path, meta: Mapping[str, Any]) -> Kernel:
        from symkin.backends.octave import loader

        return loader.load(folder, meta, self.name)

    def loaded_files(self, folder: Path, name: str) -> list[str]:
        from symkin.contract.manifest import manifest_name

        return sorted([manifest_name(name), *(p.name for p in folder.glob(f"{name}_*.m"))])


BACKEND = OctaveBackend()
"""A MATLAB/Octave folder, evaluated in a running GNU Octave."""

