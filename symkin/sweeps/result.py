"""The result of a sweep: M parameter sets solved over one time grid, and its NPZ file."""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from symkin import outfiles
from symkin.contract.loads import reaction_parts
from symkin.errors import SymkinError
from symkin.limits import listed
from symkin.runtime.outputs import spatial

Array = NDArray[np.float64]



def first_of_largest(values: NDArray[np.float64]) -> int:
    """The flat index of the first value within rounding (1e-9 relative) of the largest, NaN
    left out: where values tie (a spread the same at every time) rounding noise, which differs
    between the backends, does not decide which is named."""
    flat = np.ravel(values)
    top = np.nanmax(flat)
    return int(np.flatnonzero(flat >= top - 1e-9 * abs(top))[0])

@dataclass(frozen=True)
class SweepResult:
    """Positions, velocities and accelerations of M parameter sets over one grid.

    Attributes:
        t: the times, shape (T,).
        q, dq, d2q: shape (M, T, N); rows a failed set did not reach are NaN.
        status: (M,) int, 0 = solved; else 1 no convergence, 2 singular, 3 not finite,
            4 no assembly (``reasons`` says it in words).
        params: (M, NP) the parameter values of each set, in ``parameter_names`` order.
        parameter_names, coordinates: names of the columns of params and of q.
        reasons: (M,) "" for a solved set, else "no assembly", "singular", ...
        messages: (M,) symkin.solve's full message for a failed set, else "".
        t_reached: (M,) the time at which a set failed (t[-1] for a solved one).
        solved: (M,) time points solved per set (T for a solved one).
        iterations: (M,) Newton iterations of the C batch (0 for other kernels).
        points_named: the named points as (body, point).
    """

    t: Array
    q: Array
    dq: Array
    d2q: Array
    status: NDArray[np.int64]
    params: Array
    parameter_names: tuple[str, ...]
    coordinates: tuple[str, ...]
    reasons: tuple[str, ...]
    messages: tuple[str, ...]
    t_reached: Array
    solved: NDArray[np.int64]
    iterations: NDArray[np.int64]
    points_named: tuple[tuple[str, str], ...] = ()
    # The named points' local vectors at one parameter set, (P, 2): evaluated only when point
    # kinematics are asked for, so a sweep that needs only q pays nothing for them.
    local_vectors: Callable[[Array], Array] | None = field(default=None, repr=False,
                                                            compare=False)
    # An over-constrained file's rows removed as dependent at t0 (their labels), and per set
    # whether the solved motion breaks one of them beyond the position target
    # (runtime.outputs.redundant); () and None for every other file.
    removed: tuple[str, ...] = ()
    removed_broken: NDArray[np.bool_] | None = None
    # Inverse dynamics (a kernel with masses or forces): the kernel's multipliers_grid, and
    # the labels of the efforts and reactions; computed only when asked for, like the points.
    multipliers_grid: Callable[..., tuple[Array, Array]] | None = field(
        default=None, repr=False, compare=False)
    driver_names: tuple[str, ...] = ()
    joint_names: tuple[str, ...] = ()

    @functools.cached_property
    def forces(self) -> tuple[Array, Array] | None:
        """(effort (M, T, n_driver_equations), reaction (M, T, n_joints, 3; spatial 6)) of every
        set's solved rows (NaN beyond them); None for a mechanism without masses or forces."""
        if self.multipliers_grid is None:
            return None
        m, size = self.q.shape[:2]
        n_efforts, n_joints = len(self.driver_names), len(self.joint_names)
        effort = np.full((m, size, n_efforts), np.nan)
        parts = len(reaction_parts(self.space))
        reaction = np.full((m, size, n_joints, parts), np.nan)
        for j in range(m):
            done = int(self.solved[j])
            _, loads = self.multipliers_grid(self.t[:done], self.q[j, :done], self.dq[j, :done],
                                             self.d2q[j, :done], self.params[j])
            effort[j, :done] = loads[:, :n_efforts]
            reaction[j, :done] = loads[:, n_efforts:].reshape(done, n_joints, parts)
        return effort, reaction

    def force_envelope(self) -> list[tuple[str, float, float, float, int]]:
        """Per effort and reaction component (``motor.effort``, ``O.Fx``...) over the solved
        sets and times: (name, min, max, time of the largest magnitude, its set)."""
        if self.forces is None or not self.ok.any():
            return []
        effort, reaction = self.forces
        sets = np.flatnonzero(self.ok)
        columns = [(f"{n}.effort", effort[sets, :, k]) for k, n in enumerate(self.driver_names)]
        parts = reaction_parts(self.space)
        columns += [(f"{n}.{part}", reaction[sets, :, k, c]) for k, n in
                    enumerate(self.joint_names) for c, part in enumerate(parts)]
        found = []
        for name, values in columns:
            j, k = np.unravel_index(first_of_largest(np.abs(values)), values.shape)
            found.append((name, float(np.nanmin(values)), float(np.nanmax(values)),
                          float(self.t[k]), int(sets[j])))
        return found

    # "3d" for a spatial mechanism: 7 coordinates per body, points of 3 components.
    space: str = "2d"

    @property
    def point_size(self) -> int:
        return 3 if self.space == "3d" else 2

    @functools.cached_property
    def point_vectors(self) -> Array:
        """(M, P, 2): the named points' local vectors for each set's parameters (spatial:
        (M, P, 3))."""
        count, size = len(self.points_named), self.point_size
        if not count or not self.params.shape[0]:
            return np.zeros((self.params.shape[0], count, size))
        if self.local_vectors is None:  # never a silent zero vector
            raise SymkinError("this result carries no point vectors; sweep with symkin.sweep")
        vectors = self.local_vectors
        return np.stack([np.asarray(vectors(p), dtype=float).reshape(count, size)
                         for p in self.params])

    @property
    def ok(self) -> NDArray[np.bool_]:
        """(M,) True where the set was solved over the whole grid."""
        return np.asarray(self.status == 0)

    @property
    def failed(self) -> NDArray[np.intp]:
        """Indices of the sets that failed."""
        return np.flatnonzero(self.status != 0)

    def point(self, body: str, name: str) -> tuple[Array, Array, Array]:
        """r, dr, ddr of a named point (2.14-2.16), each (M, T, 2)."""
        if (body, name) not in self.points_named:
            known = listed(f"{b}.{p}" for b, p in self.points_named) or "none"
            raise SymkinError(f"no point {body}.{name}; the named points are: {known}")
        start = self.coordinates.index(f"{body}.x")
        s = self.point_vectors[:, self.points_named.index((body, name)), None, :]  # (M, 1, 2)
        if self.space == "3d":
            body_columns = slice(start, start + 7)
            return spatial.point_kinematics(self.q[:, :, body_columns],
                                            self.dq[:, :, body_columns],
                                            self.d2q[:, :, body_columns], s)
        q, dq, d2q = (a[:, :, start:start + 3] for a in (self.q, self.dq, self.d2q))
        cos, sin = np.cos(q[..., 2]), np.sin(q[..., 2])
        rs = np.stack([cos * s[..., 0] - sin * s[..., 1], sin * s[..., 0] + cos * s[..., 1]], -1)
        omega_rs = np.stack([-rs[..., 1], rs[..., 0]], -1)  # Omega R s
        r = q[..., :2] + rs  # (2.14)
        dr = dq[..., :2] + omega_rs * dq[..., 2, None]  # (2.15)
        ddr = d2q[..., :2] + omega_rs * d2q[..., 2, None] - rs * dq[..., 2, None] ** 2  # (2.16)
        return r, dr, ddr

    def points(self, *names: str) -> dict[str, tuple[Array, Array, Array]]:
        """``{"body.point": (r, dr, ddr)}`` for the named points given (default: all)."""
        wanted = names or tuple(f"{b}.{p}" for b, p in self.points_named)
        result = {}
        for full in wanted:
            body, _, point = full.rpartition(".")
            result[full] = self.point(body, point)
        return result

    def save(self, path: str | Path, compress: bool = False) -> Path:
        """Write an .npz: t, q, dq, d2q, status, params, parameter_names, coordinates,
        reasons, messages, t_reached, solved, iterations, and for the named points
        ``points`` (names) and r, dr, ddr of shape (M, T, P, 2); with masses or forces also
        ``effort`` (M, T, n_driver_equations), ``reaction`` (M, T, n_joints, 3),
        ``driver_names`` and ``joint_names``. ``compress``: a compressed .npz (zip deflate;
        read the same way by numpy.load), smaller, slower to write."""
        path = Path(path)
        if path.suffix.lower() != ".npz":
            raise SymkinError(f"cannot write {path.name}: a sweep is saved as .npz")
        arrays = self.point_arrays()
        forces: dict[str, Any] = {}
        if self.forces is not None:
            forces = {"effort": self.forces[0], "reaction": self.forces[1],
                      "driver_names": np.array(self.driver_names, dtype=str),
                      "joint_names": np.array(self.joint_names, dtype=str)}
        write = np.savez_compressed if compress else np.savez
        with outfiles.replacing(path) as temporary:
            self._write(write, temporary, forces, arrays)
        return path

    def _write(self, write: Any, path: Path, forces: dict[str, Any],
               arrays: tuple[Array, Array, Array]) -> None:
        write(path, **forces, t=self.t, q=self.q, dq=self.dq, d2q=self.d2q, status=self.status,
              params=self.params, parameter_names=np.array(self.parameter_names, dtype=str),
              coordinates=np.array(self.coordinates, dtype=str),
              reasons=np.array(self.reasons, dtype=str),
              messages=np.array(self.messages, dtype=str), t_reached=self.t_reached,
              solved=self.solved, iterations=self.iterations,
              points=np.array([f"{b}.{p}" for b, p in self.points_named], dtype=str),
              r=arrays[0], dr=arrays[1], ddr=arrays[2])

    def point_arrays(self) -> tuple[Array, Array, Array]:
        """r, dr, ddr of every named point, each (M, T, P, 2)."""
        shape = (*self.q.shape[:2], len(self.points_named), self.point_size)
        r, dr, ddr = (np.zeros(shape) for _ in range(3))
        for k, (body, name) in enumerate(self.points_named):
            r[:, :, k], dr[:, :, k], ddr[:, :, k] = self.point(body, name)
        return r, dr, ddr

    def summary(self) -> dict[str, Any]:
        """How many sets were solved, and the failures counted by reason."""
        counts: dict[str, int] = {}
        for reason in self.reasons:
            if reason:
                counts[reason] = counts.get(reason, 0) + 1
        return {"sets": int(self.status.size), "solved": int(self.ok.sum()), "failed": counts}
