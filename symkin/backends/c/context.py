"""What the C templates need beyond the common context: the sparse LU as statements or
tables (lu_code), ||Phi_q||_1 as column sums (norm_code) and the libm and literal suffixes of
the real type."""

from __future__ import annotations

from typing import Any

from symkin.backends.c import dynamics_budget, dynamics_lu, lu_code, norm_code, op_budget
from symkin.backends.c.printer import literal
from symkin.codegen.lower import Code
from symkin.contract import lengths, options


def template_context(code: Code) -> dict[str, Any]:
    """The C-only entries of the template context of ``code``."""
    lu = (lu_code.template_context(code.lu_plan, constants=code.constant_nz, real=code.real,
                                   prefix=code.name) if code.lu_plan else None)
    norm1 = (norm_code.norm1_context(code.pattern_cols, code.nq, code.constant_nz,
                                     literal(code.real), code.real)
             if not (lu and lu["style"] == "tables") else None)
    scale_free = lengths.scale_free_constants(code.constant_nz, code.pattern_rows,
                                              code.pattern_cols, code.coordinates)
    cap = int(options.c_defaults(code.real)["max_iterations"])
    budget = op_budget.budget(code, lu, norm1, bool(scale_free), cap)
    return {
        # fabs{{ libm_suffix }} is fabsf in float mode: no promotion to double in the runtime.
        "libm_suffix": "f" if code.real == "float" else "",
        "literal_suffix": "F" if code.real == "float" else "",
        **({"lu": lu} if lu else {}),
        # ||Phi_q||_1 straight-line, or a loop where the LU itself is table-driven
        "norm1": norm1,
        # the scale-free solve (options->unit): which columns and rows are lengths
        "length_columns": [int(c) for c in lengths.length_columns(code.coordinates)],
        "length_rows": [int(r) for r in lengths.length_rows(
            code.nq, code.pattern_rows, code.pattern_cols, code.coordinates)],
        "scale_free": scale_free,
        # the worst-case operation count of one step, for the solver's header
        "ops_budget": {"lines": op_budget.header_lines(budget), "cap": budget.cap,
                       "iteration": budget.iteration.total, "fixed": budget.fixed.total,
                       "step": budget.step.total, "dense_step": budget.dense_step.total,
                       "positions": budget.positions.total if budget.positions else None,
                       "inputs": budget.inputs.total if budget.inputs else None},
        # the same for <prefix>_dynamics_step, in a file with masses only
        **(_dynamics(code, cap) if code.forward_dynamics else {}),
    }


def _dynamics(code: Code, cap: int) -> dict[str, Any]:
    """The dynamics step's sparse LU (dynamics_lu) and its worst-case operation count."""
    dyn = dynamics_lu.template_context(code)
    return {"dyn": dyn, "dynamics_budget": dynamics_budget.template_context(code, dyn, cap)}
