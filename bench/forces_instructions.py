"""Instructions per step of the generated grid loop with and without the inverse dynamics,
counted by callgrind (valgrind): the extra cost of the multipliers, efforts and reactions
against the kinematic step, free of the machine's load.

    python3 bench/forces_instructions.py [spatial_slider_crank_forces stewart_mass ...]

Each argument is an example with forces (examples/<name>.yaml), a file of this folder
(spatial_slider_crank_forces) or ``stewart_mass``: examples/stewart.yaml with a platform of
mass 50, a full inertia tensor, an offset centre of mass, gravity and a torque (its legs'
efforts only: the Stewart file has no joints). The generated folder is compiled as a plain C
program (gcc -O2) whose main calls ``<prefix>_solve_grid_checked`` over t = t0 + k dt,
dt = (t1 - t0) / 20000 (the grid of bench/forces.py), once with NULL multiplier and load
outputs (``kinematic``) and once writing them (``with forces``); each count is (instructions
of 121 steps - of 21 steps) / 100, so set-up and the first assembly cancel.
"""

from __future__ import annotations

import re
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

import yaml

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

MAIN = r"""
#include <stdio.h>
#include <stdlib.h>
#include "@P@_solver.h"
int main(int argc, char **argv)
{
    int n = atoi(argv[1]), forces = argv[2][0] == 'f', k, done;
    double *t = malloc(sizeof(double) * n);
    double *lam = forces ? malloc(sizeof(double) * n * @U@_NQ) : 0;
    double *loads = forces ? malloc(sizeof(double) * n * @U@_NLOADS) : 0;
    static @P@_workspace w;
    static @P@_state s;
    @P@_options o;
    @P@_report r;
    for (k = 0; k < n; ++k) t[k] = @T0@ + k * @DT@;
    @P@_default_options(&o);
    for (k = 0; k < @U@_NQ; ++k) s.q[k] = @P@_q0[k];
    s.started = 0;
    done = @P@_solve_grid_checked(&o, @P@_p_nominal, n, t, &s, 0, 0, 0, 0, 0, lam, loads,
                                  &w, &r);
    printf("%d\n", done);
    return done == n ? 0 : 1;
}
"""

DEFAULT = ("crank_slider_load", "four_bar_dynamics", "spatial_slider_crank_forces",
           "stewart_mass")


def mechanism(name: str) -> dict[str, Any]:
    """The file's data (``stewart_mass``: the Stewart platform given a mass, module doc)."""
    if name == "stewart_mass":
        data = yaml.safe_load((ROOT / "examples" / "stewart.yaml").read_text(encoding="utf-8"))
        data["name"] = name
        data["bodies"]["platform"].update(
            mass=50, inertia=[[2, 0.1, 0], [0.1, 2, 0.2], [0, 0.2, 3.5]],
            com=[0.05, -0.02, 1.1])
        data["forces"] = [{"type": "gravity", "g": [0, 0, -9.81]},
                          {"type": "torque", "name": "twist", "body": "platform",
                           "m": ["sin(t)", 0.2, "platform.x_t"]}]
        return data
    folder = ROOT / ("bench" if (ROOT / "bench" / f"{name}.yaml").exists() else "examples")
    return yaml.safe_load((folder / f"{name}.yaml").read_text(encoding="utf-8"))


def _total(program: Path, steps: int, kind: str) -> int:
    out = program.parent / f"callgrind.{kind}.{steps}"
    subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}",
                    str(program), str(steps), kind], capture_output=True, check=True)
    found = re.search(r"^summary: (\d+)", out.read_text(), re.MULTILINE)
    assert found is not None, out
    return int(found.group(1))


def per_step(name: str, system: Any = None, files: dict[str, str] | None = None
             ) -> tuple[int, float, float]:
    """(NQ, kinematic, with forces) instructions per step of the mechanism ``name``; its
    System and C files (what symkin.generate writes) when the caller has them already."""
    import symkin
    from symkin.spec import validate as model

    if system is None:
        system = symkin.derive(model.from_dict(mechanism(name)))
    t0, t1, _ = system.time_grid
    with tempfile.TemporaryDirectory() as folder:
        build = Path(folder)
        if files is None:
            symkin.generate(system, backend="c", out_dir=build / "c")
        else:
            (build / "c").mkdir()
            for file_name, text in files.items():
                (build / "c" / file_name).write_text(text, encoding="utf-8")
        prefix = system.name
        (build / "main.c").write_text(
            MAIN.replace("@P@", prefix).replace("@U@", prefix.upper())
            .replace("@T0@", repr(float(t0))).replace("@DT@", repr((t1 - t0) / 20000)))
        program = build / "main"
        subprocess.run(["gcc", "-std=c99", "-O2", f"-I{build / 'c'}", "-o", str(program),
                        str(build / "main.c"), *sorted(str(p) for p in (build / "c").glob("*.c")),
                        "-lm"], check=True)
        counts = [(_total(program, 121, kind) - _total(program, 21, kind)) / 100
                  for kind in ("kinematic", "forces")]
        return len(system.q), counts[0], counts[1]


def main() -> None:
    names = sys.argv[1:] or list(DEFAULT)
    print(f"{'mechanism':28} {'NQ':>3} {'kinematic':>10} {'with forces':>12} {'extra':>6}"
          "   (instructions/step; extra: x the kinematic step)")
    for name in names:
        nq, kinematic, with_forces = per_step(name)
        print(f"{name:28} {nq:3d} {kinematic:10.0f} {with_forces:12.0f} "
              f"{(with_forces - kinematic) / kinematic:6.2f}", flush=True)


if __name__ == "__main__":
    main()
