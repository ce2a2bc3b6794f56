"""What the IFToMM benchmark scripts share: symkin's generated C and NumPy dynamics steps run
from a consistent initial state at a fixed step, the step halved until a problem's own error
measure is within the target, and the table's row.

The C step is timed in C: a loop of ``<prefix>_dynamics_step`` compiled at -O2 with the
generated folder, clock() around the loop, best of ``repeat`` runs; the NumPy step is the
generated module's ``dynamics_step``, one Python call a step, timed by process_time.
"""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType

for _variable in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_variable, "1")

import numpy as np  # noqa: E402

import symkin  # noqa: E402

Array = np.ndarray

DRIVER = r"""
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include "@P@_dynamics.h"

/* argv: h, steps, every, repeat, the file of q0 then dq0 (NQ numbers each).
   stdout: per sample t, q, dq; stderr: the best CPU time, or the failing status. */
int main(int argc, char **argv)
{
    const double h = atof(argv[1]);
    const int steps = atoi(argv[2]), every = atoi(argv[3]), repeat = atoi(argv[4]);
    const int samples = steps / every, width = 1 + 2 * @U@_NQ;
    double *rows = malloc(sizeof(double) * width * (samples + 1)), best = 1e30;
    double start_q[@U@_NQ], start_dq[@U@_NQ];
    static @P@_dynamics_work work;
    @P@_dynamics_state state;
    @P@_dynamics_report report;
    @P@_options options;
    FILE *start = fopen(argv[5], "r");
    int r, k, i, status;
    if (argc != 6 || !start) return 3;
    for (i = 0; i < @U@_NQ; ++i) if (fscanf(start, "%lf", &start_q[i]) != 1) return 3;
    for (i = 0; i < @U@_NQ; ++i) if (fscanf(start, "%lf", &start_dq[i]) != 1) return 3;
    fclose(start);
    @P@_default_options(&options);
    for (r = 0; r < repeat; ++r) {
        clock_t begin = clock();
        for (i = 0; i < @U@_NQ; ++i) {
            state.q[i] = start_q[i];
            state.dq[i] = start_dq[i];
        }
        state.t = 0;
        state.started = 0;
        for (k = 1; k <= steps; ++k) {
            status = @P@_dynamics_step(&options, @P@_p_nominal, h, &state, &work, &report);
            if (status != @U@_OK) {
                fprintf(stderr, "status %d at t = %.9g\n", status, report.t);
                return 1;
            }
            if (k % every == 0) {
                double *row = rows + width * (k / every);
                row[0] = state.t;
                for (i = 0; i < @U@_NQ; ++i) {
                    row[1 + i] = state.q[i];
                    row[1 + @U@_NQ + i] = state.dq[i];
                }
            }
        }
        if ((double)(clock() - begin) / CLOCKS_PER_SEC < best)
            best = (double)(clock() - begin) / CLOCKS_PER_SEC;
    }
    for (k = 1; k <= samples; ++k) {
        for (i = 0; i < width; ++i) printf("%.17g ", rows[width * k + i]);
        printf("\n");
    }
    fprintf(stderr, "%.9g\n", best);
    free(rows);
    return 0;
}
"""


@dataclass(frozen=True)
class Run:
    """A solver's samples: times (k,), positions and velocities (k, NQ); CPU seconds; or
    ``failure`` (why it stopped) with no samples."""

    seconds: float
    t: Array
    q: Array
    dq: Array
    failure: str = ""


Solver = Callable[[float, int], Run]


def load_module(folder: Path, name: str) -> ModuleType:
    """The generated NumPy module ``name`` in ``folder``."""
    spec = importlib.util.spec_from_file_location(name, folder / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


class SymkinC:
    """The generated C folder with the timing driver, built once; the motion from (q0, dq0)
    over [0, t_end], sampled every ``sample`` seconds."""

    def __init__(self, system: object, folder: Path, name: str, start: tuple[Array, Array],
                 t_end: float, sample: float) -> None:
        symkin.generate(system, "c", folder, linalg="dense")
        (folder / "driver.c").write_text(DRIVER.replace("@P@", name).replace("@U@",
                                                                            name.upper()))
        np.savetxt(folder / "start.txt", np.concatenate(start), fmt="%.17g")
        sources = sorted(str(p) for p in folder.glob("*.c"))
        self.exe, self.folder = folder / "driver", folder
        self.t_end, self.sample = t_end, sample
        subprocess.run(["gcc", "-std=c99", "-O2", f"-I{folder}", "-o", str(self.exe),
                        *sources, "-lm"], check=True)

    def __call__(self, h: float, repeat: int) -> Run:
        steps, every = round(self.t_end / h), round(self.sample / h)
        done = subprocess.run([str(self.exe), repr(h), str(steps), str(every), str(repeat),
                               str(self.folder / "start.txt")], capture_output=True, text=True)
        if done.returncode:
            return Run(np.inf, np.empty(0), np.empty((0, 0)), np.empty((0, 0)),
                       done.stderr.strip() or f"exit {done.returncode}")
        rows = np.loadtxt(done.stdout.splitlines(), ndmin=2)
        n = (rows.shape[1] - 1) // 2
        return Run(float(done.stderr), rows[:, 0], rows[:, 1:1 + n], rows[:, 1 + n:])


class SymkinNumPy:
    """The generated NumPy module's dynamics_step, one Python call a step."""

    def __init__(self, system: object, folder: Path, name: str, start: tuple[Array, Array],
                 t_end: float, sample: float) -> None:
        symkin.generate(system, "numpy", folder)
        self.module = load_module(folder, name)
        self.start, self.t_end, self.sample = start, t_end, sample

    def __call__(self, h: float, repeat: int) -> Run:
        steps, every = round(self.t_end / h), round(self.sample / h)
        p = self.module.P_VALUES
        begin = time.process_time()
        state = {"t": 0.0, "q": self.start[0].copy(), "dq": self.start[1].copy(), "ddq": None}
        t, q, dq = [], [], []
        for k in range(1, steps + 1):
            status, found, _, _ = self.module.dynamics_step(p, h, state)
            if status != 0 or found is None:
                return Run(np.inf, np.empty(0), np.empty((0, 0)), np.empty((0, 0)),
                           f"status {status} at t = {state['t']:.6g}")
            state = found
            if k % every == 0:
                t.append(state["t"])
                q.append(state["q"])
                dq.append(state["dq"])
        return Run(time.process_time() - begin, np.array(t), np.array(q), np.array(dq))


@dataclass(frozen=True)
class Row:
    """One line of the table."""

    solver: str
    h: float
    seconds: float
    error: float
    energy: float = np.nan  # the largest drift of the total energy, where it is conserved
    note: str = ""


def to_accuracy(name: str, solve: Solver, error: Callable[[Run], float], target: float,
                repeat: int, smallest: float, first: float = 1e-2,
                energy: Callable[[Run], float] | None = None) -> Row:
    """Halve the step from ``first`` until ``error`` is at most ``target`` (or the step would
    fall below ``smallest``: the last one tried is reported). The search runs each step once;
    the step found is run ``repeat`` times and timed by the best."""
    h = first
    while True:
        run = solve(h, 1)
        err = error(run) if not run.failure else np.inf
        print(f"  {name}: h = {h:.3e}, CPU {run.seconds:.4f} s, error {err:.2e}"
              f" {run.failure}", file=sys.stderr, flush=True)
        if err <= target or h / 2 < smallest:
            break
        h /= 2
    seconds = min(run.seconds, solve(h, repeat).seconds) if repeat > 1 else run.seconds
    drift = energy(run) if energy is not None and not run.failure else np.nan
    return Row(name, h, seconds, err, drift, run.failure)


def at_step(name: str, solve: Solver, error: Callable[[Run], float], h: float,
            energy: Callable[[Run], float] | None = None) -> Row:
    """One run at the step ``h`` (the NumPy step at the C step's: the same algorithm, equal to
    the C step's result to rounding, so the search would end at the same step)."""
    run = solve(h, 1)
    err = error(run) if not run.failure else np.inf
    drift = energy(run) if energy is not None and not run.failure else np.nan
    return Row(name, h, run.seconds, err, drift, run.failure)


def print_table(title: str, rows: list[Row]) -> None:
    print(title)
    print(f"{'solver':34} {'step h [s]':>11} {'CPU [s]':>9} {'error':>9} {'energy':>9}  note")
    for row in rows:
        print(f"{row.solver:34} {row.h:11.3e} {row.seconds:9.4f} {row.error:9.2e}"
              f" {row.energy:9.2e}  {row.note}")


def rotation(e: Array) -> Array:
    """The rotation matrix of Euler parameters (e0, e1, e2, e3)."""
    e0, v = e[0], e[1:]
    skew = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    return (e0 ** 2 - v @ v) * np.eye(3) + 2 * np.outer(v, v) + 2 * e0 * skew


def exudyn_settings(exu: ModuleType, end: float, h: float, sample: float) -> object:
    """Exudyn's settings for a fixed step h to ``end``, the sensors stored every ``sample``,
    no solution file and no console output: the same in every script (each adds its own)."""
    settings = exu.SimulationSettings()
    settings.timeIntegration.numberOfSteps = round(end / h)
    settings.timeIntegration.endTime = end
    settings.timeIntegration.verboseMode = 0
    settings.solution.file.write = False
    settings.solution.sensors.writePeriod = sample
    return settings
