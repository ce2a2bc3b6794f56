"""The fixed numbers of the condition estimator, the error model and Newton's extra steps,
which the runtime (runtime.solving.accuracy, runtime.solving.newton) and the generated C solver
(``<prefix>_solver.c``, its ``#define``s rendered from :data:`SHARED`) both use."""

from __future__ import annotations

UNIT_ROUNDOFF = {"double": 2.0**-52, "float": 2.0**-23}
"""The unit roundoff of each real type (C's DBL_EPSILON and FLT_EPSILON)."""

ESTIMATOR_STEPS = 5
"""Steps of Hager's ascent in the estimate of ||Phi_q^-1||_1
(runtime.solving.accuracy.inverse_norm1)."""

SAFETY = 10.0
"""The error model's estimates are multiplied by this before they are compared with the
targets: the condition estimate may be low by a small factor, and the rounding of Phi is only
known in size."""

TIGHTEN_STEPS = 3
"""Newton iterations allowed after convergence at an ill-conditioned point (its step stalls at
the rounding level within one or two)."""

REESTIMATE_SHIFT = 0.05
"""After those iterations the estimate of ||Phi_q^-1||_1 is not made again where
theta = ||Phi_q^-1||_1 ||Phi_q' - Phi_q||_1 (the old estimate, the change of Phi_q) is at
most this: ||Phi_q'^-1||_1 <= ||Phi_q^-1||_1 / (1 - theta) (the Banach lemma) stands for it.
An exact norm is always made again."""

CHORD_STEPS = 6
"""Simplified Newton steps (Phi alone, the last solve's factors of Phi_q) at most before an
input-driven solve of the generated C evaluates and factors Phi_q: from the last solution,
inputs that moved a little in a servo period need two or three."""

CHORD_CONTRACTION = 0.1
"""A simplified Newton step is taken only while its size is at most this times the last one's:
slower, the factors are too far from Phi_q here, and full Newton takes over."""

BRANCH_REGION = 0.5
"""A solve from the last solution q_prev may have left its assembly when the converged q differs
from q_prev + s, s Newton's first step from q_prev, by more than this fraction of s: in Newton's
region of quadratic convergence the remainder is second order in the step, far below half of
it (runtime.input_driven.branch for a run, the generated C solve_inputs for one call)."""

BRANCH_FLOOR = 1e-8
"""Remainders below BRANCH_FLOOR (1 + max |q|) are never a jump: the inputs barely moved, and
the rounding of two solves would otherwise count as one."""

EDGE_SUBSTEPS = 1000
"""The substeps (each one Newton solve of at most max_iter iterations) that the edge treatment
of one grid point may take in all, over every march it makes (runtime.solving.edges and the
generated C's solve_edge): Newton's total work per time point is bounded, so no driver can keep a
run spinning. Passing a singular configuration or bisecting to a limit position takes some 100;
a driver so fast that each grid step spans thousands of turns is what meets the bound."""


SHARED = {"ESTIMATOR_STEPS": ESTIMATOR_STEPS, "TIGHTEN_STEPS": TIGHTEN_STEPS, "SAFETY": SAFETY,
          "REESTIMATE_SHIFT": REESTIMATE_SHIFT, "EDGE_SUBSTEPS": EDGE_SUBSTEPS}
"""The constants the generated C solver defines too, by name (its macro is ``<PREFIX>_`` + the
name, rendered from this table by codegen.render)."""

INPUTS = {"CHORD_STEPS": CHORD_STEPS, "CHORD_CONTRACTION": CHORD_CONTRACTION,
          "BRANCH_REGION": BRANCH_REGION, "BRANCH_FLOOR": BRANCH_FLOOR}
"""The constants the input-driven solve of the generated C defines too (only a mechanism with
input drivers has one), by name as :data:`SHARED`."""
