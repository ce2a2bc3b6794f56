"""What the Octave templates need beyond the common context: MATLAB's 1-based indices, names
as MATLAB strings, the comment character."""

from __future__ import annotations

import re
from typing import TYPE_CHECKING, Any

from symkin.codegen.lower import comment
from symkin.contract.loads import reaction_parts

if TYPE_CHECKING:
    from symkin.codegen.lower import Code

# A MATLAB string holds these as they are; anything else (a quote, a non-ASCII letter) is
# written as '?' so that no text of the file can end the string or reach MATLAB as code.
_UNSAFE = re.compile(r"[^A-Za-z0-9_.,:;()\[\] +=<>*/-]")


def m_string(text: str) -> str:
    """A single-quoted MATLAB string of ``text`` (valid in MATLAB and Octave alike)."""
    return "'" + _UNSAFE.sub("?", text)[:200] + "'"


def m_cell(texts: list[str] | tuple[str, ...]) -> str:
    """A column cell array of strings, ``{'a'; 'b'}``; ``{}`` when empty."""
    # One string a line: a long name list never runs past the screen, nor is a string split.
    return "{" + "; ...\n        ".join(m_string(text) for text in texts) + "}"


def one_based(indices: tuple[int, ...] | list[int]) -> str:
    """0-based indices as a MATLAB row vector of 1-based ones."""
    return "[" + " ".join(str(index + 1) for index in indices) + "]"


def template_context(code: Code) -> dict[str, Any]:
    """The Octave-only template data (names carry an ``m_`` prefix)."""
    reactions = reaction_parts(code.space)
    rows, names = code.rows, code.coordinates
    return {
        # Phi_q's and Phi_p's comments: the 1-based entry, the row's joint or driver, the column.
        "m_nz_labels": [comment(f"({r + 1}, {c + 1}) {rows[r]}, {names[c]}")
                        for r, c in zip(code.pattern_rows, code.pattern_cols)],
        "m_phi_p_labels": [comment(f"({r + 1}, {k + 1}) {rows[r]}, {code.parameter_names[k]}")
                           for r, k in zip(code.phi_p_rows, code.phi_p_cols)],
        "parameter_names_plain": [comment(name) for name in code.parameter_names],
        "input_names_plain": [comment(name) for name in code.input_names],
        "coordinate_names_plain": [comment(name) for name in code.coordinates],
        "m_rows": one_based(code.pattern_rows), "m_cols": one_based(code.pattern_cols),
        "m_phi_p_rows": one_based(code.phi_p_rows), "m_phi_p_cols": one_based(code.phi_p_cols),
        "m_coordinates": m_cell(code.coordinates),
        "m_parameters": m_cell(code.parameter_names),
        "m_row_names": m_cell(code.rows),
        "m_points": m_cell([f"{body}.{point}" for body, point in code.points]),
        "m_inputs": m_cell(code.input_names),
        "m_load_names": m_cell([f"{name}.effort" for name in code.driver_names] +
                               [f"{name}.{part}" for name in code.joint_names
                                for part in reactions]),
        "m_nu": len(code.input_names),
    }
