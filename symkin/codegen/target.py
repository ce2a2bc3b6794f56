"""What code generation asks of a backend (its target language), as a typed Protocol.

Code generation never names a backend: ``lower`` and ``render`` take a Target and ask it for
its printer, its literals, its templates, how files are named and what its templates need
besides the common context. The backends themselves live in :mod:`symkin.backends`, one
folder each; ``symkin.build.backend.Backend`` adds how a rendered folder becomes a kernel.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any, Protocol

from symkin.errors import BuildError


class Target(Protocol):
    """One language code generation writes.

    Attributes:
        name: what users pass as ``backend=``; recorded in manifests and the warm-run index.
        title: the name in messages ("C", "NumPy").
        real_types: the real types it can generate, the default first.
        template_folder: its templates' folder under ``template_root``; every ``X.Y.j2`` not
            starting with ``_`` there renders to one file.
    """

    name: str
    title: str
    real_types: tuple[str, ...]
    template_folder: str

    @property
    def template_root(self) -> Path:
        """The folder jinja2 loads from; templates include each other by paths relative to
        it (``{% include "c/_banner.j2" %}``)."""
        ...

    def printer(self, real: str) -> Any:
        """A SymPy code printer for ``real`` that maps symbols via ``codegen.symbol_printing``."""
        ...

    def literal(self, real: str) -> Callable[[float], str]:
        """How a float is written as a literal of the language and real type."""
        ...

    def templates(self, linalg: str) -> list[str]:
        """The templates that each render to one file, sorted."""
        ...

    def output_name(self, template: str, prefix: str) -> str:
        """The file ``template`` renders to for the mechanism ``prefix``."""
        ...

    def purpose(self, template: str) -> str:
        """What the file rendered from ``template`` is (``{name}``: the mechanism), for its
        header."""
        ...

    def plans_lu(self, linalg: str) -> bool:
        """Whether its solver wants the sparse LU plan (``Code.lu_plan``) for ``linalg``."""
        ...

    def template_context(self, code: Any) -> dict[str, Any]:
        """What its templates need beyond the common context of ``render.template_context``
        (``code`` is the ``codegen.lower.Code``; not named here, which would be a cycle)."""
        ...


def rendered_templates(folder: Path) -> list[str]:
    """The ``X.Y.j2`` files of ``folder`` that each render to one file (partials start with
    ``_``), sorted."""
    return sorted(p.name for p in folder.glob("*.j2") if not p.name.startswith("_"))


def file_name(template: str, prefix: str, module_template: str) -> str:
    """``kernel.h.j2 -> crank_slider.h``; ``solver.c.j2 -> crank_slider_solver.c``: the
    template ``module_template`` names the file after the mechanism, the others add their
    stem."""
    stem, suffix = template.removesuffix(".j2").rsplit(".", 1)
    return f"{prefix}.{suffix}" if stem == module_template else f"{prefix}_{stem}.{suffix}"


REAL_TYPES = ("double", "float")
# The linear algebra behind the C solver: the C backend's templates/linalg.*.j2 (dense LU
# with partial pivoting) or templates/sparse_lu.*.j2 (a sparse LU whose pivot order is fixed
# here).
LINALG = ("dense", "sparse")


def check_options(backend: Target, real: str, linalg: str) -> None:
    """Refuse an unknown linear algebra or real type, or one ``backend`` does not compute in."""
    if linalg not in LINALG:
        raise BuildError(f"unknown linear algebra {linalg!r}; choose 'dense' or 'sparse'")
    if real not in REAL_TYPES:
        raise BuildError(f"unknown real type {real!r}; choose 'double' or 'float'")
    if real not in backend.real_types:
        raise BuildError(f"the {backend.title} backend computes in "
                         f"{' or '.join(backend.real_types)} precision; use "
                         f"real={backend.real_types[0]!r}")
