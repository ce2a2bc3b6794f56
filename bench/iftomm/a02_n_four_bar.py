"""IFToMM multibody benchmark A02, the N-four-bar mechanism (N = 10): symkin's generated C and
NumPy dynamics steps and Exudyn, CPU time to the same accuracy, side by side in one run.

    python3 bench/iftomm/a02_n_four_bar.py [--target 1e-6] [--repeat 3] [--n 10]
    python3 bench/iftomm/a02_n_four_bar.py --write FILE   # the mechanism file only

The problem, as the benchmark publishes it: N parallelogram cells in a row, N + 1 cranks
hinged to the ground 1 m apart and N couplers joining their tips, every bar 1 m long, 1 kg,
uniform (inertia m L^2/12 about its centre); released with the cranks vertical and the first
crank's tip B0 moving at 1 m/s along +x; gravity 9.81 m/s^2 along -y; 10 s. Whenever the
cranks pass the horizontal the mechanism is singular: there Phi_q loses N ranks (N + 1
freedoms for an instant); the motion meant is the one that stays a parallelogram chain.

Reference: as long as it stays one, every crank turns by the same angle theta and every
coupler translates, so T = ((N + 1)/3 + N) m L^2 theta'^2 / 2, V = ((N + 1)/2 + N) m g L
sin(theta): a pendulum-like equation, integrated by SciPy's DOP853 at rtol = atol = 1e-13.
Accuracy: the largest distance of any crank's tip from the reference's, sampled every
0.01 s (a solver that leaves the parallelogram branch at a singular passage shows it there).
Energy: the largest change of T + V over the samples (J; T + V is about 145 J).

symkin's model (bench/iftomm/a02_n_four_bar.yaml): 2N + 1 bodies, 3N + 1 revolute pairs,
absolute coordinates (x, y, phi) a body. Exudyn's model is its own: 2D rigid bodies with
their node at the centre of mass, revolute joints, the same initial velocities, its default
implicit generalized-alpha integrator (index-3 constraints), timed as SolveDynamic's CPU time.
"""

from __future__ import annotations

import argparse
import math
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from harness import (  # noqa: E402
    Row, Run, SymkinC, SymkinNumPy, at_step, exudyn_settings, print_table, to_accuracy)

import symkin  # noqa: E402

G, L, MASS, T_END, SAMPLE, V_B0 = 9.81, 1.0, 1.0, 10.0, 0.01, 1.0


def mechanism(n: int) -> str:
    """The mechanism file of N cells (module docstring)."""
    lines = [f"# IFToMM multibody benchmark A02, the N-four-bar mechanism, N = {n}: {n + 1}"
             " cranks hinged",
             "# to the ground 1 m apart, N couplers joining their tips; every bar 1 m, 1 kg,"
             " uniform.",
             "# Released with the cranks vertical and the first crank's tip moving at 1 m/s"
             " along +x.",
             "# Written by bench/iftomm/a02_n_four_bar.py --write.",
             "name: a02_n_four_bar",
             "parameters: {L: 1.0, m: 1.0, J: 1/12}  # J = m L^2 / 12",
             "bodies:"]
    lines += [f"  crank{k}: {{q0: [{k}, 0, pi/2], mass: m, inertia: J, com: [L/2, 0],"
              " points: {tip: [L, 0]}}" for k in range(n + 1)]
    lines += [f"  coupler{k}: {{q0: [{k}, L, 0], mass: m, inertia: J, com: [L/2, 0],"
              " points: {left: [0, 0], right: [L, 0]}}" for k in range(n)]
    lines.append("joints:")
    lines += [f"  - {{type: revolute, name: O{k}, i: ground, j: crank{k}, sA: [{k}, 0],"
              " sB: [0, 0]}" for k in range(n + 1)]
    for k in range(n):
        lines.append(f"  - {{type: revolute, name: A{k}, i: crank{k}, j: coupler{k},"
                     " sA: tip, sB: left}")
        lines.append(f"  - {{type: revolute, name: B{k + 1}, i: crank{k + 1}, j: coupler{k},"
                     " sA: tip, sB: right}")
    lines += ["forces:", "  - {type: gravity, g: [0, -9.81]}",
              "initial:", "  velocities: {crank0.phi: -1.0}  # B0 at 1 m/s along +x",
              "time: {t0: 0, t1: 10, dt: 0.01}"]
    return "\n".join(lines) + "\n"


def reference(t: np.ndarray, n: int) -> np.ndarray:
    """The cranks' angle theta(t) of the minimal-coordinate equation (module docstring)."""
    inertia = ((n + 1) / 3 + n) * MASS * L ** 2
    weight = ((n + 1) / 2 + n) * MASS * G * L
    span = (0.0, max(float(t[-1]), T_END))
    solution = solve_ivp(lambda _t, y: [y[1], -weight / inertia * math.cos(y[0])], span,
                         [math.pi / 2, -V_B0 / L], method="DOP853", rtol=1e-13, atol=1e-13,
                         t_eval=t)
    return np.asarray(solution.y[0])


def tip_error(t: np.ndarray, angles: np.ndarray, n: int) -> float:
    """The largest distance of a crank tip (angles: (k, N + 1)) from the reference's."""
    theta = reference(t, n)[:, None]
    return float(np.max(2 * L * np.abs(np.sin((angles - theta) / 2))))


def energy(q: np.ndarray, dq: np.ndarray, mass: object) -> np.ndarray:
    """T + V of every sample of symkin's coordinates (every body's centre at [L/2, 0])."""
    kinetic = np.array([0.5 * v @ mass(x) @ v for x, v in zip(q, dq)])  # type: ignore
    x, y, phi = q[:, 0::3], q[:, 1::3], q[:, 2::3]
    del x
    return kinetic + MASS * G * np.sum(y + L / 2 * np.sin(phi), axis=1)


def exudyn_run(n: int, h: float, repeat: int) -> Run:
    """Exudyn's own model of A02 (module docstring); q: the cranks' angles."""
    import exudyn as exu
    from exudyn.itemInterface import (
        LoadMassProportional,
        MarkerBodyMass,
        MarkerBodyPosition,
        NodeRigidBody2D,
        ObjectGround,
        ObjectJointRevolute2D,
        ObjectRigidBody2D,
        SensorBody,
    )

    best, angles, times, failure = np.inf, np.empty(0), np.empty(0), ""
    for _ in range(repeat):
        container = exu.SystemContainer()
        mbs = container.AddSystem()
        ground = mbs.AddObject(ObjectGround())
        inertia = MASS * L ** 2 / 12

        def bar(centre: list[float], angle: float, velocity: list[float]) -> int:
            node = mbs.AddNode(NodeRigidBody2D(referenceCoordinates=[*centre, angle],
                                               initialVelocities=velocity))
            body = mbs.AddObject(ObjectRigidBody2D(mass=MASS, inertia=inertia,
                                                   nodeNumber=node))
            mbs.AddLoad(LoadMassProportional(markerNumber=mbs.AddMarker(
                MarkerBodyMass(bodyNumber=body)), loadVector=[0, -G, 0]))
            return int(body)

        def hinge(a: int, at_a: list[float], b: int, at_b: list[float]) -> None:
            first = mbs.AddMarker(MarkerBodyPosition(bodyNumber=a, localPosition=[*at_a, 0]))
            second = mbs.AddMarker(MarkerBodyPosition(bodyNumber=b, localPosition=[*at_b, 0]))
            mbs.AddObject(ObjectJointRevolute2D(markerNumbers=[first, second]))

        # a crank's local x runs from its pivot to its tip (reference angle pi/2)
        cranks = [bar([k, L / 2], math.pi / 2, [V_B0 / 2, 0, -V_B0 / L]) for k in range(n + 1)]
        couplers = [bar([k + L / 2, L], 0.0, [V_B0, 0, 0]) for k in range(n)]
        for k, crank in enumerate(cranks):
            hinge(ground, [k, 0], crank, [-L / 2, 0])
        for k, coupler in enumerate(couplers):
            hinge(cranks[k], [L / 2, 0], coupler, [-L / 2, 0])
            hinge(cranks[k + 1], [L / 2, 0], coupler, [L / 2, 0])
        sensors = [mbs.AddSensor(SensorBody(bodyNumber=c, localPosition=[L / 2, 0, 0],
                                            storeInternal=True,
                                            outputVariableType=exu.OutputVariableType.Position))
                   for c in cranks]
        mbs.Assemble()
        settings = exudyn_settings(exu, T_END, h, SAMPLE)
        start = time.process_time()
        try:
            exu.SolveDynamic(mbs, settings)
        except Exception as stop:  # Exudyn raises on a failed Newton step
            failure = str(stop).splitlines()[0][:60]
        best = min(best, time.process_time() - start)
        tips = []
        for k, sensor in enumerate(sensors):
            data = mbs.GetSensorStoredData(sensor)
            data = data[data[:, 0] > SAMPLE / 2]
            times = data[:, 0]
            tips.append(np.arctan2(data[:, 2], data[:, 1] - k))
        angles = np.column_stack(tips)
    if failure:
        return Run(np.inf, np.empty(0), np.empty((0, 0)), np.empty((0, 0)), failure)
    return Run(float(best), times, np.unwrap(angles, axis=0), np.empty((0, 0)))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--target", type=float, default=1e-6)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--n", type=int, default=10)
    parser.add_argument("--write", type=Path, help="write the mechanism file and stop")
    args = parser.parse_args()
    n = args.n
    if args.write:
        args.write.write_text(mechanism(n), encoding="utf-8")
        return
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        (folder / "a02.yaml").write_text(mechanism(n))
        system = symkin.derive(folder / "a02.yaml")
        q0 = np.array([v for k in range(n + 1) for v in (k, 0.0, math.pi / 2)]
                      + [v for k in range(n) for v in (k, L, 0.0)])
        dq0 = np.array([v for _ in range(n + 1) for v in (0.0, 0.0, -V_B0 / L)]
                       + [v for _ in range(n) for v in (V_B0, 0.0, 0.0)])
        cranks = slice(2, 3 * (n + 1), 3)

        def symkin_error(run: Run) -> float:
            return tip_error(run.t, run.q[:, cranks], n)

        numpy_solver = SymkinNumPy(system, folder / "numpy", "a02_n_four_bar", (q0, dq0),
                                   T_END, SAMPLE)
        mass = numpy_solver.module.mass

        def drift(run: Run) -> float:
            return float(np.ptp(energy(run.q, run.dq, mass)))

        c_row = to_accuracy("symkin C (dynamics_step)",
                            SymkinC(system, folder / "c", "a02_n_four_bar", (q0, dq0), T_END,
                                    SAMPLE), symkin_error, args.target, args.repeat, 1e-5,
                            energy=drift)
        rows: list[Row] = [
            c_row,
            at_step("symkin NumPy (dynamics_step)", numpy_solver, symkin_error, c_row.h,
                    energy=drift),
            to_accuracy("Exudyn (generalized-alpha)",
                        lambda h, repeat: exudyn_run(n, h, repeat),
                        lambda run: tip_error(run.t, run.q, n), args.target, args.repeat,
                        1e-5)]
    import exudyn

    print_table(f"IFToMM A02 N-four-bar, N = {n}, 10 s, target max crank-tip error"
                f" {args.target:g} m, energy: max change of T + V [J] (Exudyn"
                f" {exudyn.__version__})", rows)


if __name__ == "__main__":
    main()
