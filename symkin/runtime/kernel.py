"""The runtime kernel: one mechanism's compiled Phi, Phi_q, Phi_t and Gamma behind one API.

A Kernel wraps a backend's compiled functions (``_Functions``: a generated NumPy module, a cffi
extension built from the generated C, ...) plus the metadata of the mechanism (coordinates,
parameters, pattern, grid). A backend whose generated code also runs whole grids or batches
subclasses it (``grid_solver``, ``batch_solver``); the backends load kernels
(``symkin.backends.load``). It imports only NumPy, so running a compiled kernel never loads
SymPy or jinja2.
"""

from __future__ import annotations

import contextlib
import importlib.util
import json
import sys
from collections.abc import Callable, Mapping
from pathlib import Path
from types import ModuleType
from typing import Any, Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from symkin.contract.loads import load_count
from symkin.contract.manifest import MANIFEST_SUFFIX, manifest_name
from symkin.contract.options import Options
from symkin.limits import listed
from symkin.runtime.protocol import BatchSolver, EdgeSolver, GridSolver

Array = NDArray[np.float64]


class _Functions(Protocol):
    """What a backend evaluates: flat output arrays in the generated order."""

    def phi(self, q: Array, t: float, p: Array) -> Array: ...
    def phi_q_nz(self, q: Array, t: float, p: Array) -> Array: ...
    def phi_t(self, q: Array, t: float, p: Array) -> Array: ...
    def gamma(self, q: Array, dq: Array, t: float, p: Array) -> Array: ...
    def points(self, p: Array) -> Array: ...
    def phi_p_nz(self, q: Array, t: float, p: Array) -> Array: ...
    # The removed rows' Phi (over-constrained files only; None where there is none).
    removed: Callable[[Array, float, Array], Array] | None
    # What the rows leave ambiguous (files with spatial revolutes or angles only; else None).
    senses: Callable[[Array, float, Array], Array] | None
    # inverse dynamics (kernels of mechanisms with masses or forces only)
    def dynamics_rhs(self, q: Array, dq: Array, ddq: Array, t: float, p: Array) -> Array: ...
    def loads(self, q: Array, lam: Array, t: float, p: Array) -> Array: ...
    # Forward dynamics: M(q, p) dense and Q - h(q, dq, t, p) (kernels of files with masses
    # whose backend generates them; else None).
    mass: Callable[[Array, Array], Array] | None
    applied: Callable[[Array, Array, float, Array], Array] | None
    # ... with rows removed as redundant too (runtime.loads.indeterminate)
    def removed_q(self, q: Array, t: float, p: Array) -> Array: ...
    def loads_full(self, q: Array, lam: Array, t: float, p: Array) -> Array: ...


class Kernel:
    """The compiled kinematics of one mechanism (what symkin.compile returns).

    Every function takes ``p=None`` to mean the nominal parameter values.
    """

    # A backend's solve of many parameter sets in one call (None: a sweep solves set by set).
    batch_solver: BatchSolver | None = None

    def edge_solver(self) -> EdgeSolver | None:
        """A backend's substeps towards a point its batch stopped at (None: none)."""
        return None

    def __init__(self, backend: str, meta: Mapping[str, Any], functions: _Functions,
                 folder: Path | None = None) -> None:
        # The backend's name (for messages and the warm-run index; decisions ask the backend).
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
        # The coordinates that enter Phi_q or Phi_t (runtime.solving.accuracy's refined model);
        # every coordinate for a kernel generated before it.
        self.nonlinear = np.zeros(len(self.coordinates), dtype=bool)
        self.nonlinear[list(meta.get("nonlinear", range(len(self.coordinates))))] = True
        self.points: tuple[tuple[str, str], ...] = tuple(tuple(p) for p in meta["points"])
        # "3d" for a spatial mechanism: 7 coordinates per body, points of 3 components.
        self.space: str = meta.get("space", "2d")
        # The non-zeros of Phi_p (row, parameter); absent from kernels built before Phi_p.
        self.phi_p_rows = np.array(meta.get("phi_p_rows", ()), dtype=np.intp)
        self.phi_p_cols = np.array(meta.get("phi_p_cols", ()), dtype=np.intp)
        self.has_phi_p = "phi_p_rows" in meta
        # The rows of an over-constrained file removed as dependent at t0 (not in Phi); the
        # driver checks them along the motion with removed_phi.
        self.removed: tuple[str, ...] = tuple(meta.get("removed", ()))
        # What the rows leave ambiguous, positive at a genuine assembly (sense_values): the
        # assembly search counts no solution of Phi = 0 where one is not.
        self.senses: tuple[str, ...] = tuple(meta.get("senses", ()))
        # A pair's coordinate and the range its file gives it, (name, a, b, owner): the
        # driver stops the motion where it is left (runtime.outputs.ranges).
        self.ranges = tuple(tuple(entry) for entry in meta.get("ranges", ()))
        # Inverse dynamics: present when the file has masses or forces.
        self.has_dynamics = "joint_names" in meta
        self.driver_names: tuple[str, ...] = tuple(meta.get("driver_names", ()))
        self.joint_names: tuple[str, ...] = tuple(meta.get("joint_names", ()))
        # The input drivers (u[] order); their u, du, ddu follow the parameters in p[].
        self.input_names: tuple[str, ...] = tuple(meta.get("input_names", ()))
        # Forward dynamics: the generated M and Q - h are there (runtime.dynamics.compiled).
        self.has_mass = getattr(functions, "mass", None) is not None
        # Those that are a length (a distance driver's f): runtime.input_driven.inputs refuses
        # them below zero.
        self.input_lengths: tuple[str, ...] = tuple(meta.get("input_lengths", ()))
        self._functions = functions
        # What symkin.solve works out once per kernel (runtime.solving.call_plan), made on
        # its first call.
        self.call_plan: Any = None

    @property
    def unchecked(self) -> _Functions:
        """The backend's functions without the argument checks: flat float64 arrays of the
        right sizes, p with the inputs, in and out (runtime.dynamics.compiled checks once
        and calls them at every stage of the integrator)."""
        return self._functions

    @property
    def has_grid_solver(self) -> bool:
        """True for a kernel whose generated code runs whole grids (the C solver)."""
        return False

    def grid_solver(self, options: Options, q: Array, p: Array, unit: float = 1.0
                    ) -> GridSolver | None:
        """A fresh run of the generated grid loop from q (its decisions made in the length
        unit ``unit``, runtime.solving.units), or None without one."""
        del options, q, p, unit
        return None

    def input_stepper(self) -> Any:
        """A backend's generated one-point solve at given inputs (runtime.input_driven.inputs), or
        None: then the runtime's Newton solves each point."""
        return None

    @property
    def point_size(self) -> int:
        """The components of a point vector: 2, or 3 in a spatial mechanism."""
        return 3 if self.space == "3d" else 2

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

    def removed_phi(self, q: ArrayLike, t: float, p: ArrayLike | None = None) -> Array:
        """Phi of the removed rows (``removed``) at (q, t), shape (NREMOVED,)."""
        if not self.removed:
            return np.zeros(0)
        evaluate = self._functions.removed
        if evaluate is None:
            raise ValueError(f"the kernel of {self.name} names removed rows but has no "
                             "routine for them; rebuild it with symkin.compile")
        return np.asarray(evaluate(self._q(q), float(t), self._p(p)), dtype=float)
    def sense_values(self, q: ArrayLike, t: float, p: ArrayLike | None = None) -> Array:
        """The senses (``senses``) at (q, t), shape (NSENSES,): each positive at a genuine
        assembly (a spatial revolute's axes' cosine, an angle driver's cos(theta - psi))."""
        if not self.senses:
            return np.zeros(0)
        evaluate = self._functions.senses
        if evaluate is None:
            raise ValueError(f"the kernel of {self.name} names senses but has no routine "
                             "for them; rebuild it with symkin.compile")
        return np.asarray(evaluate(self._q(q), float(t), self._p(p)), dtype=float)

    def sense_rows(self, q: ArrayLike, t: ArrayLike, p: ArrayLike | None = None) -> Array:
        """The senses at every row of a run, (T, NSENSES): q (T, NQ) at t (T,), p the
        kernel's p[] or one per row (T, NP + 3 NU, an input run's). The C extension loops
        over the rows without a Python call each; other functions are called per row."""
        rows_q, times = np.asarray(q, dtype=float), np.asarray(t, dtype=float)
        if not self.senses or not times.size:
            return np.zeros((times.size, len(self.senses)))
        given = np.asarray(self.p_values if p is None else p, dtype=float)
        params = given if given.ndim == 2 else self._p(given)
        batched = getattr(self._functions, "sense_rows", None)
        if batched is not None:
            return np.asarray(batched(rows_q, times, params), dtype=float)
        return np.array([self.sense_values(rows_q[k], float(times[k]),
                                           params[k] if params.ndim == 2 else params)
                         for k in range(times.size)], dtype=float)

    # -- inverse dynamics ---------------------------------------------------------------------
    def multipliers(self, q: ArrayLike, dq: ArrayLike, ddq: ArrayLike, t: float,
                    p: ArrayLike | None = None) -> Array:
        """lam of Phi_q^T lam = Q - M ddq - h(q, dq) at one state, shape (N,)."""
        self._require_dynamics()
        q, p = self._q(q), self._p(p)
        rhs = self._functions.dynamics_rhs(q, self._q(dq, "dq"), self._q(ddq, "ddq"),
                                           float(t), p)
        return np.asarray(np.linalg.solve(self.phi_q(q, t, p).T, rhs), dtype=float)

    def loads(self, q: ArrayLike, lam: ArrayLike, t: float,
              p: ArrayLike | None = None) -> Array:
        """The efforts (one per driver row) then Fx, Fy, M of each joint (spatial: Fx, Fy, Fz,
        Mx, My, Mz), from lam."""
        self._require_dynamics()
        # one multiplier a row of Phi: as many as coordinates, fewer where forces move it
        return self._functions.loads(self._q(q), self._vector(lam, len(self.rows), "lam"),
                                     float(t), self._p(p))

    def mass(self, q: ArrayLike, p: ArrayLike | None = None) -> Array:
        """The mass matrix M(q) as a dense N x N array (files with masses only)."""
        evaluate = self._functions.mass
        if evaluate is None:
            raise ValueError(f"the kernel of {self.name} has no mass matrix (no masses, or "
                             f"its backend generates none)")
        return np.asarray(evaluate(self._q(q), self._p(p)), dtype=float)

    def applied(self, q: ArrayLike, dq: ArrayLike, t: float,
                p: ArrayLike | None = None) -> Array:
        """The applied forces less the velocity terms, Q - h at (q, dq, t), shape (N,)
        (files with masses only)."""
        evaluate = self._functions.applied
        if evaluate is None:
            raise ValueError(f"the kernel of {self.name} has no applied forces (no masses, "
                             f"or its backend generates none)")
        return np.asarray(evaluate(self._q(q), self._q(dq, "dq"), float(t), self._p(p)),
                          dtype=float)

    def removed_q(self, q: ArrayLike, t: float, p: ArrayLike | None = None) -> Array:
        """The removed rows' Jacobian, (NREMOVED, N) (dynamics and removed rows only)."""
        self._require_dynamics()
        flat = self._functions.removed_q(self._q(q), float(t), self._p(p))
        return np.asarray(flat, dtype=float).reshape(len(self.removed), self.nq)

    def loads_full(self, q: ArrayLike, lam: ArrayLike, t: float,
                   p: ArrayLike | None = None) -> Array:
        """The loads of the multipliers of every row: lam (N + NREMOVED,), the kept rows'
        then the removed rows' (dynamics and removed rows only)."""
        self._require_dynamics()
        whole = np.ascontiguousarray(lam, dtype=float)
        if whole.shape != (self.nq + len(self.removed),):
            raise ValueError(f"lam must have shape ({self.nq + len(self.removed)},) for "
                             f"{self.name}, got {whole.shape}")
        return self._functions.loads_full(self._q(q), whole, float(t), self._p(p))

    def multipliers_grid(self, t: Array, q: Array, dq: Array, d2q: Array,
                         p: Array) -> tuple[Array, Array]:
        """lam (T, N) and the loads (T, NLOADS) of solved rows; NaN where Phi_q is singular.
        A backend whose generated code does it in one call overrides this loop."""
        n_loads = load_count(len(self.driver_names), len(self.joint_names), self.space)
        lam = np.full(q.shape, np.nan)
        loads = np.full((t.size, n_loads), np.nan)
        for k in range(t.size):
            # singular Phi_q: no unique multipliers, the row stays NaN and says so
            with contextlib.suppress(np.linalg.LinAlgError):
                lam[k] = self.multipliers(q[k], dq[k], d2q[k], t[k], p)
            loads[k] = self.loads(q[k], lam[k], t[k], p)
        return lam, loads

    def _require_dynamics(self) -> None:
        if not self.has_dynamics:
            raise ValueError(f"{self.name} has no masses or forces: give bodies a mass or "
                             "add a forces section to compute efforts and reactions")

    def point_vectors(self, p: ArrayLike | None = None) -> Array:
        """Local vectors of the named points, shape (NPOINTS, 2) (spatial: 3), in ``points``
        order."""
        return self._functions.points(self._p(p)).reshape(len(self.points), self.point_size)

    # -- argument checks ----------------------------------------------------------------------
    def _q(self, values: ArrayLike, what: str = "q") -> Array:
        return self._vector(values, self.nq, what)

    def _vector(self, values: ArrayLike, size: int, what: str) -> Array:
        array = np.ascontiguousarray(values, dtype=float)
        if array.shape != (size,):
            raise ValueError(f"{what} must have shape ({size},) for {self.name}, "
                             f"got {array.shape}")
        return array

    @property
    def nu(self) -> int:
        """The number of input drivers."""
        return len(self.input_names)

    def with_inputs(self, p: ArrayLike | None, u: ArrayLike, du: ArrayLike | None = None,
                    ddu: ArrayLike | None = None) -> Array:
        """The generated functions' p[] of a mechanism with inputs: the parameters (None:
        nominal), then u, du, ddu (zero when None), each (NU,)."""
        base = self.p_values if p is None else np.asarray(p, dtype=float)
        zero = np.zeros(self.nu)
        parts = [np.asarray(v, dtype=float).reshape(self.nu) if v is not None else zero
                 for v in (u, du, ddu)]
        return np.ascontiguousarray(np.concatenate([base, *parts]))

    def _p(self, values: ArrayLike | None) -> Array:
        if values is None:
            values = self.p_values
        array = np.ascontiguousarray(values, dtype=float)
        if self.nu and array.shape == self.p_values.shape:
            # The generated functions read p[NP + 3 NU]: without inputs they are taken as zero
            # (symkin.solve refuses a run of such a mechanism without them).
            return self.with_inputs(array, np.zeros(self.nu))
        if self.nu and array.shape == (self.p_values.size + 3 * self.nu,):
            return array
        if array.shape != self.p_values.shape:
            raise ValueError(f"p must have shape {self.p_values.shape} (parameters "
                             f"{listed(self.parameter_names)}), got {array.shape}")
        return array


# ----- loading -------------------------------------------------------------------------------

def read_manifest(folder: Path, name: str | None = None) -> dict[str, Any]:
    """The manifest of a generated or built folder: ``<name>_manifest.json`` (a folder
    holding several mechanisms needs ``name``). It says the backend and the mechanism."""
    data: dict[str, Any] = json.loads(_manifest(folder, name).read_text(encoding="utf-8"))
    return data


def _manifest(folder: Path, name: str | None) -> Path:
    if name is not None:
        return folder / manifest_name(name)
    found = sorted(folder.glob("*" + MANIFEST_SUFFIX))
    if len(found) != 1:
        raise FileNotFoundError(f"{folder} holds {len(found)} symkin manifests; name the "
                                "mechanism to load")
    return found[0]


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

