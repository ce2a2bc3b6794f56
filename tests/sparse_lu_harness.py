"""A standalone harness for the generated sparse LU: render, compile with gcc, call via ctypes.

Until the sparse LU is wired into the generated kernel, this stands in for the kernel: it writes
a minimal ``<prefix>.h``/``<prefix>.c`` (the real type, the size macros and the pattern arrays
that the contract puts in the kernel) next to the rendered ``<prefix>_sparse_lu.[ch]``, plus a
small C driver, and builds them into one shared library.
"""

from __future__ import annotations

import ctypes
import subprocess
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import jinja2
import numpy as np

from symkin import backends
from symkin.backends.c import lu_code
from symkin.codegen import lu_plan as sparse_lu

CFLAGS = ["-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror", "-O2", "-fPIC", "-shared"]

_STUB_H = """\
#ifndef {P}_H
#define {P}_H
typedef {real} {p}_real;
#define {P}_NQ {nq}
#define {P}_NNZ {nnz}
extern const int {p}_phi_q_row[{P}_NNZ], {p}_phi_q_col[{P}_NNZ];
#endif
"""

_STUB_C = """\
#include "{p}.h"
const int {p}_phi_q_row[{P}_NNZ] = {{{rows}}};
const int {p}_phi_q_col[{P}_NNZ] = {{{cols}}};
"""

_DRIVER_C = """\
#include <stdlib.h>
#include "{p}_sparse_lu.h"

/* Factor and solve m systems (nz: m x NNZ, b: m x NQ, solved in place; A^T x = b when
 * transposed) with one workspace; status[k] is the factor's return code, dense[k] 1 when
 * system k used the fall-back, ratio[k] the pivot ratio min |u_kk| / max |u_kk|. */
long harness_solve(int m, const double *nz, double *b, int *status, int *dense, int *failed,
                   double *ratio, int transposed)
{{
    {p}_lu *lu = malloc(sizeof *lu);
    long fallbacks;
    int k;
    if (!lu) return -1;
    {p}_lu_init(lu);
    for (k = 0; k < m; ++k) {{
        status[k] = {p}_lu_factor(nz + (long)k * {P}_NNZ, lu);
        dense[k] = lu->dense;
        failed[k] = lu->failed_pivot;
        ratio[k] = {p}_lu_pivot_ratio(lu);
        if (status[k] != 0) continue;
        if (transposed) {{
            {p}_lu_solve_transposed(lu, b + (long)k * {P}_NQ);
        }} else {{
            {p}_lu_solve(lu, b + (long)k * {P}_NQ);
        }}
    }}
    fallbacks = (long)lu->fallbacks;
    free(lu);
    return fallbacks;
}}

/* Timing loop for bench/: factor once and solve three right-hand sides, reps times. */
void harness_repeat(long reps, const double *nz, double *b)
{{
    {p}_lu *lu = malloc(sizeof *lu);
    long r;
    if (!lu) return;
    {p}_lu_init(lu);
    for (r = 0; r < reps; ++r) {{
        {p}_lu_factor(nz, lu);
        {p}_lu_solve(lu, b);
        {p}_lu_solve(lu, b);
        {p}_lu_solve(lu, b);
    }}
    free(lu);
}}
"""


def render(prefix: str, nq: int, rows: Sequence[int], cols: Sequence[int],
           plan: sparse_lu.LUPlan, real: str = "double", style: str | None = None,
           constants: Sequence[float | None] | None = None) -> dict[str, str]:
    """Render the sparse LU templates and the dense LU they fall back to, with a context
    shaped like the codegen stream's."""
    env = jinja2.Environment(loader=jinja2.FileSystemLoader(backends.get("c").template_root),
                             undefined=jinja2.StrictUndefined, trim_blocks=True,
                             lstrip_blocks=True, keep_trailing_newline=True)
    context = {"prefix": prefix, "PREFIX": prefix.upper(), "nq": nq, "nnz": len(rows),
               "n_params": 0, "real": real, "pattern_rows": list(rows),
               "pattern_cols": list(cols), "spec_sha256": "0" * 64,
               "lu": lu_code.template_context(plan, style=style, constants=constants,
                                                real=real, prefix=prefix)}
    return {f"{prefix}_{name[:-3]}": env.get_template(f"templates/{name}").render(
                template=name, header=[f"{prefix}_{name[:-3]}: sparse LU test harness"], **context)
            for name in ("sparse_lu.h.j2", "sparse_lu.c.j2", "dense_lu.h.j2", "dense_lu.c.j2")}


@dataclass
class Library:
    """The compiled harness."""

    lib: ctypes.CDLL
    n: int
    nnz: int
    ratios: np.ndarray | None = None

    def solve(self, nz: np.ndarray, b: np.ndarray, transposed: bool = False
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, int]:
        """Factor/solve a batch (A^T x = b when transposed): returns x, status, dense flags,
        failed pivots, fall-backs (the pivot ratios of the batch are left in
        ``self.ratios``)."""
        nz = np.ascontiguousarray(np.atleast_2d(nz), dtype=float)
        x = np.ascontiguousarray(np.atleast_2d(b), dtype=float).copy()
        m = nz.shape[0]
        status, dense, failed = (np.zeros(m, dtype=np.intc) for _ in range(3))
        self.ratios = np.zeros(m)
        fallbacks = self.lib.harness_solve(m, _ptr(nz), _ptr(x), _iptr(status), _iptr(dense),
                                           _iptr(failed), _ptr(self.ratios), int(transposed))
        return x, status, dense, failed, int(fallbacks)

    def solve_transposed(self, nz: np.ndarray, b: np.ndarray
                         ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Factor and solve A^T x = b for a batch: returns x, status, dense flags."""
        x, status, dense, _, _ = self.solve(nz, b, transposed=True)
        return x, status, dense

    def repeat(self, reps: int, nz: np.ndarray, b: np.ndarray) -> None:
        b = np.ascontiguousarray(b, dtype=float).copy()
        self.lib.harness_repeat(ctypes.c_long(reps), _ptr(np.ascontiguousarray(nz, float)),
                                _ptr(b))


def write_sources(folder: Path, prefix: str, nq: int, rows: Sequence[int], cols: Sequence[int],
                  plan: sparse_lu.LUPlan, real: str = "double", style: str | None = None,
                  constants: Sequence[float | None] | None = None) -> list[Path]:
    """Write the rendered sparse LU and the stub kernel; return the C sources to compile."""
    folder.mkdir(parents=True, exist_ok=True)
    names = {"p": prefix, "P": prefix.upper(), "nq": nq, "nnz": len(rows), "real": real,
             "rows": ", ".join(map(str, rows)), "cols": ", ".join(map(str, cols))}
    files = render(prefix, nq, rows, cols, plan, real, style, constants)
    files[f"{prefix}.h"] = _STUB_H.format(**names)
    files[f"{prefix}.c"] = _STUB_C.format(**names)
    for name, text in files.items():
        (folder / name).write_text(text)
    return [folder / f"{prefix}{suffix}.c" for suffix in ("", "_sparse_lu", "_dense_lu")]


def compile_library(sources: Sequence[Path], library: Path, flags: Sequence[str] = ()) -> None:
    """gcc with the contract's warning flags; the command and stderr in the error."""
    command = ["gcc", *CFLAGS, *flags, "-I", str(library.parent), *map(str, sources), "-o",
               str(library), "-lm"]
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(command)}\n{done.stderr}")


def build(folder: Path, prefix: str, nq: int, rows: Sequence[int], cols: Sequence[int],
          plan: sparse_lu.LUPlan, extra_flags: Sequence[str] = (), style: str | None = None,
          constants: Sequence[float | None] | None = None) -> Library:
    """Render, write and compile the sparse LU with the stub kernel; load it with ctypes.
    ``constants``: the non-zeros known to be numbers (the LU then ignores nz's values there)."""
    sources = write_sources(folder, prefix, nq, rows, cols, plan, style=style,
                            constants=constants)
    (folder / "harness.c").write_text(_DRIVER_C.format(p=prefix, P=prefix.upper()))
    library = folder / f"lib{prefix}_harness.so"
    compile_library([*sources, folder / "harness.c"], library, extra_flags)
    lib = ctypes.CDLL(str(library))
    lib.harness_solve.restype = ctypes.c_long
    return Library(lib, nq, len(rows))


def _ptr(array: np.ndarray) -> ctypes.c_void_p:
    return array.ctypes.data_as(ctypes.c_void_p)


def _iptr(array: np.ndarray) -> ctypes.c_void_p:
    return array.ctypes.data_as(ctypes.c_void_p)
