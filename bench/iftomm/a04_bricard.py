"""IFToMM multibody benchmark A04, Bricard's mechanism: symkin's generated C and NumPy
dynamics steps and Exudyn, CPU time to the same accuracy, side by side in one run.

    python3 bench/iftomm/a04_bricard.py [--target 1e-6] [--repeat 3]

The problem (bench/iftomm/a04_bricard.yaml): five rods of 1 m and 1 kg (square section 0.1 m)
and the ground close a loop of six revolute pairs along the edges of a unit cube; as many
equations as coordinates, one of them dependent, one freedom. Released from rest under
gravity (9.81 m/s^2 along -y); 10 s.

Reference: no closed form. symkin's own integrator (symkin.solve, Dormand-Prince with
projection) at rtol = 1e-12, atol = 1e-13; it is checked against Exudyn's run at its finest
step (an independent model and method: the column "vs Exudyn" of the notes). Accuracy: the
largest distance of the corner P3 = (1, -1, 1) (rod3's end) from the reference's over the 10
s, sampled every 0.01 s. Energy: T + V is conserved; the column gives its largest change (J;
V ranges over some 34 J).

symkin's model: 5 bodies, Euler parameters (35 coordinates, 34 rows after the dependent one
is removed). Exudyn's model is its own: five rigid bodies (Euler parameters) made by
CreateRigidBody with the cuboid's inertia, six revolute joints made by CreateRevoluteJoint at
the cube's corners, its Eigen dense solver told to pass over the redundant constraint's
singular Jacobian (ignoreSingularJacobian; its own dense LU stops there), generalized-alpha
at its defaults.
"""

from __future__ import annotations

import argparse
import math
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from harness import (  # noqa: E402
    Row, Run, SymkinC, SymkinNumPy, at_step, exudyn_settings, print_table, rotation,
    to_accuracy)

import symkin  # noqa: E402

FILE = Path(__file__).with_name("a04_bricard.yaml")
NAME = "a04_bricard"
G, T_END, SAMPLE, SIDE = 9.81, 10.0, 0.01, 0.1
CORNERS = np.array([[0, 0, 0], [1, 0, 0], [1, -1, 0], [1, -1, 1], [0, -1, 1], [0, 0, 1]],
                   dtype=float)
AXES = np.array([[0, 1, 0], [0, 0, 1], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 0, 0]],
                dtype=float)


def body_point(q: np.ndarray, body: int, drawn: np.ndarray) -> np.ndarray:
    """Where the point drawn at ``drawn`` on rod ``body`` (1 ... 5) is, each sample (k, 3):
    a drawn body's frame starts parallel to the global axes at its first point."""
    pose = q[:, 7 * (body - 1):7 * body]
    local = drawn - CORNERS[body - 1]
    return np.array([x[:3] + rotation(x[3:]) @ local for x in pose])


def p3(q: np.ndarray) -> np.ndarray:
    return body_point(q, 3, CORNERS[3])


def energy(q: np.ndarray, dq: np.ndarray, mass: object) -> np.ndarray:
    """T + V of every sample (each rod's centre half way along it)."""
    kinetic = np.array([0.5 * v @ mass(x) @ v for x, v in zip(q, dq)])  # type: ignore
    heights = sum(body_point(q, k, (CORNERS[k - 1] + CORNERS[k % 6]) / 2)[:, 1]
                  for k in range(1, 6))
    return kinetic + G * heights


def reference(system: object) -> tuple[np.ndarray, np.ndarray]:
    """Times and P3 of symkin's own integrator at rtol 1e-12 (module docstring)."""
    text = FILE.read_text(encoding="utf-8").replace(
        "time:", "integrator: {rtol: 1e-12, atol: 1e-13}\ntime:")
    with tempfile.TemporaryDirectory() as scratch:
        tight = Path(scratch) / "a04_tight.yaml"
        tight.write_text(text, encoding="utf-8")
        trajectory = symkin.solve(symkin.compile(symkin.derive(tight), backend="numpy"))
    return trajectory.t, p3(trajectory.q)


def exudyn_run(h: float, repeat: int) -> Run:
    """Exudyn's own model of A04 (module docstring); q: P3 a sample."""
    import exudyn as exu
    from exudyn.itemInterface import SensorBody
    from exudyn.utilities import InertiaCuboid

    best, points, times = math.inf, np.empty((0, 3)), np.empty(0)
    for _ in range(repeat):
        container = exu.SystemContainer()
        mbs = container.AddSystem()
        ground = mbs.CreateGround()
        rods = []
        for k in range(5):
            along = CORNERS[k + 1] - CORNERS[k]
            sides = np.where(np.abs(along) > 0, 1.0, SIDE)
            rods.append(mbs.CreateRigidBody(
                referencePosition=list((CORNERS[k] + CORNERS[k + 1]) / 2),
                inertia=InertiaCuboid(density=1.0 / SIDE ** 2, sideLengths=list(sides)),
                gravity=[0, -G, 0]))
        chain = [ground, *rods, ground]
        for k in range(6):
            mbs.CreateRevoluteJoint(bodyNumbers=[chain[k], chain[k + 1]],
                                    position=list(CORNERS[k]), axis=list(AXES[k]),
                                    useGlobalFrame=True)
        sensor = mbs.AddSensor(SensorBody(bodyNumber=rods[2], localPosition=[0, 0, 0.5],
                                          storeInternal=True,
                                          outputVariableType=exu.OutputVariableType.Position))
        mbs.Assemble()
        settings = exudyn_settings(exu, T_END, h, SAMPLE)
        settings.linearSolver.solverType = exu.LinearSolverType.EigenDense
        settings.linearSolverSettings.ignoreSingularJacobian = True
        start = time.process_time()
        try:
            exu.SolveDynamic(mbs, settings)
        except Exception as stop:  # Exudyn raises on a failed Newton step
            return Run(math.inf, np.empty(0), np.empty((0, 3)), np.empty((0, 0)),
                       str(stop).splitlines()[0][:60])
        best = min(best, time.process_time() - start)
        data = mbs.GetSensorStoredData(sensor)
        data = data[data[:, 0] > SAMPLE / 2]
        times, points = data[:, 0], data[:, 1:4]
    return Run(float(best), times, points, np.empty((0, 0)))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--target", type=float, default=1e-6)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    system = symkin.derive(FILE)
    ref_t, ref_p3 = reference(system)

    def error(t: np.ndarray, points: np.ndarray) -> float:
        k = np.rint(t / SAMPLE).astype(int)
        if points.shape[0] == 0 or not np.allclose(ref_t[k], t, atol=1e-9):
            return math.inf
        return float(np.max(np.linalg.norm(points - ref_p3[k], axis=1)))

    q0, dq0 = np.array(system.q0, dtype=float), np.zeros(len(system.q0))
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        numpy_solver = SymkinNumPy(system, folder / "numpy", NAME, (q0, dq0), T_END, SAMPLE)
        mass = numpy_solver.module.mass

        def symkin_error(run: Run) -> float:
            return error(run.t, p3(run.q))

        def drift(run: Run) -> float:
            return float(np.ptp(energy(run.q, run.dq, mass)))

        c_row = to_accuracy("symkin C (dynamics_step)",
                            SymkinC(system, folder / "c", NAME, (q0, dq0), T_END, SAMPLE),
                            symkin_error, args.target, args.repeat, 1e-5, energy=drift)
        rows: list[Row] = [
            c_row,
            at_step("symkin NumPy (dynamics_step)", numpy_solver, symkin_error, c_row.h,
                    energy=drift),
            to_accuracy("Exudyn (generalized-alpha)", exudyn_run,
                        lambda run: error(run.t, run.q), args.target, args.repeat, 1e-5)]
    import exudyn

    print_table(f"IFToMM A04 Bricard, 10 s, target max error of P3 {args.target:g} m (against"
                f" symkin.solve at rtol 1e-12), energy: max change of T + V [J] (Exudyn"
                f" {exudyn.__version__})", rows)


if __name__ == "__main__":
    main()
