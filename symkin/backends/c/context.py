"""What the C templates need beyond the common context: the real type and its libm and literal
suffixes, the Newton defaults and option rules of symkin.contract as C literals, the sparse LU
as statements or tables (lu_code), ||Phi_q||_1 as column sums (norm_code), and each routine's
C signature."""

from __future__ import annotations

from typing import Any

from symkin.backends.c import (
    dynamics_budget,
    dynamics_lu,
    linalg,
    lu_code,
    norm_code,
    op_budget,
    real,
    rhs_zeros,
)
from symkin.backends.c.printer import literal
from symkin.codegen.lower import Code
from symkin.contract import lengths, options, tuning


def template_context(code: Code) -> dict[str, Any]:
    """The C-only entries of the template context of ``code``."""
    kind = real(code)
    lu = (lu_code.template_context(code.lu_plan, constants=code.constant_nz, real=kind,
                                   prefix=code.name) if code.lu_plan else None)
    norm1 = (norm_code.norm1_context(code.pattern_cols, code.nq, code.constant_nz,
                                     literal(kind), kind)
             if not (lu and lu["style"] == "tables") else None)
    scale_free = lengths.scale_free_constants(code.constant_nz, code.pattern_rows,
                                              code.pattern_cols, code.coordinates)
    cap = int(options.c_defaults(kind)["max_iterations"])
    budget = op_budget.budget(code, lu, norm1, bool(scale_free), cap)
    zeros = {"rates": rhs_zeros.zero_rows(code, "phi_t_shared"),
             "accelerations": rhs_zeros.zero_rows(code, "gamma_shared")}
    return {
        "real": kind, "linalg": linalg(code),
        # fabs{{ libm_suffix }} is fabsf in float mode: no promotion to double in the runtime.
        "libm_suffix": "f" if kind == "float" else "",
        "literal_suffix": "F" if kind == "float" else "",
        # What must equal the runtime's, rendered from symkin.contract (never copied):
        "newton_defaults": _newton_defaults(kind),
        "option_fields": list(options.C_FIELDS),
        "option_rules": dict(options.RULES),
        "shared_constants": {name: _c_number(value)
                             for name, value in {**tuning.SHARED, **tuning.INPUTS}.items()},
        **({"lu": lu} if lu else {}),
        # the step's rhs-sparse solves: the rows of Phi_t and Gamma that are a literal 0, and
        # the solution's entries that are then +-0 (rhs_zeros)
        "zero_rows": zeros,
        "known_zeros": {key: rhs_zeros.known_zeros(lu, rows) if lu else []
                        for key, rows in zeros.items()},
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


def routine_context(code: Code, routine: dict[str, Any]) -> dict[str, Any]:
    """A routine's C signature (definition) and the argument list of a call to it."""
    kind = f"{code.name}_real"
    names = [array["name"] for array in routine["arrays"]]
    arguments = [f"{kind} t" if a == "t" else f"const {kind} {a}[]"
                 for a in routine["arguments"]]
    return {
        "call": ", ".join([*routine["arguments"], *names]),
        # C99 restrict on the outputs (definitions only; the header keeps plain []): they never
        # overlap the inputs, and knowing so lets the compiler keep q[i] in a register across
        # the stores, e.g. to merge sin(q[i]) and cos(q[i]) into one sincos call.
        "signature": ", ".join([*arguments, *(f"{kind} *restrict {n}" for n in names)]),
    }


def _newton_defaults(kind: str) -> dict[str, str]:
    """The runtime's Newton defaults for this real type, as literals (one source of truth)."""
    text = literal(kind)
    return {name: str(value) if isinstance(value, (int, bool)) else text(value)
            for name, value in options.c_defaults(kind).items()}


def _c_number(value: float) -> str:
    """The shortest text that reads back as ``value``: ``10``, ``0.05`` (cast where used)."""
    return str(int(value)) if float(value).is_integer() else repr(float(value))


def _dynamics(code: Code, cap: int) -> dict[str, Any]:
    """The dynamics step's sparse LU (dynamics_lu) and its worst-case operation count."""
    dyn = dynamics_lu.template_context(code)
    return {"dyn": dyn, "dynamics_budget": dynamics_budget.template_context(code, dyn, cap)}
