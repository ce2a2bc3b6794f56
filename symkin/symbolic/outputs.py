"""What pairs report along a motion beyond the coordinates — a cam's pressure angle and
radius of curvature at the contact — as named expressions of q, dq, t and the parameters, and
their values on a solved Trajectory (NumPy functions made at each call: 0.5 s of CPU for the
cam example, whose outputs SymPy builds unevaluated, see ``pairs.planar.cam.outputs``).

Each pair type says what it reports (:attr:`symkin.pairs.kit.PairType.outputs`); they are
named ``NAME.key`` after the pair, and written with the Trajectory (CSV columns after the
points, NPZ arrays by name).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import sympy as sp
from numpy.typing import NDArray

from symkin import pairs
from symkin.spec.validate import Mechanism
from symkin.symbolic.planar import Context
from symkin.symbolic.symbols import Symbols, make_symbols

if TYPE_CHECKING:  # a warm run that writes the outputs does not load the derivation
    from symkin.symbolic.derivation import System

UNDEFINED_BELOW = 1e-9
"""An output is NaN where its guard is below this fraction of the guard's largest value."""


@dataclass(frozen=True)
class Output:
    """One reported quantity: ``NAME.key``, its expression, and where it is undefined."""

    name: str
    expr: sp.Expr
    guard: sp.Expr | None


def pair_outputs(system: System) -> tuple[Output, ...]:
    """Every pair's outputs, joints then drivers in file order."""
    return _outputs_of(system.mechanism, make_symbols(system.mechanism))


def _outputs_of(mech: Mechanism, symbols: Symbols) -> tuple[Output, ...]:
    ctx = Context(mech, symbols)
    found = []
    for section in pairs.SECTIONS:
        for constraint in getattr(mech, section):
            report = pairs.of(constraint).outputs
            if report is None:
                continue
            for key, (expr, guard) in report(constraint, ctx).items():
                found.append(Output(f"{constraint.name}.{key}", expr, guard))
    return tuple(found)


def _numeric(symbols: Symbols, expr: sp.Expr) -> Callable[..., NDArray[np.float64]]:
    arguments = [*symbols.q, *symbols.dq, symbols.t, *symbols.p]
    # CSE first: a cam's pressure angle repeats the piecewise profile's derivatives, and
    # printing the expanded tree took a minute for the cam example (5 s with CSE)
    return sp.lambdify(arguments, expr, "numpy", cse=True)  # type: ignore[no-any-return]


def evaluate(system: System, trajectory: Any) -> tuple[tuple[str, NDArray[np.float64]],
                                                             ...]:
    """The outputs' values at every solved point of a Trajectory (its t, q, dq and params),
    shape (T,) each."""
    return _evaluate(system.mechanism, trajectory)


def _evaluate(mech: Mechanism, trajectory: Any) -> tuple[tuple[str, NDArray[np.float64]], ...]:
    symbols = make_symbols(mech)
    columns = [*trajectory.q.T, *trajectory.dq.T, trajectory.t, *trajectory.params]
    values = []
    for output in _outputs_of(mech, symbols):
        with np.errstate(all="ignore"):
            value = np.broadcast_to(np.asarray(_numeric(symbols, output.expr)(*columns),
                                               dtype=float), trajectory.t.shape).copy()
            if output.guard is not None and trajectory.t.size:
                guard = np.abs(np.broadcast_to(np.asarray(
                    _numeric(symbols, output.guard)(*columns), dtype=float),
                    trajectory.t.shape))
                value[guard <= UNDEFINED_BELOW * np.max(guard)] = np.nan
        values.append((output.name, value))
    return tuple(values)


def with_outputs(system: System, trajectory: Any) -> Any:
    """A Trajectory carrying the pairs' outputs (the same Trajectory if there are none)."""
    return with_mechanism_outputs(system.mechanism, trajectory)


def with_mechanism_outputs(mech: Mechanism, trajectory: Any) -> Any:
    """As :func:`with_outputs`, from the validated Mechanism alone: the outputs need its
    symbols and the pairs' expressions, not Phi_q or Gamma, so a warm run that writes them
    does not derive the file again."""
    values = _evaluate(mech, trajectory)
    if not values:
        return trajectory
    # Outputs already carried (a forward-dynamics run's energies) stay; the pairs' are renewed.
    new = {name for name, _ in values}
    kept = tuple(item for item in trajectory.outputs if item[0] not in new)
    return dataclasses.replace(trajectory, outputs=kept + values)
