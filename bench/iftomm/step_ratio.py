"""One ``<prefix>_dynamics_step`` against one kinematic ``<prefix>_solve_step`` of the same
mechanism: the worst-case operation counts their headers state, and the C time per step.

    python3 bench/iftomm/step_ratio.py [--rounds 200] [--repeat 5]

A mechanism has both only when every freedom is driven and it has masses (the examples
four_bar_dynamics and crank_slider_load): the dynamics step then integrates the motion the
drivers prescribe. Both loops run in C (compiled at -O2 with the generated folder, clock()
around --rounds runs of the file's time grid, best of --repeat); the dynamics runs start
from the kinematic solution at t0 and take the grid's steps with h = the file's dt.
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

import symkin  # noqa: E402

DRIVER = r"""
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include "NAME_dynamics.h"

int main(int argc, char **argv)
{
    const int steps = atoi(argv[1]), repeat = atoi(argv[2]), inner = atoi(argv[3]);
    const NAME_real t0 = TZERO, h = STEP;
    static NAME_workspace work;
    static NAME_dynamics_work dwork;
    NAME_state state;
    NAME_report report;
    NAME_dynamics_state dstate;
    NAME_dynamics_report dreport;
    NAME_options options;
    double kinematic = 1e30, dynamic = 1e30;
    int r, k, i, s;
    NAME_default_options(&options);
    for (r = 0; r < repeat; ++r) {
        clock_t start = clock();
        for (s = 0; s < inner; ++s) {
            for (i = 0; i < UPNAME_NQ; ++i) state.q[i] = NAME_q0[i];
            state.started = 0;
            for (k = 0; k < steps; ++k) {
                if (NAME_solve_step(&options, NAME_p_nominal, t0 + k * h, &state, &work,
                                    &report) != UPNAME_OK) return 1;
            }
        }
        if ((double)(clock() - start) / CLOCKS_PER_SEC < kinematic)
            kinematic = (double)(clock() - start) / CLOCKS_PER_SEC;
    }
    state.started = 0;
    for (i = 0; i < UPNAME_NQ; ++i) state.q[i] = NAME_q0[i];
    if (NAME_solve_step(&options, NAME_p_nominal, t0, &state, &work, &report) != UPNAME_OK)
        return 1;
    for (r = 0; r < repeat; ++r) {
        clock_t start = clock();
        for (s = 0; s < inner; ++s) {
        for (i = 0; i < UPNAME_NQ; ++i) {
            dstate.q[i] = state.q[i];
            dstate.dq[i] = state.dq[i];
        }
        dstate.t = t0;
        dstate.started = 0;
        for (k = 1; k < steps; ++k) {
            if (NAME_dynamics_step(&options, NAME_p_nominal, h, &dstate, &dwork,
                                   &dreport) != UPNAME_OK) {
                fprintf(stderr, "dynamics step %d: status %d, t %g, residual %g\n", k,
                        dreport.status, (double)dreport.t, (double)dreport.residual);
                return 2;
            }
        }
        }
        if ((double)(clock() - start) / CLOCKS_PER_SEC < dynamic)
            dynamic = (double)(clock() - start) / CLOCKS_PER_SEC;
    }
    printf("%.9g %.9g\n", kinematic / ((double)inner * steps),
           dynamic / ((double)inner * (steps - 1)));
    return 0;
}
"""


def macro(folder: Path, name: str) -> int:
    text = "".join(p.read_text() for p in folder.glob("*.h"))
    found = re.search(rf"#define {name} (\d+)", text)
    assert found is not None, name
    return int(found.group(1))


def measure(example: str, rounds: int, repeat: int, scratch: Path
            ) -> tuple[int, int, int, float, float]:
    system = symkin.derive(ROOT / "examples" / f"{example}.yaml")
    folder = scratch / example
    symkin.generate(system, "c", folder)
    t0, t1, dt = system.time_grid
    steps = round((t1 - t0) / dt) + 1
    source = (DRIVER.replace("UPNAME", example.upper()).replace("NAME", example)
              .replace("TZERO", repr(float(t0))).replace("STEP", repr(float(dt))))
    (folder / "driver.c").write_text(source)
    exe = folder / "driver"
    subprocess.run(["gcc", "-std=c99", "-O2", f"-I{folder}", "-o", str(exe),
                    *sorted(str(p) for p in folder.glob("*.c")), "-lm"], check=True)
    out = subprocess.run([str(exe), str(steps), str(repeat), str(rounds)], check=True,
                         capture_output=True, text=True).stdout.split()
    upper = example.upper()
    one_correction = (macro(folder, f"{upper}_OPS_DYNAMICS_FIXED")
                      + macro(folder, f"{upper}_OPS_DYNAMICS_ITERATION"))
    return (macro(folder, f"{upper}_OPS_STEP_WORST"),
            macro(folder, f"{upper}_OPS_DYNAMICS_STEP_WORST"), one_correction,
            float(out[0]), float(out[1]))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=200)
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    print("ops: worst case at the default caps (kinematic: Newton's 25 iterations; dynamics:"
          " 25 position corrections), and the dynamics step with one correction")
    print(f"{'mechanism':22} {'kin ops':>8} {'dyn ops':>8} {'ratio':>6} {'dyn 1 corr':>10} "
          f"{'kin us/step':>12} {'dyn us/step':>12} {'ratio':>6}")
    with tempfile.TemporaryDirectory() as scratch:
        for example in ("four_bar_dynamics", "crank_slider_load"):
            kin_ops, dyn_ops, one, kin, dyn = measure(example, args.rounds, args.repeat,
                                                      Path(scratch))
            print(f"{example:22} {kin_ops:8d} {dyn_ops:8d} {dyn_ops / kin_ops:6.2f} {one:10d} "
                  f"{kin * 1e6:12.3f} {dyn * 1e6:12.3f} {dyn / kin:6.2f}")


if __name__ == "__main__":
    main()
