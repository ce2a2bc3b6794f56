"""Instructions of one generated ``<prefix>_dynamics_step`` and of one kinematic
``<prefix>_solve_step`` of the same mechanism, counted by callgrind (valgrind).

    python3 bench/dynamics_instructions.py [--steps 100] [four_bar_dynamics crank_slider_load]

Each argument is an example with masses whose drivers fix its motion (it has both steps).
The generated folder is compiled with a main (gcc -O2) that assembles the file's t0 with the
kinematic step, then takes K kinematic steps of the file's dt and K dynamics steps of h = dt
from there; the count per step is (instructions at K = 1 + --steps minus at K = 1) / --steps,
so set-up, the first assembly and the dynamics step's first evaluation cancel. Instruction
counts do not depend on the load of a shared machine, unlike the times of step_ratio.py.
The dynamics steps of both default examples are guarded by tests/test_performance_budget.py
against bench/budgets.json.
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import symkin  # noqa: E402

MAIN = r"""
#include <stdlib.h>
#include "@P@_dynamics.h"
int main(int argc, char **argv)
{
    const int steps = atoi(argv[1]), dynamics = argv[2][0] == 'd';
    static @P@_workspace work;
    static @P@_dynamics_work dwork;
    @P@_state state;
    @P@_report report;
    @P@_dynamics_state dstate;
    @P@_dynamics_report dreport;
    @P@_options options;
    int i, k;
    @P@_default_options(&options);
    for (i = 0; i < @U@_NQ; ++i) state.q[i] = @P@_q0[i];
    state.started = 0;
    if (@P@_solve_step(&options, @P@_p_nominal, @T0@, &state, &work, &report) != @U@_OK)
        return 1;
    for (i = 0; i < @U@_NQ; ++i) { dstate.q[i] = state.q[i]; dstate.dq[i] = state.dq[i]; }
    dstate.t = @T0@;
    dstate.started = 0;
    for (k = 1; k <= steps; ++k) {
        if (dynamics) {
            if (@P@_dynamics_step(&options, @P@_p_nominal, @DT@, &dstate, &dwork,
                                  &dreport) != @U@_OK) return 2;
        } else if (@P@_solve_step(&options, @P@_p_nominal, @T0@ + k * @DT@, &state, &work,
                                  &report) != @U@_OK) {
            return 3;
        }
    }
    return 0;
}
"""


def _instructions(program: Path, steps: int, kind: str) -> int:
    out = program.parent / f"callgrind.{kind}.{steps}"
    subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}",
                    str(program), str(steps), kind], check=True, capture_output=True)
    found = re.search(r"^summary: (\d+)", out.read_text(), re.MULTILINE)
    assert found is not None, out
    return int(found.group(1))


def program(example: str, scratch: Path) -> Path:
    """The example's generated folder compiled with MAIN (gcc -O2) in ``scratch``."""
    system = symkin.derive(ROOT / "examples" / f"{example}.yaml")
    folder = scratch / example
    symkin.generate(system, "c", folder)
    t0, _, dt = system.time_grid
    source = (MAIN.replace("@P@", example).replace("@U@", example.upper())
              .replace("@T0@", repr(float(t0))).replace("@DT@", repr(float(dt))))
    (folder / "main.c").write_text(source)
    built = folder / "main"
    subprocess.run(["gcc", "-std=c99", "-O2", f"-I{folder}", "-o", str(built),
                    *sorted(str(p) for p in folder.glob("*.c")), "-lm"], check=True)
    return built


def count(built: Path, steps: int, kind: str) -> float:
    """Instructions per step of ``kind`` ("kinematic" or "dynamics") of a built program."""
    return (_instructions(built, 1 + steps, kind) - _instructions(built, 1, kind)) / steps


def per_step(example: str, steps: int, scratch: Path) -> tuple[float, float]:
    """(kinematic, dynamics) instructions per step of ``example``."""
    built = program(example, scratch)
    return count(built, steps, "kinematic"), count(built, steps, "dynamics")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("examples", nargs="*", default=["four_bar_dynamics",
                                                        "crank_slider_load"])
    parser.add_argument("--steps", type=int, default=100)
    args = parser.parse_args()
    print(f"{'mechanism':22} {'kin instr/step':>15} {'dyn instr/step':>15} {'ratio':>6}")
    with tempfile.TemporaryDirectory() as scratch:
        for example in args.examples:
            kinematic, dynamics = per_step(example, args.steps, Path(scratch))
            print(f"{example:22} {kinematic:15.0f} {dynamics:15.0f} "
                  f"{dynamics / kinematic:6.2f}")


if __name__ == "__main__":
    main()
