"""Instructions per time step of the generated C solver, counted by callgrind (valgrind).

    python3 bench/instructions.py [--tighten-cond C] [--linalg dense] crank_slider chain:100 ...
    python3 bench/instructions.py --solve crank_slider ...

Each argument is an example's name (examples/<name>.yaml, started from its q0), FAMILY:BODIES
of bench/scaling_limit.py (started from the closed form), or ``handwritten``: the hand-written
dense C crank-slider of bench/baselines/crank_slider.c on the textbook grid, for the ratio.
The generated folder is compiled as a plain C program (gcc -O2) whose main calls
``<prefix>_solve_grid`` over t = k * dt; the count is (instructions of 121 steps -
instructions of 21 steps) / 100, so set-up and the first assembly cancel. Instruction
counts do not depend on the load of a shared machine, unlike times. dt is 1.5/20000 for an
example (the textbook grid), 0.001 for a family. The crank-slider's count is guarded by
tests/test_performance_budget.py against bench/budgets.json (972 when last lowered; the
table of where a step's instructions go is in bench/README.md, "The step given back").
``--tighten-cond C`` replaces the solver's default ``tighten_cond`` (``inf``: no extra Newton
iterations at all, so every step does the same work at every size). ``--linalg dense``
generates the dense LU with partial pivoting instead of the sparse one (the path of the
sparse LU's fall-back too).
``--solve`` counts one ``symkin.solve`` call instead (per_solve_call: the C kernel of the
example on a 31-point grid, the Python around the generated solver included).
"""

from __future__ import annotations

import math
import re
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "bench"))

MAIN = r"""
#include <stdio.h>
#include <math.h>
#include <stdlib.h>
#include "@P@_solver.h"
int main(int argc, char **argv)
{
    int n = atoi(argv[1]), k, done;
    double *t = malloc(sizeof(double) * n);
    static @P@_workspace w;
    static @P@_state s;
    @P@_options o;
    @P@_report r;
    for (k = 0; k < n; ++k) t[k] = k * @DT@;
    @P@_default_options(&o);
    @TIGHTEN@
    for (k = 0; k < @U@_NQ; ++k) s.q[k] = @P@_q0[k];
    s.started = 0;
    done = @P@_solve_grid(&o, @P@_p_nominal, n, t, &s, 0, 0, 0, &w, &r);
    printf("%d %lu\n", done, r.fallbacks);
    return done == n ? 0 : 1;
}
"""


HANDWRITTEN_MAIN = r"""
#include <stdio.h>
#include <stdlib.h>
long cs_solve_grid(long steps, double dt, double *Q, double *DQ, double *D2Q,
                   long *newton_iterations, unsigned long *fallbacks);
int main(int argc, char **argv)
{
    long n = atol(argv[1]), iterations = 0;
    unsigned long fallbacks = 0;
    double *rows = malloc(sizeof(double) * 27 * (n + 1));
    long done = cs_solve_grid(n, 1.5 / 20000, rows, rows + 9 * (n + 1), rows + 18 * (n + 1),
                              &iterations, &fallbacks);
    printf("%ld %ld\n", done, iterations);
    return 0;
}
"""


def handwritten_per_step() -> tuple[str, int, float]:
    """The hand-written dense C crank-slider's instructions per step, counted alike."""
    with tempfile.TemporaryDirectory() as folder:
        build = Path(folder)
        (build / "main.c").write_text(HANDWRITTEN_MAIN)
        program = build / "main"
        subprocess.run(["gcc", "-std=c99", "-O2", "-o", str(program), str(build / "main.c"),
                        str(ROOT / "bench" / "baselines" / "crank_slider.c"), "-lm"], check=True)
        return "handwritten", 9, (_total(program, 121) - _total(program, 21)) / 100


def _total(program: Path, steps: int) -> int:
    out = program.parent / f"callgrind.{steps}"
    subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}",
                    str(program), str(steps)], capture_output=True, check=True)
    text = subprocess.run(["callgrind_annotate", str(out)], capture_output=True, text=True,
                          check=True).stdout
    match = re.search(r"([\d,]+) \(100.0%\)\s+PROGRAM TOTALS", text)
    assert match, text[:500]
    return int(match.group(1).replace(",", ""))


def per_step(spec: str, tighten_cond: str | None = None, linalg: str = "sparse"
             ) -> tuple[str, int, float]:
    import symkin
    from symkin.spec import validate as model

    if ":" in spec:
        import scaling_limit

        family, bodies = spec.split(":")
        data, _ = scaling_limit.mechanism(family, int(bodies))
        system, dt = symkin.derive(model.from_dict(data)), "0.001"
    else:
        system, dt = symkin.derive(ROOT / "examples" / f"{spec}.yaml"), "(1.5 / 20000)"
    with tempfile.TemporaryDirectory() as folder:
        build = Path(folder)
        symkin.generate(system, backend="c", out_dir=build / "c", linalg=linalg)
        prefix = system.name
        tighten = "" if tighten_cond is None else f"o.tighten_cond = {tighten_cond};"
        (build / "main.c").write_text(
            MAIN.replace("@P@", prefix).replace("@U@", prefix.upper()).replace("@DT@", dt)
            .replace("@TIGHTEN@", tighten))
        sources = [str(p) for p in sorted((build / "c").glob("*.c"))]
        program = build / "main"
        subprocess.run(["gcc", "-std=c99", "-O2", f"-I{build / 'c'}", "-o", str(program),
                        str(build / "main.c"), *sources, "-lm"], check=True)
        return spec, len(system.q), (_total(program, 121) - _total(program, 21)) / 100


SOLVE_CALLS = r"""
import os
import sys
from pathlib import Path

import numpy as np

import symkin
from symkin import backends
from symkin.build import index

kernel = index.prepare(Path(sys.argv[1]), index.Options(backend=backends.resolve("c"))).kernel
t = np.linspace(0.0, 1.5, 31)
for _ in range(int(sys.argv[2])):  # past the first calls' one-time costs
    symkin.solve(kernel, t=t)
os.getppid()  # the marker: callgrind writes what it counted so far, and counts afresh
for _ in range(int(sys.argv[3])):
    symkin.solve(kernel, t=t)
os.getppid()
"""

# The libc function the script above calls only around its counted calls.
MARKER = "getppid"
WARM_CALLS, COUNTED_CALLS = 101, 1000


def per_solve_call(spec: str, cache_dir: str | None = None) -> float:
    """Instructions of one ``symkin.solve(kernel, t=t)`` on a 31-point grid over 0..1.5 with
    the C kernel of examples/<spec>.yaml: the count of 1000 calls / 1000 in one process, after
    101 calls that pay the first calls' one-time costs, the kernel built beforehand (outside
    the count) and loaded from the cache. callgrind writes its counts out and starts afresh
    each time the script enters the marker (``--dump-before``), so the 1000 calls are
    counted alone. A count over 100 calls moved by up to 20 % between runs (the
    interpreter's allocations and collections land unevenly); over 1000 by about 3 %."""
    import os

    from symkin import backends
    from symkin.build import index

    path = ROOT / "examples" / f"{spec}.yaml"
    index.prepare(path, index.Options(backend=backends.resolve("c")), cache_dir=cache_dir)
    env = dict(os.environ, PYTHONHASHSEED="0",
               PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    if cache_dir is not None:
        env["SYMKIN_CACHE_DIR"] = str(cache_dir)
    with tempfile.TemporaryDirectory() as folder:
        script = Path(folder) / "calls.py"
        script.write_text(SOLVE_CALLS)
        counts = Path(folder) / "callgrind.out"
        subprocess.run(["valgrind", "--tool=callgrind", f"--dump-before={MARKER}",
                        f"--callgrind-out-file={counts}", sys.executable, str(script),
                        str(path), str(WARM_CALLS), str(COUNTED_CALLS)],
                       capture_output=True, text=True, check=True, env=env)
        # Part 1: up to the first marker; part 2: the counted calls; the file without a
        # number: from the second marker to the exit. More parts: something else called it.
        parts = sorted(p.name for p in Path(folder).glob("callgrind.out*"))
        assert parts == ["callgrind.out", "callgrind.out.1", "callgrind.out.2"], parts
        match = re.search(r"^summary: (\d+)", (Path(folder) / "callgrind.out.2").read_text(),
                          re.MULTILINE)
        assert match, "no summary line in the counted part"
        return int(match.group(1)) / COUNTED_CALLS


def main() -> int:
    args = sys.argv[1:]
    if args[:1] == ["--solve"]:
        for spec in args[1:] or ["crank_slider"]:
            print(f"{spec:20s} {per_solve_call(spec):10.0f} instructions/symkin.solve call",
                  flush=True)
        return 0
    tighten_cond = None
    if args[:1] == ["--tighten-cond"]:
        value = float(args[1])  # a C literal: INFINITY for inf (any spelling)
        tighten_cond = "INFINITY" if math.isinf(value) else repr(value)
        args = args[2:]
    linalg = "sparse"
    if args[:1] == ["--linalg"]:
        linalg = args[1]
        args = args[2:]
    for spec in args or ["crank_slider"]:
        name, nq, count = (handwritten_per_step() if spec == "handwritten"
                           else per_step(spec, tighten_cond, linalg))
        print(f"{name:20s} N = {nq:5d}  {count:10.0f} instructions/step", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
