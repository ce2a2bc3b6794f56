"""The equations of motion through a generated kernel: the :class:`~model.Model` the
integrator reads, with Φ, Φ_q, Φ_t, Γ, M, Q - h, the loads and the senses evaluated by the
compiled code of the backend asked for (the cffi C extension or the generated NumPy module).

What the generated code does not compute (the potential V and the non-conservative forces
Q_nc behind the energy outputs, the initial velocities a file gives and the integrator's
tolerances) comes beside it as :class:`Remainder`, plain functions of flat arrays that the
build stage makes from the System.

A mechanism its forces move has fewer rows of Φ than coordinates: the kernel's functions
carry NQ-long buffers (kinematics' square shape), of which the first ``len(rows)`` are Φ's.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from symkin.runtime.kernel import Kernel

Array = NDArray[np.float64]


class Remainder(Protocol):
    """The part of the equations of motion the generated kernels leave out
    (symbolic.motion_numeric.Remainder): V(q, t, p), Q_nc(q, dq, t, p), the given
    velocities with given_values(p) (None without any), the tolerances."""

    @property
    def given(self) -> tuple[Any, ...]: ...
    @property
    def rtol(self) -> float: ...
    @property
    def atol(self) -> float: ...
    @property
    def potential(self) -> Callable[..., Any]: ...
    @property
    def nonconservative(self) -> Callable[..., Any]: ...
    @property
    def given_values(self) -> Callable[..., Any] | None: ...


class CompiledModel:
    """A :class:`~model.Model` over a generated kernel (module docstring).

    Args:
        kernel: a kernel whose backend generates the mass matrix and applied forces
            (``kernel.has_mass``).
        rest: the energy terms, given velocities and tolerances of the same mechanism.
    """

    def __init__(self, kernel: Kernel, rest: Remainder) -> None:
        self.kernel = kernel
        self.name, self.space = kernel.name, kernel.space
        self.coordinates, self.rows = kernel.coordinates, kernel.rows
        self.parameter_names, self.p_values = kernel.parameter_names, kernel.p_values
        self.q0, self.time_grid = kernel.q0, kernel.time_grid
        self.driver_names, self.joint_names = kernel.driver_names, kernel.joint_names
        self.reaction_size = 6 if kernel.space == "3d" else 3
        self.points, self.point_vectors = kernel.points, kernel.point_vectors()
        self.removed, self.senses = kernel.removed, kernel.senses
        self.sense_values = kernel.sense_values if kernel.senses else None
        # a run's rows in one call (the C kernel's senses_rows): the check along the motion
        self.sense_rows = kernel.sense_rows if kernel.senses else None
        self.given, self.rtol, self.atol = rest.given, rest.rtol, rest.atol
        self.given_values = rest.given_values
        self.potential, self.nonconservative = rest.potential, rest.nonconservative
        self._m = len(kernel.rows)
        # Φ_q is (rows, NQ) here: the pattern's entries all lie in Φ's rows
        self._at = (kernel.pattern_rows, kernel.pattern_cols)
        # called at every Runge-Kutta stage: the kernel's argument checks are skipped, the
        # integrator's arrays being flat float64 of the kernel's sizes (symkin.solve's
        # arguments are checked once: runtime.arguments)
        self._f = kernel.unchecked
        if self._f.mass is None or self._f.applied is None:
            raise ValueError(f"the kernel of {kernel.name} has no mass matrix or applied "
                             "forces: its backend generates none")
        self._mass, self._applied = self._f.mass, self._f.applied

    def phi(self, q: Array, t: float, p: Array) -> Array:
        return self._f.phi(q, t, p)[:self._m]

    def phi_q(self, q: Array, t: float, p: Array) -> Array:
        dense = np.zeros((self._m, q.size))
        dense[self._at] = self._f.phi_q_nz(q, t, p)
        return dense

    def phi_t(self, q: Array, t: float, p: Array) -> Array:
        return self._f.phi_t(q, t, p)[:self._m]

    def gamma(self, q: Array, dq: Array, t: float, p: Array) -> Array:
        return self._f.gamma(q, dq, t, p)[:self._m]

    def mass(self, q: Array, p: Array) -> Array:
        return self._mass(q, p)

    def applied(self, q: Array, dq: Array, t: float, p: Array) -> Array:
        return self._applied(q, dq, t, p)

    def loads(self, q: Array, lam: Array, t: float, p: Array) -> Array:
        return self.kernel.loads(q, lam, t, p)
