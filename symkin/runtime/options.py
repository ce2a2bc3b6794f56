"""Newton's tolerances and the singularity test, with their defaults per real type, and the
status codes shared with the generated C solver. Defined once: the generated C's
``<prefix>_default_options`` is rendered from :data:`DEFAULTS` (codegen.render)."""

from __future__ import annotations

from dataclasses import dataclass

# Status codes shared with the generated C solver (templates/c/solver.h.j2).
# NOT_FINITE: Phi at the predicted q, or the velocity or acceleration, is inf or NaN, i.e. an
# expression of the mechanism is singular at that time (a time function such as 1/(t - 0.5)).
OK, NO_CONVERGENCE, SINGULAR, NOT_FINITE = 0, 1, 2, 3


@dataclass(frozen=True)
class Options:
    """Newton tolerances and the singularity test.

    Args:
        tol_phi: converged when max |Phi| of the current iterate is at most this...
        tol_dq: ...and the last Newton step max |dq| is at most this.
        max_iterations: Newton iterations allowed per time point.
        min_pivot_ratio: Phi_q counts as singular when min |u_kk| / max |u_kk| of its LU
            factors falls below this (a cheap estimate of the reciprocal condition number).
    """

    tol_phi: float = 1e-10
    tol_dq: float = 1e-9
    max_iterations: int = 25
    min_pivot_ratio: float = 1e-10


# The defaults per real type, defined once: the generated C's <prefix>_default_options is
# rendered from this table (codegen.render), so Python and C can never disagree.
DEFAULTS = {
    "double": Options(),
    "float": Options(tol_phi=1e-5, tol_dq=1e-4, min_pivot_ratio=1e-6),
}


def defaults(real: str) -> Options:
    """The Newton options for a kernel computing in ``real`` ("double" or "float")."""
    return DEFAULTS[real]
