"""The worst-case operation count of one ``<prefix>_dynamics_step``, for its header.

Each formula mirrors one function of backends/c/templates/dynamics.c.j2 (named beside it), every
branch that adds work taken; the kernel routines are counted from their printed statements
(codegen.op_count), as op_budget does for the kinematic step. Composition, as the step runs:

    options check + first-step evaluation (factor and accelerations at the start)
    + Runge-Kutta (3 stages, each a factorization and a solve)
    + factorization at the Runge-Kutta result
    + (cap + 1) x position check + cap x (position correction + factorization at its q)
    + velocity correction + accelerations.

The first step's evaluation is counted in every step: a budget holds for any call.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from symkin.backends.c.op_budget import OPTIONS_CHECK
from symkin.codegen.op_count import Flops, count_all


def _routine(code: Any, name: str) -> Flops:
    """One call of a kernel routine: its temporaries and outputs, every part."""
    routine = code.routine(name)
    temporaries = (text for part in routine.parts for _, text in part.temporaries)
    return count_all(temporaries) + count_all(routine.outputs)


def max_abs(n: int) -> Flops:
    """<prefix>_dyn_max_abs: |v_i| twice on a new maximum, one comparison each."""
    return Flops(abs=2 * n, cmp=n)


def factor(code: Any) -> Flops:
    """<prefix>_dyn_factor: M and Phi_q, their scatter with max |a|, the dense LU of order
    NA with partial pivoting (search, pivot test, 1 / pivot, multipliers, Schur update)."""
    n = code.nq + code.nrows
    total = _routine(code, "mass") + _routine(code, "phi_q")
    total += max_abs(len(code.mass_rows) + code.nnz) + Flops(mul=2)
    for k in range(n):
        r = n - k - 1
        total += Flops(abs=1 + 2 * r, cmp=r + 1, div=1, mul=r + r * r, add=r * r)
    return total


def solve(n: int) -> Flops:
    """<prefix>_dyn_solve: the two triangles, a division per row of U."""
    triangle = Flops(mul=n * (n - 1) // 2, add=n * (n - 1) // 2)
    return triangle * 2 + Flops(div=n)


@dataclass(frozen=True)
class DynamicsBudget:
    """The step's pieces and its worst case at the default cap of position corrections."""

    cap: int
    evaluation: Flops  # a factorization and the accelerations
    runge_kutta: Flops
    iteration: Flops  # one position check, correction and factorization
    velocity: Flops
    step: Flops

    @property
    def fixed(self) -> Flops:
        return self.step + self.iteration * -self.cap


def budget(code: Any, cap: int) -> DynamicsBudget:
    """The worst case of one step of ``code``'s dynamics with ``cap`` position corrections."""
    nq, nr = code.nq, code.nrows
    na = nq + nr
    accelerations = _routine(code, "applied") + _routine(code, "gamma") + solve(na)
    evaluation = factor(code) + accelerations
    stage = evaluation + Flops(mul=2 * nq, add=2 * nq)  # <prefix>_dyn_stage
    point = Flops(mul=2 * nq, add=2 * nq)  # <prefix>_dyn_point
    runge_kutta = (Flops(div=3, mul=2 * nq) + (point + stage) * 3
                   + Flops(add=2 * nq))  # <prefix>_dyn_runge_kutta
    check = _routine(code, "phi") + max_abs(nr) + Flops(add=1, cmp=4)
    correction = solve(na) + Flops(add=nr + nq) + factor(code)  # <prefix>_dyn_positions
    velocity = (_routine(code, "phi_t") + Flops(add=nr + nq) + solve(na)
                + Flops(mul=2 * code.nnz, add=2 * code.nnz) + max_abs(nr))
    final = velocity + accelerations + Flops(add=2 * nq, cmp=2 * nq)
    step = (OPTIONS_CHECK + Flops(cmp=3, add=2) + evaluation + runge_kutta
            + factor(code) + check * (cap + 1) + correction * cap + final)
    return DynamicsBudget(cap=cap, evaluation=evaluation, runge_kutta=runge_kutta,
                          iteration=check + correction, velocity=velocity, step=step)


def header_lines(plan: DynamicsBudget) -> list[str]:
    """The comment block of ``<prefix>_dynamics.h`` (lines without the comment markers)."""
    def kinds(f: Flops) -> str:
        return (f"{f.total} ({f.add} add/sub, {f.mul} mul, {f.div} div, {f.sqrt} sqrt, "
                f"{f.call} other calls, {f.abs} fabs, {f.cmp} compares)")

    return [
        f"One evaluation (M, Phi_q, their LU, Q - h, Gamma, a solve): {plan.evaluation.total}",
        f"Runge-Kutta, three stages: {plan.runge_kutta.total}; one position correction: "
        f"{plan.iteration.total}; velocity correction: {plan.velocity.total}",
        f"Step, worst case with the default cap of {plan.cap} corrections: {kinds(plan.step)}",
        "  (another cap c: OPS_DYNAMICS_FIXED + c * OPS_DYNAMICS_ITERATION)",
    ]


def template_context(code: Any, cap: int) -> dict[str, Any]:
    """The ``dynamics_budget`` entry of the C template context."""
    plan = budget(code, cap)
    return {"lines": header_lines(plan), "cap": plan.cap, "iteration": plan.iteration.total,
            "fixed": plan.fixed.total, "step": plan.step.total}

