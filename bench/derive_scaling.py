"""Derivation time against mechanism size: validation (model) and symbolic derivation (derive).

Two parametric families, both with DOF == driving equations at every size:

* ``chain``: the four-bar chain of bench/scaling_family.py (revolute pairs, one angle driver);
* ``mixed``: independent units of four bodies each, so that every kind of row scales: an
  offset crank-slider (a crank pinned to the ground, a rod, a slider on a horizontal
  prismatic guide 1.5 below the pivot) plus a lever whose slot holds the crank pin (pin_slot);
  unit k is driven by an angle driver when k is even and by a custom driver (the crank along
  a line through its pivot that turns with t, an equation mixing q and t) when k is odd.

For each size the script prints the validation and derivation times (best of --repeat), the
number of coordinates and Jacobian non-zeros, and at the end the log-log slope of time
against the number of bodies; linear cost means a slope near 1.

    python3 bench/derive_scaling.py                       # 10 .. 320 bodies, both families
    python3 bench/derive_scaling.py --family mixed --sizes 10 40 160 640
"""

from __future__ import annotations

import argparse
import importlib.util
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from sympy.core.cache import clear_cache

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from symkin.spec import validate as model
from symkin.symbolic import derivation


def _chain_family() -> Callable[[int], dict[str, Any]]:
    spec = importlib.util.spec_from_file_location("scaling_family",
                                                  ROOT / "bench" / "scaling_family.py")
    assert spec is not None and spec.loader is not None
    family = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(family)
    return lambda bodies: family.chain(family.loops_for(bodies))


def mixed(bodies: int) -> dict[str, Any]:
    """Independent shaper units (4 bodies each), at least ``bodies`` bodies in all."""
    units = max(1, -(-bodies // 4))
    spec: dict[str, Any] = {
        "name": f"mixed{units}",
        "parameters": {"a": 1.0, "b": 3.0, "h": 2.0, "d": 6.0, "w": 2.0},
        "bodies": {}, "joints": [], "drivers": [],
        "time": {"t0": 0, "t1": 1, "dt": 0.01},
    }
    for k in range(units):
        spec["bodies"].update(_unit_bodies(k))
        spec["joints"] += _unit_joints(k)
        spec["drivers"].append(_unit_driver(k))
    return spec


def _unit_bodies(k: int) -> dict[str, Any]:
    x = 6.0 * k  # unit k sits at x = k d on the ground, crank pointing up at t = 0
    return {f"crank{k}": {"q0": [x, 0, 1.571], "points": {"pin": ["a", 0]}},
            f"rod{k}": {"q0": [x, 1, -0.985]},
            f"slider{k}": {"q0": [x + 1.658, -1.5, 0]},
            f"lever{k}": {"q0": [x, -2, 1.571]}}


def _unit_joints(k: int) -> list[dict[str, Any]]:
    crank, rod, slider, lever = (f"{name}{k}" for name in ("crank", "rod", "slider", "lever"))
    return [
        {"type": "revolute", "i": "ground", "j": crank, "sA": [f"{k}*d", 0], "sB": [0, 0]},
        {"type": "revolute", "i": crank, "j": rod, "sA": "pin", "sB": [0, 0]},
        {"type": "revolute", "i": rod, "j": slider, "sA": ["b", 0], "sB": [0, 0]},
        {"type": "prismatic", "i": slider, "j": "ground", "sA": [0, 0],
         "sB": [f"{k}*d", -1.5], "v": [0, 1]},
        {"type": "revolute", "i": "ground", "j": lever, "sA": [f"{k}*d", "-h"], "sB": [0, 0]},
        {"type": "pin_slot", "i": crank, "j": lever, "sA": "pin", "sB": [0, 0], "v": [0, 1]},
    ]


def _unit_driver(k: int) -> dict[str, Any]:
    crank = f"crank{k}"
    if k % 2 == 0:
        return {"type": "angle", "i": crank, "j": "ground", "theta": "pi/2 + w*t"}
    equation = (f"cos(pi/2 + w*t)*({crank}.y) - sin(pi/2 + w*t)*({crank}.x - {k}*d)"
                f" + a*sin({crank}.phi - pi/2 - w*t)")
    return {"type": "custom", "equations": [equation]}


FAMILIES: dict[str, Callable[[int], dict[str, Any]]] = {"mixed": mixed}


def measure(family: Callable[[int], dict[str, Any]], size: int, repeat: int) -> dict[str, float]:
    """Best-of-``repeat`` validation and derivation CPU times for one size.

    SymPy's cache is cleared before each run: a repeated run of a small mechanism would
    otherwise find all its expressions cached (a large one overflows the cache), which makes
    small sizes look cheap and the slope look steeper than it is. CPU time of this process
    (not wall time) keeps other load on the machine out of the figures.
    """
    spec = family(size)
    best_model = best_derive = float("inf")
    for _ in range(repeat):
        clear_cache()
        start = time.process_time()
        mech = model.from_dict(spec)
        middle = time.process_time()
        system = derivation.derive(mech)
        end = time.process_time()
        best_model, best_derive = min(best_model, middle - start), min(best_derive, end - middle)
    return {"bodies": len(mech.bodies), "n": len(system.q), "nnz": len(system.pattern()),
            "model_s": best_model, "derive_s": best_derive}


def slope(x: list[float], y: list[float]) -> float:
    """The least-squares slope of log y against log x."""
    return float(np.polyfit(np.log(x), np.log(y), 1)[0])


def report(name: str, rows: list[dict[str, float]]) -> None:
    print(f"family {name}")
    print(f"{'bodies':>7} {'N':>6} {'nnz':>6} {'model s':>9} {'derive s':>9} "
          f"{'derive ms/body':>15}")
    for r in rows:
        print(f"{r['bodies']:7d} {r['n']:6d} {r['nnz']:6d} {r['model_s']:9.3f} "
              f"{r['derive_s']:9.3f} {1e3 * r['derive_s'] / r['bodies']:15.2f}")
    bodies = [r["bodies"] for r in rows]
    print(f"log-log slope: model {slope(bodies, [r['model_s'] for r in rows]):.2f}, "
          f"derive {slope(bodies, [r['derive_s'] for r in rows]):.2f}\n")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--family", choices=["chain", "mixed", "both"], default="both")
    parser.add_argument("--sizes", type=int, nargs="+", default=[10, 20, 40, 80, 160, 320])
    parser.add_argument("--repeat", type=int, default=2)
    args = parser.parse_args(argv)
    families = dict(FAMILIES, chain=_chain_family())
    names = ["chain", "mixed"] if args.family == "both" else [args.family]
    for name in names:
        report(name, [measure(families[name], size, args.repeat) for size in args.sizes])
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
