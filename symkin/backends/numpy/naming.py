"""What the NumPy template needs beyond the common context: the generated functions' Python
names, signatures and docstrings, and the mechanism's names as Python string literals."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from symkin.codegen.lower import Code

# The module's function of a routine, where it is not the routine's own name.
_NAME = {"phi_q": "phi_q_nz", "points": "_points", "phi_p": "phi_p_nz",
         "phi_phi_q": "phi_phi_q_nz", "mass": "mass_nz"}
_DOC = {
    "phi": "Phi(q, t), shape (NQ,).",
    "phi_q": "The non-zeros of Phi_q in pattern order, shape (NNZ,).",
    "phi_t": "Phi_t(q, t), shape (NQ,).",
    "gamma": "Gamma(q, dq, t), the right-hand side of Phi_q ddq = Gamma, shape (NQ,).",
    "points": "Local vectors of the named points, flat (x, y) pairs in POINTS order.",
    "phi_p": "The non-zeros of Phi_p (d Phi / d p) in PHI_P_ROWS/COLS order, shape (NNZ_P,).",
    "removed": "The rows removed as dependent at t0, in REMOVED order, shape (NREMOVED,).",
    "senses": "Positive at a genuine assembly, in SENSES order, shape (NSENSES,).",
    "phi_phi_q": "(Phi, the non-zeros of Phi_q, the shared values) with one CSE: each sine "
                 "and cosine once.",
    "phi_t_shared": "Phi_t(q, t) from the shared values of phi_phi_q_nz at the same q, t, p.",
    "gamma_shared": "Gamma(q, dq, t) from the shared values of phi_phi_q_nz at the same q, t, p.",
    "dynamics_rhs": "Q - M ddq - h(q, dq), the right-hand side of Phi_q^T lam = rhs, (NQ,).",
    "loads": "The efforts (DRIVER_NAMES) then Fx, Fy, M of each joint (JOINT_NAMES) from lam.",
    "dynamics_rhs_shared": "dynamics_rhs from the shared values of phi_phi_q_nz at the same q.",
    "loads_shared": "loads from the shared values of phi_phi_q_nz at the same q, t, p.",
    "removed_q": "The removed rows' Jacobian, row-major, shape (NREMOVED * NQ,).",
    "loads_full": "loads from lam of every row: the kept rows' (NQ), then the removed rows'.",
    "mass": "The non-zeros of the mass matrix M(q) in MASS_ROWS/COLS order, shape (NNZ_M,).",
    "applied": "The applied forces less the velocity terms, Q(q, dq, t) - h(q, dq), (NQ,).",
    "motion": "(the non-zeros of M, of Phi_q, Q - h, Gamma) at q, dq, t with one CSE: each "
              "sine and cosine once.",
}


def template_context(code: Code) -> dict[str, Any]:
    """The mechanism's names as Python string literals: repr() of a str is always a valid,
    inert literal."""
    return {
        "name_literal": repr(code.name),
        "coordinate_literals": [repr(n) for n in code.coordinates],
        "parameter_literals": [repr(n) for n in code.parameter_names],
        "row_literals": [repr(r) for r in code.rows],
        "removed_literals": [repr(r) for r in code.removed],
        "sense_literals": [repr(r) for r in code.senses],
        "range_literals": [repr(tuple(entry)) for entry in code.ranges],
        "point_literals": [repr(tuple(p)) for p in code.points],
        "driver_literals": [repr(n) for n in code.driver_names],
        "joint_literals": [repr(n) for n in code.joint_names],
    }


def routine_context(code: Code, routine: dict[str, Any]) -> dict[str, Any]:
    """A routine's Python function name, signature (``p`` last and optional) and docstring."""
    name = routine["name"]
    arguments = [a for a in routine["arguments"] if a != "p"] + ["p=None"]
    return {"python_name": _NAME.get(name, name), "python_signature": ", ".join(arguments),
            "doc": _doc(code, name)}


def _doc(code: Code, routine: str) -> str:
    """The generated function's docstring; a spatial mechanism's points are triples, its
    reactions six components."""
    doc = _DOC[routine]
    if code.space != "3d":
        return doc
    return doc.replace("(x, y) pairs", "(x, y, z) triples").replace("Fx, Fy, M", "Fx ... Mz")
