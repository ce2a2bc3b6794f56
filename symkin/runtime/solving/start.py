"""The assembled start, checked before the first step: a singular or limit configuration at t0
is reported up front instead of stepped from.

From a singular start the predictor has no direction to follow (the tangent of the motion is
not unique there), so the first step may jump to another branch or wind an angle by thousands
of turns; which one depends on rounding, so two backends could disagree. The check is made on
the first solved point, whichever backend solved it, by the same Python code: both backends
take the same decision.

The test is scale-free. Phi_q mixes units: a row that closes a loop is a length, a row that
holds an angle is dimensionless, and so are the columns of angles against those of positions.
Its plain condition number therefore grows with the unit a mechanism is drawn in (a
crank-slider in millimetres looks 1000 times worse conditioned than in metres). The check
uses the condition of Phi_q with its position columns multiplied by the mechanism's length
scale L and its length rows divided by it, the Jacobian in the coordinates x/L, y/L, phi:
drawing the same mechanism in another unit leaves that matrix unchanged. L is the largest
lever arm in Phi_q: max |dPhi_i/dphi_j| / max_k |dPhi_i/dx_k| over the length rows i (the
length of a link, the distance of a slide from its body's origin), read from Phi_q at the start.

Imports NumPy only: part of the runtime.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from symkin.contract.lengths import POSITION_SUFFIXES
from symkin.contract.options import Options
from symkin.runtime.protocol import KinematicsKernel
from symkin.runtime.solving import accuracy
from symkin.runtime.solving.edges import LIMIT_COND, limit_motion
from symkin.runtime.solving.linalg import SPARSE_FROM, dependencies, factor_sparse

Array = NDArray[np.float64]



@dataclass(frozen=True)
class Singular:
    """A start at a singular or limit configuration: its scaled condition, the length scale,
    the dependent rows, the joints the null motion moves and the drivers held."""

    cond: float
    scale: float
    groups: tuple[tuple[str, ...], ...]
    aligned: tuple[str, ...]
    drivers: tuple[str, ...]


SIZE_FROM = 100
"""Coordinates up to which the start's threshold is the limit positions' (runtime.solving.edges); a
larger mechanism's grows with the square of its size (start_threshold)."""


def start_threshold(options: Options, size: int = 0) -> float:
    """The scaled condition above which the start of a mechanism of ``size`` coordinates
    counts as singular: up to SIZE_FROM the one that makes a stop a limit position
    (runtime.solving.edges), so the start and the motion are judged alike.

    Beyond, it grows as (size / SIZE_FROM)^2, because the condition of a regular mechanism
    does too: Phi_q^-1 carries a residual of one joint through every body beyond it, each
    moved by up to a lever arm L, and the 1-norm adds them up (a regular lazy tongs of 1000
    bars, 3000 coordinates, has 3.95e6). A dead centre's does not: its rank is lost locally
    (the textbook crank-slider drawn at its dead centre has 6.8e6 at 9 coordinates)."""
    growth = max(1.0, size / SIZE_FROM) ** 2
    return min(LIMIT_COND, options.max_cond / 10) * growth


def positions(kernel: KinematicsKernel) -> NDArray[np.bool_]:
    """Which columns of Phi_q are lengths (x, y, z of a body)."""
    return _positions(tuple(kernel.coordinates)).copy()


@functools.lru_cache(maxsize=64)
def _positions(coordinates: tuple[str, ...]) -> NDArray[np.bool_]:
    """positions, once per mechanism (a sweep asks for every failed set)."""
    return np.array([name.endswith(POSITION_SUFFIXES) for name in coordinates], dtype=bool)


def length_rows(kernel: KinematicsKernel) -> NDArray[np.bool_]:
    """Which rows of Phi are lengths: those with a structural entry in a position column."""
    return _structure(kernel).length_rows.copy()


@dataclass(frozen=True)
class _Structure:
    """What the lever arms need of a kernel's pattern, worked out once per kernel: each
    row's non-zeros as a row of ``slots`` (indices into the non-zeros, padded with one past
    the last, which reads as 0), whether each slot is in a position column, and the scalings
    of scaled_nonzeros less the length scale."""

    slots: NDArray[np.intp]
    moved: NDArray[np.bool_]
    turned: NDArray[np.bool_]
    length_rows: NDArray[np.bool_]
    by_position: NDArray[np.bool_]
    row_of: NDArray[np.intp]
    col_of: NDArray[np.intp]
    recent: dict[tuple[bytes, float, bytes], tuple[Array, float]]
    recent_scales: dict[tuple[bytes, float, bytes], float]


_STRUCTURES: dict[int, tuple[object, _Structure]] = {}
"""_Structure by the id of the kernel's pattern_rows array (kept, so that the id is not
reused while the entry lives); a kernel's ScaledKernel views share their kernel's."""


def _structure(kernel: KinematicsKernel) -> _Structure:
    key = kernel.pattern_rows
    hit = _STRUCTURES.get(id(key))
    if hit is not None and hit[0] is key:
        return hit[1]
    if len(_STRUCTURES) >= 64:
        _STRUCTURES.clear()
    rows = np.asarray(kernel.pattern_rows, dtype=np.intp)
    cols = np.asarray(kernel.pattern_cols, dtype=np.intp)
    by_position = _positions(tuple(kernel.coordinates))[cols]
    m = len(kernel.rows)
    count = np.bincount(rows, minlength=m)
    width = max(1, int(count.max(initial=0)))
    slots = np.full((m, width), rows.size, dtype=np.intp)
    order = np.argsort(rows, kind="stable")
    starts = np.concatenate(([0], np.cumsum(count)[:-1]))
    place = np.arange(rows.size) - np.repeat(starts, count)
    slots[rows[order], place] = order
    padded = np.append(by_position, False)[slots]
    real = slots < rows.size
    length = np.zeros(m, dtype=bool)
    length[rows[by_position]] = True
    structure = _Structure(slots, padded & real, ~padded & real, length, by_position, rows,
                           cols, {}, {})
    _STRUCTURES[id(key)] = (key, structure)
    return structure


def length_scale(kernel: KinematicsKernel, nz: Array) -> float:
    """L, the largest lever arm in Phi_q (module docstring), from its structural non-zeros
    ``nz``; 1 where there is none (a mechanism with no rotation, whose matrix needs no
    scaling)."""
    structure = _structure(kernel)
    magnitude = np.append(np.abs(nz), 0.0)[structure.slots]
    moved = np.where(structure.moved, magnitude, 0.0).max(axis=1)
    turned = np.where(structure.turned, magnitude, 0.0).max(axis=1)
    lengths = moved > 0
    arms = turned[lengths] / moved[lengths]
    scale = float(arms.max(initial=0.0))
    return scale if math.isfinite(scale) and scale > 0 else 1.0


RECENT = 8
"""Configurations whose Phi_q and L a kernel keeps (lever_arms): a loop of solves from one
start asks for the same few every call."""


def lever_arms(kernel: KinematicsKernel, q: Array, t: float, p: Array) -> tuple[Array, float]:
    """The non-zeros of Phi_q at (q, t, p) and L from them, kept for the RECENT last
    configurations of the kernel (read-only arrays)."""
    recent = _structure(kernel).recent
    key = (np.ascontiguousarray(q, dtype=np.float64).tobytes(), float(t),
           np.ascontiguousarray(p, dtype=np.float64).tobytes())
    hit = recent.get(key)
    if hit is not None:
        return hit
    with np.errstate(all="ignore"):
        nz = np.array(kernel.phi_q_nz(q, t, p), dtype=np.float64)
    nz.flags.writeable = False
    found = (nz, length_scale(kernel, nz) if np.isfinite(nz).all() else math.nan)
    if len(recent) >= RECENT:
        recent.clear()
    recent[key] = found
    return found


_FLOAT64 = np.dtype(np.float64)


def lever_arm(kernel: KinematicsKernel, q: Array, t: float, p: Array) -> float:
    """L at (q, t, p), NaN where Phi_q is not finite there: one call of the generated
    ``<prefix>_length_scales`` (what sweeps use) where the kernel has a batch solver, with no
    Phi_q through Python, kept for the RECENT last configurations; else from Phi_q's
    non-zeros (lever_arms)."""
    batch = getattr(kernel, "batch_solver", None)
    if batch is None:
        return lever_arms(kernel, q, t, p)[1]
    q, p = _float64(q), _float64(p)
    recent = _structure(kernel).recent_scales
    key = (q.tobytes(), float(t), p.tobytes())
    scale = recent.get(key)
    if scale is None:
        scale = _generated_scale(batch, q, t, p)
        if len(recent) >= RECENT:
            recent.clear()
        recent[key] = scale
    return scale


def measured_lever_arm(kernel: KinematicsKernel, q: Array, t: float, p: Array) -> float:
    """lever_arm without its memory, for a caller that keeps the answer in its own
    (runtime.solving.call_plan: one memory, not two)."""
    batch = getattr(kernel, "batch_solver", None)
    if batch is None:
        return lever_arms(kernel, q, t, p)[1]
    return _generated_scale(batch, _float64(q), t, _float64(p))


def _float64(values: Array) -> Array:
    """values as a float64 array (itself when it is one: its bytes are a key)."""
    if type(values) is np.ndarray and values.dtype is _FLOAT64:
        return values
    return np.asarray(values, dtype=np.float64)


def _generated_scale(batch: Any, q: Array, t: float, p: Array) -> float:
    """L from one call of the generated ``<prefix>_length_scales``."""
    return from_raw(float(batch.length_scales(p[None, :], q, float(t))[0]))


def from_raw(scale: float) -> float:
    """L from a raw length scale as a solver gives it (``<prefix>_length_scales``): NaN where
    Phi_q is not finite, 1 where there is no lever arm (Phi_q as it is, as length_scale
    says); an L as lever_arm gives it is returned as it is."""
    if not math.isfinite(scale):
        return math.nan
    return scale if scale > 0 else 1.0


def factored_lever_arm(kernel: KinematicsKernel, factors: Any) -> float | None:
    """L at the point whose Phi_q ``factors`` (runtime.solving.linalg) factored, from the
    matrix they keep: lever_arm's value there for a kernel whose dense Phi_q is its
    phi_q_nz scattered (runtime.kernel.Kernel's), as the runtime's Newton factors it below
    SPARSE_FROM coordinates; None for sparse factors."""
    matrix = getattr(factors, "matrix", None)
    if type(matrix) is not np.ndarray:
        return None
    nz = matrix[kernel.pattern_rows, kernel.pattern_cols]
    return length_scale(kernel, nz) if np.isfinite(nz).all() else math.nan


def scaled_nonzeros(kernel: KinematicsKernel, nz: Array) -> tuple[Array, float]:
    """The non-zeros of Phi_q in the coordinates x/L, y/L, phi with its length rows divided
    by L (same pattern), and L."""
    structure = _structure(kernel)
    scale = length_scale(kernel, nz)
    column = np.where(structure.by_position, scale, 1.0)
    row = np.where(structure.length_rows[structure.row_of], scale, 1.0)
    return nz * column / row, scale


def scaled_cond(kernel: KinematicsKernel, scaled: Array) -> float:
    """The 1-norm condition number of the scaled Phi_q from its non-zeros (inf when it is
    singular): exact from NumPy's inverse below SPARSE_FROM coordinates (a warm C run never
    imports SciPy), estimated with the sparse LU (runtime.solving.linalg) from there on."""
    if not np.all(np.isfinite(scaled)):
        return math.inf
    n = len(kernel.coordinates)
    rows = np.asarray(kernel.pattern_rows, dtype=np.intp)
    cols = np.asarray(kernel.pattern_cols, dtype=np.intp)
    if n < SPARSE_FROM:
        try:
            inverse = np.linalg.inv(_dense(n, rows, cols, scaled))
        except np.linalg.LinAlgError:
            return math.inf
        inverse_norm = float(np.abs(inverse).sum(axis=0).max(initial=0.0))
    else:
        factors = factor_sparse(n, rows, cols, scaled)
        if not factors.pivot_ratio > 0.0:
            return math.inf
        inverse_norm = factors.inverse_norm1()
    cond = inverse_norm * accuracy.norm1(scaled, cols, n)
    return cond if math.isfinite(cond) else math.inf


def _dense(n: int, rows: NDArray[np.intp], cols: NDArray[np.intp], nz: Array) -> Array:
    matrix = np.zeros((n, n))
    np.add.at(matrix, (rows, cols), nz)
    return matrix


SAFETY = 10.0
"""The margin on a solver's condition estimate before a start counts as clearly regular (the
estimator's lower bound can fall short of the true norm)."""


def clearly_regular(estimate: float, scale: float, threshold: float) -> bool:
    """Whether a solver's condition ``estimate`` of Phi_q (in the unit it solved in, where
    the length scale is ``scale``) shows the start regular without a factorisation of its
    own: Phi_q in units of L differs from that matrix by diagonal scalings of its length
    columns and rows by L, which change the 1-norm condition by at most max(L, 1/L)^2."""
    bound = estimate * max(scale, 1.0 / scale) ** 2
    return math.isfinite(bound) and bound * SAFETY <= threshold


def cleared(kernel: KinematicsKernel, options: Options, estimate: float,
            scale: float | None) -> bool:
    """Whether a solver's condition ``estimate`` of Phi_q at a start and the length scale
    ``scale`` there (raw or as lever_arm gives it; None: not known) show the start clearly
    regular (clearly_regular): singular_start's first test, which needs nothing else."""
    return clears(estimate, scale, start_threshold(options, len(kernel.coordinates)))


def clears(estimate: float, scale: float | None, threshold: float) -> bool:
    """cleared with the start's threshold already worked out (a loop of solves keeps it in
    its call plan): from_raw and clearly_regular written out, one function call in all."""
    if scale is None or not math.isfinite(scale):  # from_raw's NaN: not cleared
        return False
    arm = scale if scale > 0 else 1.0
    bound = estimate * (arm if arm >= 1.0 else 1.0 / arm) ** 2  # max(arm, 1 / arm) ** 2
    return math.isfinite(bound) and bound * SAFETY <= threshold


def singular_start(kernel: KinematicsKernel, q: Array, t: float, p: Array, options: Options,
                   estimate: float = math.nan, scale: float | None = None
                   ) -> Singular | None:
    """The start (q at t) judged before the first step: None when Phi_q is regular there.
    ``estimate``: the solver's condition estimate of Phi_q at q, from the factors it made
    there (NaN: none), which spares the check its own factorisation where it suffices;
    ``scale``: the length scale at q as that solver found it (raw, Run.lever_arm; None: it
    is worked out here, lever_arm)."""
    threshold = start_threshold(options, len(kernel.coordinates))
    if math.isfinite(estimate):
        arm = lever_arm(kernel, q, t, p) if scale is None else scale
        if cleared(kernel, options, estimate, arm):
            return None
    nz, _ = lever_arms(kernel, q, t, p)
    scaled, scale = scaled_nonzeros(kernel, nz)
    cond = scaled_cond(kernel, scaled)
    if cond <= threshold:
        return None
    n = len(kernel.coordinates)
    matrix = _dense(n, np.asarray(kernel.pattern_rows, dtype=np.intp),
                    np.asarray(kernel.pattern_cols, dtype=np.intp), scaled)
    _, found = dependencies(matrix, list(kernel.rows), rcond=1.0 / threshold)
    aligned, drivers = limit_motion(kernel, matrix)
    return Singular(cond, scale, tuple(tuple(group) for group in found), aligned, drivers)


FAR = 0.5
"""A body's assembled start is far from its q0 when its origin moved by more than this times
the mechanism's length scale, or its angle by more than this many radians (about 29 deg)."""


@dataclass(frozen=True)
class Moved:
    """A body whose assembled start is far from its q0: how far its origin moved and how much
    it turned (radians, in -pi..pi)."""

    body: str
    distance: float
    turn: float


def far_from_guess(kernel: KinematicsKernel, q0: Array, q: Array, t: float, p: Array
                   ) -> tuple[tuple[Moved, ...], float]:
    """The bodies whose assembled start q is far (FAR) from the guess q0, and the length
    scale L they are judged by. A body whose q0 is all zeros gave no guess (the chapter's
    start from q = 0) and is never reported."""
    scale = length_scale(kernel, np.asarray(kernel.phi_q_nz(q, t, p), dtype=np.float64))
    by_position = positions(kernel)
    bodies = [name.rsplit(".", 1)[0] for name in kernel.coordinates]
    moved = []
    for body in dict.fromkeys(bodies):
        columns = np.array([b == body for b in bodies])
        if not np.any(q0[columns]):
            continue
        place = columns & by_position
        distance = float(np.linalg.norm(q[place] - q0[place]))
        turns = np.angle(np.exp(1j * (q[columns & ~by_position] - q0[columns & ~by_position])))
        turn = float(np.abs(turns).max(initial=0.0))
        if distance > FAR * scale or turn > FAR:
            moved.append(Moved(body, distance, turn))
    return tuple(moved), scale
