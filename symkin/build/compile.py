"""Stage 5 — build: compile the generated code into a loadable Kernel, cached by content hash.

The C backend uses cffi in API mode: cffi writes the extension's C wrapper, and this module
compiles it with the generated sources itself, so a failure keeps the exact command and the
compiler's output. Each build happens in a private temporary folder that is renamed into the
cache in one step, so any number of processes building the same kernel at once all succeed and
none ever sees a half-written one. The cache key covers everything that can change the binary:
the sources, the cffi declarations, the compiler and flags, and the cffi and Python versions
and platform.
"""

from __future__ import annotations

import importlib.machinery
import importlib.util
import json
import shlex
import subprocess
import sys
import sysconfig
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from types import ModuleType
from typing import Any

from symkin import resources
from symkin.build import toolchain
from symkin.build.cache import content_key, open_cache, publish, verified
from symkin.build.toolchain import BACKENDS, resolve_backend
from symkin.codegen import lower as codegen
from symkin.codegen import render
from symkin.codegen.cdef import from_headers as cdef_from_headers
from symkin.contract.manifest import MANIFEST_SUFFIX, manifest_name
from symkin.errors import BuildError
from symkin.runtime import kernel
from symkin.symbolic.derivation import System

# Plain -O2: -ffast-math would break the NaN checks of the solver and reorder sums, and
# -march=native would make a cached binary non-portable.
C_FLAGS = ("-std=c99", "-O2", "-fPIC")
WRAPPER_FLAGS = ("-O2", "-fPIC")
# Per file: the straight-line sparse LU gains nothing from GCC's SLP vectoriser (scattered
# slots), which took most of GCC's time and memory on large mechanisms (at 1001 bodies 46 s
# and 2.3 GB for that file alone; without it 30 s and 0.4 GB).
UNIT_FLAGS = {"_sparse_lu.c": ("-fno-tree-slp-vectorize",)}
# The kernel (<prefix>.c) is straight-line arithmetic whose common subexpressions SymPy has
# already eliminated: -O1 gives the same instructions (callgrind: 22.11 M against 22.09 M for
# the crank-slider's 20001 steps, sincos merged alike) in half of -O2's compile time (301-body
# chain: 6.0 s against 12.0 s).
KERNEL_FLAGS = ("-O1",)
JOBS = 2
"""Compiler processes at once: the generated files are independent translation units."""


def compile(system: System, backend: str = "auto", *, real: str = "double", cse: bool = True,
            linalg: str = codegen.DEFAULT_LINALG, cache_dir: str | Path | None = None
            ) -> kernel.Kernel:
    """Generate, compile (or find in the cache) and load the kernel of ``system``.

    Args:
        system: the derived kinematics.
        backend: ``"auto"`` (default: C when a compiler is found, else NumPy with a note),
            ``"c"`` (cffi extension; an error without a compiler) or ``"numpy"`` (generated
            Python module).
        real: the C real type, ``"double"`` or ``"float"``.
        cse: eliminate common subexpressions.
        linalg: the LU behind the C solver, ``"sparse"`` (default) or ``"dense"``.
        cache_dir: where built kernels are kept; default :func:`cache_root`.

    Raises:
        BuildError: the compiler failed (the message has the command and its output).
        NoCompilerError: ``backend="c"`` and no C compiler is found.
    """
    if backend not in BACKENDS:
        raise BuildError(f"unknown backend {backend!r}; choose one of {', '.join(BACKENDS)}")
    backend = resolve_backend(backend)
    cache = open_cache(cache_dir)
    if backend == "c":
        compiler = toolchain.c_compiler()
        assert compiler is not None  # resolve_backend chose C because there is one
        return _compile_c(codegen.lower(system, "c", real, cse, linalg), cache, compiler)
    return _load_numpy(codegen.lower(system, backend, real, cse), cache)


# ----- C backend -----------------------------------------------------------------------------

def _compile_c(code: codegen.Code, cache: Path, compiler: list[str]) -> kernel.Kernel:
    files = render.render_sources(code)
    files[manifest_name(code.name)] = render.manifest(code, files)
    return _compile_files(files, code.name, cache, compiler)


def from_sources(files: dict[str, str], cache_dir: str | Path | None = None) -> kernel.Kernel:
    """Build (or find in this machine's cache) and load a kernel from its generated files.

    ``files`` is a generated folder as text, its manifest included (what a sweep sends to the
    processes and cluster workers that solve it); no derivation, so no SymPy. The files are
    keyed and verified exactly as ``compile`` keys and verifies its own.

    Raises:
        BuildError: the files hold no symkin manifest, or the compiler failed.
        NoCompilerError: they are C and this machine has no C compiler.
    """
    manifests = [name for name in files if name.endswith(MANIFEST_SUFFIX)]
    if len(manifests) != 1:
        raise BuildError(f"expected one symkin manifest among the files, found {len(manifests)}")
    meta = json.loads(files[manifests[0]])
    name = meta.get("name")
    plain = all(isinstance(n, str) and Path(n).name == n and not n.startswith(".")
                for n in files)
    if not (isinstance(name, str) and name.isidentifier() and plain
            and manifests[0] == manifest_name(name)
            and set(files) == {*meta.get("files", {}), manifests[0]}):
        raise BuildError("the files are not one generated symkin folder (names, manifest and "
                         "file list must agree); send the folder symkin.compile built")
    cache = open_cache(cache_dir)
    if meta["backend"] == "numpy":
        sources = {name: text for name, text in files.items() if name != manifests[0]}
        key = content_key({"files": sources})
        folder = cache / f"_symkin_{meta['name']}_py_{key[:20]}"
        _build_unless_verified(cache, folder, files, lambda build: _write_files(build, files))
        source = folder / f"{meta['name']}.py"
        return kernel.from_module(kernel.import_file(folder.name, source, None), folder)
    compiler = toolchain.c_compiler()
    if compiler is None:
        resolve_backend("c")  # raises NoCompilerError with the how-to-install message
    assert compiler is not None
    return _compile_files(files, meta["name"], cache, compiler)


def _write_files(folder: Path, files: dict[str, str]) -> None:
    for name, text in files.items():
        (folder / name).write_text(text, encoding="utf-8", newline="\n")


def _compile_files(files: dict[str, str], name: str, cache: Path, compiler: list[str]
                   ) -> kernel.Kernel:
    """Build the C files of one kernel into the cache (unless a verified build is there)."""
    cdef = cdef_from_headers(files)
    key = content_key({"files": files, "cdef": cdef, "compiler": compiler, "flags": C_FLAGS,
                       "unit_flags": UNIT_FLAGS,
                       "kernel_flags": KERNEL_FLAGS,
                "wrapper_flags": WRAPPER_FLAGS, **toolchain.fingerprint(compiler)})
    module_name = f"_symkin_{name}_{key[:20]}"
    folder = cache / module_name
    library = folder / (module_name + resources.extension_suffix())
    _build_unless_verified(cache, folder, files, lambda build: _build_c(
        build, files, cdef, module_name, compiler, name))
    module = _import_extension(module_name, library)
    meta = json.loads(files[manifest_name(name)])
    return kernel.from_cffi(module.ffi, module.lib, meta, folder)


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
    jobs = [(compiler, [*C_FLAGS, *_unit_flags(source, prefix, gcc), *include], build / source)
            for source in sorted(n for n in files if n.endswith(".c"))]
    jobs.append((compiler, [*WRAPPER_FLAGS, *include], wrapper))
    # the largest first, so that the two workers finish together
    jobs.sort(key=lambda job: -job[2].stat().st_size)
    with ThreadPoolExecutor(max_workers=JOBS) as pool:
        objects = sorted(pool.map(lambda job: _object(*job), jobs))
    library = build / (module_name + resources.extension_suffix())
    run([*compiler, *_link_flags(), "-o", str(library), *map(str, objects), "-lm"], build)


def _unit_flags(source: str, prefix: str, gcc: bool) -> tuple[str, ...]:
    """The extra flags of one generated file (GCC's own options only with GCC)."""
    if source == f"{prefix}.c":
        return KERNEL_FLAGS
    if not gcc:
        return ()
    return next((flags for suffix, flags in UNIT_FLAGS.items() if source.endswith(suffix)), ())


def _object(compiler: list[str], flags: list[str], source: Path) -> Path:
    target = source.with_suffix(".o")
    run([*compiler, *flags, "-c", str(source), "-o", str(target)], source.parent)
    return target


def _link_flags() -> list[str]:
    if sys.platform == "darwin":
        return ["-bundle", "-undefined", "dynamic_lookup"]
    return ["-shared"]


class CompilerError(BuildError):
    """The C compiler failed: ``command`` is what ran, ``stderr`` what it said."""

    def __init__(self, command: list[str], returncode: int, stderr: str) -> None:
        self.command = command
        self.returncode = returncode
        self.stderr = stderr
        super().__init__(f"the C compiler failed (exit status {returncode}):\n"
                         f"  {shlex.join(command)}\n{stderr.strip()}")


def run(command: list[str], cwd: Path) -> None:
    """Run a compiler command; on failure raise CompilerError with the command and its output."""
    try:
        result = subprocess.run(command, cwd=cwd, capture_output=True, text=True, check=False)
    except OSError as error:
        raise BuildError(f"could not run {shlex.join(command)}: {error}") from None
    if result.returncode != 0:
        raise CompilerError(command, result.returncode, result.stderr)


def _import_extension(module_name: str, library: Path) -> ModuleType:
    loader = importlib.machinery.ExtensionFileLoader(module_name, str(library))
    return kernel.import_file(module_name, library, loader)


# ----- NumPy backend -------------------------------------------------------------------------

def _load_numpy(code: codegen.Code, cache: Path) -> kernel.Kernel:
    files = render.render_sources(code)
    key = content_key({"files": files})
    module_name = f"_symkin_{code.name}_py_{key[:20]}"
    folder = cache / module_name
    source = folder / f"{code.name}.py"
    expected = {**files, manifest_name(code.name): render.manifest(code, files)}
    _build_unless_verified(cache, folder, expected, lambda build: render.write(code, build))
    return kernel.from_module(kernel.import_file(module_name, source, None), folder)


def _build_unless_verified(cache: Path, folder: Path, expected: dict[str, str],
                           build: Callable[[Path], Any]) -> None:
    """Publish a fresh build unless ``folder`` holds a verified one (see build.cache); a
    folder that fails verification, whoever put it there, is never loaded."""
    if verified(folder, expected):
        return
    publish(cache, folder, build)
    if not verified(folder, expected):
        raise BuildError(f"the kernel folder {folder} changed while it was being built; "
                         "run again, and make sure no other user can write to the cache")


