"""Wall time of a cold and a warm `symkin run`, and what the imports a warm run skips cost.

    python3 bench/cold_warm.py [--repeat 7] [--backends numpy c] [--mechanism FILE]

Each figure is the median (and the fastest) of --repeat runs of a fresh
`python -m symkin run FILE --backend B -o out.npz` process, timed from outside:
  cold      an empty cache: validate, derive (SymPy), generate, compile (C), solve, write;
  no index  the build cache is full but the kernel index is not (what a second run cost before
            the index: validation and derivation again, no compiling);
  warm      the index hits: load the cached kernel and solve; SymPy, pydantic and jinja2 are
            never imported (checked on every run).
Then the cost of importing each heavy module in a fresh interpreter, less `python -c pass`.

The runs use a snapshot of the package: the index is keyed on symkin's own source, so an edit
to the tree during the benchmark would otherwise (correctly) turn warm runs cold.
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
HEAVY = ("sympy", "pydantic", "jinja2")
CHECK = ("import json, sys\nfrom symkin.cli import main\nstatus = main(sys.argv[1:])\n"
         f"print('heavy:' + json.dumps([m for m in {HEAVY!r} if m in sys.modules]))\n"
         "sys.exit(status)\n")
IMPORTS = ("numpy", "scipy.linalg", "sympy", "pydantic", "jinja2", "yaml", "cffi")


def snapshot(folder: Path) -> Path:
    """Copy the package and its templates, plus the run wrapper; return the wrapper."""
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc")
    for part in ("symkin", "templates"):
        shutil.copytree(ROOT / part, folder / part, ignore=ignore)
    wrapper = folder / "run_symkin.py"
    wrapper.write_text(CHECK)
    return wrapper


def timed_run(wrapper: Path, cache: Path, mechanism: Path, backend: str, out: Path
              ) -> tuple[float, str]:
    """One `symkin run` in a fresh process: (wall seconds, its stdout)."""
    env = {**os.environ, "PYTHONPATH": str(wrapper.parent), "SYMKIN_CACHE_DIR": str(cache)}
    command = [sys.executable, str(wrapper), "run", str(mechanism), "--backend", backend,
               "-o", str(out)]
    start = time.perf_counter()
    result = subprocess.run(command, env=env, capture_output=True, text=True, check=False)
    elapsed = time.perf_counter() - start
    if result.returncode != 0:
        sys.exit(f"symkin run failed:\n{result.stderr}")
    return elapsed, result.stdout


def measure(repeat: int, once: Callable[[int], float]) -> tuple[float, float]:
    """(median, fastest) of ``repeat`` calls."""
    times = [once(k) for k in range(repeat)]
    return statistics.median(times), min(times)


def backend_rows(wrapper: Path, work: Path, mechanism: Path, backend: str, repeat: int
                 ) -> list[tuple[str, float, float]]:
    out = work / "out.npz"

    def cold(k: int) -> float:
        return timed_run(wrapper, work / f"cold-{backend}-{k}", mechanism, backend, out)[0]

    shared = work / f"shared-{backend}"
    timed_run(wrapper, shared, mechanism, backend, out)  # fill the build cache and the index

    def no_index(k: int) -> float:
        shutil.rmtree(shared / "index", ignore_errors=True)
        elapsed, stdout = timed_run(wrapper, shared, mechanism, backend, out)
        assert "cached kernel" not in stdout, stdout
        return elapsed

    def warm(k: int) -> float:
        elapsed, stdout = timed_run(wrapper, shared, mechanism, backend, out)
        if "cached kernel" not in stdout or "heavy:[]" not in stdout:
            sys.exit(f"the warm run did not hit the index cleanly:\n{stdout}")
        return elapsed

    return [(f"{backend} {name}", *measure(repeat, run))
            for name, run in (("cold", cold), ("no index", no_index), ("warm", warm))]


def import_rows(repeat: int) -> list[tuple[str, float, float]]:
    def start(code: str) -> Callable[[int], float]:
        def once(k: int) -> float:
            begin = time.perf_counter()
            subprocess.run([sys.executable, "-c", code], check=True)
            return time.perf_counter() - begin
        return once

    empty = measure(repeat, start("pass"))
    rows = [("python -c pass", *empty)]
    for module in IMPORTS:
        median, fastest = measure(repeat, start(f"import {module}"))
        rows.append((f"import {module} (less python -c pass)", median - empty[0],
                     fastest - empty[1]))
    return rows


def table(rows: list[tuple[str, float, float]]) -> str:
    lines = ["| what | median s | fastest s |", "|---|---:|---:|"]
    lines += [f"| {name} | {median:.3f} | {fastest:.3f} |" for name, median, fastest in rows]
    return "\n".join(lines)


def main() -> None:
    options = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    options.add_argument("--repeat", type=int, default=7)
    options.add_argument("--backends", nargs="+", default=["numpy", "c"], choices=("numpy", "c"))
    options.add_argument("--mechanism", type=Path, default=ROOT / "examples" / "crank_slider.yaml")
    args = options.parse_args()
    with tempfile.TemporaryDirectory(prefix="symkin-cold-warm-") as folder:
        work = Path(folder)
        wrapper = snapshot(work / "code")
        rows = []
        for backend in args.backends:
            rows += backend_rows(wrapper, work, args.mechanism.resolve(), backend, args.repeat)
    print(f"`symkin run {args.mechanism.name} -o out.npz`, wall time of a fresh process, "
          f"{args.repeat} runs each\n")
    print(table(rows))
    print("\nImport cost in a fresh interpreter\n")
    print(table(import_rows(args.repeat)))


if __name__ == "__main__":
    main()
