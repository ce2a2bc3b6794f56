"""Generation and compile times, and op counts, for the textbook crank-slider and a large chain.

Each stage is timed once, in a fresh cache folder, so the compile time is a real compile:

    python3 bench/codegen_times.py                # textbook example and a 101-body chain
    python3 bench/codegen_times.py --loops 10     # a 21-body chain instead
"""

from __future__ import annotations

import argparse
import importlib.util
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import symkin
from symkin import backends
from symkin.codegen import lower as codegen
from symkin.codegen import render
from symkin.spec import validate as model

ROOT = Path(__file__).resolve().parent.parent


def _scaling_family() -> Any:
    spec = importlib.util.spec_from_file_location("scaling_family",
                                                  ROOT / "bench" / "scaling_family.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _timed(action: Callable[[], Any]) -> tuple[Any, float]:
    start = time.perf_counter()
    result = action()
    return result, time.perf_counter() - start


def measure(mech: model.Mechanism, cse: bool = True) -> dict[str, Any]:
    """Seconds per stage and op counts for one mechanism."""
    system, derive_s = _timed(lambda: symkin.derive(mech))
    code, lower_s = _timed(lambda: codegen.lower(system, backends.get("c"), cse=cse))
    with tempfile.TemporaryDirectory() as scratch:
        _, render_s = _timed(lambda: render.write(code, Path(scratch) / "c"))
        _, compile_s = _timed(lambda: symkin.compile(system, "c", cse=cse,
                                                    cache_dir=Path(scratch) / "cache"))
        _, numpy_s = _timed(lambda: symkin.compile(system, "numpy", cse=cse,
                                                  cache_dir=Path(scratch) / "cache"))
        source_bytes = sum(p.stat().st_size for p in (Path(scratch) / "c").glob(f"{mech.name}.c"))
    return {"name": mech.name, "bodies": len(mech.bodies), "nq": code.nq, "nnz": code.nnz,
            "cse": cse, "derive": derive_s, "codegen": lower_s, "render": render_s,
            "compile_c (codegen+render+cc, cold)": compile_s, "numpy load (codegen+render)":
            numpy_s, "kernel .c bytes": source_bytes, "ops": code.ops,
            "ops_before_cse": code.ops_before_cse}


def report(row: dict[str, Any]) -> str:
    lines = [(f"{row['name']}: {row['bodies']} bodies, N = {row['nq']}, nnz = {row['nnz']}, "
             f"cse = {row['cse']}")]
    for key, value in row.items():
        if isinstance(value, float):
            lines.append(f"  {key:38s} {value:8.2f} s")
    lines.append(f"  {'kernel .c bytes':38s} {row['kernel .c bytes']:8d}")
    ops, before = row["ops"], row["ops_before_cse"]
    lines.append("  ops after CSE:  " + ", ".join(f"{k} {v}" for k, v in sorted(ops.items())))
    lines.append("  ops before CSE: " + ", ".join(f"{k} {v}" for k, v in sorted(before.items())))
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--loops", type=int, default=50, help="four-bar loops in the chain "
                        "(bodies = 1 + 2 loops; default 50 -> 101 bodies)")
    args = parser.parse_args(argv)
    family = _scaling_family()
    mechanisms = [model.load(ROOT / "examples" / "crank_slider.yaml"),
                  model.from_dict(family.chain(args.loops))]
    for mech in mechanisms:
        for cse in (True, False):
            print(report(measure(mech, cse)), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
