"""The status codes of one solved time point, shared by the runtime's Newton and the generated
C solver (``<PREFIX>_OK`` ... in ``<prefix>_solver.h``, rendered from :data:`CODES`)."""

from __future__ import annotations

OK = 0
"""Converged."""
NO_CONVERGENCE = 1
"""The iteration cap was reached, or the iterates diverged."""
SINGULAR = 2
"""Phi_q is singular or ill-conditioned."""
NOT_FINITE = 3
"""Phi at the predicted q, or the velocity or acceleration, is inf or NaN, i.e. an expression
of the mechanism is singular at that time (a time function such as 1/(t - 0.5))."""

BAD_OPTIONS = 4
"""Generated C only: an option breaks its rule (contract.options.RULES: NaN, a tolerance or
target <= 0, unit <= 0, ...); nothing was solved and the state is as it was. The runtime never
meets it: Options refuses such values when it is made."""

BAD_INPUT = 5
"""Generated C ``solve_inputs`` only: an input breaks its rule (a length, a distance driver's
f, is negative: its row holds the square, so it would be solved as its absolute value);
nothing was solved and the state is as it was. The runtime refuses such inputs before any
call (runtime.input_driven.inputs.negative_length)."""

INPUT_CODES = {"BAD_INPUT": BAD_INPUT}
"""The status only a mechanism with length inputs can return (its header alone defines it)."""

CODES = {"OK": OK, "NO_CONVERGENCE": NO_CONVERGENCE, "SINGULAR": SINGULAR,
         "NOT_FINITE": NOT_FINITE, "BAD_OPTIONS": BAD_OPTIONS}
"""Every status by its name (the C macro is ``<PREFIX>_`` + the name)."""
