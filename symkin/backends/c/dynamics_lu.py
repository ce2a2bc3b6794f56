"""The forward-dynamics step's sparse LU as data for ``templates/dynamics.c.j2``: the
straight-line factor and solves of the augmented matrix's plan (codegen.dynamics_plan), made
by the statements of the kinematic LU (lu_code) with this matrix's known numbers folded in,
the loads of M's and Phi_q's varying non-zeros into their slots, and the step's three solves
written out: each reads its right-hand side from where it lies (no copy into a vector, the
rows of M's part that are zero not read) and writes the solution where it goes.

The statements call their helpers under the prefix ``<prefix>_dyn`` (``<prefix>_dyn_lu_amax``,
``<prefix>_dyn_lu_pivot_ok``, ``<PREFIX>_DYN_LU_TAU``), defined in the dynamics source, so the
step compiles with or without the kinematic solver's sparse LU beside it.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from symkin.backends.c import lu_code, real
from symkin.backends.c.printer import literal
from symkin.codegen.dynamics_plan import AugmentedPlan
from symkin.codegen.lower import comment
from symkin.codegen.lu_plan import LUPlan

SOURCES = {"m": "mass", "j": "nz"}
"""Where a slot's value is read from: the work struct's M and Phi_q non-zeros."""


def prefix(name: str) -> str:
    """The prefix of the dynamics LU's helpers."""
    return f"{name}_dyn"


def straight(plan: LUPlan, constants: Sequence[float | None] | None, real: str, name: str,
             part_ops: int = lu_code.PART_OPS) -> dict[str, Any]:
    """The straight-line factor and solve of ``plan``, in parts (lu_code's statements).
    Constants fold in double only, as for the kinematic LU. The statements never read a known
    slot nor the reciprocal of a constant pivot (literals there): nothing to initialise."""
    fabs = "fabsf" if real == "float" else "fabs"
    code = lu_code.statements(plan, constants if real == "double" else None, literal(real),
                              prefix(name), fabs)
    steps = lu_code.step_dicts(plan, code)
    backward = list(reversed(steps))
    return {
        "n_lu": plan.n_lu, "n_fill": plan.n_lu - plan.nnz, "tau": repr(float(plan.tau)),
        "flops": plan.flops, "solve_flops": plan.solve_flops,
        "swaps": [[swap.k, swap.p] for swap in plan.swaps],
        "row_perm": list(plan.row_perm), "col_perm": list(plan.col_perm),
        "loaded": code.loaded, "known_max": code.known_max, "tiny_check": code.tiny_check,
        "constant_pivots": code.constant_pivots, "pivot_ok": code.uses_pivot_ok,
        "amax": code.ratio_tests > 0,
        "factor_parts": lu_code.split_parts(steps, lambda s: len(s["factor"]), part_ops),
        "forward_parts": lu_code.split_parts([s for s in steps if s["forward"]],
                                             lambda s: len(s["forward"]), part_ops),
        "backward_parts": lu_code.split_parts([s for s in backward if s["backward"]],
                                              lambda s: len(s["backward"]), part_ops),
    }


def loads(augmented: AugmentedPlan, loaded: Sequence[int]) -> list[dict[str, Any]]:
    """Per varying non-zero of M or Phi_q (in slot order of its first slot): the array it is
    read from, its index there, the slots it fills (a Phi_q entry fills two: below M and
    transposed beside it) and whether it is divided by the mass scale (M's)."""
    wanted = set(loaded)
    found: dict[tuple[str, int], list[int]] = {}
    for slot, source in enumerate(augmented.sources):
        if slot in wanted:
            found.setdefault(source, []).append(slot)
    return [{"array": SOURCES[kind], "index": index, "slots": slots, "scaled": kind == "m"}
            for (kind, index), slots in found.items()]


def permuted(plan: LUPlan, nq: int, kept: Sequence[int], read: Callable[[str, int], str],
             write: Callable[[str, int, str], str | None]) -> dict[str, list[str]]:
    """The loads of the permuted right-hand side ``x`` and the stores of the solution of one
    solve on the sparse path: ``read("q", i)`` is the value of the right-hand side's
    coordinate row i ("0" where it is zero), ``read("k", r)`` that of Phi's kept row r;
    ``write(kind, i, "x[k]")`` the statement that puts a coordinate's or a kept row's
    solution where it goes (None: not wanted)."""
    def side(index: int) -> tuple[str, int]:
        return ("q", index) if index < nq else ("k", kept[index - nq])

    reads = [f"x[{k}] = {read(*side(r))};" for k, r in enumerate(plan.row_perm)]
    writes = [write(*side(c), f"x[{k}]") for k, c in enumerate(plan.col_perm)]
    return {"reads": reads, "writes": [line for line in writes if line is not None]}


def solves(plan: LUPlan, nq: int, kept: Sequence[int]) -> dict[str, dict[str, list[str]]]:
    """The step's three solves written out (permuted): the accelerations (M's rows (Q - h)
    / s from work->b, Phi's Gamma from work->phi; ddq and lam * s out), the position
    correction (-Phi in work->phi; q += dx) and the velocity one (-(Phi_q dq + Phi_t) in
    work->lam; dq += dv)."""
    def motion_out(kind: str, index: int, x: str) -> str:
        return f"ddq[{index}] = {x};" if kind == "q" else f"lam[{index}] = {x} * work->scale;"

    return {
        "motion": permuted(plan, nq, kept, lambda kind, i: (
            f"work->b[{i}] * work->inverse_scale" if kind == "q" else f"work->phi[{i}]"),
            motion_out),
        "positions": permuted(plan, nq, kept, lambda kind, i: (
            "0" if kind == "q" else f"-work->phi[{i}]"),
            lambda kind, i, x: f"work->q[{i}] += {x};" if kind == "q" else None),
        "velocities": permuted(plan, nq, kept, lambda kind, i: (
            "0" if kind == "q" else f"-work->lam[{i}]"),
            lambda kind, i, x: f"work->dq[{i}] += {x};" if kind == "q" else None),
    }


def violation(code: Any, target: str, constants: Sequence[float | None] | None) -> list[str]:
    """Per row of Phi, ``target[r] = work->phi[r] + sum_e nz_e dq_c`` written out (Phi_t + Phi_q
    dq, Phi_t in work->phi), Phi_q's numbers folded in (double only, as the LU's): a
    product by 1 or -1 is an addition."""
    terms: dict[int, list[str]] = {}
    for e, (r, c) in enumerate(zip(code.pattern_rows, code.pattern_cols)):
        value = constants[e] if constants is not None else None
        if value == 1.0:
            term = f" + work->dq[{c}]"
        elif value == -1.0:
            term = f" - work->dq[{c}]"
        elif value is not None and value == 0.0:
            continue
        else:
            term = f" + work->nz[{e}] * work->dq[{c}]"
        terms.setdefault(r, []).append(term)
    return [f"{target}[{r}] = work->phi[{r}]{''.join(terms.get(r, []))};"
            for r in range(code.nrows)]


def template_context(code: Any) -> dict[str, Any]:
    """The ``dyn`` entry of the C template context (a file with masses only)."""
    augmented: AugmentedPlan = code.augmented
    lu = straight(augmented.plan, augmented.constants, real(code), code.name)
    position = {row: k for k, row in enumerate(augmented.kept)}
    folded = code.constant_nz if real(code) == "double" else None
    return {
        "lu": lu,
        "solves": solves(augmented.plan, code.nq, augmented.kept),
        # s = max |M_ij| is on M's diagonal (M is positive semi-definite: |M_ij| <=
        # sqrt(M_ii M_jj)), so only the diagonal is searched
        "mass_diagonal": [e for e, (r, c) in enumerate(zip(code.mass_rows, code.mass_cols))
                          if r == c],
        "violation": violation(code, "work->lam", folded),
        "residual": violation(code, "work->phi", folded),
        "loads": loads(augmented, lu["loaded"]),
        "nkept": len(augmented.kept),
        "kept": list(augmented.kept),
        "removed": list(augmented.removed),
        "removed_rows": [(r, comment(code.rows[r])) for r in augmented.removed],
        # the dense fall-back's scatter: each non-zero of Phi_q's row in the matrix, or -1
        # where its row is left out
        "kept_row": [code.nq + position[r] if r in position else -1
                     for r in code.pattern_rows],
    }
