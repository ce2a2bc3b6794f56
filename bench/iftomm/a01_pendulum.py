"""IFToMM multibody benchmark A01, the simple pendulum: symkin's generated C and NumPy
dynamics steps and Exudyn, CPU time to the same accuracy, side by side in one run.

    python3 bench/iftomm/a01_pendulum.py [--target 1e-6] [--repeat 5]

The problem, as the benchmark publishes it: a point mass m = 1 kg on a massless rod of
length L = 1 m hinged at the origin, released at rest with the rod horizontal, gravity
g = 9.81 m/s^2 along -y, 10 s of motion. Reference: the minimal-coordinate equation
theta'' = -(g / L) cos(theta), integrated by SciPy's DOP853 at rtol = atol = 1e-13.
Accuracy: the largest distance of the mass from the reference's, sampled every 0.01 s.
Each solver's step is halved from 1e-2 s until that distance is at most --target; the table
gives the CPU time (best of --repeat runs) and the error of the first step that reaches it.

symkin's model is a body whose centre of mass is at the rod's end (mass 1, inertia 0) and a
revolute pair at the origin, solved in absolute coordinates (x, y, phi) with two constraint
rows; its C step is timed in C (a loop of <prefix>_dynamics_step compiled at -O2 with the
generated folder, clock() around the loop). Exudyn's model is its own: a 2D mass point and a
distance constraint, solved by its default implicit generalized-alpha integrator (index-3
constraints, its default settings: with spectral radius 1 it stops at once), timed as
SolveDynamic's CPU time.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

for _variable in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_variable, "1")

import numpy as np  # noqa: E402
from scipy.integrate import solve_ivp  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from harness import exudyn_settings  # noqa: E402  (beside this script)

import symkin  # noqa: E402

G, L, T_END, SAMPLE = 9.81, 1.0, 10.0, 0.01
MECHANISM = """\
name: a01_pendulum
parameters: {L: 1.0, m: 1.0}
bodies:
  bob: {q0: [0, 0, 0], mass: m, inertia: 0, com: [L, 0]}
joints:
  - {type: revolute, name: O, i: ground, j: bob, sA: [0, 0], sB: [0, 0]}
forces:
  - {type: gravity, g: [0, -9.81]}
time: {t0: 0, t1: 10, dt: 0.01}
"""

DRIVER = r"""
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include "a01_pendulum_dynamics.h"

int main(int argc, char **argv)
{
    const double h = atof(argv[1]);
    const int steps = atoi(argv[2]), every = atoi(argv[3]), repeat = atoi(argv[4]);
    const int samples = steps / every;
    double *rows = malloc(sizeof(double) * 3 * (samples + 1)), best = 1e30;
    static a01_pendulum_dynamics_work work;
    a01_pendulum_dynamics_state state;
    a01_pendulum_dynamics_report report;
    a01_pendulum_options options;
    int r, k, i;
    a01_pendulum_default_options(&options);
    for (r = 0; r < repeat; ++r) {
        clock_t start = clock();
        for (i = 0; i < A01_PENDULUM_NQ; ++i) state.q[i] = state.dq[i] = 0;
        state.t = 0;
        state.started = 0;
        for (k = 1; k <= steps; ++k) {
            if (a01_pendulum_dynamics_step(&options, a01_pendulum_p_nominal, h, &state,
                                           &work, &report) != A01_PENDULUM_OK) return 1;
            if (k % every == 0) {
                rows[3 * (k / every)] = state.t;
                rows[3 * (k / every) + 1] = state.q[2];
            }
        }
        if ((double)(clock() - start) / CLOCKS_PER_SEC < best)
            best = (double)(clock() - start) / CLOCKS_PER_SEC;
    }
    for (k = 1; k <= samples; ++k) printf("%.17g %.17g\n", rows[3 * k], rows[3 * k + 1]);
    fprintf(stderr, "%.9g\n", best);
    free(rows);
    return 0;
}
"""


def reference(t: np.ndarray) -> np.ndarray:
    """The mass's position (len(t), 2) from the minimal-coordinate equation."""
    span = (0.0, max(float(t[-1]), T_END))  # a halved step's last t may round past T_END
    solution = solve_ivp(lambda _t, y: [y[1], -G / L * np.cos(y[0])], span, [0.0, 0.0],
                         method="DOP853", rtol=1e-13, atol=1e-13, t_eval=t)
    return L * np.column_stack([np.cos(solution.y[0]), np.sin(solution.y[0])])


def error(t: np.ndarray, position: np.ndarray) -> float:
    return float(np.max(np.linalg.norm(position - reference(t), axis=1)))


class SymkinC:
    """The generated C folder with the timing driver, built once."""

    def __init__(self, system: object, folder: Path) -> None:
        symkin.generate(system, "c", folder, linalg="dense")
        (folder / "driver.c").write_text(DRIVER)
        sources = sorted(str(p) for p in folder.glob("*.c"))
        self.exe = folder / "driver"
        subprocess.run(["gcc", "-std=c99", "-O2", f"-I{folder}", "-o", str(self.exe),
                        *sources, "-lm"], check=True)

    def __call__(self, h: float, repeat: int) -> tuple[float, float]:
        steps, every = round(T_END / h), round(SAMPLE / h)
        done = subprocess.run([str(self.exe), repr(h), str(steps), str(every), str(repeat)],
                              check=True, capture_output=True, text=True)
        rows = np.array([[float(v) for v in line.split()] for line in done.stdout.splitlines()])
        position = L * np.column_stack([np.cos(rows[:, 1]), np.sin(rows[:, 1])])
        return float(done.stderr), error(rows[:, 0], position)


class SymkinNumPy:
    """The generated NumPy module's dynamics_step, one Python call a step."""

    def __init__(self, system: object, folder: Path) -> None:
        import importlib.util

        symkin.generate(system, "numpy", folder)
        spec = importlib.util.spec_from_file_location("a01_pendulum",
                                                      folder / "a01_pendulum.py")
        assert spec is not None and spec.loader is not None
        self.module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(self.module)

    def __call__(self, h: float, repeat: int) -> tuple[float, float]:
        steps, every = round(T_END / h), round(SAMPLE / h)
        p = self.module.P_VALUES
        start = time.process_time()
        state = {"t": 0.0, "q": np.zeros(3), "dq": np.zeros(3), "ddq": None}
        t, phi = [], []
        for k in range(1, steps + 1):
            status, state, _, _ = self.module.dynamics_step(p, h, state)
            assert status == 0
            if k % every == 0:
                t.append(state["t"])
                phi.append(state["q"][2])
        seconds = time.process_time() - start
        position = L * np.column_stack([np.cos(phi), np.sin(phi)])
        return seconds, error(np.array(t), position)


def exudyn_run(h: float, repeat: int) -> tuple[float, float]:
    """Exudyn's own model of A01 (see the module docstring)."""
    import exudyn as exu
    from exudyn.itemInterface import (
        LoadCoordinate,
        MarkerBodyPosition,
        MarkerNodeCoordinate,
        MarkerNodePosition,
        MassPoint2D,
        NodePoint2D,
        ObjectConnectorDistance,
        ObjectGround,
        SensorNode,
    )

    best, result = np.inf, 0.0
    for _ in range(repeat):
        container = exu.SystemContainer()
        mbs = container.AddSystem()
        ground = mbs.AddObject(ObjectGround())
        node = mbs.AddNode(NodePoint2D(referenceCoordinates=[L, 0], initialCoordinates=[0, 0]))
        mbs.AddObject(MassPoint2D(mass=1.0, nodeNumber=node))
        at_ground = mbs.AddMarker(MarkerBodyPosition(bodyNumber=ground,
                                                       localPosition=[0, 0, 0]))
        at_mass = mbs.AddMarker(MarkerNodePosition(nodeNumber=node))
        mbs.AddObject(ObjectConnectorDistance(markerNumbers=[at_ground, at_mass], distance=L))
        y = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=1))
        mbs.AddLoad(LoadCoordinate(markerNumber=y, load=-G))
        sensor = mbs.AddSensor(SensorNode(nodeNumber=node, storeInternal=True,
                                          outputVariableType=exu.OutputVariableType.Position))
        mbs.Assemble()
        settings = exudyn_settings(exu, T_END, h, SAMPLE)
        start = time.process_time()
        exu.SolveDynamic(mbs, settings)
        best = min(best, time.process_time() - start)
        data = mbs.GetSensorStoredData(sensor)
        rows = data[data[:, 0] > SAMPLE / 2]
        result = error(rows[:, 0], rows[:, 1:3])
    return float(best), result


def to_accuracy(name: str, solve: Callable[[float, int], tuple[float, float]], target: float,
                repeat: int, smallest: float) -> tuple[str, float, float, float]:
    """Halve the step from 1e-2 until the error is at most ``target``."""
    h = 1e-2
    while True:
        seconds, err = solve(h, repeat)
        if err <= target or h / 2 < smallest:
            return name, h, seconds, err
        h /= 2


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--target", type=float, default=1e-6)
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        (folder / "a01.yaml").write_text(MECHANISM)
        system = symkin.derive(folder / "a01.yaml")
        rows = [to_accuracy("symkin C (dynamics_step)", SymkinC(system, folder / "c"),
                            args.target, args.repeat, 1e-5),
                to_accuracy("symkin NumPy (dynamics_step)",
                            SymkinNumPy(system, folder / "numpy"), args.target, 1, 1e-4),
                to_accuracy("Exudyn (generalized-alpha)", exudyn_run, args.target,
                            args.repeat, 1e-6)]
    import exudyn

    print(f"IFToMM A01 simple pendulum, 10 s, target max position error {args.target:g} m"
          f" (Exudyn {exudyn.__version__})")
    print(f"{'solver':32} {'step h [s]':>12} {'CPU [s]':>10} {'error [m]':>11}")
    for name, h, seconds, err in rows:
        print(f"{name:32} {h:12.3e} {seconds:10.4f} {err:11.2e}")


if __name__ == "__main__":
    main()
