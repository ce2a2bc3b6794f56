"""What code generation asks of a backend (its target language), as a typed Protocol.

Code generation never names a backend: ``lower`` and ``render`` take a Target and ask it for
its printer, its literals, its templates, how files are named and what its templates need
besides the common context. A backend's options (such as a real type) are its own: declared
as :class:`Option` fields, checked by :func:`chosen_options`, carried to it as an opaque
mapping. The backends themselves live in :mod:`symkin.backends`, one
folder each; ``symkin.build.backend.Backend`` adds how a rendered folder becomes a kernel.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any, NamedTuple, Protocol

from symkin.errors import BuildError


class Option(NamedTuple):
    """A choice a backend offers (a real type, the LU behind its solver), declared by the
    backend: the stages carry the chosen values as an opaque mapping and never read one; the
    CLI builds its flags from these declarations.

    Attributes:
        name: the keyword (``symkin.compile(..., name=value)``) and the flag (``--name``).
        choices: the values it takes.
        default: the value taken when none is given (one of ``choices``).
        help: one line for ``--help``.

    A NamedTuple, not a dataclass: the CLI reads the declarations to build its flags, and
    ``--help`` stays light (dataclasses import inspect, which the light start forbids).
    """

    name: str
    choices: tuple[str, ...]
    default: str
    help: str


class Target(Protocol):
    """One language code generation writes.

    Attributes:
        name: what users pass as ``backend=``; recorded in manifests and the warm-run index.
        title: the name in messages.
        options: the choices it offers (:class:`Option`); what it is given is checked
            against them by :func:`chosen_options`.
        template_folder: its templates' folder under ``template_root``; every ``X.Y.j2`` not
            starting with ``_`` there renders to one file.
    """

    name: str
    title: str
    options: tuple[Option, ...]
    template_folder: str

    @property
    def template_root(self) -> Path:
        """The folder jinja2 loads from; templates include each other by paths relative to
        it (``{% include "templates/_banner.j2" %}``)."""
        ...

    def printer(self, options: Mapping[str, str]) -> Any:
        """A SymPy code printer that maps symbols via ``codegen.symbol_printing``."""
        ...

    def literal(self, options: Mapping[str, str]) -> Callable[[float], str]:
        """How a number is written as a literal of the language (and chosen real type)."""
        ...

    def precision(self, options: Mapping[str, str]) -> str:
        """The real type the generated code computes in, as the manifest records it for the
        runtime (a key of ``contract.tuning.UNIT_ROUNDOFF``) and the headers name it."""
        ...

    def templates(self, code: Any) -> list[str]:
        """The templates that each render to one file for ``code`` (a ``codegen.lower.Code``),
        sorted."""
        ...

    def output_name(self, template: str, prefix: str) -> str:
        """The file ``template`` renders to for the mechanism ``prefix``."""
        ...

    def purpose(self, template: str) -> str:
        """What the file rendered from ``template`` is (``{name}``: the mechanism), for its
        header."""
        ...

    def plans_lu(self, options: Mapping[str, str]) -> bool:
        """Whether its solver wants the sparse LU plan (``Code.lu_plan``)."""
        ...

    def template_context(self, code: Any) -> dict[str, Any]:
        """What its templates need beyond the common context of ``render.template_context``
        (``code`` is the ``codegen.lower.Code``; not named here, which would be a cycle)."""
        ...

    def routine_context(self, code: Any, routine: dict[str, Any]) -> dict[str, Any]:
        """What its templates need of one routine beyond the common entries ``routine`` (its
        name, arguments, output arrays and parts): signatures, names in the language."""
        ...


def rendered_templates(folder: Path) -> list[str]:
    """The ``X.Y.j2`` files of ``folder`` that each render to one file (partials start with
    ``_``), sorted."""
    return sorted(p.name for p in folder.glob("*.j2") if not p.name.startswith("_"))


def file_name(template: str, prefix: str, module_template: str) -> str:
    """``kernel.X.j2 -> crank_slider.X``; ``solver.X.j2 -> crank_slider_solver.X``: the
    template ``module_template`` names the file after the mechanism, the others add their
    stem."""
    stem, suffix = template.removesuffix(".j2").rsplit(".", 1)
    return f"{prefix}.{suffix}" if stem == module_template else f"{prefix}_{stem}.{suffix}"


def chosen_options(backend: Target, given: Mapping[str, str] | None = None, *,
                   flags: bool = False) -> dict[str, str]:
    """The options ``backend`` is to generate with: ``given`` checked against its declarations,
    the defaults of the rest filled in.

    Args:
        backend: the target.
        given: option name to value, as the user gave them.
        flags: spell them as command-line flags (``--name value``) in a message.

    Raises:
        BuildError: an option the backend does not take, or a value it does not offer (the
            message names what it takes).
    """
    declared = {option.name: option for option in backend.options}
    for name, value in (given or {}).items():
        shown = str(value)[:40] + ("..." if len(str(value)) > 40 else "")  # bounded message
        spelled = f"--{name} {shown}" if flags else f"{name}={shown!r}"
        option = declared.get(name)
        if option is None:
            takes = (", ".join(sorted(declared)) if declared else "none")
            raise BuildError(f"{spelled} is not for the {backend.title} backend, which takes no "
                             f"option {name!r} (its options: {takes})")
        if value not in option.choices:
            raise BuildError(f"{spelled} is not for the {backend.title} backend, which takes "
                             f"{name} {' or '.join(map(repr, option.choices))}")
    return {name: (given or {}).get(name, option.default) for name, option in declared.items()}
