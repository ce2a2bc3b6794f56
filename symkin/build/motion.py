"""The kernel of a mechanism its forces move (forward dynamics, runtime.dynamics).

The backend asked for generates and builds the kernel as for kinematics (its M, Q - h, Φ,
Φ_q, Φ_t, Γ, loads and senses run as compiled code: runtime.dynamics.compiled); the energy
terms and initial velocities the generated code has no routine for come from the System
(symbolic.motion_numeric.remainder). A backend that generates no equations of motion (no
``equations_of_motion`` flag: Octave's) is refused before anything is built.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from symkin.build.backend import Backend
from symkin.build.compile import compile as compile_system
from symkin.codegen.target import chosen_options
from symkin.errors import BackendRefused
from symkin.runtime.dynamics.compiled import CompiledModel
from symkin.runtime.dynamics.model import MotionKernel
from symkin.symbolic import motion_numeric
from symkin.symbolic.motion import moves_under_forces

__all__ = ["kernel", "moves_under_forces"]


def kernel(system: Any, backend: Backend, options: Mapping[str, str] | None = None, *,
           cse: bool = True, cache_dir: str | Path | None = None) -> MotionKernel:
    """The MotionKernel of ``system`` on ``backend`` (``options``, ``cse``, ``cache_dir`` as
    build.compile's).

    Raises:
        BackendRefused: the backend generates no equations of motion, or ``real`` is not
            double (the projection's tolerance is below a float's resolution).
        MechanismError: an input driver (symbolic.motion), before anything is built.
    """
    if not getattr(backend, "equations_of_motion", False):
        raise BackendRefused(
            f"{system.name} has fewer drivers than freedoms and moves under its forces, but "
            f"the {backend.title} backend generates no mass matrix or applied forces to "
            "integrate it with: run it with --backend c or --backend numpy "
            "(symkin.compile(..., backend='c' or 'numpy'))")
    real = chosen_options(backend, options).get("real", "double")
    if real != "double":
        raise BackendRefused(
            f"{system.name} moves under its forces: its motion is integrated in double (the "
            f"projection onto the constraints works to 1e-11), not in {real}. Leave real at "
            "double; symkin generate writes the float <prefix>_dynamics_step for a controller")
    # first: it refuses what the motion cannot have (input drivers) before anything is built
    rest = motion_numeric.remainder(system)
    compiled = compile_system(system, backend, options, cse=cse, cache_dir=cache_dir)
    if not compiled.has_mass:  # a plug-in that says so but generates none
        raise BackendRefused(f"the {backend.title} kernel of {system.name} has no mass matrix: "
                             "run it with --backend c or --backend numpy")
    return MotionKernel(CompiledModel(compiled, rest), compiled.backend)
