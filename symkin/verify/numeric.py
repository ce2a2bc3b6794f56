"""Verification — does a hand derivation of Phi, Phi_q, Phi_t or Gamma agree with the System?

Two routes:

* numeric (:func:`verify`): a user's NumPy functions ``phi(q, t, p)``, ``phi_q(q, t, p)``,
  ``phi_t(q, t, p)`` and ``gamma(q, dq, t, p)`` — in the coordinate, parameter and row order
  ``symkin show`` prints — are evaluated next to the derived expressions (``sympy.lambdify``)
  at many random states (q, dq, t) *and* random parameter values around the nominal design, so
  a slip multiplied by a zero dimension or a zero speed at the nominal design is still caught.
  Every entry that differs is reported with the row's owner (joint or driver, type, bodies),
  the column's coordinate, the derived expression, both values and the worst relative error.
* symbolic (:func:`compare`): SymPy expressions or matrices, equal per entry when their
  difference simplifies to zero, with a numeric fallback where simplification gives up.

A hand module is the user's own Python file: loading it runs it, as pytest runs a test file. It
is loaded by path (nothing is added to ``sys.path``) and every exception it raises is turned into
a :class:`HandModuleError` that names the function and the line.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import sympy as sp

from symkin.errors import MechanismError
from symkin.limits import listed
from symkin.spec import constants
from symkin.spec.validate import Mechanism
from symkin.symbolic.derivation import System, derive
from symkin.verify.hand import (
    FUNCTIONS,
    call_hand,
    check_order,
    hand_functions,
    load_hand_module,
)
from symkin.verify.report import FunctionResult, Mismatch, Report
from symkin.verify.sampling import State, length_scale, sample_states

DEFAULT_SAMPLES = 50
DEFAULT_SPREAD = 0.3
DEFAULT_TOLERANCE = 1e-8
# Entries smaller than this fraction of a function's largest value are compared on that
# absolute scale, so rounding in a near-zero entry is not mistaken for a relative error; and
# below this fraction of the length scale when the derived function is zero everywhere.
FLOOR_FRACTION = 1e-3
FLOOR_OF_LENGTH = 1e-6


# ----- the derived side, as NumPy functions ---------------------------------------------------

@dataclass(frozen=True)
class Derived:
    """The System's four functions, lambdified once, plus what a report needs to label entries.

    Build it with :func:`derived_functions`; pass it to :func:`verify` to verify many hand
    modules (or seeds) without lambdifying again.
    """

    system: System
    phi: Callable[..., Any]
    phi_t: Callable[..., Any]
    gamma: Callable[..., Any]
    phi_q_nz: Callable[..., Any]
    pattern: tuple[tuple[int, int], ...]

    @property
    def size(self) -> int:
        return len(self.system.q)

    def evaluate(self, name: str, state: State) -> np.ndarray:
        """The derived value of one function at one state, with the hand function's shape."""
        args = (state.q, state.dq, state.t, state.p)
        if name == "phi_q":
            matrix = np.zeros((len(self.system.rows), self.size))
            if self.pattern:
                rows, cols = zip(*self.pattern)
                matrix[rows, cols] = _flat(self.phi_q_nz(*args))
            return matrix
        return _flat(getattr(self, name)(*args))

    def expression(self, name: str, row: int, column: int | None) -> sp.Expr:
        if name == "phi_q":
            return self.system.phi_q[row, column]
        return getattr(self.system, name)[row]


def _flat(value: Any) -> np.ndarray:
    return np.asarray(value, dtype=float).reshape(-1)


def derived_functions(system: System) -> Derived:
    """Lambdify Phi, Phi_t, Gamma and the non-zeros of Phi_q of a System (once)."""
    _refuse_inputs(system)
    q = sp.symbols(f"q0:{len(system.q)}")
    dq = sp.symbols(f"dq0:{len(system.dq)}")
    p = sp.symbols(f"p0:{len(system.p)}")
    t = sp.Symbol("t")
    # Safe argument names: coordinates are named "crank.x", which is no Python identifier.
    rename = dict(zip(system.q, q)) | dict(zip(system.dq, dq)) | dict(zip(system.p, p))
    rename[system.t] = t

    def make(values: Iterable[sp.Expr]) -> Callable[..., Any]:
        column = [sp.sympify(value).xreplace(rename) for value in values]
        function: Callable[..., Any] = constants.lambdify_floats([q, dq, t, p], column)
        return function

    pattern = tuple(system.pattern())
    return Derived(system=system, phi=make(system.phi), phi_t=make(system.phi_t),
                   gamma=make(system.gamma),
                   phi_q_nz=make(system.phi_q[r, k] for r, k in pattern), pattern=pattern)


def _refuse_inputs(system: System) -> None:
    """A hand file's functions take (q, t, p): a driver whose values come from the caller at
    run time has nothing to compare them with."""
    if system.inputs:
        first = system.inputs[0]
        raise MechanismError(
            f"the driver's function is an input (values given at run time), which a hand "
            f"derivation phi(q, t, p) cannot take; inputs: {listed(system.input_places)}",
            ("drivers", first.driver, first.key),
            "To check a derivation, write the driver as a function of t (e.g. theta: w*t).")


# ----- the comparison -------------------------------------------------------------------------

def verify(target: Mechanism | System | Derived | str | Path, hand: Any, *,
           samples: int = DEFAULT_SAMPLES, seed: int = 0, spread: float = DEFAULT_SPREAD,
           tolerance: float = DEFAULT_TOLERANCE) -> Report:
    """Compare a hand derivation with the derived one at random states and parameters.

    Args:
        target: the mechanism (file path, Mechanism, System, or :func:`derived_functions`).
        hand: a module, any object with some of the attributes ``phi``, ``phi_q``, ``phi_t``,
            ``gamma``, or the path of a Python file defining them.
        samples: how many random (q, dq, t, p) to try.
        seed: seed of the random states; the same seed gives the same report.
        spread: relative spread of the parameters around the nominal design (0 keeps them
            nominal).
        tolerance: largest accepted relative error of an entry.

    Raises:
        HandModuleError: the hand file is missing or broken, a function raises or returns the
            wrong shape.
    """
    derived = target if isinstance(target, Derived) else derived_functions(
        target if isinstance(target, System) else derive(target))
    origin = str(hand)
    if isinstance(hand, (str, Path)):
        hand = load_hand_module(hand)
    else:
        origin = getattr(hand, "__file__", None) or getattr(hand, "__name__", None) or \
            type(hand).__name__
    system = derived.system
    check_order(hand, origin, "COORDINATES", system.coordinates)
    check_order(hand, origin, "PARAMETERS", system.parameter_names)
    functions = hand_functions(hand, origin)
    states = sample_states(system, samples, seed, spread)
    results = tuple(_compare_function(derived, name, function, states, origin, tolerance)
                    for name, function in functions.items())
    return Report(system.name, origin, samples, seed, spread, tolerance, results,
                  tuple(name for name in FUNCTIONS if name not in functions),
                  length_scale(system))


def _compare_function(derived: Derived, name: str, function: Callable[..., Any],
                      states: list[State], origin: str, tolerance: float) -> FunctionResult:
    rows = len(derived.system.rows)
    shape = (rows, derived.size) if name == "phi_q" else (rows,)
    hand = np.array([call_hand(name, function, s, origin, shape) for s in states])
    ours = np.array([derived.evaluate(name, s).reshape(shape) for s in states])
    system = derived.system
    found = mismatches(
        name, ours, hand, states, tolerance, FLOOR_OF_LENGTH * length_scale(system),
        lambda row: str(system.rows[row]),
        lambda row, column: show_expression(system, derived.expression(name, row, column)),
        system.coordinates)
    return FunctionResult(name, int(np.prod(shape)), found)


def mismatches(name: str, ours: np.ndarray, hand: np.ndarray, states: list[State],
               tolerance: float, least: float, owner: Callable[[int], str],
               expression: Callable[[int, int | None], str], coordinates: tuple[str, ...],
               base: int = 0) -> tuple[Mismatch, ...]:
    """Every entry (row, or row and column) whose relative error exceeds ``tolerance`` in some
    sample, with its worst sample; ``owner`` and ``expression`` label an entry, ``base`` is
    where the hand file counts from (1 in MATLAB)."""
    errors = relative_errors(ours, hand, least)
    bad = errors > tolerance
    found = []
    for index in zip(*np.nonzero(bad.any(axis=0))):
        worst = int(np.argmax(errors[(slice(None), *index)]))
        row, column = int(index[0]), (int(index[1]) if len(index) > 1 else None)
        found.append(Mismatch(
            function=name, row=row, column=column, owner=owner(row),
            coordinate=coordinates[column] if column is not None else None,
            derived=expression(row, column),
            derived_value=float(ours[(worst, *index)]), hand_value=float(hand[(worst, *index)]),
            error=float(errors[(worst, *index)]), sample=worst,
            failing=int(bad[(slice(None), *index)].sum()), state=states[worst], base=base))
    return tuple(found)


def relative_errors(derived: np.ndarray, hand: np.ndarray, least: float = 0.0) -> np.ndarray:
    """|hand - derived| / max(|hand|, |derived|, floor), per sample and entry.

    The floor is FLOOR_FRACTION of the function's largest derived value over all samples, and
    at least ``least``; a non-finite hand value where the derived one is finite counts as an
    infinite error, and samples where the derived value itself is not finite are not judged.
    """
    finite = np.isfinite(derived)
    magnitude = np.abs(np.where(finite, derived, 0.0))
    floor = max(FLOOR_FRACTION * magnitude.max(initial=0.0), least)
    with np.errstate(invalid="ignore", over="ignore"):
        scale = np.maximum(np.maximum(magnitude, np.abs(hand)), floor)
        difference = np.abs(hand - derived)
        errors = np.where(difference == 0, 0.0,
                          difference / np.where(scale > 0, scale, 1.0))
    errors = np.where(np.isfinite(hand), errors, np.inf)
    return np.where(finite, errors, 0.0)


def show_expression(system: System, expr: sp.Expr) -> str:
    """An expression as ``symkin show`` prints it: rates of coordinates as ``crank.phi'``."""
    rates = {dq: sp.Symbol(f"{name}'") for dq, name in zip(system.dq, system.coordinates)}
    return str(sp.sstr(sp.sympify(expr).xreplace(rates)))


