"""Generation-time analysis of the forward-dynamics step's linear algebra: which rows of Phi
its matrix uses, and the sparse LU of that matrix with a pivot order fixed here.

The generated step solves, at every stage of its integrator, the index-1 system

    [M      Phi_k^T] [ddq]   [Q - h  ]
    [Phi_k  0      ] [lam] = [Gamma_k]

whose pattern is known before any number exists: M's non-zeros, and Phi_q's (the kept rows
k) below it and transposed beside it. So the pivot order, the fill-in and every operation of
its factorization are fixed once, by the same analysis as the kinematic solver's LU of Phi_q
(codegen.lu_plan: Markowitz's rule on the structure, checked on a numeric sample, threshold
pivoting on the sample where the structure's order fails it; the run-time pivot test sends a
factorization that fails it to the dense fall-back). The samples are the mechanism at the
file's q0 assembled at t0 (codegen.sample), configurations spread about it (SPREAD), the
start turned to the quarter turns (ALIGNED) and mechanisms assembled anywhere on the turn
(TURNS), M and Phi_q evaluated there. Where no fixed
order holds at all of them, rows of one pattern trade places at run time when the larger
entry asks for it (codegen.lu_interchange, as for the kinematic LU), so that the dense
fall-back stays for what no interchange mends.

Units. The threshold tests compare entries of one column, M's (a mass, an inertia) with
Phi_q's (numbers, lengths): with masses in tonnes or grams no fixed order would pass them for
long. So the matrix factored is [M/s Phi_k^T; Phi_k 0], s = max |M_ij| at the state (the
solution's lam is then lam/s, the step multiplies it back): the order chosen here, on the
sample scaled the same way, holds for any unit of mass, and a sweep of the masses.

Redundant rows. A mechanism whose joints repeat each other (a parallelogram's extra bar,
Bricard's linkage) leaves Phi_q short of row rank all along its motion: the augmented matrix
is singular, q'' is unique and lam is not. Where the kinematic derivation already removed
such rows (a fully driven file, System.removed) Phi has only the independent ones. A file the
forces move keeps every row in Phi; here the rows dependent at the sample are chosen as the
derivation chooses them (symbolic.redundancy: the rank of the equilibrated Phi_q, rows kept
in the same priority, joints last and later before earlier removed), and the step's matrix
uses the kept rows only. Their multipliers are one of the many solutions, the removed rows'
zero, as the kinematic side's ``loads`` takes them; the step still checks every row's
residual, so a dependency that stops holding is seen.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import sympy as sp

from symkin.codegen import lu_interchange, lu_plan, sample, symbol_printing
from symkin.errors import BuildError, SolveError
from symkin.spec import constants
from symkin.symbolic import redundancy
from symkin.symbolic.derivation import System


@dataclass(frozen=True)
class AugmentedPlan:
    """The step's matrix as plain data.

    Attributes:
        kept: the rows of Phi in the matrix, in order (all of them unless some are dependent).
        removed: the rows left out as dependent at the sample.
        sources: per slot of the matrix's pattern, where its value comes from: ("m", e) the
            e-th non-zero of M, ("j", e) the e-th non-zero of Phi_q (once below M, once
            transposed beside it).
        plan: the sparse LU of the (NQ + len(kept)) square pattern, slots in ``sources``
            order.
        constants: per slot, its value when it is a number at every state (else None; always
            None for M's, which are scaled at run time).
    """

    kept: tuple[int, ...]
    removed: tuple[int, ...]
    sources: tuple[tuple[str, int], ...]
    plan: lu_plan.LUPlan
    constants: tuple[float | None, ...]

    @property
    def order(self) -> int:
        return self.plan.n

    @property
    def nnz_m(self) -> int:
        return sum(1 for kind, _ in self.sources if kind == "m")


SPREAD_SAMPLES = 8
SPREAD = 1.0
"""Besides the assembled start, the pivot order is checked at SPREAD_SAMPLES configurations,
each coordinate moved from the start by up to SPREAD (seeded): a mechanism its forces move
goes where no driver says, and an order chosen at one configuration alone can fail at
another (a free body's Euler parameters at another orientation). The order that holds at
all of them, or fails at the fewest, is taken (lu_plan.analyse_over)."""


ALIGNED = 4
"""Samples of the start with every planar angle (``.phi``) at j quarter turns and every body's
Euler parameters (``.e0`` .. ``.e3``) at the j-th unit vector, j < ALIGNED: the orientations
where the entries of Phi_q and M that are sines, cosines or parameters vanish (a free body at
the identity has Phi_q's normalisation row 2 (1, 0, 0, 0)), which seeded samples never meet
and a body its forces turn meets at every quarter turn."""


def aligned(names: Sequence[str], start: np.ndarray) -> list[np.ndarray]:
    """The ALIGNED samples of ``start`` (coordinates named as ``names``)."""
    found = []
    for j in range(ALIGNED):
        q = start.copy()
        for i, name in enumerate(names):
            suffix = name.rsplit(".", 1)[-1]
            if suffix == "phi":
                q[i] = j * np.pi / 2
            elif suffix in ("e0", "e1", "e2", "e3"):
                q[i] = 1.0 if suffix == f"e{j}" else 0.0
        found.append(q)
    return found if any(n.rsplit(".", 1)[-1] in ("phi", "e0") for n in names) else []


TURNS = 16
"""Seeded configurations with every planar angle anywhere on the turn (the others moved by up
to SPREAD), each taken onto Phi(q, t0) = 0 by minimum-norm Newton (those that do not get
there in TURN_ITERATIONS are left out): where a mechanism its forces move goes. A pivot can
shrink at a configuration the loops' closure alone reaches, which no unassembled sample meets
(Andrews' squeezer: about 2 % of its factorizations before these samples, none after)."""

TURN_ITERATIONS = 30


def turned(names: Sequence[str], start: np.ndarray, generator: np.random.Generator,
           closure: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]) -> list[np.ndarray]:
    """The TURNS samples about ``start``: ``closure(q)`` gives Phi and the dense Phi_q at q
    (at t0); the assembled ones, in the order drawn."""
    angles = [i for i, name in enumerate(names) if name.endswith(".phi")]
    found = []
    for _ in range(TURNS):
        q = start + generator.uniform(-SPREAD, SPREAD, start.size)
        q[angles] = generator.uniform(-np.pi, np.pi, len(angles))
        assembled = _onto_constraints(q, closure)
        if assembled is not None:
            found.append(assembled)
    return found


def _onto_constraints(q: np.ndarray, closure: Callable[[np.ndarray], tuple[np.ndarray,
                                                                              np.ndarray]]
                      ) -> np.ndarray | None:
    """Minimum-norm Newton from q onto Phi = 0 (Phi_q has fewer rows than columns where the
    forces move the mechanism): the q reached, or None."""
    for _ in range(TURN_ITERATIONS):
        phi, jacobian = closure(q)
        if not (np.all(np.isfinite(phi)) and np.all(np.isfinite(jacobian))):
            return None
        if np.max(np.abs(phi), initial=0.0) <= sample.NEWTON.tol_phi:
            return q
        q = q - np.linalg.lstsq(jacobian, phi, rcond=None)[0]
    return None


def analyse(system: System, pattern: Sequence[tuple[int, int]],
            m_pattern: Sequence[tuple[int, int]]) -> AugmentedPlan:
    """The kept rows and the sparse LU of the step's matrix (module docstring).

    Raises:
        BuildError: the matrix's pattern is structurally singular (a coordinate neither mass
            nor constraint reaches).
    """
    samples = _samples(system, pattern, m_pattern)
    nq, nphi = len(system.q), len(system.phi)
    kept = _kept_rows(system, pattern, samples[0][1], nq, nphi)
    position = {row: k for k, row in enumerate(kept)}
    entries = [(r, c, ("m", e)) for e, (r, c) in enumerate(m_pattern)]
    below = [(nq + position[r], c, ("j", e)) for e, (r, c) in enumerate(pattern)
             if r in position]
    entries += below + [(c, r, source) for r, c, source in below]
    values = [[float(mass[e]) / _mass_scale(mass) if kind == "m" else float(jacobian[e])
               for _, _, (kind, e) in entries] for mass, jacobian in samples]
    try:
        plan = lu_interchange.analyse_over(nq + len(kept), [r for r, _, _ in entries],
                                           [c for _, c, _ in entries], values)
    except SolveError as error:
        raise BuildError(f"cannot plan the sparse LU of the equations of motion: {error}. "
                         "A coordinate that no mass and no constraint reaches has no "
                         "acceleration: give its body a mass and an inertia") from None
    # M's entries are divided by the run's scale: none of them is a number in the code
    jacobian_numbers = _numbers(system.phi_q, pattern)
    constants = tuple(None if kind == "m" else jacobian_numbers[e]
                      for _, _, (kind, e) in entries)
    return AugmentedPlan(kept=tuple(kept),
                         removed=tuple(r for r in range(nphi) if r not in position),
                         sources=tuple(source for _, _, source in entries), plan=plan,
                         constants=constants)


def _mass_scale(values: np.ndarray) -> float:
    """max |M_ij|, the scale M is divided by (1 where M is all zero)."""
    largest = float(np.max(np.abs(values), initial=0.0))
    return largest if largest > 0 else 1.0


def _numbers(matrix: sp.MatrixBase, pattern: Sequence[tuple[int, int]]
             ) -> list[float | None]:
    """Per entry of ``pattern``, its value when the entry is a number (the same at every
    state), else None."""
    return [float(matrix[r, c]) if matrix[r, c].is_Number else None for r, c in pattern]


def _samples(system: System, pattern: Sequence[tuple[int, int]],
             m_pattern: Sequence[tuple[int, int]]) -> list[tuple[np.ndarray, np.ndarray]]:
    """M's and Phi_q's non-zeros at the file's q0 assembled at t0 (codegen.sample), then at
    SPREAD_SAMPLES configurations about it (every coordinate moved by up to SPREAD, seeded),
    at the ALIGNED ones and the TURNS;
    those with an entry that is not finite left out, seeded values on the patterns where
    none is left (the run-time test guards it)."""
    internal = symbol_printing.internal_symbols(system)
    prepare = symbol_printing.Preparer(internal)
    arguments = ([internal[s] for s in system.q], internal[system.t],
                 [internal[s] for s in system.code_parameters])
    mass = system.dynamics.mass_matrix if system.dynamics else sp.zeros(0, 0)
    functions = (constants.lambdify_analysis(arguments,
                                             [prepare(mass[r, c]) for r, c in m_pattern]),
                 constants.lambdify_analysis(arguments,
                                             [prepare(system.phi_q[r, c]) for r, c in pattern]),
                 constants.lambdify_analysis(arguments, [prepare(e) for e in system.phi]))
    t0, p = np.float64(system.time_grid[0]), np.array(system.code_p_values, dtype=float)
    generator = np.random.default_rng(sample.STRUCTURE_SEED)
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore")  # a singular first guess is handled by the sample
        start = np.array(sample.sample_configuration(system), dtype=float)
        spread = SPREAD_SAMPLES if start.size <= sample.MAX_SAMPLED_NQ else 0
        moved = [start + generator.uniform(-SPREAD, SPREAD, start.size) for _ in range(spread)]
        rows, cols = [r for r, _ in pattern], [c for _, c in pattern]

        def closure(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            jacobian = np.zeros((len(system.phi), start.size))
            jacobian[rows, cols] = np.array(functions[1](q, t0, p), dtype=float).reshape(-1)
            return np.array(functions[2](q, t0, p), dtype=float).reshape(-1), jacobian

        extra = ([*aligned(system.coordinates, start),
                  *turned(system.coordinates, start, generator, closure)] if spread else [])
        found = [(np.array(functions[0](q, t0, p), dtype=float).reshape(-1),
                  np.array(functions[1](q, t0, p), dtype=float).reshape(-1))
                 for q in [start, *moved, *extra]]
    finite = [values for values in found if all(np.all(np.isfinite(v)) for v in values)]
    return finite or [(generator.uniform(0.5, 1.5, len(m_pattern)),
                       generator.uniform(0.5, 1.5, len(pattern)))]


def _kept_rows(system: System, pattern: Sequence[tuple[int, int]], values: np.ndarray,
               nq: int, nphi: int) -> list[int]:
    """The rows of Phi independent at the sample, chosen in the derivation's priority
    (symbolic.redundancy.ordered_selection): every row where they are all independent."""
    if system.removed or nphi == 0:
        return list(range(nphi))  # the derivation removed the dependent rows already
    jacobian = np.zeros((nphi, nq))
    for (r, c), value in zip(pattern, values):
        jacobian[r, c] = value
    scaled = redundancy.equilibrate(jacobian)
    rank = redundancy.numerical_rank(scaled)
    if rank == nphi:
        return list(range(nphi))
    sections = [row.section for row in system.rows]
    joints = [k for k, section in enumerate(sections) if section == "joints"]
    others = [k for k, section in enumerate(sections) if section != "joints"]
    kept, _ = redundancy.ordered_selection(scaled, others + joints)
    if len(kept) != rank:
        raise BuildError(
            f"the rank of Phi_q at the assembled start cannot be decided: {rank} by its "
            f"singular values, {len(kept)} by the rows in order; move t0 away from a "
            "singular configuration, or remove the nearly repeated joint")
    return sorted(kept)

