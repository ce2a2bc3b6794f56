"""Fused evaluation (codegen.lower): one routine per Newton iterate evaluates Phi, the
non-zeros of Phi_q and the sines and cosines that Phi_t and Gamma (and the multipliers'
routines) also use, with one CSE; the routines at the converged point read those values."""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp

from symkin.spec.substitution import Substitution


def fused_expressions(prepared: dict[str, list[sp.Expr]], dynamics_routines: Sequence[str]
                      ) -> tuple[dict[str, list[sp.Expr]], list[sp.Expr]]:
    """The fused routines' expressions, and the values they share.

    ``phi_phi_q`` outputs Phi, the non-zeros of Phi_q and every sine or cosine that Phi or
    Phi_q and also Phi_t or Gamma use, with one CSE over all of them (so each is evaluated
    once); ``phi_t_shared`` and ``gamma_shared`` read those values (``shared[k]``) instead of
    calling sin and cos again. They are evaluated at the same q, t and p, so the values are
    the same numbers bit for bit. ``dynamics_routines``: the multipliers' routines, which
    read the shared values too where the file has them.
    """
    def trig(names: tuple[str, ...]) -> set[sp.Expr]:
        found: set[sp.Expr] = set()
        for name in names:
            for e in prepared[name]:
                found |= e.atoms(sp.sin, sp.cos)
        return found

    # With inverse dynamics, also those the multipliers' routines use (a file without masses
    # or forces shares exactly what it did before).
    dynamics = tuple(name for name in dynamics_routines if name in prepared)
    shared = sorted(trig(("phi", "phi_q")) & trig(("phi_t", "gamma", *dynamics)),
                    key=sp.default_sort_key)
    # one memory of rebuilt subtrees: Gamma repeats Phi_t's piecewise parts
    mapped = Substitution({f: sp.Symbol(f"_shared{k}", real=True)
                                           for k, f in enumerate(shared)})
    return {"phi_phi_q": [*prepared["phi"], *prepared["phi_q"], *shared],
            "phi_t_shared": [mapped(e) for e in prepared["phi_t"]],
            "gamma_shared": [mapped(e) for e in prepared["gamma"]],
            **{f"{name}_shared": [mapped(e) for e in prepared[name]]
               for name in dynamics}}, shared


def fused_order(prepared: dict[str, list[sp.Expr]], pattern: Sequence[tuple[int, int]],
                shared: list[sp.Expr]) -> list[int]:
    """The fused routine's outputs row by row: Phi's row, that row's non-zeros of Phi_q, then
    the shared values it first uses; so a part keeps a row's sines and cosines together."""
    nq, nnz = len(prepared["phi"]), len(pattern)
    by_row: dict[int, list[int]] = {}
    for e, (r, _) in enumerate(pattern):
        by_row.setdefault(r, []).append(e)
    where = {f: nq + nnz + k for k, f in enumerate(shared)}
    order: list[int] = []
    for r in range(nq):
        row = [r, *(nq + e for e in by_row.get(r, []))]
        order += row
        exprs = [prepared["phi"][r], *(prepared["phi_q"][e] for e in by_row.get(r, []))]
        for e in exprs:
            for f in sorted(e.atoms(sp.sin, sp.cos) & where.keys(), key=sp.default_sort_key):
                order.append(where.pop(f))
    return order + sorted(where.values())
