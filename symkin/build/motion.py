"""The kernel of a mechanism its forces move (forward dynamics, runtime.dynamics).

Until the generated code carries the equations of motion, such a kernel evaluates them
through NumPy functions lambdified from the System (symbolic.motion_numeric); its backend
name says so (``lambdified``), and a C request is refused rather than answered by NumPy.
"""

from __future__ import annotations

from typing import Any

from symkin.errors import BuildError
from symkin.runtime.dynamics.model import MotionKernel
from symkin.symbolic import motion_numeric
from symkin.symbolic.motion import moves_under_forces

BACKEND = "lambdified"
# what a caller passes who takes whatever runs (the CLI, which then says which ran)
ANY = "any"
# the backends whose request a lambdified kernel answers ("auto": whatever runs here)
ANSWERS = ("auto", "numpy", ANY)

__all__ = ["ANY", "BACKEND", "kernel", "moves_under_forces"]


def kernel(system: Any, backend: str) -> MotionKernel:
    """The MotionKernel of ``system``; ``backend``: the name asked for."""
    if backend not in ANSWERS:
        raise BuildError(f"symkin.solve cannot integrate a mechanism its forces move (fewer "
                         f"drivers than freedoms) on the {backend!r} backend yet: use the numpy "
                         "backend (--backend numpy); symkin.generate writes that backend's "
                         "<prefix>_dynamics_step for a real-time loop")
    return MotionKernel(motion_numeric.numeric(system), BACKEND)
