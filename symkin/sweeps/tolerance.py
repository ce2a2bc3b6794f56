"""Tolerance analysis: designs to sweep (a grid, a table, Monte-Carlo draws), the envelope of a
point's position over the sets, and the first-order estimate of its spread from q_p.

Tolerances are half-widths: ``a=±0.01`` means a lies in a ± 0.01. A normal draw reads the
half-width as 3 sigma (99.7 % of parts inside), a uniform draw as the interval itself
(sigma = X / sqrt 3). The first-order estimate propagates the same sigmas through the
sensitivities, var r = sum_k (dr/dp_k)^2 sigma_k^2 (independent parameters): where it agrees
with the Monte-Carlo spread, the linearisation holds.
"""

from __future__ import annotations

import csv
import itertools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from symkin.errors import UsageError
from symkin.limits import listed
from symkin.runtime import driver
from symkin.runtime.kernel import Kernel
from symkin.sweeps.result import SweepResult

Array = NDArray[np.float64]
DISTRIBUTIONS = ("normal", "uniform")
MAX_SETS = 10_000_000


@dataclass(frozen=True)
class Vary:
    """``NAME=LO:HI:COUNT``: COUNT values from LO to HI, ends included."""

    name: str
    low: float
    high: float
    count: int


def grid_design(kernel: Kernel, varies: Sequence[Vary]) -> Array:
    """Every combination of the varied values (the others nominal), (M, NP)."""
    _known(kernel, [v.name for v in varies])
    total = math.prod(v.count for v in varies)
    if total > MAX_SETS:
        raise UsageError(f"the grid has {total:.3g} parameter sets, more than the "
                         f"{MAX_SETS:,} allowed; use fewer values per name")
    axes = [np.linspace(v.low, v.high, v.count) for v in varies]
    table = np.tile(kernel.p_values, (total, 1))
    names = list(kernel.parameter_names)
    for row, values in enumerate(itertools.product(*axes)):
        for v, value in zip(varies, values):
            table[row, names.index(v.name)] = value
    return table


def table_design(kernel: Kernel, path: Path) -> Array:
    """A CSV table whose header names parameters (others nominal), one set per row."""
    try:
        with path.open(newline="", encoding="utf-8") as stream:
            rows = list(csv.reader(stream))
    except (OSError, UnicodeDecodeError) as error:
        raise UsageError(f"cannot read the parameter table {path}: "
                         f"{getattr(error, 'strerror', None) or error}") from None
    rows = [row for row in rows if any(cell.strip() for cell in row)]
    if len(rows) < 2:
        raise UsageError(f"{path}: the parameter table needs a header row of parameter names "
                         "and at least one row of values")
    header = [cell.strip() for cell in rows[0]]
    _known(kernel, header, where=f"{path}:1: ")
    names = list(kernel.parameter_names)
    table = np.tile(kernel.p_values, (len(rows) - 1, 1))
    for line, row in enumerate(rows[1:], start=2):
        if len(row) != len(header):
            raise UsageError(f"{path}:{line}: {len(row)} values for {len(header)} columns")
        for name, cell in zip(header, row):
            table[line - 2, names.index(name)] = _number(cell, f"{path}:{line}: {name}")
    return table


def sigmas(kernel: Kernel, tolerances: Mapping[str, float], distribution: str) -> Array:
    """The standard deviation of every parameter (0 for those without a tolerance)."""
    _known(kernel, list(tolerances))
    if distribution not in DISTRIBUTIONS:
        raise UsageError(f"unknown distribution {distribution!r}; choose normal or uniform")
    scale = 3.0 if distribution == "normal" else math.sqrt(3.0)
    names = list(kernel.parameter_names)
    result = np.zeros(len(names))
    for name, half_width in tolerances.items():
        result[names.index(name)] = half_width / scale
    return result


def monte_carlo_design(kernel: Kernel, count: int, tolerances: Mapping[str, float],
                       distribution: str = "normal", seed: int | None = None) -> Array:
    """``count`` sets drawn around the nominal design within the tolerances, (M, NP)."""
    if not 1 <= count <= MAX_SETS:
        raise UsageError(f"--monte-carlo {count}: draw between 1 and {MAX_SETS:,} sets")
    spread = sigmas(kernel, tolerances, distribution)
    rng = np.random.default_rng(seed)
    if distribution == "normal":
        deviation = rng.standard_normal((count, spread.size))
    else:
        deviation = rng.uniform(-math.sqrt(3.0), math.sqrt(3.0), (count, spread.size))
    return kernel.p_values + deviation * spread


@dataclass(frozen=True)
class Envelope:
    """A point's position over the solved sets, per time point: each (T, 2)."""

    low: Array
    high: Array
    mean: Array
    std: Array


def envelope(result: SweepResult, body: str, point: str) -> Envelope:
    """min, max, mean and standard deviation of the point's position over the solved sets."""
    r = result.point(body, point)[0][result.ok]
    if r.shape[0] == 0:
        empty = np.full((result.t.size, result.point_size), np.nan)
        return Envelope(empty, empty, empty, empty)
    return Envelope(r.min(axis=0), r.max(axis=0), r.mean(axis=0),
                    r.std(axis=0, ddof=1) if r.shape[0] > 1 else np.zeros_like(r[0]))


def point_sensitivities(kernel: Kernel, t: Array, params: Array | None = None
                        ) -> dict[str, tuple[Array, Array]]:
    """Each named point's position and its derivative over the parameters at one design:
    ``{"body.point": (r (T, 2), r_p (T, 2, NP))}``, from q_p and eq. 2.14 differentiated:
    r_p = r_i,p + Omega R s phi_i,p + R s_p (s_p, of the plain point vectors, by central
    differences)."""
    p = kernel.p_values if params is None else np.asarray(params, dtype=float)
    trajectory = driver.solve(kernel, t=t, params=p, sensitivities=True)
    q_p = trajectory.q_p
    assert q_p is not None  # asked for
    s_p = _point_vector_derivatives(kernel, p)
    result = {}
    for k, (body, name) in enumerate(kernel.points):
        start = kernel.coordinates.index(f"{body}.x")
        phi = trajectory.q[:, start + 2]
        cos, sin = np.cos(phi), np.sin(phi)
        rotation = np.stack([np.stack([cos, -sin], -1), np.stack([sin, cos], -1)], -2)
        s = trajectory.point_vectors[k]
        rs = rotation @ s  # (T, 2)
        omega_rs = np.stack([-rs[:, 1], rs[:, 0]], -1)
        r = trajectory.q[:, start:start + 2] + rs
        r_p = (q_p[:, start:start + 2, :] + omega_rs[:, :, None] * q_p[:, None, start + 2, :]
               + rotation @ s_p[k])
        result[f"{body}.{name}"] = (r, r_p)
    return result


def first_order_std(r_p: Array, spread: Array) -> Array:
    """The standard deviation of r from independent parameters of standard deviation
    ``spread`` (covariance propagation, first order): sqrt(sum_k r_p[..., k]^2 sigma_k^2)."""
    variance: Array = np.einsum("...k,k->...", r_p**2, spread**2)
    return np.sqrt(variance)


def _point_vector_derivatives(kernel: Kernel, p: Array) -> Array:
    """d s / d p of every named point's local vector, (P, 2, NP), by central differences
    (the vectors are plain expressions of the parameters, usually linear)."""
    columns = []
    for k in range(p.size):
        h = 1e-6 * max(1.0, abs(p[k]))
        step = np.zeros_like(p)
        step[k] = h
        columns.append((kernel.point_vectors(p + step) - kernel.point_vectors(p - step)) / (2 * h))
    if not columns:
        return np.zeros((len(kernel.points), 2, 0))
    derivatives: Array = np.stack(columns, -1)
    return derivatives


def _known(kernel: Kernel, names: Sequence[str], where: str = "") -> None:
    unknown = [n for n in names if n not in kernel.parameter_names]
    repeated = sorted({n for n in names if list(names).count(n) > 1})
    if unknown or repeated:
        what = f"unknown parameter {unknown[0]!r}" if unknown else \
            f"parameter {repeated[0]!r} given twice"
        raise UsageError(f"{where}{what}; the mechanism's parameters are: "
                         f"{listed(kernel.parameter_names) or 'none'}")


def _number(text: str, where: str) -> float:
    try:
        value = float(text.strip())
    except ValueError:
        raise UsageError(f"{where}: {text.strip()!r} is not a number") from None
    if not math.isfinite(value):
        raise UsageError(f"{where}: {text.strip()!r} is not a finite number")
    return value
