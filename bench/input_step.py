"""Time of one generated ``<prefix>_solve_inputs`` call in C, as a controller would make it.

    python3 bench/input_step.py [--mechanism examples/crank_slider_input.yaml] [--points 100000]

The mechanism's C folder is generated into a temporary folder with a timing ``main``: the
single input is swept as u = u0 + sin(2 pi k / N) (with its rate and acceleration in k for
``--rates``), each call starting from the previous solution, and the loop is timed with
CLOCK_MONOTONIC (best of 5). Printed: microseconds per call with positions only (du = ddu =
NULL) and with rates and accelerations, the mean Newton iterations, and the largest
|phi - u| of the driven angle (for the example, whose driver is phi_crank = u).
Mechanisms with one input driver only.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import symkin  # noqa: E402

MAIN = r"""
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdio.h>
#include <time.h>
#include "PREFIX_solver.h"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static double run(int n, int rates, long *iterations, double *error, int coordinate)
{
    static PREFIX_workspace work;
    PREFIX_options options;
    PREFIX_state state;
    PREFIX_report report;
    const double w = 2 * 3.14159265358979323846 / n;
    double started;
    int i, k;
    PREFIX_default_options(&options);
    for (i = 0; i < PREFIX_NQ; ++i) state.q[i] = PREFIX_q0[i];
    state.t = 0;
    state.started = 0;
    *iterations = 0;
    *error = 0;
    started = now();
    for (k = 0; k < n; ++k) {
        const PREFIX_real u = U0 + sin(w * k), du = w * cos(w * k), ddu = -w * w * sin(w * k);
        if (PREFIX_solve_inputs(&options, PARAMS, &u, rates ? &du : NULL, rates ? &ddu : NULL,
                                &state, &work, &report) != PREFIX_OK) {
            fprintf(stderr, "failed at %d: status %d\n", k, report.status);
            return -1;
        }
        *iterations += report.iterations;
        *error = fmax(*error, fabs(state.q[coordinate] - u));
    }
    return now() - started;
}

int main(int argc, char **argv)
{
    const int n = argc > 1 ? atoi(argv[1]) : 100000;
    int rates, r;
    for (rates = 0; rates < 2; ++rates) {
        double best = 1e300, error = 0;
        long iterations = 0;
        for (r = 0; r < 5; ++r) {
            double seconds = run(n, rates, &iterations, &error, COORDINATE);
            if (seconds < 0) return 1;
            best = seconds < best ? seconds : best;
        }
        printf("%s: %.3f us per solve_inputs call, %.2f Newton iterations a call, "
               "max |q - u| of the driven coordinate %.2e\n",
               rates ? "positions, rates, accelerations" : "positions only",
               1e6 * best / n, (double)iterations / n, error);
    }
    return 0;
}
"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--mechanism", default=str(ROOT / "examples/crank_slider_input.yaml"))
    parser.add_argument("--coordinate", default="crank.phi",
                        help="the coordinate the input drives (for the accuracy column)")
    parser.add_argument("--points", type=int, default=100000)
    args = parser.parse_args()
    system = symkin.derive(args.mechanism)
    if len(system.inputs) != 1:
        sys.exit("input_step.py times mechanisms with one input driver")
    with tempfile.TemporaryDirectory() as folder:
        out = Path(folder)
        symkin.generate(system, backend="c", out_dir=out)
        text = (MAIN.replace("PREFIX_NQ", f"{system.name.upper()}_NQ")
                .replace("PREFIX_OK", f"{system.name.upper()}_OK")
                .replace("PREFIX", system.name).replace("U0", repr(system.input_values[0]))
                .replace("PARAMS", f"{system.name}_p_nominal" if system.p else "NULL")
                .replace("COORDINATE", str(system.coordinates.index(args.coordinate))))
        (out / "main.c").write_text(text.replace("#include <time.h>",
                                                 "#include <stdlib.h>\n#include <time.h>"))
        exe = out / "main"
        subprocess.run(["gcc", "-std=c99", "-O2", "-o", str(exe), *map(str, out.glob("*.c")),
                        "-lm"], check=True)
        subprocess.run([str(exe), str(args.points)], check=True)


if __name__ == "__main__":
    main()
