"""The public API's entry points that take a backend by name (``symkin.generate``,
``symkin.compile``): the name is resolved through the registry of :mod:`symkin.backends`
here, at the boundary, and the stages get the backend object."""

from __future__ import annotations

from pathlib import Path

from symkin import backends
from symkin.build import motion
from symkin.build.compile import compile as compile_system
from symkin.codegen import lower, render
from symkin.runtime.dynamics.model import MotionKernel
from symkin.runtime.kernel import Kernel
from symkin.symbolic.derivation import System


def generate(system: System, backend: str = "c", out_dir: str | Path = "generated",
             real: str = "double", cse: bool = True,
             linalg: str = lower.DEFAULT_LINALG, force: bool = False) -> list[Path]:
    """Generate the source files of one backend into ``out_dir`` (``codegen.render.generate``).

    Args:
        system: the derived kinematics.
        backend: a registered backend's name: ``"c"`` (a self-contained C99 folder; writing
            it needs no compiler) or ``"numpy"`` (one Python module); ``"auto"`` as for
            :func:`compile`.
        out_dir, real, cse, linalg, force: see ``codegen.render.generate``.

    Raises:
        BuildError: an unknown backend name.
        UsageError: ``out_dir`` holds files symkin did not write (and not ``force``).
    """
    chosen = backends.resolve(backend) if backend == backends.AUTO else backends.get(backend)
    return render.generate(system, chosen, out_dir, real=real, cse=cse, linalg=linalg,
                           force=force)


def compile(system: System, backend: str = backends.AUTO, *, real: str = "double",
            cse: bool = True, linalg: str = lower.DEFAULT_LINALG,
            cache_dir: str | Path | None = None) -> Kernel | MotionKernel:
    """Generate, compile (or find in the cache) and load the kernel of ``system``.

    Args:
        system: the derived kinematics.
        backend: ``"auto"`` (default: C when a compiler is found, else NumPy with a note),
            or a registered backend's name: ``"c"`` (cffi extension; an error without a
            compiler), ``"numpy"`` (generated Python module).
        real: the C real type, ``"double"`` or ``"float"``.
        cse: eliminate common subexpressions.
        linalg: the LU behind the C solver, ``"sparse"`` (default) or ``"dense"``.
        cache_dir: where built kernels are kept; default ``build.cache.cache_root``.

    Raises:
        BuildError: an unknown backend name, or the compiler failed (the message has the
            command and its output).
        NoCompilerError: ``backend="c"`` and no C compiler is found.

    A mechanism its forces move (fewer drivers than freedoms, symbolic.motion) gives a
    MotionKernel: the integrator of runtime.dynamics evaluating the equations of motion
    through this backend's compiled kernel (C or NumPy; Octave is refused with a
    UsageError).
    """
    chosen = backends.resolve(backend)
    if motion.moves_under_forces(system):
        return motion.kernel(system, chosen, real=real, cse=cse, linalg=linalg,
                             cache_dir=cache_dir)
    return compile_system(system, chosen, real=real, cse=cse, linalg=linalg,
                         cache_dir=cache_dir)

