"""Stage 5 — build: generate the code of a System and hand it to its backend, which builds
(or finds in the cache, keyed by content) and loads the Kernel.

How a rendered folder becomes a kernel is the backend's (``Backend.build``: a compiled
extension, an imported module, a running interpreter); every build happens in a private
temporary folder renamed into the cache in one step (``build.cache``), so any number of
processes building the same kernel at once all succeed and none ever sees a half-written one.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from symkin.build.backend import Backend
from symkin.build.cache import open_cache
from symkin.codegen import lower, render
from symkin.runtime.kernel import Kernel
from symkin.symbolic.derivation import System


def compile(system: System, backend: Backend, options: Mapping[str, str] | None = None, *,
            cse: bool = True, cache_dir: str | Path | None = None) -> Kernel:
    """Generate, build (or find in the cache) and load the kernel of ``system``.

    Args:
        system: the derived kinematics.
        backend: the backend (``symkin.backends.resolve`` turns a name or ``"auto"`` into
            one; ``symkin.compile`` takes the name).
        options: the backend's own options by name (``backend.options`` declares them;
            the rest take their defaults).
        cse: eliminate common subexpressions.
        cache_dir: where built kernels are kept; default ``build.cache.cache_root``.

    Raises:
        BuildError: an option the backend does not take, or generation or the build failed
            (a compiler's message has the command and its output).
        NoCompilerError: the backend needs a compiler and none is found.
    """
    backend.require()
    cache = open_cache(cache_dir)
    return backend.build(render.rendered(lower.lower(system, backend, options, cse)), cache)
