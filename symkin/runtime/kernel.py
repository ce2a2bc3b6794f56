"""The runtime kernel: one mechanism's compiled Phi, Phi_q, Phi_t and Gamma behind one API.

A Kernel wraps either a generated NumPy module or a cffi extension built from the generated C,
plus the metadata of the mechanism (coordinates, parameters, pattern, grid). It imports only
NumPy, so running a compiled kernel never loads SymPy or jinja2.
"""

from __future__ import annotations

import hashlib
import importlib.machinery
import importlib.util
import json
import sys
from collections.abc import Callable, Mapping
from pathlib import Path
from types import ModuleType
from typing import Any, Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from symkin import resources
from symkin.contract.manifest import MANIFEST_SUFFIX, manifest_name
from symkin.contract.options import Options
from symkin.runtime.csolver import GridSolver, SolverPool

Array = NDArray[np.float64]


class _Functions(Protocol):
    """What a backend evaluates: flat output arrays in the generated order."""

    def phi(self, q: Array, t: float, p: Array) -> Array: ...
    def phi_q_nz(self, q: Array, t: float, p: Array) -> Array: ...
    def phi_t(self, q: Array, t: float, p: Array) -> Array: ...
    def gamma(self, q: Array, dq: Array, t: float, p: Array) -> Array: ...
    def points(self, p: Array) -> Array: ...
    def phi_p_nz(self, q: Array, t: float, p: Array) -> Array: ...


class Kernel:
    """The compiled kinematics of one mechanism (DESIGN.md, Python API).

    Every function takes ``p=None`` to mean the nominal parameter values.
    """

    def __init__(self, backend: str, meta: Mapping[str, Any], functions: _Functions,
                 ffi: Any = None, lib: Any = None, folder: Path | None = None) -> None:
        self.backend = backend
        # The real type the kernel computes in: "float" only for C kernels built so.
        self.real: str = meta.get("real", "double")
        # The cache folder the kernel was loaded from (None for one built elsewhere).
        self.folder = folder
        self.name: str = meta["name"]
        self.coordinates: tuple[str, ...] = tuple(meta["coordinates"])
        self.parameter_names: tuple[str, ...] = tuple(meta["parameter_names"])
        self.p_values: Array = np.array(meta["p_values"], dtype=float)
        self.q0: Array = np.array(meta["q0"], dtype=float)
        self.time_grid: tuple[float, float, float] = tuple(meta["time_grid"])
        self.rows: tuple[str, ...] = tuple(meta["rows"])
        self.pattern_rows = np.array(meta["pattern_rows"], dtype=np.intp)
        self.pattern_cols = np.array(meta["pattern_cols"], dtype=np.intp)
        self.points: tuple[tuple[str, str], ...] = tuple(tuple(p) for p in meta["points"])
        # The non-zeros of Phi_p (row, parameter); absent from kernels built before Phi_p.
        self.phi_p_rows = np.array(meta.get("phi_p_rows", ()), dtype=np.intp)
        self.phi_p_cols = np.array(meta.get("phi_p_cols", ()), dtype=np.intp)
        self.has_phi_p = "phi_p_rows" in meta
        self.ffi = ffi
        self.lib = lib
        self._functions = functions
        self._solvers: SolverPool | None = None  # GridSolvers reused from run to run
        # Looked up once: solve asks on every call.
        self._has_grid_solver = lib is not None and hasattr(lib, f"{self.name}_solve_grid")

    @property
    def has_grid_solver(self) -> bool:
        """True for a C kernel whose generated solver runs whole grids (``solve_grid``)."""
        return self._has_grid_solver

    def grid_solver(self, options: Options, q: Array, p: Array) -> GridSolver | None:
        """A fresh run of the generated C grid loop from q, or None without a C solver."""
        if self._solvers is None:
            if not self.has_grid_solver:
                return None
            self._solvers = SolverPool(self.ffi, self.lib, self.name, self.real)
        return self._solvers.take(options, q, p)

    @property
    def nq(self) -> int:
        return len(self.coordinates)

    @property
    def nnz(self) -> int:
        return len(self.pattern_rows)

    def __repr__(self) -> str:
        return f"<symkin Kernel {self.name!r} backend={self.backend} nq={self.nq}>"

    # -- evaluation ---------------------------------------------------------------------------
    def phi(self, q: ArrayLike, t: float, p: ArrayLike | None = None) -> Array:
        """Phi(q, t), shape (N,)."""
        return self._functions.phi(self._q(q), float(t), self._p(p))

    def phi_q_nz(self, q: ArrayLike, t: float, p: ArrayLike | None = None) -> Array:
        """The non-zeros of Phi_q in the order of ``pattern_rows``/``pattern_cols``."""
        return self._functions.phi_q_nz(self._q(q), float(t), self._p(p))

    def phi_q(self, q: ArrayLike, t: float, p: ArrayLike | None = None) -> Array:
        """Phi_q as a dense N x N array."""
        dense = np.zeros((self.nq, self.nq))
        dense[self.pattern_rows, self.pattern_cols] = self.phi_q_nz(q, t, p)
        return dense

    def phi_t(self, q: ArrayLike, t: float, p: ArrayLike | None = None) -> Array:
        """Phi_t(q, t), shape (N,)."""
        return self._functions.phi_t(self._q(q), float(t), self._p(p))

    def gamma(self, q: ArrayLike, dq: ArrayLike, t: float, p: ArrayLike | None = None) -> Array:
        """Gamma(q, dq, t), the right-hand side of Phi_q ddq = Gamma, shape (N,)."""
        return self._functions.gamma(self._q(q), self._q(dq, "dq"), float(t), self._p(p))

    def phi_p(self, q: ArrayLike, t: float, p: ArrayLike | None = None) -> Array:
        """Phi_p = d Phi / d p as a dense N x NP array (the design sensitivities' right side)."""
        if not self.has_phi_p:
            raise ValueError(f"the kernel of {self.name} was built without Phi_p; rebuild it "
                             "with symkin.compile")
        dense = np.zeros((self.nq, self.p_values.size))
        dense[self.phi_p_rows, self.phi_p_cols] = self._functions.phi_p_nz(
            self._q(q), float(t), self._p(p))
        return dense

    def point_vectors(self, p: ArrayLike | None = None) -> Array:
        """Local vectors of the named points, shape (NPOINTS, 2), in ``points`` order."""
        return self._functions.points(self._p(p)).reshape(len(self.points), 2)

    # -- argument checks ----------------------------------------------------------------------
    def _q(self, values: ArrayLike, what: str = "q") -> Array:
        array = np.ascontiguousarray(values, dtype=float)
        if array.shape != (self.nq,):
            raise ValueError(f"{what} must have shape ({self.nq},) for {self.name}, "
                             f"got {array.shape}")
        return array

    def _p(self, values: ArrayLike | None) -> Array:
        if values is None:
            return self.p_values
        array = np.ascontiguousarray(values, dtype=float)
        if array.shape != self.p_values.shape:
            raise ValueError(f"p must have shape {self.p_values.shape} (parameters "
                             f"{', '.join(self.parameter_names)}), got {array.shape}")
        return array


# ----- backends ------------------------------------------------------------------------------

class _ModuleFunctions:
    """Adapter over a generated NumPy module."""

    def __init__(self, module: ModuleType) -> None:
        self.phi = module.phi
        self.phi_q_nz = module.phi_q_nz
        self.phi_t = module.phi_t
        self.gamma = module.gamma
        self.points = module._points
        self.phi_p_nz: Callable[[Array, float, Array], Array] = getattr(
            module, "phi_p_nz", _no_phi_p)


def _no_phi_p(q: Array, t: float, p: Array) -> Array:
    raise ValueError("this kernel was generated without Phi_p; rebuild it with symkin.compile")


class _CFunctions:
    """Adapter over a cffi extension: converts arrays to the generated real type and back."""

    def __init__(self, ffi: Any, lib: Any, prefix: str, real: str, nq: int, nnz: int,
                 npoints: int, nnz_p: int = 0) -> None:
        self._ffi = ffi
        self._dtype = np.float32 if real == "float" else np.float64
        self._ctype = f"{real}[]"
        self._sizes = {"phi": nq, "phi_q": nnz, "phi_t": nq, "gamma": nq, "points": 2 * npoints,
                       "phi_p": nnz_p}
        # getattr with a default: a kernel folder built before phi_p existed has none.
        self._c: dict[str, Any] = {name: getattr(lib, f"{prefix}_{name}", None)
                                   for name in self._sizes}

    def _in(self, array: Array) -> Any:
        if array.size == 0:
            return self._ffi.NULL
        return self._ffi.from_buffer(self._ctype, np.ascontiguousarray(array, self._dtype))

    def _call(self, name: str, *arguments: Any) -> Array:
        out = np.zeros(self._sizes[name], dtype=self._dtype)
        target = self._ffi.from_buffer(self._ctype, out) if out.size else self._ffi.NULL
        self._c[name](*arguments, target)
        return out.astype(np.float64, copy=False)

    def phi(self, q: Array, t: float, p: Array) -> Array:
        return self._call("phi", self._in(q), t, self._in(p))

    def phi_q_nz(self, q: Array, t: float, p: Array) -> Array:
        return self._call("phi_q", self._in(q), t, self._in(p))

    def phi_t(self, q: Array, t: float, p: Array) -> Array:
        return self._call("phi_t", self._in(q), t, self._in(p))

    def gamma(self, q: Array, dq: Array, t: float, p: Array) -> Array:
        return self._call("gamma", self._in(q), self._in(dq), t, self._in(p))

    def points(self, p: Array) -> Array:
        return self._call("points", self._in(p))

    def phi_p_nz(self, q: Array, t: float, p: Array) -> Array:
        return self._call("phi_p", self._in(q), t, self._in(p))


def from_module(module: ModuleType, folder: Path | None = None) -> Kernel:
    """A Kernel over a generated NumPy module (its metadata comes from the module)."""
    meta = {
        "name": module.NAME, "coordinates": module.COORDINATES,
        "parameter_names": module.PARAMETER_NAMES, "p_values": module.P_VALUES,
        "q0": module.Q0, "time_grid": module.TIME_GRID, "rows": module.ROWS,
        "pattern_rows": module.PATTERN_ROWS, "pattern_cols": module.PATTERN_COLS,
        "points": module.POINTS,
        **({"phi_p_rows": module.PHI_P_ROWS, "phi_p_cols": module.PHI_P_COLS}
           if hasattr(module, "PHI_P_ROWS") else {}),
    }
    return Kernel("numpy", meta, _ModuleFunctions(module), folder=folder)


def from_cffi(ffi: Any, lib: Any, meta: Mapping[str, Any], folder: Path | None = None) -> Kernel:
    """A Kernel over a cffi extension built from the generated C; ``meta`` is the manifest."""
    functions = _CFunctions(ffi, lib, meta["name"], meta["real"], len(meta["coordinates"]),
                            len(meta["pattern_rows"]), len(meta["points"]),
                            len(meta.get("phi_p_rows", ())))
    return Kernel("c", meta, functions, ffi=ffi, lib=lib, folder=folder)


def load(folder: str | Path, name: str | None = None) -> Kernel:
    """Load a built kernel from its folder (a cache entry, or a generated NumPy folder).

    The folder's ``<name>_manifest.json`` says the backend and the mechanism (a folder holding
    several mechanisms needs ``name``); a C folder must also hold the compiled extension.
    Needs only NumPy (and cffi for C), never SymPy.
    """
    folder = Path(folder)
    meta = json.loads(_manifest(folder, name).read_text(encoding="utf-8"))
    if meta["backend"] == "numpy":
        source = folder / f"{meta['name']}.py"
        digest = hashlib.sha256(source.read_bytes()).hexdigest()
        module = import_file(f"_symkin_{meta['name']}_py_{digest[:20]}", source, None)
        return from_module(module, folder)
    library = extension_file(folder, meta["name"])
    name = library.name[: -len(resources.extension_suffix())]
    loader = importlib.machinery.ExtensionFileLoader(name, str(library))
    module = import_file(name, library, loader)
    return from_cffi(module.ffi, module.lib, meta, folder)


def _manifest(folder: Path, name: str | None) -> Path:
    if name is not None:
        return folder / manifest_name(name)
    found = sorted(folder.glob("*" + MANIFEST_SUFFIX))
    if len(found) != 1:
        raise FileNotFoundError(f"{folder} holds {len(found)} symkin manifests; name the "
                                "mechanism to load")
    return found[0]


def extension_file(folder: Path, name: str | None = None) -> Path:
    """The compiled extension in a C kernel folder.

    A build-cache folder is named after its module, so that file is the one; any other folder
    must hold exactly one ``_symkin_<name>_*`` extension.
    """
    own = folder / (folder.name + resources.extension_suffix())
    if own.is_file():
        return own
    pattern = f"_symkin_{name or ''}{'_' if name else ''}*{resources.extension_suffix()}"
    libraries = sorted(folder.glob(pattern))
    if len(libraries) != 1:
        found = "no" if not libraries else "more than one"
        raise FileNotFoundError(f"{folder} holds {found} compiled extension; build it with "
                                "symkin.compile")
    return libraries[0]


def import_file(name: str, path: Path, loader: Any) -> ModuleType:
    """Import a module from a file once per process (later calls reuse it)."""
    if name not in sys.modules:
        spec = importlib.util.spec_from_file_location(name, path, loader=loader)
        if spec is None or spec.loader is None:
            raise ImportError(f"cannot import {path}")
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        sys.modules[name] = module
    return sys.modules[name]

