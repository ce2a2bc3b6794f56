"""What makes a backend: a printer, a template folder, how literals and files are named.

Adding a backend means one module beside ``c.py`` and ``numpy.py`` with a :class:`Backend`,
a folder ``templates/<template_folder>/`` and an entry in :data:`symkin.codegen.backends.ALL`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class Backend:
    """One code-generation backend.

    Attributes:
        name: what users pass as ``backend=``.
        template_folder: its folder under ``templates/``.
        printer: ``printer(real)`` -> a SymPy code printer mapping symbols via symbol_text.
        literal: ``literal(real)`` -> a function printing a float as a literal of the language.
        module_template: the stem of the template rendered to ``<prefix>.<suffix>``; every
            other ``X.Y.j2`` renders to ``<prefix>_X.Y``.
        purposes: per template stem, what its file is (``{name}`` is the mechanism), for the
            header of the generated file.
    """

    name: str
    template_folder: str
    printer: Callable[[str], Any]
    literal: Callable[[str], Callable[[float], str]]
    module_template: str
    purposes: Mapping[str, str]

    def purpose(self, template: str) -> str:
        """What the file rendered from ``template`` is, for its header."""
        return self.purposes[template.split(".")[0]]

    def output_name(self, template: str, prefix: str) -> str:
        """``kernel.h.j2 -> crank_slider.h``; ``solver.c.j2 -> crank_slider_solver.c``."""
        stem, suffix = template.removesuffix(".j2").rsplit(".", 1)
        return f"{prefix}.{suffix}" if stem == self.module_template else f"{prefix}_{stem}.{suffix}"
