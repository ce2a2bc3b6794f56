"""A derived System through pickle, unchanged: the copy generates the same bytes.

SymPy rebuilds a pickled expression by calling its class on its arguments, which evaluates
what the derivation deliberately left unevaluated: ``-2*(a**2 + b**2)`` comes back expanded,
so the copy's code would count other operations. A System therefore pickles its fields as one
blob and rebuilds them with evaluation off; their arguments are already in SymPy's canonical
form, so nothing else changes.
"""

from __future__ import annotations

import dataclasses
import pickle
from typing import Any

from sympy.core.parameters import evaluate


def dumps(instance: Any) -> bytes:
    """The class of a dataclass ``instance`` and its fields by name, pickled."""
    fields = {field.name: getattr(instance, field.name) for field in dataclasses.fields(instance)}
    return pickle.dumps((type(instance), fields), protocol=pickle.HIGHEST_PROTOCOL)


def restore(blob: bytes) -> Any:
    """The instance :func:`dumps` pickled, its expressions rebuilt without evaluation."""
    with evaluate(False):
        kind, fields = pickle.loads(blob)  # the caller's own pickle of a System
    return kind(**fields)
