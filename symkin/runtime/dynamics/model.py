"""What the integrator needs from a mechanism, and the kernel ``symkin.compile`` returns for
one that its forces move.

A :class:`Model` is plain data and functions of flat float64 arrays, in the generated
kernels' argument order (q, dq, t, p). A run's model is runtime.dynamics.compiled's, over
the generated kernel of the backend asked for (``PREFIX_mass``, ``PREFIX_applied``, Φ and
its derivatives); symbolic.motion_numeric.Functions, lambdified from the System, is the same
protocol, which the tests compare the kernels with.
"""

from __future__ import annotations

from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from symkin.errors import UsageError

Array = NDArray[np.float64]


class Model(Protocol):
    """The equations of motion of one mechanism (symbolic.motion_numeric.Functions)."""

    name: str
    space: str
    coordinates: tuple[str, ...]
    rows: tuple[str, ...]
    parameter_names: tuple[str, ...]
    p_values: Array
    q0: Array
    time_grid: tuple[float, float, float]
    def phi(self, *arguments: Any) -> Array: ...
    def phi_q(self, *arguments: Any) -> Array: ...
    def phi_t(self, *arguments: Any) -> Array: ...
    def gamma(self, *arguments: Any) -> Array: ...
    def mass(self, *arguments: Any) -> Array: ...
    def applied(self, *arguments: Any) -> Array: ...
    def potential(self, *arguments: Any) -> Array: ...
    def nonconservative(self, *arguments: Any) -> Array: ...
    def loads(self, *arguments: Any) -> Array: ...
    driver_names: tuple[str, ...]
    joint_names: tuple[str, ...]
    reaction_size: int
    points: tuple[tuple[str, str], ...]
    point_vectors: Array
    given: tuple[Any, ...]  # name, columns, axis of each; given_values(p): their values
    given_values: Any
    rtol: float
    atol: float
    senses: tuple[str, ...]  # with sense_values(q, t, p): runtime.solving.assembly.reversed_senses
    sense_values: Any


class MotionKernel:
    """A mechanism its forces move, ready to integrate (``symkin.solve`` runs it).

    Carries the kernel attributes the shared argument checks read (coordinates, parameters,
    q0, the file's grid) and the :class:`Model` itself.
    """

    # symkin.solve asks for this instead of comparing types
    moves_under_forces = True

    def __init__(self, model: Model, backend: str) -> None:
        self.model = model
        self.backend = backend
        self.name = model.name
        self.space = model.space
        self.coordinates = model.coordinates
        self.parameter_names = model.parameter_names
        self.p_values = model.p_values
        self.q0 = model.q0
        self.time_grid = model.time_grid
        self.rows = model.rows
        self.points = model.points
        self.has_dynamics = True

    @property
    def nq(self) -> int:
        return len(self.coordinates)

    def __repr__(self) -> str:
        return (f"<MotionKernel {self.name}: {self.nq} coordinates, {len(self.rows)} "
                f"constraints, {self.backend}>")


def refuse_motion(kernel: Any, command: str) -> None:
    """A UsageError when ``kernel`` is a mechanism its forces move and ``command`` (scan,
    sweep) works on driven kinematics only."""
    if getattr(kernel, "moves_under_forces", False):
        raise UsageError(f"{command} works on a mechanism whose drivers fix its motion; "
                         f"{kernel.name} has fewer drivers than freedoms and moves under its "
                         "forces: integrate it with symkin run or symkin.solve")
