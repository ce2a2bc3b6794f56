"""A C kernel loaded through cffi: the generated functions, the grid solver and the batch
solver of one compiled extension, behind the runtime's Kernel.

Needs only NumPy and cffi: loading a built C kernel never imports SymPy or jinja2.
"""

from __future__ import annotations

import importlib.machinery
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from symkin import resources
from symkin.backends.c import batch, multipliers
from symkin.backends.c.cinputs import InputStepper
from symkin.backends.c.csolver import GridSolver, SolverPool
from symkin.contract.loads import load_count
from symkin.contract.options import Options
from symkin.runtime.kernel import Array, Kernel, import_file
from symkin.runtime.protocol import EdgeSolver


class CKernel(Kernel):
    """A Kernel over a cffi extension built from the generated C.

    Attributes:
        ffi, lib: the extension's cffi handles, for callers of the generated C functions.
    """

    def __init__(self, ffi: Any, lib: Any, meta: Mapping[str, Any],
                 folder: Path | None = None) -> None:
        n_loads = load_count(len(meta.get("driver_names", ())), len(meta.get("joint_names", ())),
                             meta.get("space", "2d"))
        functions = _CFunctions(ffi, lib, meta["name"], meta["real"], len(meta["coordinates"]),
                                len(meta["pattern_rows"]),
                                len(meta["points"]) * (3 if meta.get("space") == "3d" else 2),
                                len(meta.get("phi_p_rows", ())), len(meta.get("removed", ())),
                                n_loads, len(meta.get("senses", ())))
        super().__init__("c", meta, functions, folder=folder)
        self.ffi = ffi
        self.lib = lib
        self._solvers: SolverPool | None = None  # GridSolvers reused from run to run
        # Looked up once: solve asks on every call.
        self._has_grid_solver = hasattr(lib, f"{self.name}_solve_grid")
        # options.unit honoured (a kernel built before it, or with a literal lever arm: not)
        self.scale_free = bool(getattr(lib, f"{self.name.upper()}_SCALE_FREE", 0))
        # the batch that takes a unit per set (a kernel built before it: sets run one by one)
        if hasattr(lib, f"{self.name}_length_scales"):
            self.batch_solver = batch.Batch(ffi, lib, self.name, self.real, self.scale_free)

    @property
    def has_grid_solver(self) -> bool:
        """True when the generated solver runs whole grids (``solve_grid``)."""
        return self._has_grid_solver

    def grid_solver(self, options: Options, q: Array, p: Array, unit: float = 1.0
                    ) -> GridSolver | None:
        """A fresh run of the generated C grid loop from q, its decisions made in the length
        unit ``unit`` (runtime.solving.units), or None without a C solver (or, for a unit other than
        1, one that cannot honour it)."""
        if unit != 1.0 and not self.scale_free:
            return None
        solvers = self._solvers
        if solvers is None:
            if not self.has_grid_solver:
                return None
            solvers = self._solvers = SolverPool(self.ffi, self.lib, self.name, self.real)
        return solvers.take(options, q, p, unit)

    def multipliers_grid(self, t: Array, q: Array, dq: Array, d2q: Array,
                         p: Array) -> tuple[Array, Array]:
        """lam and the loads of solved rows in one call of the generated C."""
        return multipliers.grid(self.ffi, self.lib, self.name, self.real, t, q, dq, d2q, p,
                                load_count(len(self.driver_names), len(self.joint_names),
                                           self.space))

    def edge_solver(self) -> EdgeSolver | None:
        """The generated solve_edge (None in a kernel built before it, and in float: its
        substeps, down to 1e-9 of the grid step, fall below the resolution of a float t, so
        symkin.solve's own edge treatment, in double, decides such a set)."""
        if self.real == "float" or not hasattr(self.lib, f"{self.name}_solve_edge"):
            return None
        from symkin.backends.c.edge import EdgeSolver as CEdgeSolver

        return CEdgeSolver(self.ffi, self.lib, self.name, self.nq)

    def input_stepper(self) -> InputStepper | None:
        """The generated solve_inputs, for a mechanism with input drivers (else None)."""
        if not self.nu or not hasattr(self.lib, f"{self.name}_solve_inputs"):
            return None
        return InputStepper(self.ffi, self.lib, self.name, self.real, self.nq)


class _CFunctions:
    """Adapter over a cffi extension: converts arrays to the generated real type and back."""

    def __init__(self, ffi: Any, lib: Any, prefix: str, real: str, nq: int, nnz: int,
                 point_components: int, nnz_p: int = 0, nremoved: int = 0,
                 n_loads: int = 0, nsenses: int = 0) -> None:
        self._ffi = ffi
        self._dtype = np.float32 if real == "float" else np.float64
        self._ctype = f"{real}[]"
        self._sizes = {"phi": nq, "phi_q": nnz, "phi_t": nq, "gamma": nq,
                       "points": point_components, "phi_p": nnz_p, "removed": nremoved,
                       "dynamics_rhs": nq, "loads": n_loads, "removed_q": nremoved * nq,
                       "loads_full": n_loads, "senses": nsenses}
        # getattr with a default: a kernel folder built before phi_p existed has none.
        self._c: dict[str, Any] = {name: getattr(lib, f"{prefix}_{name}", None)
                                   for name in self._sizes}
        self._c["senses_rows"] = getattr(lib, f"{prefix}_senses_rows", None)
        # Only an over-constrained file's kernel has it (Kernel.removed_phi).
        self.removed: Callable[[Array, float, Array], Array] | None = (
            self._removed if nremoved else None)
        # Only the kernel of a file with spatial revolutes or angles has it.
        self.senses: Callable[[Array, float, Array], Array] | None = (
            self._senses if nsenses else None)
        # Only the kernel of a file with masses has them (forward dynamics).
        self.mass: Callable[[Array, Array], Array] | None = None
        self.applied: Callable[[Array, Array, float, Array], Array] | None = None
        if hasattr(lib, f"{prefix}_mass"):
            self._mass_c, self._applied_c = (getattr(lib, f"{prefix}_{what}")
                                             for what in ("mass", "applied"))
            count = int(getattr(lib, f"{prefix.upper()}_NNZ_M"))
            # the mass matrix's sparsity pattern, the static arrays of the generated header
            self._mass_at = tuple(np.array(ffi.unpack(getattr(lib, f"{prefix}_mass_{side}"),
                                                      count), dtype=np.intp)
                                  for side in ("row", "col"))
            self._nq = nq
            self.mass, self.applied = self._mass, self._applied

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

    def _removed(self, q: Array, t: float, p: Array) -> Array:
        return self._call("removed", self._in(q), t, self._in(p))

    def _senses(self, q: Array, t: float, p: Array) -> Array:
        return self._call("senses", self._in(q), t, self._in(p))

    def sense_rows(self, q: Array, t: Array, p: Array) -> Array:
        """The senses at every row (T, NSENSES) of q (T, NQ) at t (T,), p[] (NP,) or one
        per row (T, NP): one call of the generated senses_rows for the whole run (a call
        per row through _senses costs several times the row's own solve)."""
        count, size = self._sizes["senses"], t.size
        out = np.zeros((size, count), dtype=self._dtype)
        rows = np.ascontiguousarray(q, self._dtype)
        params = np.ascontiguousarray(p, self._dtype)
        times = np.ascontiguousarray(t, self._dtype)
        stride = params.shape[-1] if params.ndim == 2 else 0
        self._c["senses_rows"](size, self._ffi.from_buffer(self._ctype, rows),
                               self._ffi.from_buffer(self._ctype, times),
                               self._ffi.from_buffer(self._ctype, params) if params.size
                               else self._ffi.NULL, stride,
                               self._ffi.from_buffer(self._ctype, out))
        return out.astype(np.float64, copy=False)

    def dynamics_rhs(self, q: Array, dq: Array, ddq: Array, t: float, p: Array) -> Array:
        return self._call("dynamics_rhs", self._in(q), self._in(dq), self._in(ddq), t,
                          self._in(p))

    def loads(self, q: Array, lam: Array, t: float, p: Array) -> Array:
        return self._call("loads", self._in(q), self._in(lam), t, self._in(p))

    def removed_q(self, q: Array, t: float, p: Array) -> Array:
        return self._call("removed_q", self._in(q), t, self._in(p))

    def loads_full(self, q: Array, lam: Array, t: float, p: Array) -> Array:
        return self._call("loads_full", self._in(q), self._in(lam), t, self._in(p))

    def _mass(self, q: Array, p: Array) -> Array:
        rows, cols = self._mass_at
        nz = np.zeros(rows.size, dtype=self._dtype)
        self._mass_c(self._in(q), self._in(p), self._ffi.from_buffer(self._ctype, nz))
        dense = np.zeros((self._nq, self._nq))
        dense[rows, cols] = nz
        return dense

    def _applied(self, q: Array, dq: Array, t: float, p: Array) -> Array:
        out = np.zeros(self._nq, dtype=self._dtype)
        self._applied_c(self._in(q), self._in(dq), t, self._in(p),
                        self._ffi.from_buffer(self._ctype, out))
        return out.astype(np.float64, copy=False)


def load(folder: Path, meta: Mapping[str, Any]) -> CKernel:
    """Load the compiled extension of a built C folder; ``meta`` is its manifest."""
    library = extension_file(folder, meta["name"])
    return import_extension(library.name[: -len(resources.extension_suffix())], library,
                            meta, folder)


def import_extension(module_name: str, library: Path, meta: Mapping[str, Any],
                     folder: Path) -> CKernel:
    """The kernel of the extension ``library`` (imported once per process)."""
    loader = importlib.machinery.ExtensionFileLoader(module_name, str(library))
    module = import_file(module_name, library, loader)
    return CKernel(module.ffi, module.lib, meta, folder)


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
