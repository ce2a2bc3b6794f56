"""The equations of motion as NumPy callables (SymPy's lambdify), for runtime.dynamics.

The runtime imports no SymPy: it receives :class:`Functions`, plain data plus functions
whose code uses NumPy only. Their signatures are the generated kernels' (q, dq, t, p flat
arrays), so the kernels' own ``mass`` and ``applied`` can take their place without the
runtime noticing.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
import sympy as sp

from symkin.spec import constants
from symkin.symbolic.motion import EquationsOfMotion, Given, derive

Array = np.ndarray


@dataclass  # not frozen: runtime.dynamics.model.Model's members are plain attributes
class Functions:
    """One mechanism's motion, evaluated numerically (every array flat, float64).

    Attributes:
        name, space, coordinates, rows, parameter_names, p_values, q0, time_grid: as the
            kernel's (rows: each row's label).
        phi(q, t, p) (m,), phi_q(q, t, p) (m, N), phi_t(q, t, p) (m,), gamma(q, dq, t, p)
            (m,): the constraints as derived.
        mass(q, p) (N, N): M. applied(q, dq, t, p) (N,): Q - h.
        potential(q, t, p) (): V. nonconservative(q, dq, t, p) (N,): Q_nc.
        loads(q, lam, t, p) (NLOADS,): efforts then reactions, as the forces section's;
            driver_names, joint_names label them; reaction_size: 3 (planar) or 6 (spatial).
        points: (body, name) of every named point; point_vectors (P, 2|3) at p_values.
        given, rtol, atol: the file's initial velocities and tolerances; given_values(p)
            (G,): the given velocities at the parameters p (a run's own, not only nominal).
        removed: the rows removed as redundant (their loads are then not unique).
        senses, sense_values(q, t, p) (S,): what the rows leave ambiguous, positive at a
            genuine assembly (the kernels' ``senses``; runtime.solving.assembly checks the start).
    """

    name: str
    space: str
    coordinates: tuple[str, ...]
    rows: tuple[str, ...]
    parameter_names: tuple[str, ...]
    p_values: Array
    q0: Array
    time_grid: tuple[float, float, float]
    phi: Callable[..., Array]
    phi_q: Callable[..., Array]
    phi_t: Callable[..., Array]
    gamma: Callable[..., Array]
    mass: Callable[..., Array]
    applied: Callable[..., Array]
    potential: Callable[..., Array]
    nonconservative: Callable[..., Array]
    loads: Callable[..., Array]
    driver_names: tuple[str, ...]
    joint_names: tuple[str, ...]
    reaction_size: int
    points: tuple[tuple[str, str], ...]
    point_vectors: Array
    given: tuple[Given, ...]
    rtol: float
    atol: float
    removed: tuple[str, ...] = ()
    given_values: Callable[..., Array] | None = None
    senses: tuple[str, ...] = ()
    sense_values: Callable[..., Array] | None = None


def _compiled(arguments: list[Any], expr: Any, shape: tuple[int, ...]) -> Callable[..., Array]:
    """``expr`` of the argument groups (each a tuple of symbols, given as one flat array)."""
    # dummify: coordinate names hold dots, which are no Python identifiers
    # constants folded to doubles first (constants.lambdify_floats: exact numbers would reach
    # NumPy as Python ints its ufuncs refuse)
    raw = constants.lambdify_floats(arguments, expr, dummify=True, cse=True)

    def evaluate(*values: Any) -> Array:
        # NumPy numbers, also for t: a load 1/(t - 0.5) at t = 0.5 is inf (then flagged),
        # where Python's float division raises ZeroDivisionError
        numbers = [np.asarray(value, dtype=float) for value in values]
        with np.errstate(all="ignore"):
            return np.asarray(raw(*numbers), dtype=float).reshape(shape)

    return evaluate


def functions(system: Any, equations: EquationsOfMotion) -> Functions:
    """The :class:`Functions` of ``system`` whose equations of motion are ``equations``."""
    q, dq, t, p = list(system.q), list(system.dq), system.t, list(system.p)
    n, m = len(q), system.phi_q.shape[0]
    found = system.dynamics
    lam = list(found.lam[:m])
    loads = found.loads.xreplace({symbol: 0 for symbol in found.lam[m:]})
    point_size = 3 if system.mechanism.is_spatial else 2
    vectors = [[float(sp.sympify(v).subs(dict(zip(system.p, system.p_values)))) for v in vec]
               for _, _, vec in system.points]
    return Functions(
        name=system.name, space="3d" if system.mechanism.is_spatial else "2d",
        coordinates=tuple(system.coordinates), rows=tuple(str(row) for row in system.rows),
        parameter_names=tuple(system.parameter_names),
        p_values=np.array(system.p_values, dtype=float), q0=np.array(system.q0, dtype=float),
        time_grid=system.time_grid,
        phi=_compiled([q, t, p], system.phi, (m,)),
        phi_q=_compiled([q, t, p], sp.Matrix(system.phi_q), (m, n)),
        phi_t=_compiled([q, t, p], system.phi_t, (m,)),
        gamma=_compiled([q, dq, t, p], system.gamma, (m,)),
        mass=_compiled([q, p], equations.mass_matrix, (n, n)),
        applied=_compiled([q, dq, t, p], equations.applied, (n,)),
        potential=_compiled([q, t, p], equations.potential, ()),
        nonconservative=_compiled([q, dq, t, p], equations.nonconservative, (n,)),
        loads=_compiled([q, lam, t, p], loads, (loads.shape[0],)),
        driver_names=found.driver_names, joint_names=found.joint_names,
        reaction_size=6 if point_size == 3 else 3,
        points=tuple((body, name) for body, name, _ in system.points),
        point_vectors=np.array(vectors, dtype=float).reshape(len(vectors), point_size),
        given=equations.given, rtol=equations.rtol, atol=equations.atol,
        removed=tuple(str(item) for item in system.removed),
        given_values=_given_values(p, equations),
        senses=tuple(label for label, _ in system.senses),
        sense_values=_compiled([q, t, p], sp.Matrix([expr for _, expr in system.senses]),
                               (len(system.senses),)) if system.senses else None)


@dataclass(frozen=True)
class Remainder:
    """What a generated kernel leaves out of the equations of motion (runtime.dynamics.
    compiled): V (q, t, p) (), Q_nc (q, dq, t, p) (N,), the given initial velocities with
    their values at p, and the integrator's tolerances."""

    potential: Callable[..., Array]
    nonconservative: Callable[..., Array]
    given: tuple[Given, ...]
    given_values: Callable[..., Array] | None
    rtol: float
    atol: float


def remainder(system: Any) -> Remainder:
    """The :class:`Remainder` of ``system``, a mechanism its forces move."""
    equations = _equations(system)
    q, dq, t, p = list(system.q), list(system.dq), system.t, list(system.p)
    n = len(q)
    return Remainder(
        potential=_compiled([q, t, p], equations.potential, ()),
        nonconservative=_nonconservative([q, dq, t, p], equations.nonconservative, n),
        given=equations.given, given_values=_given_values(p, equations),
        rtol=equations.rtol, atol=equations.atol)


def _nonconservative(arguments: list[Any], expr: Any, n: int) -> Callable[..., Array]:
    """Q_nc as a function; without damping, forces or torques (a pendulum under gravity) a
    constant zero, which the integrator asks for at every stage."""
    if not any(sp.sympify(item) != 0 for item in expr):
        return lambda *values: np.zeros(n)
    return _compiled(arguments, expr, (n,))


def _given_values(p: list[Any], equations: EquationsOfMotion) -> Callable[..., Array] | None:
    if not equations.given:
        return None
    return _compiled([p], sp.Matrix([item.value for item in equations.given]),
                     (len(equations.given),))


def _equations(system: Any) -> EquationsOfMotion:
    equations = derive(system)
    if equations is None:
        raise ValueError("the mechanism's drivers fix its motion: nothing to integrate")
    return equations


def numeric(system: Any) -> Functions:
    """The :class:`Functions` of ``system``, a mechanism its forces move."""
    return functions(system, _equations(system))
