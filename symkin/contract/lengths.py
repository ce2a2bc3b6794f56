"""Which coordinates and which rows of Phi are lengths: the split the scale-free solve rests on
(runtime.solving.units scales them in Python, the generated C solver from the tables codegen renders
from the same rules, so both backends scale the same entries)."""

from __future__ import annotations

from collections.abc import Sequence

POSITION_SUFFIXES = (".x", ".y", ".z")
"""Coordinates that are lengths; every other coordinate (an angle) is dimensionless."""


def length_columns(coordinates: Sequence[str]) -> list[bool]:
    """Per coordinate, whether it is a length (x, y, z of a body)."""
    return [name.endswith(POSITION_SUFFIXES) for name in coordinates]


def length_rows(n_rows: int, pattern_rows: Sequence[int], pattern_cols: Sequence[int],
                coordinates: Sequence[str]) -> list[bool]:
    """Per row of Phi, whether it is a length: it has a structural entry in a length column."""
    columns = length_columns(coordinates)
    rows = [False] * n_rows
    for row, col in zip(pattern_rows, pattern_cols):
        rows[row] = rows[row] or columns[col]
    return rows


def scale_free_constants(constant_nz: Sequence[float | None], pattern_rows: Sequence[int],
                         pattern_cols: Sequence[int], coordinates: Sequence[str]) -> bool:
    """Whether every non-zero of Phi_q known at generation time keeps its value in another
    length unit. An entry scales by (column is a length) / (row is a length): only a number
    in a length row and an angle column (a lever arm written as a literal) would change, and
    generated code that folds it in cannot solve in another unit."""
    columns = length_columns(coordinates)
    rows = length_rows(len(coordinates), pattern_rows, pattern_cols, coordinates)
    return not any(value is not None and rows[r] and not columns[c]
                   for value, r, c in zip(constant_nz, pattern_rows, pattern_cols))
