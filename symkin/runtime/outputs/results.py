"""Stage 7 — results: point kinematics (2.14-2.16), the Trajectory and the files a run writes.

Imports only NumPy (and the contract): it is part of the runtime. Plots and animation live
in symkin.present.plots.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from symkin import outfiles
from symkin.contract.columns import ENERGY_COLUMNS, RATE_SUFFIXES
from symkin.errors import SymkinError
from symkin.limits import listed
from symkin.runtime.loads.forces import Forces
from symkin.runtime.outputs import spatial

SAVE_FORMATS = (".npz", ".csv")

OMEGA = np.array([[0.0, -1.0], [1.0, 0.0]])


def rotation(phi: ArrayLike) -> NDArray[np.float64]:
    """R(phi) for one angle (2x2) or many (..., 2, 2)."""
    phi = np.asarray(phi, dtype=float)
    c, s = np.cos(phi), np.sin(phi)
    return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)


def point_kinematics(q: ArrayLike, dq: ArrayLike, ddq: ArrayLike, s: ArrayLike
                     ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Position, velocity and acceleration of a point fixed in a body.

    Args:
        q, dq, ddq: the body's [x, y, phi] and its first and second time derivatives,
            shape (3,) or (T, 3).
        s: the point's local vector s^(i), shape (2,).

    Returns:
        r = r_i + R s (2.14), dr = dr_i + Omega R s dphi (2.15),
        ddr = ddr_i + Omega R s ddphi - R s dphi^2 (2.16); each shape (2,) or (T, 2).
    """
    q, dq, ddq = (np.asarray(a, dtype=float) for a in (q, dq, ddq))
    Rs = rotation(q[..., 2]) @ np.asarray(s, dtype=float)
    ORs = Rs @ OMEGA.T
    r = q[..., :2] + Rs
    dr = dq[..., :2] + ORs * dq[..., 2, None]
    ddr = ddq[..., :2] + ORs * ddq[..., 2, None] - Rs * dq[..., 2, None] ** 2
    return r, dr, ddr


@dataclass(frozen=True)
class Trajectory:
    """The solved kinematics on a time grid (rows: time points; columns: coordinates).

    Attributes:
        t: the times, shape (T,).
        q, dq, d2q: coordinates and their first and second time derivatives, shape (T, N).
        coordinates: the coordinate names, ``crank.x``, ``crank.y``, ``crank.phi``, ...
        points: the named points as (body, point), in file order.
        point_vectors: their local vectors s at the solved parameter values, shape (P, 2).
        params: the parameter values solved with.
        lu_fallbacks: factorizations of the generated C solver whose sparse LU left its fixed
            pivot order for the dense partial-pivoting path (always 0 elsewhere).
        q_p: design sensitivities dq/dp, shape (T, N, NP), when solved with
            ``sensitivities=True`` (from Phi_q q_p = -Phi_p); else None.
        dq_p: velocity sensitivities d dq/dp, (T, N, NP), with ``q_p``.
        flagged: (T,) True where q, dq or ddq may miss the accuracy targets (Phi_q is
            ill-conditioned there, or a singular configuration was passed through).
        cond: (T,) the estimated 1-norm condition number of Phi_q at each point.
        singular: the singular configurations passed through, as (t, rank loss, groups of
            dependent rows).
        removed: the rows of an over-constrained file removed as dependent at t0 (their
            labels); empty for every other file.
        removed_residual: (T, len(removed)) their Phi along the motion, or None; a point
            where one exceeds the position target is flagged (runtime.outputs.redundant).
        space: ``3d`` for a spatial mechanism: 7 coordinates per body (x, y, z, e0..e3),
            points of 3 components, and each body's angular velocity and acceleration.
        outputs: what pairs report beyond the coordinates, as (name, values of shape (T,)):
            a cam's ``NAME.pressure_angle`` and ``NAME.curvature_radius``
            (symkin.symbolic.outputs); written after the points.
    """

    t: NDArray[np.float64]
    q: NDArray[np.float64]
    dq: NDArray[np.float64]
    d2q: NDArray[np.float64]
    coordinates: tuple[str, ...]
    points: tuple[tuple[str, str], ...] = ()
    point_vectors: NDArray[np.float64] = field(default_factory=lambda: np.zeros((0, 2)))
    params: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))
    lu_fallbacks: int = 0
    q_p: NDArray[np.float64] | None = None
    dq_p: NDArray[np.float64] | None = None
    flagged: NDArray[np.bool_] = field(default_factory=lambda: np.zeros(0, dtype=bool))
    cond: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))
    singular: tuple[tuple[float, int, tuple[tuple[str, ...], ...]], ...] = ()
    removed: tuple[str, ...] = ()
    removed_residual: NDArray[np.float64] | None = None
    space: str = "2d"
    forces: Forces | None = None
    """Efforts and reactions (runtime.loads.forces) when the mechanism has masses or forces."""
    outputs: tuple[tuple[str, NDArray[np.float64]], ...] = ()
    branch_jumps: NDArray[np.bool_] | None = None
    """(T,) True where an input-driven run may have jumped to another assembly than the row
    before (runtime.input_driven.branch); None for a run over t."""

    def __post_init__(self) -> None:
        # A Trajectory built without them (by hand, or from older code) is unflagged.
        if self.flagged.shape != self.t.shape:
            object.__setattr__(self, "flagged", np.zeros(self.t.shape, dtype=bool))
        if self.cond.shape != self.t.shape:
            object.__setattr__(self, "cond", np.full(self.t.shape, np.nan))

    @classmethod
    def solved(cls, t: NDArray[np.float64], q: NDArray[np.float64], dq: NDArray[np.float64],
               d2q: NDArray[np.float64], coordinates: tuple[str, ...],
               points: tuple[tuple[str, str], ...], point_vectors: NDArray[np.float64],
               params: NDArray[np.float64], lu_fallbacks: int, flagged: NDArray[np.bool_],
               cond: NDArray[np.float64],
               singular: tuple[tuple[float, int, tuple[tuple[str, ...], ...]], ...] = (),
               space: str = "2d") -> Trajectory:
        """The solver's result, whose arrays are consistent by construction (flagged and cond
        of shape (T,)): the same object as the constructor's, built without its field-by-field
        frozen assignment and checks, which cost more than solving a short grid."""
        self = object.__new__(cls)
        # Stored one by one into the instance's own dict: update(**fields) would first build
        # a dict of the keywords and then copy it (15 % more instructions in all).
        fields = self.__dict__
        fields["t"], fields["q"], fields["dq"], fields["d2q"] = t, q, dq, d2q
        fields["coordinates"], fields["points"] = coordinates, points
        fields["point_vectors"], fields["params"] = point_vectors, params
        fields["lu_fallbacks"], fields["q_p"], fields["dq_p"] = lu_fallbacks, None, None
        fields["flagged"], fields["cond"], fields["singular"] = flagged, cond, singular
        fields["removed"], fields["removed_residual"], fields["space"] = (), None, space
        fields["forces"], fields["outputs"], fields["branch_jumps"] = None, (), None
        return self

    @property
    def spatial(self) -> bool:
        return self.space == "3d"

    @property
    def point_size(self) -> int:
        """A point's components: 2, or 3 in a spatial mechanism."""
        return 3 if self.spatial else 2

    @property
    def effort(self) -> NDArray[np.float64] | None:
        """(T, n_driver_equations): what each driver applies (None without dynamics)."""
        return None if self.forces is None else self.forces.effort

    @property
    def reaction(self) -> NDArray[np.float64] | None:
        """(T, n_joints, 3): Fx, Fy, M body i exerts on body j (spatial: (T, n_joints, 6),
        Fx, Fy, Fz, Mx, My, Mz; None without dynamics)."""
        return None if self.forces is None else self.forces.reaction

    @property
    def bodies(self) -> tuple[str, ...]:
        """The moving bodies, in coordinate order (a pair's own coordinate ``NAME.s`` is no
        body's: each body has an ``.x``)."""
        return tuple(name[:-2] for name in self.coordinates if name.endswith(".x"))

    def body(self, name: str
             ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """(q, dq, d2q) of one body, each shape (T, 3): x, y, phi (spatial: (T, 7): x, y,
        z, e0..e3)."""
        if name not in self.bodies:
            raise SymkinError(f"no body {name!r}; the bodies are: {', '.join(self.bodies)}")
        start = self.coordinates.index(f"{name}.x")
        columns = slice(start, start + (7 if self.spatial else 3))
        return self.q[:, columns], self.dq[:, columns], self.d2q[:, columns]

    def point(self, body: str, name: str
              ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """Position, velocity and acceleration of a named point (2.14-2.16), each (T, 2)
        (spatial: (T, 3), from the Euler parameters)."""
        if (body, name) not in self.points:
            known = listed(f"{b}.{p}" for b, p in self.points) or "none"
            raise SymkinError(f"no point {body}.{name}; the named points are: {known}")
        s = self.point_vectors[self.points.index((body, name))]
        # rows whose rates were not asked for (NaN), or absurdly large (1e200: their square
        # overflows), give NaN or inf here as they should, without NumPy's warning on top
        with np.errstate(over="ignore", invalid="ignore"):
            if self.spatial:
                return spatial.point_kinematics(*self.body(body), s)
            return point_kinematics(*self.body(body), s)

    def angular(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """omega and alpha of every body of a spatial mechanism, global, each (T, B, 3)."""
        found = [spatial.angular(*self.body(body)) for body in self.bodies]
        shape = (self.t.size, len(found), 3)
        omega = np.stack([w for w, _ in found], 1) if found else np.zeros(shape)
        alpha = np.stack([a for _, a in found], 1) if found else np.zeros(shape)
        return omega, alpha

    def point_arrays(self) -> tuple[NDArray[np.float64], ...]:
        """r, dr, ddr of every named point, each shape (T, P, 2) (spatial: (T, P, 3))."""
        shape = (self.t.size, len(self.points), self.point_size)
        r, dr, ddr = (np.zeros(shape) for _ in range(3))
        for k, (body, name) in enumerate(self.points):
            r[:, k], dr[:, k], ddr[:, k] = self.point(body, name)
        return r, dr, ddr

    def save(self, path: str | Path) -> Path:
        """Write .npz (all arrays: t, q, dq, d2q, coordinates, points, r, dr, ddr, flagged,
        cond; removed, removed_residual where rows were removed as redundant; each pair
        output by its name) or .csv (t, q, q_t, q_tt columns, then each named point's x, y,
        vx, vy, ax, ay, then the pair outputs, then flagged)."""
        path = Path(path)
        suffix = path.suffix.lower()
        if suffix not in SAVE_FORMATS:
            raise SymkinError(f"cannot write {path.name}: the output must end in .npz or .csv")
        with outfiles.replacing(path) as temporary:
            (self._save_npz if suffix == ".npz" else self._save_csv)(temporary)
        return path

    def _point_columns(self) -> list[str]:
        """``<body>.<point>_x, _y, _vx, _vy, _ax, _ay`` for every named point (spatial:
        ``_x, _y, _z, _vx, _vy, _vz, _ax, _ay, _az``)."""
        axes = "xyz"[:self.point_size]
        suffixes = [f"{kind}{axis}" for kind in ("", "v", "a") for axis in axes]
        return [f"{body}.{point}_{suffix}" for body, point in self.points
                for suffix in suffixes]

    def _angular_columns(self) -> list[str]:
        """``<body>.omega_x .. _z, <body>.alpha_x .. _z`` for every body (spatial only)."""
        return [f"{body}.{kind}_{axis}" for body in self.bodies
                for kind in ("omega", "alpha") for axis in "xyz"] if self.spatial else []

    def _save_npz(self, path: Path) -> None:
        r, dr, ddr = self.point_arrays()
        names = np.array([f"{b}.{p}" for b, p in self.points], dtype=str).reshape(-1)
        arrays: dict[str, Any] = {
            "t": self.t, "q": self.q, "dq": self.dq, "d2q": self.d2q,
            "coordinates": np.array(self.coordinates, dtype=str), "points": names,
            "r": r, "dr": dr, "ddr": ddr, "flagged": self.flagged, "cond": self.cond,
            **dict(self.outputs)}
        # An over-constrained file's removed rows, only then (every other file's NPZ as before).
        if self.removed and self.removed_residual is not None:
            arrays.update(removed=np.array(self.removed, dtype=str),
                          removed_residual=self.removed_residual)
        if self.spatial:
            omega, alpha = self.angular()
            arrays.update(omega=omega, alpha=alpha,
                          bodies=np.array(self.bodies, dtype=str).reshape(-1))
        arrays.update(self._forces_arrays())
        np.savez(path, **arrays)

    def _forces_arrays(self) -> dict[str, NDArray[Any]]:
        """NPZ ``effort``, ``driver_names``, ``reaction``, ``joint_names`` (with dynamics)."""
        if self.forces is None:
            return {}
        f = self.forces
        arrays = {"effort": f.effort, "driver_names": np.array(f.driver_names, dtype=str),
                  "reaction": f.reaction, "joint_names": np.array(f.joint_names, dtype=str)}
        # Only where rows were removed as redundant (every other file's NPZ as before).
        efforts, reactions = f.effort_determinate, f.reaction_determinate
        if efforts is not None and reactions is not None:
            arrays.update(effort_determinate=efforts, reaction_determinate=reactions)
        return arrays

    def _save_csv(self, path: Path) -> None:
        header = ["t", *self.coordinates,
                  *(c + suffix for suffix in RATE_SUFFIXES for c in self.coordinates),
                  *self._point_columns(),
                  *self._angular_columns(),
                  *(ENERGY_COLUMNS.get(name, name) for name, _ in self.outputs), "flagged",
                  *(self.forces.columns() if self.forces is not None else ())]
        r, dr, ddr = self.point_arrays()
        # Per point: x, y, vx, vy, ax, ay (2.14-2.16); spatial: x, y, z, vx, vy, vz, ax...
        # the column count given, not inferred: a run that stopped before its first row
        # still writes its header
        points = np.concatenate([r, dr, ddr], axis=2).reshape(
            self.t.size, 3 * self.point_size * len(self.points))
        columns = [self.t, self.q, self.dq, self.d2q, points]
        if self.spatial:
            omega, alpha = self.angular()
            columns.append(np.concatenate([omega, alpha], axis=2).reshape(
                self.t.size, 6 * len(self.bodies)))
        columns += [values for _, values in self.outputs]
        forces = [self.forces.table()] if self.forces is not None else []
        table = np.column_stack([*columns, self.flagged, *forces])
        np.savetxt(path, table, delimiter=",", header=",".join(header), comments="",
                   fmt="%.17g")
