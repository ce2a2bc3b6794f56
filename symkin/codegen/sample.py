"""A sample configuration of a mechanism, for choices made at generation time.

The pivot order of the generated sparse LU is checked on Phi_q at the mechanism assembled at
t0, then along its motion. Those configurations are found here with plain NumPy (SymPy's
lambdify of Phi and Phi_q) and the dense Newton and Levenberg-Marquardt of
symkin.contract.dense_solvers, so code generation never depends on the runtime. A mechanism
driven by inputs has no motion in t: its inputs are walked instead (``input_walks``).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from typing import Any, TypeAlias

import numpy as np
import sympy as sp

from symkin.codegen import lu_interchange, lu_plan, symbol_printing
from symkin.contract import dense_solvers
from symkin.contract.options import defaults
from symkin.errors import BuildError, SolveError
from symkin.spec import constants
from symkin.symbolic.derivation import System

Prepared: TypeAlias = tuple[Sequence[sp.Expr], Sequence[sp.Expr]]
"""Phi and the non-zeros of Phi_q as prepared for printing (codegen.symbol_printing)."""

# Assembly tolerances: the runtime's own Newton defaults (a tighter sample changes nothing).
NEWTON = defaults("double")


# The motion is sampled at this many times of the file's grid (evenly spread), each reached
# from the last by dense Newton over CONTINUATION_STEPS smaller steps; only for systems up to
# MAX_SAMPLED_NQ coordinates (the samples are solved and replayed in Python).
MOTION_SAMPLES = 32
CONTINUATION_STEPS = 4
MAX_SAMPLED_NQ = 150
# A sample this ill-conditioned is a singular configuration: no pivot order survives it, so
# it does not vote (the run-time test and the edge treatment handle the passage).
SINGULAR_COND = 1e10
# Inputs are walked from their values at the assembled start, each alone both ways, then in
# INPUT_DIRECTIONS directions drawn once from a seeded generator (together they move the
# mechanism where no single input can), out to INPUT_SPAN times the larger of |value| and 1
# (radians for an angle, the file's unit for a length) in the largest component;
# INPUT_SAMPLES samples a walk, each reached in CONTINUATION_STEPS steps; a walk ends where
# Newton fails (the edge of the workspace).
INPUT_SPAN = 0.5
INPUT_SAMPLES = 4
INPUT_DIRECTIONS = 16
INPUT_SEED = 26

# The seed of the one sample of Phi_q's pattern that plans the LU where no sample of the
# motion is finite (_plan_samples).
STRUCTURE_SEED = 41


def sparse_lu_plan(system: System, pattern: Sequence[tuple[int, int]],
                   prepared: Prepared | None = None) -> lu_plan.LUPlan:
    """The pivot order of the sparse LU, chosen on Phi_q at the assembled configuration and
    checked over the motion (lu_plan.analyse_over), with run-time interchanges of rows of one
    pattern where no fixed order holds (lu_interchange), so that a step's cost is predictable.
    ``prepared``: Phi and Phi_q's non-zeros (in ``pattern``'s order) as the lowering prepared
    them for printing, where it has (else they are prepared here)."""
    samples = _plan_samples(system, pattern, prepared)
    try:
        plan = lu_interchange.analyse_over(len(system.q), [r for r, _ in pattern],
                                    [c for _, c in pattern], samples)
    except SolveError as error:
        raise BuildError(f"cannot plan the sparse LU of Phi_q: {error}") from None
    return plan


def _plan_samples(system: System, pattern: Sequence[tuple[int, int]],
                  prepared: Prepared | None = None) -> list[list[float]]:
    """Phi_q's non-zeros along the motion, those with a non-finite entry left out: an
    expression singular where it is sampled (sqrt(t - 2) before t = 2) is the run's to
    report, where it happens, as the NumPy kernel does. Where no sample is finite, or SymPy
    cannot turn Phi into NumPy at all (its printer compares a constant that has no real
    value), one sample of seeded values on the pattern: a pivot order for the structure."""
    try:
        kernel = _SampleKernel(system, pattern, prepared=prepared)
    except (TypeError, ValueError):
        kernel = None
    found: list[np.ndarray] = []
    if kernel is not None:
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            # A singular first guess (SciPy's LinAlgWarning) is expected here and handled.
            warnings.simplefilter("ignore")
            start = sample_configuration(system, kernel)
            found = [kernel.phi_q_nz(q, t, p)
                     for q, t, p in motion_configurations(system, kernel, start)]
    finite = [[float(v) for v in sample] for sample in found if np.all(np.isfinite(sample))]
    if finite:
        return finite
    generator = np.random.default_rng(STRUCTURE_SEED)
    values = generator.uniform(0.5, 1.5, len(pattern)) * generator.choice([-1.0, 1.0],
                                                                            len(pattern))
    return [[float(v) for v in values]]


def motion_configurations(system: System, kernel: Any, start: Sequence[float]
                          ) -> list[tuple[np.ndarray, float, np.ndarray]]:
    """(q, t, p) at the assembled start, then at up to MOTION_SAMPLES times of the file's grid
    (or along the input walks), each followed from the last by dense Newton; a walk stops
    where Newton fails (a limit position or a singular passage), and ill-conditioned samples
    are left out."""
    t0, t1, _ = system.time_grid
    p = np.array(system.code_p_values, dtype=float)
    q = np.array(start, dtype=float)
    if len(system.q) > MAX_SAMPLED_NQ:
        return [(q, float(t0), p)]
    if system.inputs:
        return input_walks(system, kernel, q)
    if not t1 > t0:
        return [(q, float(t0), p)]
    times = np.linspace(t0, t1, MOTION_SAMPLES * CONTINUATION_STEPS + 1)[1:]
    return [(q, float(t0), p), *_follow(kernel, q, [(float(t), p) for t in times])]


def input_walks(system: System, kernel: Any, start: np.ndarray
                ) -> list[tuple[np.ndarray, float, np.ndarray]]:
    """(q, t0, p) at the start with its inputs' values there, then along straight walks of the
    inputs from there (INPUT_SPAN, INPUT_DIRECTIONS)."""
    t0 = float(system.time_grid[0])
    p = start_inputs(system, kernel, start)
    at = len(system.p) + np.arange(len(system.inputs))  # where u sits in the code's p
    span = INPUT_SPAN * np.maximum(np.abs(p[at]), 1.0)
    drawn = np.random.default_rng(INPUT_SEED).standard_normal((INPUT_DIRECTIONS, len(at)))
    directions = [*np.eye(len(at)), *-np.eye(len(at)),
                  *(drawn / np.abs(drawn).max(axis=1, keepdims=True))]
    found = [(start, t0, p)]
    fractions = np.linspace(0.0, 1.0, INPUT_SAMPLES * CONTINUATION_STEPS + 1)[1:]
    for direction in directions:
        path = []
        for fraction in fractions:
            walked = p.copy()
            walked[at] += fraction * span * direction
            path.append((t0, walked))
        found += _follow(kernel, start, path)
    return found


def input_values(system: System) -> tuple[float, ...]:
    """Each input's value in the file's q0 (start_inputs): what the generated folder's
    example program holds the inputs at, so that its first solve starts where the mechanism
    is assembled (a leg length, not the nominal 0 at which its row is flat)."""
    if not system.inputs:
        return ()
    # Printed to 17 digits: Phi with SymPy's printer as it sorts the sums (the roots' last
    # digits depend on their rounding), and no Phi_q (the roots take numerical slopes).
    kernel = _SampleKernel(system, (), _lambdify_sorted)
    with np.errstate(all="ignore"):
        # polished past Newton's tolerance: these are printed as the inputs' values
        p = start_inputs(system, kernel, np.array(system.q0, dtype=float), polish=2)
    start = len(system.p)
    return tuple(float(v) for v in p[start:start + len(system.inputs)])


def start_inputs(system: System, kernel: Any, q: np.ndarray, polish: int = 0) -> np.ndarray:
    """The code's p with each input at its value in configuration q: the root of its row in u
    by Newton (numerical slope), from its nominal value, else from 1 (a length's row may be
    flat at 0); the nominal value where neither converges. ``polish``: Newton steps more
    once the row is within the tolerance."""
    t0 = float(system.time_grid[0])
    p = np.array(system.code_p_values, dtype=float)
    for index, item in enumerate(system.inputs):
        row = next(r for r, expression in enumerate(system.phi)
                   if item.u in expression.free_symbols)
        at = len(system.p) + index

        def residual(u: float, row: int = row, at: int = at) -> float:
            trial = p.copy()
            trial[at] = u
            return float(kernel.phi(q, t0, trial)[row])

        for guess in (p[at], 1.0):
            root = _scalar_root(residual, float(guess), polish)
            if root is not None:
                p[at] = root
                break
    return p


def _scalar_root(f: Any, u: float, polish: int = 0) -> float | None:
    """Newton on a scalar f with a central-difference slope; None when it does not converge.
    Within the tolerance, up to ``polish`` steps more (towards the root's rounding level: the
    slope's small error then only scales a step that is already tiny)."""
    for _ in range(NEWTON.max_iterations + polish):
        h = 1e-7 * max(1.0, abs(u))
        value, slope = f(u), (f(u + h) - f(u - h)) / (2 * h)
        within = abs(value) <= NEWTON.tol_phi
        if within and (polish == 0 or value == 0.0 or not math.isfinite(slope)
                       or slope == 0.0):
            return u
        if not (math.isfinite(value) and math.isfinite(slope)) or slope == 0.0:
            return None
        polish -= within
        u -= value / slope
    return None


def _follow(kernel: Any, q: np.ndarray, path: Sequence[tuple[float, np.ndarray]]
            ) -> list[tuple[np.ndarray, float, np.ndarray]]:
    """Dense Newton from q along the path's (t, p), each point from the last; every
    CONTINUATION_STEPS-th solution that is not singular is kept. Stops where Newton fails."""
    found = []
    for k, (t, p) in enumerate(path, start=1):
        try:
            next_q = dense_solvers.newton(kernel, q, t, p, NEWTON)
        except (ArithmeticError, ValueError, np.linalg.LinAlgError):
            next_q = None
        if next_q is None or not np.all(np.isfinite(next_q)):
            break
        q = next_q
        if k % CONTINUATION_STEPS == 0 and np.linalg.cond(kernel.phi_q(q, t, p)) < SINGULAR_COND:
            found.append((q, t, p))
    return found


def sample_configuration(system: System, kernel: Any = None) -> tuple[float, ...]:
    """Where the pivot order of the sparse LU is chosen: the mechanism assembled at t0.

    The file's q0 is only a first guess (the chapter starts from q = 0), and a pivot order
    that is numerically good there may be poor on the motion itself; the assembled position
    is the first point the solver factors. It is found numerically here with dense Newton, then
    Levenberg-Marquardt (symkin.contract.dense_solvers, the runtime's too); when that fails, q0
    is used and the run-time pivot checks still guard every factorization.

    Args:
        system: the derived kinematics.
        kernel: Phi and Phi_q as NumPy functions; built here when not given.
    """

    q0 = np.array(system.q0, dtype=float)
    kernel = kernel or _SampleKernel(system, system.pattern())
    p = np.array(system.code_p_values, dtype=float)
    try:
        with np.errstate(all="ignore"):
            q = _assemble(kernel, q0, float(system.time_grid[0]), p)
    except (ArithmeticError, ValueError, np.linalg.LinAlgError):
        return tuple(q0)
    if q is None or not np.all(np.isfinite(q)):
        return tuple(q0)
    return tuple(float(v) for v in q)


def _lambdify_sorted(arguments: Any, expressions: list[Any]) -> Any:
    return sp.lambdify(arguments, expressions, modules=constants.numpy_modules())


class _SampleKernel:
    """Phi and the non-zeros of Phi_q as NumPy functions (sympy.lambdify over the internal
    symbols, by ``lambdify``), with the few Kernel attributes the driver's assembly reads."""

    def __init__(self, system: System, pattern: Sequence[tuple[int, int]],
                 lambdify: Any = constants.lambdify_analysis,
                 prepared: Prepared | None = None) -> None:
        internal = symbol_printing.internal_symbols(system)
        arguments = ([internal[s] for s in system.q], internal[system.t],
                     [internal[s] for s in system.code_parameters])
        self.coordinates = system.coordinates
        self.pattern_rows = np.array([r for r, _ in pattern], dtype=np.intp)
        self.pattern_cols = np.array([c for _, c in pattern], dtype=np.intp)
        if prepared is None:
            prepare = symbol_printing.Preparer(internal)
            prepared = ([prepare(e) for e in system.phi],
                        [prepare(system.phi_q[r, c]) for r, c in pattern])
        self._phi = lambdify(arguments, list(prepared[0]))
        self._nz = lambdify(arguments, list(prepared[1]))
        self._p = np.array(system.code_p_values, dtype=float)

    # t as a NumPy float: IEEE semantics as in the generated code (inf, NaN), never a Python
    # ZeroDivisionError or a complex power.
    def phi(self, q: Any, t: float, p: Any = None) -> np.ndarray:
        return np.array(self._phi(q, np.float64(t), self._p if p is None else p), dtype=float)

    def phi_q_nz(self, q: Any, t: float, p: Any = None) -> np.ndarray:
        return np.array(self._nz(q, np.float64(t), self._p if p is None else p), dtype=float)

    def phi_q(self, q: Any, t: float, p: Any = None) -> np.ndarray:
        dense = np.zeros((len(self.coordinates),) * 2)
        dense[self.pattern_rows, self.pattern_cols] = self.phi_q_nz(q, t, p)
        return dense


def _assemble(kernel: Any, q0: np.ndarray, t0: float, p: np.ndarray) -> np.ndarray | None:
    """Newton from q0, else Levenberg-Marquardt then Newton: the assembled q, or None."""
    q = dense_solvers.newton(kernel, q0, t0, p, NEWTON)
    if q is not None:
        return q
    start, _ = dense_solvers.levenberg_marquardt(kernel, q0, t0, p, NEWTON)
    return dense_solvers.newton(kernel, start, t0, p, NEWTON)

