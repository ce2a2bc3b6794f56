"""The generated C's ``<prefix>_multipliers_grid`` through cffi: the Lagrange multipliers
and the efforts and reactions of a whole solved trajectory in one call."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]


def grid(ffi: Any, lib: Any, name: str, real: str, t: Array, q: Array, dq: Array, d2q: Array,
         p: Array, n_loads: int) -> tuple[Array, Array]:
    """lam (T, N) and loads (T, n_loads) of the solved rows t, q, dq, d2q (NaN where Phi_q
    is singular), in the kernel's real type and returned as float64."""
    dtype = np.float32 if real == "float" else np.float64
    n = t.size
    lam = np.zeros(q.shape, dtype=dtype)
    loads = np.zeros((n, n_loads), dtype=dtype)
    if n == 0:
        return lam.astype(float), loads.astype(float)
    arrays = [np.ascontiguousarray(a, dtype=dtype) for a in (p, t, q, dq, d2q)]
    real_array = f"{name}_real[]"
    pointers = [ffi.from_buffer(real_array, a) if a.size else ffi.NULL for a in arrays]
    lu = ffi.new_allocator(should_clear_after_alloc=False)(f"{name}_lu *")
    out_loads = ffi.from_buffer(real_array, loads) if loads.size else ffi.NULL
    getattr(lib, f"{name}_multipliers_grid")(pointers[0], n, *pointers[1:],
                                             ffi.from_buffer(real_array, lam), out_loads, lu)
    return lam.astype(np.float64, copy=False), loads.astype(np.float64, copy=False)
