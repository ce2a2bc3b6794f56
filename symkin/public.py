"""The public API's entry points that take a backend by name (``symkin.generate``,
``symkin.compile``): the name is resolved through the registry of :mod:`symkin.backends`
here, at the boundary, and the stages get the backend object."""

from __future__ import annotations

from pathlib import Path

from symkin import backends
from symkin.build import motion
from symkin.build.compile import compile as compile_system
from symkin.codegen import render
from symkin.runtime.dynamics.model import MotionKernel
from symkin.runtime.kernel import Kernel
from symkin.symbolic.derivation import System


def generate(system: System, backend: str = "c", out_dir: str | Path = "generated", *,
             cse: bool = True, force: bool = False, **options: str) -> list[Path]:
    """Generate the source files of one backend into ``out_dir`` (``codegen.render.generate``).

    Args:
        system: the derived kinematics.
        backend: a registered backend's name (``symkin.backends.names()``; writing source
            needs no compiler); ``"auto"`` as for :func:`compile`.
        out_dir, cse, force: see ``codegen.render.generate``.
        **options: the backend's own options by name, such as a real type (each backend's
            ``options`` field declares what it takes).

    Raises:
        BuildError: an unknown backend name, or an option the backend does not take.
        UsageError: ``out_dir`` holds files symkin did not write (and not ``force``).
    """
    chosen = backends.resolve(backend) if backend == backends.AUTO else backends.get(backend)
    return render.generate(system, chosen, out_dir, options, cse=cse, force=force)


def compile(system: System, backend: str = backends.AUTO, *, cse: bool = True,
            cache_dir: str | Path | None = None, **options: str) -> Kernel | MotionKernel:
    """Generate, compile (or find in the cache) and load the kernel of ``system``.

    Args:
        system: the derived kinematics.
        backend: ``"auto"`` (default: the first registered backend that builds here, with a
            note when a preferred one cannot), or a registered backend's name
            (``symkin.backends.names()``; an error when it cannot build here).
        cse: eliminate common subexpressions.
        cache_dir: where built kernels are kept; default ``build.cache.cache_root``.
        **options: the backend's own options by name, such as a real type or the LU behind
            its solver (each backend's ``options`` field declares what it takes).

    Raises:
        BuildError: an unknown backend name, an option the backend does not take, or the
            build failed (a compiler's message has the command and its output).
        NoCompilerError: the backend needs a compiler and none is found.

    A mechanism its forces move (fewer drivers than freedoms, symbolic.motion) gives a
    MotionKernel: the integrator of runtime.dynamics evaluating the equations of motion
    through this backend's compiled kernel (a backend whose generated code has no equations
    of motion is refused with a BackendRefused).
    """
    chosen = backends.resolve(backend)
    if motion.moves_under_forces(system):
        return motion.kernel(system, chosen, options, cse=cse, cache_dir=cache_dir)
    return compile_system(system, chosen, options, cse=cse, cache_dir=cache_dir)
