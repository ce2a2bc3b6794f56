"""The CPU cost of building a C kernel cold: the Python of the build and the compiler's CPU,
file by file.

    python3 bench/c_build_cost.py crank_slider four_bar tests/trust/spherical_four_bar.yaml
    python3 bench/c_build_cost.py --rounds 3 chain:101

Each argument is an example's name (examples/<name>.yaml), a mechanism file, or
FAMILY:BODIES of bench/scaling_limit.py. The mechanism is derived and its C folder generated
once (not counted); then the folder is built ``--rounds`` times, each into an empty cache:
"python s" is the CPU of this process inside the backend's build (cffi's declarations and
wrapper source, hashing, loading), "gcc s" the CPU of the compiler processes it ran
(``RUSAGE_CHILDREN``), also per compiled file. The files are compiled one at a time here
(symkin runs two at once, which changes the wall time but not the CPU), so that each
compiler process's CPU is its own. Run it with PYTHONPATH set to a tree to measure that tree.
"""

from __future__ import annotations

import argparse
import resource
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def _system(spec: str) -> Any:
    import symkin
    from symkin.spec import validate as model

    if ":" in spec and not Path(spec).exists():
        import scaling_limit

        family, bodies = spec.split(":")
        data, _ = scaling_limit.mechanism(family, int(bodies))
        return symkin.derive(model.from_dict(data))
    path = Path(spec)
    return symkin.derive(path if path.suffix else ROOT / "examples" / f"{spec}.yaml")


def _files(system: Any) -> tuple[Any, dict[str, str]]:
    from symkin import backends
    from symkin.codegen import lower, render

    backend = backends.get("c")
    return backend, render.rendered(lower.lower(system, backend, None, True))


def _recording(per_file: dict[str, float], compile_unit: Callable[..., Path]
               ) -> Callable[..., Path]:
    def timed(compiler: list[str], flags: list[str], source: Path) -> Path:
        before = _children_cpu()
        target = compile_unit(compiler, flags, source)
        # the wrapper's name carries the cache key: one label for it
        name = "wrapper" if source.name.startswith("_symkin_") else source.name
        per_file[name] = _children_cpu() - before
        return target

    return timed


def measure(spec: str, rounds: int) -> list[dict[str, Any]]:
    """One row per cold build of ``spec``."""
    from symkin.backends.c import cffi_build

    system = _system(spec)
    backend, files = _files(system)
    cffi_build.JOBS = 1
    compile_unit = cffi_build._object
    rows = []
    for _ in range(rounds):
        per_file: dict[str, float] = {}
        cffi_build._object = _recording(per_file, compile_unit)
        try:
            with tempfile.TemporaryDirectory() as cache:
                children, own = _children_cpu(), time.process_time()
                backend.build(dict(files), Path(cache))
                own, children = time.process_time() - own, _children_cpu() - children
        finally:
            cffi_build._object = compile_unit
        rows.append({"name": system.name, "python_s": own, "gcc_s": children,
                     "files": per_file})
    return rows


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("mechanisms", nargs="+")
    parser.add_argument("--rounds", type=int, default=2)
    args = parser.parse_args()
    for spec in args.mechanisms:
        for row in measure(spec, args.rounds):
            files = "  ".join(f"{name} {seconds:.2f}" for name, seconds in
                              sorted(row["files"].items(), key=lambda item: -item[1]))
            print(f"{row['name']:20s} python {row['python_s']:5.2f} s  gcc {row['gcc_s']:6.2f} s"
                  f"  ({files})", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
