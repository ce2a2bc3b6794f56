"""``symkin run MECH --inputs table.csv``: the values of a mechanism's input drivers, read
from a CSV table.

Columns: ``t`` first (the time grid of the run, strictly increasing), then each input driver's
name, each optionally followed by ``NAME_t`` (its rate) and ``NAME_tt`` (its acceleration).
Rates are given for every input or for none (then the run gives positions only: dq and d2q are
NaN), accelerations likewise and only with rates. Every mistake is refused with the file, the
line and the column it is in (exit status 2).
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from symkin import limits
from symkin.contract.columns import RATE_SUFFIXES
from symkin.runtime.input_driven.inputs import negative_length

Array = NDArray[np.float64]
SUFFIXES = ("", *RATE_SUFFIXES)  # a value's column, its rate's and its acceleration's


class TableError(ValueError):
    """A mistake in the table: the message names the file, the line and how to fix it."""


@dataclass(frozen=True)
class InputTable:
    """The checked table: the grid t (T,) and u, du, ddu (T, NU), du/ddu None if absent."""

    t: Array
    u: Array
    du: Array | None
    ddu: Array | None


def read(path: Path, names: tuple[str, ...], lengths: tuple[str, ...] = ()) -> InputTable:
    """Read and check ``path`` for the input drivers ``names``, of which ``lengths`` (a
    distance driver's f) may not be negative.

    Raises:
        TableError: the file cannot be read, or its header, a cell or the grid is wrong.
    """
    try:
        # utf-8-sig: a byte-order mark (spreadsheets' "CSV UTF-8") is not part of the header
        with path.open(newline="", encoding="utf-8-sig") as handle:
            rows = list(csv.reader(handle))
    except (OSError, UnicodeDecodeError, csv.Error) as error:
        raise TableError(f"{path}: cannot read the input table: {error}") from None
    if not rows:
        raise TableError(f"{path}: the input table is empty; its first line names the "
                         f"columns: {expected(names)}")
    kinds = _header(path, [cell.strip() for cell in rows[0]], names)
    body = [(line, row) for line, row in enumerate(rows[1:], start=2) if any(c.strip()
                                                                           for c in row)]
    if not body:
        raise TableError(f"{path}: the input table has a header but no rows of values")
    if len(body) > limits.MAX_GRID_POINTS:
        raise TableError(f"{path}: {len(body)} rows, more than the "
                         f"{limits.MAX_GRID_POINTS:,} time points a run may have")
    values = np.array([_numbers(path, line, row, rows[0]) for line, row in body])
    lines = [line for line, _ in body]
    _increasing(path, values[:, 0], lines)
    _not_negative(path, values, lines, [cell.strip() for cell in rows[0]], lengths)
    return _split(values, rows[0], names, kinds)


def _not_negative(path: Path, values: Array, lines: list[int], header: list[str],
                  lengths: tuple[str, ...]) -> None:
    """A length's column (an actuator's |B - A|) has no negative value (the rule and its
    words are runtime.input_driven.inputs', which symkin.solve applies too)."""
    names = tuple(header)
    negative = negative_length(values, names, lengths)
    if negative is not None:
        k, name, message = negative
        raise TableError(f"{path}:{lines[k]}: column {name}: {message}")


def expected(names: tuple[str, ...]) -> str:
    columns = ", ".join(f"{name}[, {name}_t, {name}_tt]" for name in names)
    return f"t, {columns}"


def _header(path: Path, header: list[str], names: tuple[str, ...]) -> set[str]:
    """Check the header; returns which of the suffixes ('', '_t', '_tt') are given."""
    where = f"{path}:1"
    if not header or header[0] != "t":
        raise TableError(f"{where}: the first column must be t (the time grid), got "
                         f"{header[0] if header else 'nothing'!r}; expected {expected(names)}")
    known = {name + suffix: (name, suffix) for name in names for suffix in SUFFIXES}
    seen: set[str] = set()
    for column in header[1:]:
        if column not in known:
            raise TableError(f"{where}: unknown column {column!r}: the input drivers are "
                             f"{', '.join(names)}; expected {expected(names)}")
        if column in seen:
            raise TableError(f"{where}: the column {column!r} is given twice")
        seen.add(column)
    kinds = set()
    for suffix in SUFFIXES:
        given = [name for name in names if name + suffix in seen]
        if given and len(given) != len(names):
            missing = [name + suffix for name in names if name + suffix not in seen]
            what = "values" if not suffix else "rates" if suffix == "_t" else "accelerations"
            raise TableError(f"{where}: {what} of some inputs but not of "
                             f"{', '.join(missing)}: give the column for every input or none")
        if given:
            kinds.add(suffix)
    if "" not in kinds:
        raise TableError(f"{where}: the columns {', '.join(names)} (the inputs' values) are "
                         f"missing; expected {expected(names)}")
    if "_tt" in kinds and "_t" not in kinds:
        raise TableError(f"{where}: accelerations (_tt) need the rates (_t) too")
    return kinds


def _numbers(path: Path, line: int, row: list[str], header: list[str]) -> list[float]:
    if len(row) != len(header):
        raise TableError(f"{path}:{line}: {len(row)} values, but the header has "
                         f"{len(header)} columns")
    numbers = []
    for column, cell in zip(header, row):
        try:
            # float() also reads 1_5 as 15, a digit group no table means as a number
            value = float(cell) if "_" not in cell else math.nan
        except ValueError:
            value = math.nan
        if not math.isfinite(value):
            raise TableError(f"{path}:{line}: column {column.strip()}: {cell.strip()!r} is "
                             "not a finite number")
        numbers.append(value)
    return numbers


def _increasing(path: Path, t: Array, lines: list[int]) -> None:
    for k in range(1, t.size):
        if not t[k] > t[k - 1]:
            raise TableError(f"{path}:{lines[k]}: t = {t[k]:.10g} does not come after the "
                             f"previous t = {t[k - 1]:.10g}: the times must increase")


def _split(values: Array, header: list[str], names: tuple[str, ...],
           kinds: set[str]) -> InputTable:
    index = {column.strip(): k for k, column in enumerate(header)}

    def block(suffix: str) -> Array | None:
        if suffix not in kinds:
            return None
        return np.ascontiguousarray(values[:, [index[name + suffix] for name in names]])

    u = block("")
    assert u is not None  # _header requires the values
    return InputTable(np.ascontiguousarray(values[:, 0]), u, block("_t"), block("_tt"))
