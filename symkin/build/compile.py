"""Stage 5 — build: generate the code of a System and hand it to its backend, which builds
(or finds in the cache, keyed by content) and loads the Kernel.

How a rendered folder becomes a kernel is the backend's (``Backend.build``: cffi for C, an
import for NumPy); every build happens in a private temporary folder renamed into the cache in
one step (``build.cache``), so any number of processes building the same kernel at once all
succeed and none ever sees a half-written one.
"""

from __future__ import annotations

from pathlib import Path

from symkin.build.backend import Backend
from symkin.build.cache import open_cache
from symkin.codegen import lower, render
from symkin.contract.manifest import manifest_name
from symkin.runtime.kernel import Kernel
from symkin.symbolic.derivation import System


def compile(system: System, backend: Backend, *, real: str = "double", cse: bool = True,
            linalg: str = lower.DEFAULT_LINALG, cache_dir: str | Path | None = None
            ) -> Kernel:
    """Generate, build (or find in the cache) and load the kernel of ``system``.

    Args:
        system: the derived kinematics.
        backend: the backend (``symkin.backends.resolve`` turns a name or ``"auto"`` into
            one; ``symkin.compile`` takes the name).
        real: the real type, ``"double"`` or ``"float"`` (C only).
        cse: eliminate common subexpressions.
        linalg: the LU behind the C solver, ``"sparse"`` (default) or ``"dense"``.
        cache_dir: where built kernels are kept; default ``build.cache.cache_root``.

    Raises:
        BuildError: generation or the build failed (a compiler's message has the command and
            its output).
        NoCompilerError: the backend needs a compiler and none is found.
    """
    backend.require()
    cache = open_cache(cache_dir)
    code = lower.lower(system, backend, real, cse, linalg)
    files = render.render_sources(code)
    files[manifest_name(code.name)] = render.manifest(code, files)
    return backend.build(files, cache)
