"""The worst-case operation count of one ``<prefix>_dynamics_step``, for its header.

Each formula mirrors one function of backends/c/templates/dynamics.c.j2 (named beside it), every
branch that adds work taken; the kernel routines and the sparse LU's straight-line factor and
solves are counted from their printed statements (codegen.op_count), as op_budget does for the
kinematic step. Composition, as the step runs:

    options check + first-step evaluation (M, Phi_q, Q - h, Gamma in one call, a
      factorization and a solve at the start)
    + Runge-Kutta (3 stages, each such an evaluation)
    + (cap + 1) x position check (Phi and Phi_q in one call) + cap x position correction (a
      solve on the last stage's factors)
    + velocity correction (a factorization of the last stage's M and the checked Phi_q,
      Phi_t on the check's sines and cosines, a solve) + an evaluation at the corrected
      (q, dq) (the accelerations, the next step's first stage).

The first step's evaluation is counted in every step: a budget holds for any call. The
header also states the worst case on the dense fall-back (every factorization a sparse attempt
that fails at its last pivot, then dense LU; every solve dense).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from symkin.backends.c import dynamics_lu
from symkin.backends.c.op_budget import OPTIONS_CHECK, _amax_helpers
from symkin.codegen.op_count import Flops, count_all


def _routine(code: Any, name: str) -> Flops:
    """One call of a kernel routine: its temporaries and outputs, every part."""
    routine = code.routine(name)
    temporaries = (text for part in routine.parts for _, text in part.temporaries)
    return count_all(temporaries) + count_all(routine.outputs)


def max_abs(n: int) -> Flops:
    """<prefix>_dyn_max_abs: |v_i| twice on a new maximum, one comparison each."""
    return Flops(abs=2 * n, cmp=n)


@dataclass(frozen=True)
class Algebra:
    """One factorization (of M and Phi_q already evaluated) and one solve."""

    factor: Flops
    solve: Flops


def sparse(code: Any, dyn: dict[str, Any]) -> Algebra:
    """<prefix>_dyn_factor on the sparse path (<prefix>_dyn_load, the tiny check, the
    straight-line parts) and <prefix>_dyn_solve's straight-line substitutions."""
    lu = dyn["lu"]
    scaled = sum(1 for entry in dyn["loads"] if entry["scaled"])
    load = (Flops(abs=1, cmp=1, add=1) * len(dyn["mass_diagonal"])  # max |M_ii|, NaN test
            + Flops(cmp=2, div=1) + Flops(mul=scaled)  # s, 1 / s, amax of M / s, M / s
            + Flops(abs=1, cmp=1, add=2) * (len(dyn["loads"]) - scaled)
            + Flops(mul=1, add=1))  # the tiny bound
    lines = [line for part in lu["factor_parts"] for s in part["steps"] for line in s["factor"]]
    factor = (load + Flops(cmp=1 if lu["tiny_check"] else 0)
              + count_all(lines, _amax_helpers(dynamics_lu.prefix(code.name))))
    solve = count_all([line for key in ("forward", "backward")
                       for part in lu[f"{key}_parts"] for s in part["steps"] for line in s[key]])
    return Algebra(factor=factor, solve=solve)


def dense(code: Any, dyn: dict[str, Any]) -> Algebra:
    """The fall-back: the sparse attempt failing at its last pivot, then
    <prefix>_dyn_factor_dense (the scatter with max |a|, the LU of order NA with partial
    pivoting: search, pivot test, 1 / pivot, multipliers, Schur update); dense substitution."""
    n = code.nq + dyn["nkept"]
    factor = (sparse(code, dyn).factor + max_abs(len(code.mass_rows) + code.nnz)
              + Flops(mul=len(code.mass_rows)))  # M / s
    factor += Flops(mul=2, cmp=code.nnz)  # the tiny bound; the test of a row left out
    for k in range(n):
        r = n - k - 1
        factor += Flops(abs=1 + 2 * r, cmp=r + 1, div=1, mul=r + r * r, add=r * r)
    triangle = Flops(mul=n * (n - 1) // 2, add=n * (n - 1) // 2)
    return Algebra(factor=factor, solve=triangle * 2 + Flops(div=n))


@dataclass(frozen=True)
class DynamicsBudget:
    """The step's pieces and its worst case at the default cap of position corrections."""

    cap: int
    evaluation: Flops  # a factorization and the accelerations
    runge_kutta: Flops
    iteration: Flops  # one position check and correction
    final: Flops  # the factorization at the corrected q, velocities and accelerations
    step: Flops
    dense_step: Flops  # the step with every factorization on the fall-back

    @property
    def fixed(self) -> Flops:
        return self.step + self.iteration * -self.cap


def _lines(lines: list[str]) -> Flops:
    """The operations of written-out statements on the work struct (``->`` is no minus)."""
    return count_all(line.replace("->", "_") for line in lines)


def _pieces(code: Any, dyn: dict[str, Any], algebra: Algebra, cap: int
            ) -> tuple[Flops, ...]:
    """(evaluation, Runge-Kutta, one iteration, final, step) on ``algebra``."""
    nq, nr = code.nq, code.nrows
    # <prefix>_dyn_solve_motion: (Q - h) / s, the solve, lam * s
    motion_solve = algebra.solve + Flops(mul=nq + nr)
    evaluation = _routine(code, "motion") + algebra.factor + motion_solve  # _dyn_evaluate
    stage = evaluation + Flops(mul=2 * nq, add=2 * nq)  # <prefix>_dyn_stage
    point = Flops(mul=2 * nq, add=2 * nq)  # <prefix>_dyn_point
    runge_kutta = (Flops(div=3, mul=2 * nq) + (point + stage) * 3
                   + Flops(add=2 * nq))  # <prefix>_dyn_runge_kutta
    check = _routine(code, "phi_phi_q") + max_abs(nr) + Flops(add=1, cmp=4)
    correction = algebra.solve + Flops(add=nr + nq)  # <prefix>_dyn_correct_positions
    iteration = check + correction
    # <prefix>_dyn_velocities: its factorization, Phi_t, the violation before and after
    velocity = (algebra.factor + _routine(code, "phi_t_shared") + _lines(dyn["violation"])
                + Flops(add=nr + nq) + algebra.solve + _lines(dyn["residual"]) + max_abs(nr))
    final = velocity + evaluation + Flops(add=4 * nq, cmp=1)  # and the NaN test
    step = (OPTIONS_CHECK + Flops(cmp=3, add=2) + evaluation + runge_kutta
            + check * (cap + 1) + correction * cap + final)
    return evaluation, runge_kutta, iteration, final, step


def budget(code: Any, cap: int, dyn: dict[str, Any] | None = None) -> DynamicsBudget:
    """The worst case of one step of ``code``'s dynamics with ``cap`` position corrections
    (``dyn``: the step's sparse LU, dynamics_lu.template_context, made here when not given)."""
    dyn = dynamics_lu.template_context(code) if dyn is None else dyn
    evaluation, runge_kutta, iteration, final, step = _pieces(code, dyn, sparse(code, dyn),
                                                              cap)
    dense_step = _pieces(code, dyn, dense(code, dyn), cap)[-1]
    return DynamicsBudget(cap=cap, evaluation=evaluation, runge_kutta=runge_kutta,
                          iteration=iteration, final=final, step=step, dense_step=dense_step)


def header_lines(plan: DynamicsBudget) -> list[str]:
    """The comment block of ``<prefix>_dynamics.h`` (lines without the comment markers)."""
    def kinds(f: Flops) -> str:
        return (f"{f.total} ({f.add} add/sub, {f.mul} mul, {f.div} div, {f.sqrt} sqrt, "
                f"{f.call} other calls, {f.abs} fabs, {f.cmp} compares)")

    return [
        f"One evaluation (M, Phi_q, Q - h, Gamma, the sparse LU, a solve): "
        f"{plan.evaluation.total}",
        f"Runge-Kutta, three stages: {plan.runge_kutta.total}; one position correction: "
        f"{plan.iteration.total}; the velocity correction (a factorization) and the "
        f"accelerations at the corrected q, dq: {plan.final.total}",
        f"Step, worst case with the default cap of {plan.cap} corrections: {kinds(plan.step)}",
        "  (another cap c: OPS_DYNAMICS_FIXED + c * OPS_DYNAMICS_ITERATION)",
        f"On the dense fall-back at every factorization, worst case: {plan.dense_step.total}",
    ]


def template_context(code: Any, dyn: dict[str, Any], cap: int) -> dict[str, Any]:
    """The ``dynamics_budget`` entry of the C template context."""
    plan = budget(code, cap, dyn)
    return {"lines": header_lines(plan), "cap": plan.cap, "iteration": plan.iteration.total,
            "fixed": plan.fixed.total, "step": plan.step.total,
            "dense_step": plan.dense_step.total}
