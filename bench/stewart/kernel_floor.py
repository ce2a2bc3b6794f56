"""What one forward-kinematics solve cannot go below: the generated kernels of a committed C
folder timed one by one, and the least any solve policy built on them can cost.

    python3 bench/stewart/kernel_floor.py [--mechanism NAME ...] [--calls 100000]
                                          [--instructions]

For each committed folder (default generated/stewart_fk and generated/stewart_legs_fk) a
timing main calls each kernel on its own at the file's q0, nudged by 1e-12 per call so the
compiler cannot hoist it, and prints nanoseconds per call (best of 5, CLOCK_MONOTONIC, gcc
-O2): Phi; Phi and Phi_q fused; the sparse LU factorization of Phi_q; one solve with its
factors; Gamma. With ``--instructions`` the same calls are counted by callgrind as well (per
call, the kernel's inclusive count), which does not move with the load of a shared machine.

From these it prints three floors, sums of kernel calls with nothing else counted (no
convergence test, no condition estimate, no copies, no branch test):

- ``newton_iteration``: one fused Phi and Phi_q, one factorization, one solve. A solve that
  ends on fresh factors (what makes dq, ddq and the condition those of the solution) costs
  at least this, and at least one more Phi to see that the step converged;
- ``chord_two_steps``: three Phi and two solves on factors carried from an earlier call, the
  fewest with which simplified Newton from the last solution both contracts (two steps give
  its rate) and shows a residual under the tolerance;
- ``rates_accels``: Gamma and two solves, added by the velocities and accelerations.
"""

from __future__ import annotations

import argparse
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

KERNELS = ("phi", "phi_phi_q", "lu_factor", "lu_solve", "gamma")

MAIN = r"""
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "PREFIX.h"
#include "PREFIX_sparse_lu.h"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static PREFIX_real q[PREFIX_NQ], dq[PREFIX_NQ], out[PREFIX_NQ], nz[PREFIX_NNZ];
static PREFIX_real shared[PREFIX_NSHARED > 0 ? PREFIX_NSHARED : 1];
static PREFIX_real pu[PREFIX_NPU > 0 ? PREFIX_NPU : 1];
static PREFIX_lu lu;

/* One call of kernel k at q, which moves by 1e-12 per call. */
static void call(int k)
{
    q[0] += 1e-12;
    switch (k) {
    case 0: PREFIX_phi(q, 0, pu, out); break;
    case 1: PREFIX_phi_phi_q(q, 0, pu, out, nz, shared); break;
    case 2: PREFIX_lu_factor(nz, &lu); break;
    case 3: memcpy(out, dq, sizeof out); PREFIX_lu_solve(&lu, out); break;
    default: PREFIX_gamma(q, dq, 0, pu, out); break;
    }
}

int main(int argc, char **argv)
{
    const int n = argc > 1 ? atoi(argv[1]) : 100000, only = argc > 2 ? atoi(argv[2]) : -1;
    int i, k, r, j;
    for (i = 0; i < PREFIX_NQ; ++i) {
        q[i] = PREFIX_q0[i];
        dq[i] = 1e-3 * (i % 7 + 1); /* any rates: the kernels' cost does not depend on them */
    }
    for (i = 0; i < PREFIX_NPU; ++i) pu[i] = PREFIX_NP > 0 && i < PREFIX_NP ? PARAM(i) : 0;
    PREFIX_lu_init(&lu);
    PREFIX_phi_phi_q(q, 0, pu, out, nz, shared);
    if (PREFIX_lu_factor(nz, &lu) != 0) {
        fprintf(stderr, "Phi_q does not factor at q0\n");
        return 1;
    }
    for (k = 0; k < 5; ++k) {
        double best = 1e300;
        if (only >= 0 && k != only) continue;
        for (r = 0; r < (only >= 0 ? 1 : 5); ++r) {
            double started = now();
            for (j = 0; j < n; ++j) call(k);
            if (now() - started < best) best = now() - started;
        }
        printf("kernel=%d ns_per_call=%.1f\n", k, 1e9 * best / n);
    }
    if (PREFIX_lu_fallbacks(&lu) != 0) {
        fprintf(stderr, "the sparse LU fell back to dense: not the factorization meant\n");
        return 1;
    }
    return 0;
}
"""


def build(name: str, out: Path) -> Path:
    """Copy the committed folder, write the timing main, compile; the executable."""
    folder = ROOT / "generated" / name / "c"
    if not folder.is_dir():
        sys.exit(f"no committed C folder generated/{name}/c")
    shutil.copytree(folder, out)
    # the nominal parameters, where the file has any (declared as an array in a header)
    declared = "".join(h.read_text() for h in out.glob("*.h"))
    params = "p_nominal" if re.search(rf"\b{name}_p_nominal\[", declared) else None
    text = MAIN.replace("PREFIX_NQ", f"{name.upper()}_NQ").replace(
        "PREFIX_NNZ", f"{name.upper()}_NNZ").replace(
        "PREFIX_NSHARED", f"{name.upper()}_NSHARED").replace(
        "PREFIX_NPU", f"{name.upper()}_NPU").replace("PREFIX_NP", f"{name.upper()}_NP").replace(
        "PARAM(i)", f"{name}_{params}[i]" if params else "0").replace("PREFIX", name)
    (out / "floor_main.c").write_text(text)
    exe = out / "floor"
    sources = sorted(str(s) for s in out.glob("*.c") if not s.name.endswith("_solver.c"))
    subprocess.run(["gcc", "-std=c99", "-O2", f"-I{out}", "-o", str(exe), *sources, "-lm"],
                   check=True)
    return exe


def instructions(exe: Path, kernel: int, calls: int) -> float:
    """Instructions per call of one kernel (callgrind, the whole run less an empty one)."""
    def total(n: int) -> int:
        out = exe.parent / f"callgrind_{kernel}_{n}.out"
        subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}",
                        str(exe), str(n), str(kernel)], check=True, capture_output=True)
        summary = subprocess.run(["callgrind_annotate", str(out)], check=True,
                                 capture_output=True, text=True).stdout
        found = re.search(r"^\s*([\d,]+) \(100\.0%\)\s+PROGRAM TOTALS", summary, re.M)
        if found is None:
            found = re.search(r"^\s*([\d,]+)\s+PROGRAM TOTALS", summary, re.M)
        if found is None:
            sys.exit("no program total in callgrind's output")
        return int(found.group(1).replace(",", ""))
    return (total(calls) - total(0)) / calls


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--mechanism", nargs="+", default=["stewart_fk", "stewart_legs_fk"],
                        help="committed folders, by name (generated/NAME/c)")
    parser.add_argument("--calls", type=int, default=100000)
    parser.add_argument("--instructions", action="store_true",
                        help="also count instructions per call (callgrind)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        for name in args.mechanism:
            exe = build(name, Path(folder) / name)
            lines = subprocess.run([str(exe), str(args.calls)], check=True, capture_output=True,
                                   text=True).stdout
            ns = [float(v) for v in re.findall(r"ns_per_call=([\d.]+)", lines)]
            report(name, "ns", dict(zip(KERNELS, ns)))
            if args.instructions:
                counts = {kernel: instructions(exe, k, 2000) for k, kernel in enumerate(KERNELS)}
                report(name, "instructions", counts)


def report(name: str, unit: str, per: dict[str, float]) -> None:
    """The kernels' figures and the three floors, one line each."""
    floors = {"newton_iteration": per["phi_phi_q"] + per["lu_factor"] + per["lu_solve"],
              "chord_two_steps": 3 * per["phi"] + 2 * per["lu_solve"],
              "rates_accels": per["gamma"] + 2 * per["lu_solve"]}
    for label, value in [*per.items(), *floors.items()]:
        print(f"mechanism={name} {label}_{unit}={value:.0f}", flush=True)


if __name__ == "__main__":
    main()
