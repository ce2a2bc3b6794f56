"""Time the generated forward kinematics of the Stewart-Gough platform in the same run as the
LinuxCNC-style baseline, through fk_bench.c's documented solver signature.

    python3 bench/stewart/symkin_fk.py [--poses 10000] [--repeats 5] [--mechanism FILE ...]
                                       [--committed] [--instructions]

For each mechanism (default examples/stewart_fk.yaml, one moving body, and
examples/stewart_legs_fk.yaml, with its 12 leg bodies; both the geometry of stewart.c) the C
folder is generated into a temporary folder with an adapter of the signature of stewart.h:
the six legs go into u[] (less the home lengths for the slide inputs of the leg-body file),
one call of `<prefix>_solve_inputs` on a state kept in the context (the previous solution),
and the pose is read out of the platform's coordinates (x, y, z and the Euler parameters,
turned into roll, pitch, yaw). Two solvers per mechanism: positions only (du = ddu = NULL)
and with rates and accelerations (du, ddu given: the harness has no leg rates, so zeros are
passed; the two linear solves cost the same for any values). fk_bench.c, compiled with
FK_EXTRA_SOLVERS and gcc -O2, prints one line per solver and tilt.
``--committed`` times the folders committed under generated/ instead of generating them (the
golden test keeps them equal to what the templates give; the leg-body file takes minutes to
generate). ``--instructions`` also counts each symkin solver's instructions per solve with
callgrind (valgrind; --poses 10000 and both tilts: the adapter's inclusive count over the
2 x poses solves), which unlike times do not move with the load of a shared machine.
"""

from __future__ import annotations

import argparse
import json
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(HERE))

import make_fk_examples  # noqa: E402

import symkin  # noqa: E402

ADAPTER = r"""
#include <math.h>
#include <string.h>
#include "extra_solvers.h"
#include "PREFIX_solver.h"

typedef struct {
    PREFIX_options options;
    PREFIX_state state;
    PREFIX_workspace work;
    PREFIX_report report;
    PREFIX_real u[6], du[6], ddu[6];
    double last[6]; /* the pose returned last: a guess equal to it continues the run */
    int rates, ready;
} PREFIX_fk_context;

static const double PREFIX_home[6] = {HOME};
static PREFIX_fk_context PREFIX_positions, PREFIX_with_rates = {.rates = 1};
void *PREFIX_positions_context = &PREFIX_positions;
void *PREFIX_rates_context = &PREFIX_with_rates;

/* R = Rz(c) Ry(b) Rx(a) as unit Euler parameters (half angles). */
static void PREFIX_pose_to_e(const double pose[6], PREFIX_real q[7])
{
    const double ca = cos(pose[3] / 2), sa = sin(pose[3] / 2), cb = cos(pose[4] / 2),
                 sb = sin(pose[4] / 2), cc = cos(pose[5] / 2), sc = sin(pose[5] / 2);
    q[0] = pose[0]; q[1] = pose[1]; q[2] = pose[2];
    q[3] = cc * cb * ca + sc * sb * sa;
    q[4] = cc * cb * sa - sc * sb * ca;
    q[5] = cc * sb * ca + sc * cb * sa;
    q[6] = sc * cb * ca - cc * sb * sa;
}

/* Roll, pitch, yaw of A(e): the entries (2,1), (2,2), (2,0), (1,0), (0,0) of A. */
static void PREFIX_e_to_pose(const PREFIX_real q[7], double pose[6])
{
    const double e0 = q[3], e1 = q[4], e2 = q[5], e3 = q[6];
    const double r00 = 2 * (e0 * e0 + e1 * e1) - 1, r10 = 2 * (e1 * e2 + e0 * e3);
    const double r20 = 2 * (e1 * e3 - e0 * e2), r21 = 2 * (e2 * e3 + e0 * e1);
    const double r22 = 2 * (e0 * e0 + e3 * e3) - 1;
    pose[0] = q[0]; pose[1] = q[1]; pose[2] = q[2];
    pose[3] = atan2(r21, r22);
    pose[4] = asin(r20 > 1 ? -1 : r20 < -1 ? 1 : -r20);
    pose[5] = atan2(r10, r00);
}

int PREFIX_fk(void *context, const double legs[6], double pose[6], int *iterations)
{
    PREFIX_fk_context *c = context;
    int i, status;
    if (!c->ready) {
        PREFIX_default_options(&c->options);
        memset(c->du, 0, sizeof c->du);
        memset(c->ddu, 0, sizeof c->ddu);
        c->state.t = 0;
        c->ready = 1;
        c->last[0] = NAN;
    }
    if (memcmp(pose, c->last, sizeof c->last) != 0) { /* a new run: start from its guess */
        for (i = 0; i < PREFIX_NQ_MACRO; ++i)
            c->state.q[i] = PREFIX_q0[i];
        PREFIX_pose_to_e(pose, c->state.q + PLATFORM);
        c->state.started = 0;
    }
    for (i = 0; i < 6; ++i)
        c->u[i] = legs[i] - PREFIX_home[i];
    status = PREFIX_solve_inputs(&c->options, PARAMS, c->u, c->rates ? c->du : NULL,
                                 c->rates ? c->ddu : NULL, &c->state, &c->work, &c->report);
    *iterations = c->report.iterations;
    PREFIX_e_to_pose(c->state.q + PLATFORM, pose);
    memcpy(c->last, pose, sizeof c->last);
    return status != PREFIX_OK_MACRO;
}
"""


def home_lengths() -> list[float]:
    base, top = make_fk_examples.geometry()
    return [sum((p - b) ** 2 for p, b in zip(pt, bs)) ** 0.5 for pt, bs in zip(top, base)]


class Committed:
    """What adapter needs of a System, read from a committed folder's manifest."""

    def __init__(self, path: str) -> None:
        self.name = Path(path).stem
        self.folder = ROOT / "generated" / self.name / "c"
        manifest = json.loads((self.folder / f"{self.name}_manifest.json").read_text())
        self.input_names, self.coordinates = manifest["input_names"], manifest["coordinates"]
        self.p = manifest["parameter_names"]


def adapter(system, out: Path) -> tuple[str, str]:
    """Generate the mechanism's C into out (or copy the committed folder) and write its
    adapter; the header lines."""
    name = system.name
    if tuple(system.input_names) != tuple(f"leg{i}" for i in range(1, 7)):
        sys.exit(f"{name}: expected the six inputs leg1..leg6")
    if isinstance(system, Committed):
        shutil.copytree(system.folder, out)
    else:
        symkin.generate(system, backend="c", out_dir=out)
    # The leg-body file's inputs are slides from the home lengths; the one-body file's the
    # lengths themselves (distance drivers).
    slides = any(c.startswith("piston") for c in system.coordinates)
    home = home_lengths() if slides else [0.0] * 6
    text = (ADAPTER.replace("PREFIX_NQ_MACRO", f"{name.upper()}_NQ")
            .replace("PREFIX_OK_MACRO", f"{name.upper()}_OK")
            .replace("PREFIX", name).replace("HOME", ", ".join(map(repr, home)))
            .replace("PLATFORM", str(system.coordinates.index("platform.x")))
            .replace("PARAMS", f"{name}_p_nominal" if system.p else "NULL"))
    (out / f"{name}_fk_adapter.c").write_text(text)
    declare = (f"int {name}_fk(void *, const double[6], double[6], int *);\n"
               f"extern void *{name}_positions_context, *{name}_rates_context;\n")
    table = (f'{{"symkin_{name}_positions", {name}_fk, NULL}}, '
             f'{{"symkin_{name}_rates_accels", {name}_fk, NULL}},')
    return declare, table


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--poses", type=int, default=10000)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--mechanism", nargs="+", default=[
        str(ROOT / "examples/stewart_fk.yaml"), str(ROOT / "examples/stewart_legs_fk.yaml")])
    parser.add_argument("--instructions", action="store_true",
                        help="also count instructions per solve (callgrind)")
    parser.add_argument("--committed", action="store_true",
                        help="time the folders under generated/ (no code generation)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        out = Path(folder)
        declares, tables, sources = [], [], []
        for path in args.mechanism:
            system = Committed(path) if args.committed else symkin.derive(path)
            sub = out / system.name
            declare, table = adapter(system, sub)
            declares.append(declare)
            # The contexts are globals: set them in the table through a local initialiser.
            tables.append(table.replace("NULL}, ", f"{system.name}_positions_context}}, ", 1)
                          .replace("NULL},", f"{system.name}_rates_context}},"))
            sources += sorted(map(str, sub.glob("*.c")))
        (out / "extra_solvers.h").write_text(
            "#ifndef EXTRA_SOLVERS_H\n#define EXTRA_SOLVERS_H\n" + "".join(declares)
            + "#define FK_EXTRA_SOLVERS_TABLE " + " ".join(tables) + "\n#endif\n")
        exe = out / "fk_bench"
        includes = [f"-I{out}", *sorted({f"-I{Path(s).parent}" for s in sources})]
        subprocess.run(["gcc", "-std=c99", "-O2", "-DFK_EXTRA_SOLVERS", *includes, "-o", str(exe),
                        str(HERE / "fk_bench.c"), str(HERE / "linuxcnc_style_fk.c"),
                        str(HERE / "stewart.c"), *sources, "-lm"], check=True)
        subprocess.run([str(exe), str(args.poses), str(args.repeats)], check=True)
        if args.instructions:
            for name in [n for table in tables for n in re.findall(r'"symkin_(\w+)"', table)]:
                print(f"solver=symkin_{name} instructions_per_solve="
                      f"{count_instructions(exe, name, args.poses):.0f}", flush=True)


def count_instructions(exe: Path, solver: str, poses: int) -> float:
    """Instructions per solve of one solver of fk_bench, by callgrind: its adapter's inclusive
    count over one pass of both tilts."""
    out = exe.parent / f"callgrind_{solver}.out"
    subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", str(exe),
                    str(poses), "1", solver], check=True, capture_output=True)
    table = subprocess.run(["callgrind_annotate", "--inclusive=yes", str(out)], check=True,
                           capture_output=True, text=True).stdout
    adapter = solver.rsplit("_", 2)[0] if solver.endswith("rates_accels") else solver.rsplit(
        "_", 1)[0]
    count = re.search(rf"^\s*([\d,]+) .*:{adapter}_fk \[", table, re.M)
    if count is None:
        sys.exit(f"no count of {adapter}_fk in callgrind's output")
    return int(count.group(1).replace(",", "")) / (2 * poses)


if __name__ == "__main__":
    main()
