"""Redundant constraints: which rows of an over-constrained Phi are dependent, found numerically
at the mechanism assembled at t0, and which of them to remove so that the run is square.

The mobility count cannot judge a mechanism whose joints repeat each other (a parallelogram
four-bar with an extra parallel bar, a Cardan shaft between two revolutes): Grübler counts the
equations, not their rank. So a file with more equations than coordinates is assembled here
(Levenberg-Marquardt, then Gauss-Newton steps, on all its rows: least squares while the rows
are more than the coordinates), and the rank of Phi_q at that configuration decides:

- the rank is taken from the singular values of Phi_q after equilibration (every column, then
  every row, scaled to unit 2-norm: the rank does not change, and neither the mechanism's size
  nor the units of a coordinate decide it). A singular value below RANK_TOLERANCE times the
  largest is a dependency;
- the rows kept are chosen in a fixed order by a QR factorisation of Phi_q^T whose columns are
  taken in that order (Gram-Schmidt with re-orthogonalisation): rows of other sections
  (drivers, normalisation rows) before joint rows, earlier rows before later ones. A row whose
  component outside the span of the rows already kept is below RANK_TOLERANCE (relative to its
  own norm) is dependent and removed. The order makes the choice deterministic: the same file
  always removes the same rows, whatever the rounding;
- where the two disagree (a singular value near the tolerance), the rank cannot be decided and
  the file is refused rather than run on a guess.

RANK_TOLERANCE = 1e-8: the assembly solves Phi to about 1e-13 of the mechanism's scale, so a
true dependency shows a singular value of that order (1e-16 for a drawing exact to 17
digits); 1e-8 leaves a margin of five orders above it, and a mechanism whose independent rows
are within 1e-8 of dependent is within 1e-8 of a singular configuration, where the runtime
would flag every point anyway.

A rank below the number of coordinates is refused: either the mechanism has freedoms no
driver fixes, or t0 is a singular configuration. The two are told apart at a second, perturbed
assembly: the configuration is moved along the null space of Phi_q and assembled again half a
grid step later (the drivers may pin a singular configuration at t0 itself); a mechanism with
a free motion keeps its rank there, a singular configuration does not.

Needs NumPy and SciPy besides SymPy (lambdify), and the dense solvers of symkin.contract.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import sympy as sp

from symkin.contract import dense_solvers
from symkin.contract.options import defaults
from symkin.spec import substitution
from symkin.symbolic.differentiation import row_jacobian

RANK_TOLERANCE = 1e-8
"""Relative size (of the equilibrated Phi_q) below which a row counts as dependent."""

ASSEMBLY_TOLERANCE = 1e-9
"""Max |Phi| (relative to the mechanism's scale, max(1, max |q|)) a least-squares assembly of
an over-constrained file must reach: more means the equations contradict each other at t0."""

PERTURBATION = 1e-3
"""How far (relative to the scale) the second assembly moves along the null space."""

_NEWTON = defaults("double")


@dataclass(frozen=True)
class Finding:
    """What the rank analysis at t0 found.

    Attributes:
        kept: indices of the rows kept, in their original order.
        removed: indices of the dependent rows removed, in their original order.
        rank: the rank of Phi_q at the assembled t0.
        q: the assembled configuration.
        dependency: per removed row, its relative component outside the kept rows' span.
        mobility: the freedoms the joints leave at t0: coordinates less the rank of the rows
            given as ``joints`` (the joints' and the normalisation rows).
    """

    kept: tuple[int, ...]
    removed: tuple[int, ...]
    rank: int
    q: tuple[float, ...]
    dependency: tuple[float, ...]
    mobility: int = 0


class Refusal(Exception):
    """The rank analysis refuses the file: ``row`` is the index of the row to blame (or None),
    ``message`` and ``hint`` say why and what to do."""

    def __init__(self, message: str, hint: str, row: int | None = None) -> None:
        super().__init__(message)
        self.message, self.hint, self.row = message, hint, row


class _Equations:
    """Phi and the dense Phi_q of all rows as NumPy functions (dummy symbols: names from the
    file never become Python identifiers). Phi_q is lambdified from each row's structural
    non-zeros (differentiation.row_jacobian, the derivatives the derivation keeps for the rows
    it keeps), not from a dense symbolic Jacobian: its zeros cost nothing to print."""

    def __init__(self, phi: Sequence[sp.Expr], q: Sequence[sp.Symbol], t: sp.Symbol,
                 p: Sequence[sp.Symbol], p_values: Sequence[float],
                 entries: Sequence[Mapping[int, sp.Expr]] | None = None) -> None:
        if entries is None:
            column = {symbol: k for k, symbol in enumerate(q)}
            entries = [row_jacobian(row, column, tuple(q)) for row in phi]
        at = [(r, k) for r, row in enumerate(entries) for k in sorted(row)]
        arguments = (list(q), t, list(p))
        self._phi = substitution.lambdify_folded(arguments, list(phi))
        self._nonzeros = substitution.lambdify_folded(arguments,
                                                      [entries[r][k] for r, k in at])
        self._rows = np.array([r for r, _ in at], dtype=np.intp)
        self._columns = np.array([k for _, k in at], dtype=np.intp)
        self.rows, self.size = len(phi), len(q)
        self.p = np.array(p_values, dtype=float)

    def phi(self, q: Any, t: float, p: Any = None) -> np.ndarray:
        values = self._phi(q, np.float64(t), self.p if p is None else p)
        return np.array(values, dtype=float).reshape(self.rows)

    def phi_q(self, q: Any, t: float, p: Any = None) -> np.ndarray:
        values = self._nonzeros(q, np.float64(t), self.p if p is None else p)
        dense = np.zeros((self.rows, self.size))
        dense[self._rows, self._columns] = np.array(values, dtype=float).reshape(-1)
        return dense


def analyse(phi: Sequence[sp.Expr], q: Sequence[sp.Symbol], t: sp.Symbol,
            p: Sequence[sp.Symbol], p_values: Sequence[float], q0: Sequence[float],
            t0: float, priority: Sequence[int], t_near: float | None = None,
            joints: Sequence[int] = (), freedoms: bool = False,
            entries: Sequence[Mapping[int, sp.Expr]] | None = None) -> Finding:
    """Assemble all rows at t0, find their rank and which rows to remove.

    Args:
        phi, q, t, p, p_values: the equations, their symbols and nominal parameter values.
        q0: the first guess (the file's q0).
        t0: where to assemble.
        priority: the row indices in the order they are kept (the first independent ones win).
        t_near: a time near t0 for the second assembly of a rank below the coordinates'
            count (default t0: moved in configuration only).
        joints: the rows a coordinate is subject to without the drivers (the joints' and a
            spatial body's normalisation), whose rank gives the mobility at t0.
        freedoms: a rank below the number of coordinates that a nearby assembly keeps is
            a motion the forces decide (a file with masses), not refused.
        entries: each row's structural non-zeros of Phi_q by column, where the caller has
            them (differentiation.row_jacobian); else taken here.

    Raises:
        Refusal: the rows contradict each other at t0 (no assembly), the rank is below the
            number of coordinates, or it cannot be decided.
    """
    equations = _Equations(phi, q, t, p, p_values, entries)
    with np.errstate(all="ignore"):
        assembled = _assemble(equations, np.array(q0, dtype=float), t0)
        jacobian = equations.phi_q(assembled, t0)
    if not np.all(np.isfinite(jacobian)):
        raise Refusal("Phi_q is not finite at the configuration assembled at t0",
                      "Check the expressions of the file at t0.")
    scaled = equilibrate(jacobian)
    rank = numerical_rank(scaled)
    kept, dependency = ordered_selection(scaled, priority)
    if len(kept) != rank:
        raise Refusal(f"the rank of Phi_q at t0 cannot be decided: {rank} by its singular "
                      f"values, {len(kept)} by the rows in order (a dependency near the "
                      f"relative tolerance {RANK_TOLERANCE:g})",
                      "Move t0 away from a singular configuration, or remove the nearly "
                      "repeated joint.")
    near = t0 if t_near is None else t_near
    if rank < equations.size and not (
            freedoms and _perturbed_rank(equations, assembled, near) == rank):
        raise _short_rank(equations, assembled, t0, rank, near)
    removed = tuple(k for k in range(equations.rows) if k not in kept)
    joint_rank = numerical_rank(scaled[list(joints)]) if joints else 0
    return Finding(kept=tuple(sorted(kept)), removed=removed, rank=rank,
                   q=tuple(float(v) for v in assembled),
                   dependency=tuple(dependency[k] for k in removed),
                   mobility=equations.size - joint_rank)


def _assemble(equations: _Equations, q0: np.ndarray, t0: float) -> np.ndarray:
    """Least squares on all rows: Levenberg-Marquardt from q0, then Gauss-Newton steps (the
    minimum-norm least-squares step) until the residual stops falling."""
    q, _ = dense_solvers.levenberg_marquardt(equations, q0, t0, equations.p, _NEWTON)
    q = _gauss_newton(equations, q, t0)
    residual = equations.phi(q, t0)
    scale = max(1.0, float(np.abs(q).max(initial=0.0)))
    worst = int(np.argmax(np.abs(residual))) if residual.size else 0
    size = float(np.abs(residual).max(initial=0.0))
    if not math.isfinite(size) or size > ASSEMBLY_TOLERANCE * scale:
        raise Refusal(f"the equations cannot all hold at t0: the best least-squares assembly "
                      f"leaves max |Phi| = {size:.3g}, largest in this row",
                      "An over-constrained mechanism runs only when its extra equations "
                      "repeat the others: check this joint's or driver's dimensions against "
                      "the rest (or q0, if it is far from the assembly).", worst)
    return q


def _gauss_newton(equations: _Equations, q: np.ndarray, t: float, steps: int = 8
                  ) -> np.ndarray:
    import scipy.linalg

    best = float(np.abs(equations.phi(q, t)).max(initial=0.0))
    for _ in range(steps):
        jacobian, phi = equations.phi_q(q, t), equations.phi(q, t)
        if not (np.all(np.isfinite(jacobian)) and np.all(np.isfinite(phi))):
            break
        delta = scipy.linalg.lstsq(jacobian, -phi, check_finite=False)[0]
        trial = q + delta
        size = float(np.abs(equations.phi(trial, t)).max(initial=0.0))
        if not size < best:
            break
        q, best = trial, size
    return q


def equilibrate(jacobian: np.ndarray) -> np.ndarray:
    """Columns, then rows, scaled to unit 2-norm (zero ones left as they are)."""
    columns = np.linalg.norm(jacobian, axis=0)
    scaled = jacobian / np.where(columns > 0, columns, 1.0)
    rows = np.linalg.norm(scaled, axis=1)
    return scaled / np.where(rows > 0, rows, 1.0)[:, None]


def numerical_rank(scaled: np.ndarray) -> int:
    """The number of singular values above RANK_TOLERANCE times the largest."""
    values = np.linalg.svd(scaled, compute_uv=False)
    if values.size == 0 or values[0] == 0.0:
        return 0
    return int(np.count_nonzero(values > RANK_TOLERANCE * values[0]))


def ordered_selection(scaled: np.ndarray, priority: Sequence[int]
                      ) -> tuple[list[int], dict[int, float]]:
    """QR of the rows in ``priority`` order (Gram-Schmidt, twice): the rows that add to the
    span of those before them, and each row's relative component outside that span."""
    basis: list[np.ndarray] = []
    kept: list[int] = []
    outside: dict[int, float] = {}
    for k in priority:
        row = scaled[k]
        norm = float(np.linalg.norm(row))
        rest = row.copy()
        for _ in range(2):  # re-orthogonalisation: one pass loses orthogonality in roundoff
            for b in basis:
                rest -= (b @ rest) * b
        left = float(np.linalg.norm(rest))
        outside[k] = left / norm if norm > 0 else 0.0
        if norm > 0 and outside[k] > RANK_TOLERANCE and len(basis) < scaled.shape[1]:
            basis.append(rest / left)
            kept.append(k)
    return kept, outside


def _short_rank(equations: _Equations, q: np.ndarray, t0: float, rank: int, t_near: float
                ) -> Refusal:
    """The refusal of a rank below the number of coordinates: a freedom no driver fixes, or a
    singular configuration at t0 (the rank rises at a perturbed assembly)."""
    missing = equations.size - rank
    again = _perturbed_rank(equations, q, t_near)
    if again is not None and again > rank:
        return Refusal(f"at t0 the {equations.rows} equations have rank {rank} for "
                       f"{equations.size} coordinates, but rank {again} at a configuration "
                       "assembled nearby: t0 is a singular configuration",
                       "Start the time grid (time.t0) where the mechanism is not singular.")
    return Refusal(f"at t0 the {equations.rows} equations have rank {rank} for "
                   f"{equations.size} coordinates (also at a configuration assembled nearby): "
                   f"the mechanism keeps {missing} freedom(s) no driver fixes",
                   f"Add drivers for {missing} more freedom(s), or check for a missing joint.")


def _perturbed_rank(equations: _Equations, q: np.ndarray, t: float) -> int | None:
    """The rank at a configuration moved along the null space of Phi_q and assembled again at
    t, a time near t0 (None when that assembly fails). Moving the time matters where the
    drivers pin the singular configuration at t0 (no other assembly exists there)."""
    jacobian = equations.phi_q(q, t)
    _, _, vt = np.linalg.svd(equilibrate(jacobian))
    direction = vt[-1] / np.where(np.linalg.norm(jacobian, axis=0) > 0,
                                  np.linalg.norm(jacobian, axis=0), 1.0)
    scale = max(1.0, float(np.abs(q).max(initial=0.0)))
    step = PERTURBATION * scale * direction / max(float(np.abs(direction).max()), 1e-300)
    with np.errstate(all="ignore"):
        moved = _gauss_newton(equations, q + step, t, steps=20)
        residual = float(np.abs(equations.phi(moved, t)).max(initial=0.0))
        if not residual <= ASSEMBLY_TOLERANCE * scale:
            return None
        return numerical_rank(equilibrate(equations.phi_q(moved, t)))
