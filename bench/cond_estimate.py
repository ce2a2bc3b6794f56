"""What the per-point condition estimate (and the flag decision) costs the generated C solver.

    python3 bench/cond_estimate.py [--steps 200000] [--repeat 7]

The textbook crank-slider (examples/crank_slider.yaml) is generated as C twice into a
temporary folder: as symkin writes it, and with the estimate replaced by a constant (this
script edits the generated <prefix>_estimate to set inv_norm = cond = 1, so the tightening
and flag tests still run but cost nothing more). A small main() runs <prefix>_solve_grid over
t = k dt, k = 0..steps, dt = 1.5/steps from the assembled configuration, best of --repeat
runs, gcc -O2; it prints the time per step of both builds and their difference.
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
#include <math.h>
#include <stdio.h>
#include <time.h>
#include "crank_slider_solver.h"

int main(int argc, char **argv)
{
    static double t[STEPS + 1];
    static crank_slider_state state;
    static crank_slider_workspace work;
    crank_slider_options options;
    crank_slider_report report;
    const double p[3] = {1.0, 5.0, 4.0};
    const double q0[9] = {0, 0, 1.5707963267948966, 0, 1, 0.6435011087932844, 4, 4, 0};
    double best = 1e30;
    int k, r, solved = 0;
    (void)argc; (void)argv;
    crank_slider_default_options(&options);
    for (k = 0; k <= STEPS; ++k) t[k] = 1.5 * k / STEPS;
    for (r = 0; r < REPEAT; ++r) {
        clock_t began;
        double seconds;
        for (k = 0; k < 9; ++k) state.q[k] = q0[k];
        state.started = 0;
        began = clock();
        solved = crank_slider_solve_grid(&options, p, STEPS + 1, t, &state, NULL, NULL, NULL,
                                         &work, &report);
        seconds = (double)(clock() - began) / CLOCKS_PER_SEC;
        best = seconds < best ? seconds : best;
    }
    printf("%d %.6e\n", solved, best / (STEPS + 1));
    return 0;
}
"""

STUB = re.compile(r"(static void crank_slider_estimate\([^)]*\)\n\{\n)(.*?)(\n\})", re.DOTALL)


def build(folder: Path, steps: int, repeat: int, stub: bool) -> Path:
    solver = folder / "crank_slider_solver.c"
    text = solver.read_text()
    if stub:
        text, count = STUB.subn(r"\1    (void)work;\n    report->inv_norm = report->cond = 1;\3",
                                text)
        assert count == 1, "the generated estimate was not found"
    (folder / "solver_variant.c").write_text(text)
    (folder / "main.c").write_text(MAIN)
    sources = [folder / "main.c", folder / "solver_variant.c",
               *(p for p in sorted(folder.glob("*.c"))
                 if p.name not in ("main.c", "solver_variant.c", "crank_slider_solver.c"))]
    program = folder / ("stubbed" if stub else "estimating")
    subprocess.run(["gcc", "-std=c99", "-O2", f"-DSTEPS={steps}", f"-DREPEAT={repeat}",
                    "-I", str(folder), *map(str, sources), "-lm", "-o", str(program)],
                   check=True)
    return program


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=200000)
    parser.add_argument("--repeat", type=int, default=7)
    args = parser.parse_args()
    system = symkin.derive(ROOT / "examples" / "crank_slider.yaml")
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        symkin.generate(system, backend="c", out_dir=folder)
        times = {}
        for stub in (False, True):
            program = build(folder, args.steps, args.repeat, stub)
            solved, per_step = subprocess.run([str(program)], check=True, capture_output=True,
                                              text=True).stdout.split()
            assert int(solved) == args.steps + 1
            times[stub] = float(per_step)
    with_estimate, without = times[False], times[True]
    print(f"crank-slider, {args.steps + 1} steps, best of {args.repeat}, gcc -O2")
    print(f"  with the condition estimate:    {with_estimate * 1e9:8.1f} ns/step")
    print(f"  estimate replaced by constant:  {without * 1e9:8.1f} ns/step")
    print(f"  cost of the estimate:           {(with_estimate - without) * 1e9:8.1f} ns/step "
          f"({(with_estimate / without - 1) * 100:.0f} %)")


if __name__ == "__main__":
    main()
