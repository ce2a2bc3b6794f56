"""The code-generation backends, each one unit: a config, a printer and a template folder."""

from __future__ import annotations

from symkin.codegen.backends import c, numpy
from symkin.codegen.backends.config import Backend

ALL: dict[str, Backend] = {b.name: b for b in (c.BACKEND, numpy.BACKEND)}
NAMES = tuple(ALL)


def get(name: str) -> Backend:
    """The backend called ``name`` (lower() has already refused unknown names)."""
    return ALL[name]
