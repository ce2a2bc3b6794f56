"""Sweeps: many parameter sets of one mechanism through the generated batch solver, in this
process, in local processes or on a Dask cluster; and tolerance analysis on top of them.

``symkin.sweep`` names both this package and the function ``symkin.sweep(kernel, params, ...)``:
Python binds a subpackage to its parent's attribute once it is imported, so the package itself
is made callable and forwards to :func:`symkin.sweep.api.sweep`.
"""

from __future__ import annotations

import sys
import types
from typing import Any


class _CallablePackage(types.ModuleType):
    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        from symkin.sweep.api import sweep

        return sweep(*args, **kwargs)


sys.modules[__name__].__class__ = _CallablePackage
