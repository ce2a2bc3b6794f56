"""The C backend's build: cffi in API mode writes the extension's C wrapper, and this module
compiles it with the generated sources itself, so a failure keeps the exact command and the
compiler's output. Each build happens in a private temporary folder that is renamed into the
cache in one step (``build.cache``). The cache key covers everything that can change the
binary: the sources, the cffi declarations, the compiler and flags, and the cffi and Python
versions and platform.
"""

from __future__ import annotations

import json
import sys
import sysconfig
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from symkin import resources
from symkin.backends.c import toolchain
from symkin.backends.c.cdef import from_headers as cdef_from_headers
from symkin.backends.c.loader import CKernel, import_extension
from symkin.backends.c.toolchain import run
from symkin.build.cache import build_unless_verified, content_key
from symkin.contract.manifest import manifest_name

# Plain -O2: -ffast-math would break the NaN checks of the solver and reorder sums, and
# -march=native would make a cached binary non-portable.
C_FLAGS = ("-std=c99", "-O2", "-fPIC")
# The cffi wrapper is glue (argument conversion through cffi's backend, one Python-callable
# and one direct entry point per declared function), and the largest file of a small kernel's
# build (143 kB for the crank-slider): at -O2 it took more than half of that build's gcc time
# (0.8 of 1.4 s), at -O0 0.25 s. Only one of its functions runs per symkin.solve call
# (callgrind: 269 instructions at -O0 against 201 at -O2, of about 180,000 a call); the
# generated solver, kernel and LU that it calls keep C_FLAGS and the per-file flags below.
WRAPPER_FLAGS = ("-O0", "-fPIC")
# Per file: the straight-line sparse LU gains nothing from GCC's SLP vectoriser (scattered
# slots), which took most of GCC's time and memory on large mechanisms (at 1001 bodies 46 s
# and 2.3 GB for that file alone; without it 30 s and 0.4 GB).
UNIT_FLAGS = {"_sparse_lu.c": ("-fno-tree-slp-vectorize",)}
# The kernel (<prefix>.c) is straight-line arithmetic whose common subexpressions SymPy has
# already eliminated: -O1 gives the same instructions (callgrind: 22.11 M against 22.09 M for
# the crank-slider's 20001 steps, sincos merged alike) in half of -O2's compile time (301-body
# chain: 6.0 s against 12.0 s).
KERNEL_FLAGS = ("-O1",)
# GCC's dead-store elimination finds nothing in the kernel (every output slot is stored once,
# temporaries are locals) but walked the aliases of every store: a third of the 1001-body
# chain's kernel compile (14.5 s -> 9.2 s). The machine code is the same without it (objdump
# of the 27 committed examples' kernels and of that chain's).
KERNEL_GCC_FLAGS = ("-fno-tree-dse", "-fno-dse")
LARGE_LU_BYTES = 400_000
"""A straight-line sparse LU file larger than this is compiled at -O1: -O2 took 9.2 s on the
1001-body chain's (960 kB), -O1 4.9 s, for 3 % more instructions in the factorization and
solves (1.4 % of a step). The same operations in the same order either way (no fast-math,
no contraction into FMA on the baseline x86-64): the same numbers to the bit. The committed
examples' files are below 130 kB."""
JOBS = 2
"""Compiler processes at once: the generated files are independent translation units."""


def build(files: dict[str, str], name: str, cache: Path, compiler: list[str]) -> CKernel:
    """Build the C files of one kernel into the cache (unless a verified build is there)."""
    cdef = cdef_from_headers(files)
    key = content_key({"files": files, "cdef": cdef, "compiler": compiler, "flags": C_FLAGS,
                       "unit_flags": UNIT_FLAGS,
                       "kernel_flags": [KERNEL_FLAGS, KERNEL_GCC_FLAGS, LARGE_LU_BYTES],
                "wrapper_flags": WRAPPER_FLAGS, **toolchain.fingerprint(compiler)})
    module_name = f"_symkin_{name}_{key[:20]}"
    folder = cache / module_name
    library = folder / (module_name + resources.extension_suffix())
    build_unless_verified(cache, folder, files, lambda build: _build_c(
        build, files, cdef, module_name, compiler, name))
    meta = json.loads(files[manifest_name(name)])
    return import_extension(module_name, library, meta, folder)


def _build_c(build: Path, files: dict[str, str], cdef: str, module_name: str,
             compiler: list[str], prefix: str) -> None:
    import cffi
    from cffi.recompiler import make_c_source

    for name, text in files.items():
        (build / name).write_text(text, encoding="utf-8")
    headers = [f"{prefix}.h"] + sorted(n for n in files if n.endswith(".h") and n != f"{prefix}.h")
    ffi = cffi.FFI()
    ffi.cdef(cdef)
    wrapper = build / f"{module_name}.c"
    preamble = "".join(f'#include "{h}"\n' for h in headers)
    make_c_source(ffi, module_name, preamble, str(wrapper), verbose=False)
    # -iquote: the generated headers are found by #include "..." only, so a generated file can
    # never stand in for a system header included with <...>.
    include = [f"-iquote{build}"] + [f"-I{sysconfig.get_paths()[k]}"
                                     for k in ("include", "platinclude")]
    version = toolchain.compiler_version(tuple(compiler)).lower()
    gcc = ("gcc" in version or version.startswith("cc (")) and "clang" not in version
    jobs = [(compiler, [*C_FLAGS, *_unit_flags(source, prefix, gcc, len(files[source])),
                        *include], build / source)
            for source in sorted(n for n in files if n.endswith(".c"))]
    jobs.append((compiler, [*WRAPPER_FLAGS, *include], wrapper))
    # the largest first, so that the two workers finish together
    jobs.sort(key=lambda job: -job[2].stat().st_size)
    with ThreadPoolExecutor(max_workers=JOBS) as pool:
        objects = sorted(pool.map(lambda job: _object(*job), jobs))
    library = build / (module_name + resources.extension_suffix())
    run([*compiler, *_link_flags(), "-o", str(library), *map(str, objects), "-lm"], build)


def _unit_flags(source: str, prefix: str, gcc: bool, size: int) -> tuple[str, ...]:
    """The extra flags of one generated file of ``size`` characters (GCC's own options only
    with GCC)."""
    if source == f"{prefix}.c":
        return KERNEL_FLAGS + (KERNEL_GCC_FLAGS if gcc else ())
    if not gcc:
        return ()
    flags: tuple[str, ...] = next(
        (flags for suffix, flags in UNIT_FLAGS.items() if source.endswith(suffix)), ())
    if source.endswith("_sparse_lu.c") and size > LARGE_LU_BYTES:
        flags += ("-O1",)
    return flags


def _object(compiler: list[str], flags: list[str], source: Path) -> Path:
    target = source.with_suffix(".o")
    run([*compiler, *flags, "-c", str(source), "-o", str(target)], source.parent)
    return target


def _link_flags() -> list[str]:
    if sys.platform == "darwin":
        return ["-bundle", "-undefined", "dynamic_lookup"]
    return ["-shared"]
