"""The text and LaTeX report of a System, as ``symkin show`` prints it."""

from __future__ import annotations

from typing import Any

import sympy as sp

from symkin.spec.validate import degrees_of_freedom
from symkin.symbolic.derivation import System


def _names(system: System) -> dict[sp.Symbol, sp.Symbol]:
    """Readable names for printing: coordinates as ``crank.phi``, rates as ``crank.phi'``."""
    return {dq: sp.Symbol(f"{name}'") for dq, name in zip(system.dq, system.coordinates)}


def text(system: System) -> str:
    """A plain-text report: coordinates, Phi, Phi_q (pattern and entries), Phi_t, Gamma, DOF."""
    rename = _names(system)

    def show(expr: sp.Expr) -> str:
        return str(sp.sstr(expr.xreplace(rename)))

    width = max(len(str(row)) for row in system.rows)
    summary = (f"mechanism {system.name}: {len(system.q)} coordinates, {len(system.rows)} "
               f"equations, {_freedoms(system)} degree(s) of freedom")
    lines = [summary, *_removed_lines(system, show), "", "coordinates q:"]
    lines += [f"  q[{k}] = {name}" for k, name in enumerate(system.coordinates)]
    lines += ["", "parameters p:"]
    lines += [f"  p[{k}] = {s.name} = {v:g}" for k, (s, v) in
              enumerate(zip(system.p, system.p_values))]
    for title, column in (("Phi", system.phi), ("Phi_t", system.phi_t), ("Gamma", system.gamma)):
        lines += ["", f"{title}:"]
        lines += [f"  [{r}] {row!s:<{width}}  {show(column[r])}"
                  for r, row in enumerate(system.rows)]
    entries = system.phi_q.todok()
    lines += ["", f"Phi_q pattern ({len(entries)} non-zeros):"]
    lines += [f"  [{r}] " + "".join("x" if (r, k) in entries else "."
                                    for k in range(len(system.q))) for r in range(len(system.rows))]
    lines += ["", "Phi_q entries:"]
    lines += [f"  ({r},{k}) d/d {system.coordinates[k]}: {show(value)}"
              for (r, k), value in sorted(entries.items())]
    return "\n".join(lines) + "\n"


def _removed_lines(system: System, show: Any) -> list[str]:
    """What the rank analysis of an over-constrained file removed, and why."""
    if not system.removed:
        return []
    written = len(system.rows) + len(system.removed)
    rows = ("the joints' and the normalisation rows" if system.mechanism.is_spatial
            else "the joints' rows")
    lines = ["", f"degrees of freedom: {degrees_of_freedom(system.mechanism)} by the count, "
             f"{system.mobility} by the rank of {rows} at t0",
             f"removed as redundant ({written} equations for {len(system.q)} coordinates; "
             f"at the configuration assembled at t0 Phi_q has rank {len(system.rows)}, so "
             f"{len(system.removed)} row(s) depend on the others): each is left out of Phi "
             "and checked along the motion, where a point that breaks it is flagged:"]
    lines += [f"  {removed.row}  {show(removed.phi)}" for removed in system.removed]
    return lines


def latex(system: System) -> str:
    """A LaTeX fragment with the same content (an equation per matrix)."""
    rename = {q: sp.Symbol(_latex_name(name)) for q, name in zip(system.q, system.coordinates)}
    rename.update({dq: sp.Symbol(r"\dot{" + _latex_name(name) + "}")
                   for dq, name in zip(system.dq, system.coordinates)})
    parts = _latex_header(system, rename)
    for title, matrix in (("\\Phi", system.phi), ("\\Phi_{\\mathbf{q}}", system.phi_q),
                          ("\\Phi_t", system.phi_t), ("\\Gamma", system.gamma)):
        body = sp.latex(sp.Matrix(matrix).xreplace(rename))
        parts.append(f"\\begin{{equation}}\n{title} = {body}\n\\end{{equation}}")
    return "\n".join(parts) + "\n"


def _latex_header(system: System, rename: dict[sp.Symbol, sp.Symbol]) -> list[str]:
    """The DOF count, the coordinate vector and a table of row labels."""
    q = sp.latex(sp.Matrix(system.q).xreplace(rename).T)
    rows = "\n".join(rf"{r} & {_tex_text(str(row))} \\" for r, row in enumerate(system.rows))
    summary = (rf"Mechanism \texttt{{{_tex_text(system.name)}}}: {len(system.q)} coordinates, "
               rf"{len(system.rows)} equations, {_freedoms(system)} "
               "degree(s) of freedom."
               + "".join(rf" Removed as redundant at $t_0$ (checked along the motion): "
                         rf"{_tex_text(str(r.row))}." for r in system.removed))
    return [summary,
            "\\begin{equation}\n" + rf"\mathbf{{q}} = {q}^T" + "\n\\end{equation}",
            "\\begin{tabular}{rl}\n" + r"row & owner \\" + "\n\\hline\n" + rows
            + "\n\\end{tabular}"]


def _tex_text(text: str) -> str:
    """Names are identifiers, so '_' is the only character that needs escaping in text."""
    return text.replace("_", r"\_")


def _latex_name(coordinate: str) -> str:
    body, part = coordinate.split(".")
    # spatial: z and the Euler parameters e0..e3 as e_{0..3}; s: a pair's own coordinate
    symbol = ({"x": "x", "y": "y", "z": "z", "phi": "\\varphi", "s": "s"}.get(part)
              or f"e_{part[1:]}")
    if part.startswith("e"):
        return f"{{{symbol}}}_{{\\mathrm{{{body.replace('_', '-')}}}}}"
    return f"{symbol}_{{\\mathrm{{{body.replace('_', '-')}}}}}"


def _freedoms(system: System) -> int:
    """The freedoms to report: an over-constrained file's by the rank of its joints' rows at t0
    (its count can be negative: a Cardan shaft counts -2 and moves with 1), else the count."""
    if system.mobility is not None:
        return system.mobility
    return degrees_of_freedom(system.mechanism)
