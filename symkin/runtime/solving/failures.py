"""The messages of a failed solve: where, why, and what to try — for a point that does not
converge, a singular Phi_q (with its rank loss and minimal dependent rows), an expression not
finite at some t, a mechanism that cannot be assembled, and a motion that stops at a limit
position. Imports NumPy only: part of the runtime."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from symkin.contract.options import defaults
from symkin.contract.status import NO_CONVERGENCE, NOT_FINITE, SINGULAR
from symkin.contract.tuning import EDGE_SUBSTEPS
from symkin.limits import listed, listed_groups
from symkin.runtime.protocol import KinematicsKernel
from symkin.runtime.solving.assembly import Assembly
from symkin.runtime.solving.edges import Resolution
from symkin.runtime.solving.linalg import dependencies
from symkin.runtime.solving.newton import Newton
from symkin.runtime.solving.start import Singular

Array = NDArray[np.float64]

# Diagnosis only (never a stopping test): condition numbers of Phi_q taken as singular at a
# failed iterate, and as "nearly singular" at the last point solved before a failure.
ILL_CONDITIONED, NEARLY_SINGULAR = 1e8, 1e5


def explain(kernel: KinematicsKernel, p: Array, result: Newton, t: float, assembling: bool,
            assembly: Assembly | None, last: tuple[float, Array] | None
            ) -> tuple[str, str, list[str]]:
    """Why a solve failed at t: (message, reason, dependent rows). ``last`` is the last point
    solved before t (its time and q), if any."""
    where = f"at t = {t:.10g}"
    not_finite = _not_finite(kernel, result.q, t, p) if result.status in (NOT_FINITE, SINGULAR) \
        else None
    # Not assembled (the residual is not small): Phi_q singular at the guess is no dead centre.
    unassembled = assembly is not None and not result.residual <= max(options_tol(kernel), 1e-6)
    rows, near = ([], None) if not_finite or unassembled else \
        _singular_rows(kernel, last, p, result, t)
    facts = f"(residual max|Phi| = {result.residual:.3g} after {result.iterations} iterations)"
    if not_finite:
        reason = "not finite"
        message = (f"{not_finite} is not finite {where}: an expression in it is singular there "
                   "(a division by zero, the root or logarithm of a negative number, or a "
                   "derivative of such). End the time grid before it, or change the expression.")
    elif assembling and not rows:
        reason = "no assembly"
        message = _no_assembly(kernel, result, t, p, assembly)
    elif rows:
        reason = "singular"
        when = where if near is None else (f"near t = {near:.10g}, the last point solved; "
                                           f"Newton-Raphson then failed {where}")
        message = (f"Phi_q is singular {when} {facts}: {rows[0]}. This is a dead-centre or "
                   "toggle position, a redundant joint, or a driver that cannot move the "
                   "mechanism here; " + (
                       "keep the inputs off it, or drive the mechanism through other joints."
                       if _inputs(kernel) else
                       "end the time grid before it, or change the drivers."))
    else:
        reason = "no convergence"
        message = (f"Newton-Raphson did not converge {where} {facts}. " + (
            "Give inputs closer together (a reading this far from the last one leaves "
            "Newton's reach), or check that they are reachable." if _inputs(kernel) else
            "Try a smaller time step dt, or check that the drivers are smooth and reachable."))
    return message, reason, rows[1:]


def _inputs(kernel: KinematicsKernel) -> bool:
    """Whether the kernel's drivers read inputs (the advice is then about them, not dt)."""
    return bool(getattr(kernel, "input_names", ()))


def options_tol(kernel: KinematicsKernel) -> float:
    return defaults(getattr(kernel, "real", "double")).tol_phi


def _no_assembly(kernel: KinematicsKernel, result: Newton, t: float, p: Array,
                 assembly: Assembly | None) -> str:
    """Cannot be assembled: how close the best start came, the joints that cannot close, and
    whether the evidence points at the link lengths or at a better q0."""
    worst = _worst_rows(kernel.phi(result.q, t, p), list(kernel.rows))
    if assembly is None or not assembly.residuals:
        return (f"the mechanism cannot be assembled at t = {t:.10g} (residual max|Phi| = "
                f"{result.residual:.3g}): the largest violations are in {worst}. Check the link "
                "lengths, or give a better q0 in the mechanism file.")
    residuals = assembly.residuals
    least = min(residuals)
    if assembly.evidence == "link lengths":
        alike = sum(1 for r in residuals if r <= 1.05 * least + 1e-9)
        why = (f"the evidence points at the link lengths: {alike} of {len(residuals)} starts end "
               "at this same least residual, as when a chain is too short or too long to "
               "close. Check the dimensions")
    else:
        why = (f"the evidence points at a better q0: the starts end at different residuals "
               f"({least:.3g} to {max(residuals):.3g}), local minima of a mechanism that may "
               "well assemble. Give a q0 close to an assembled configuration (a rough sketch "
               "is enough)")
    return (f"the mechanism cannot be assembled at t = {t:.10g}: from {len(residuals)} "
            "starts (Newton and damped Newton from q0, the bodies placed along their joints, "
            f"q0 perturbed, random angles) the least residual max|Phi| is {least:.3g}, "
            f"and the joints that cannot close are {worst}; {why}.")


def explain_stop(stop: Resolution, t: float) -> tuple[str, str]:
    """Why the motion stopped before the grid point t: (message, reason)."""
    reached = stop.reached
    assert reached is not None
    last, failed = reached.t, stop.failed_at
    if stop.substeps >= EDGE_SUBSTEPS:
        reason = "too many substeps"
        message = (f"the grid point t = {t:.10g} was not reached within {EDGE_SUBSTEPS} "
                   f"substeps (the last reached t = {last:.10g}, a step of {failed - last:.3g} "
                   "from it still failing): the motion between grid points is too fast or "
                   "too rough for the step. Check the drivers' functions (a rate such as "
                   "1e6*t turns thousands of times per step), or use a smaller --dt.")
    elif stop.limit:
        reason = "limit position"
        message = (f"the driven motion reaches a limit position near t = {last:.10g} (bisected "
                   f"to {last:.13g} .. {failed:.13g}; the grid point t = {t:.10g} is beyond "
                   f"it): {listed(stop.aligned)} become aligned, and "
                   f"{listed(stop.drivers, ' and ')} cannot be followed beyond it (Phi_q loses "
                   f"rank 1 there, condition {reached.point.cond:.3g}). The motion can go on "
                   "only by reversing the driver from this time (the mechanism then moves back "
                   "on its other branch), or by driving one of the aligned joints instead, "
                   "which passes through this position smoothly; or end the time grid before "
                   "it.")
    else:
        reason = "no convergence"
        message = (f"Newton-Raphson did not converge at t = {t:.10g}, not even with the step "
                   f"reduced to {failed - last:.3g} after t = {last:.10g}; Phi_q is "
                   f"well-conditioned there (condition {reached.point.cond:.3g}), so this is "
                   "not a singular position: check that the drivers are smooth and reachable.")
    return message, reason


def explain_start(start: Singular, t: float) -> str:
    """Why the motion is not stepped from its assembled start at t."""
    aligned = listed(start.aligned) or "no joint"
    drivers = listed(start.drivers, " and ") or "no driver"
    groups = listed_groups(start.groups)
    return (f"the mechanism is assembled at t = {t:.10g} in a singular or limit configuration "
            f"(condition of Phi_q {start.cond:.3g} in units of the mechanism's length scale "
            f"{start.scale:.3g}): {aligned} become aligned, the equations of {groups} are "
            f"dependent, and {drivers} cannot choose the branch to follow from here. The "
            "motion is not stepped from such a start (its first step could jump to another "
            "branch or wind an angle). Start the time grid or the drivers away from it, or "
            "check the pairs' directions: in the drawn layout `axis` is a slide's or slot's "
            "direction, in the local layout `v` is its normal.")


def explain_reversed(labels: tuple[str, ...], t: float) -> str:
    """Why a solution of Phi = 0 at t is not run from: the senses (runtime.solving.assembly) that
    are not positive there, at most ten named."""
    named = listed(labels, "; ")
    return (f"at t = {t:.10g} the equations are solved where the mechanism is not assembled "
            f"as meant: {named} - a revolute's (or cylindrical's) axes reversed, or an angle "
            "driver's joint turned half a turn from its angle (their rows hold there too). "
            "The motion is not run from there. Give a first guess q0 (or a drawing) nearer "
            "the mechanism as meant; `symkin scan` lists its assemblies.")


def _not_finite(kernel: KinematicsKernel, q: Array, t: float, p: Array) -> str | None:
    """The first of Phi, Phi_t, Phi_q, Gamma that is inf or NaN at (q, t), as the row of the
    mechanism it comes from, or None when all four are finite."""
    labels = list(kernel.rows)
    phi = kernel.phi(q, t, p)
    jacobian = kernel.phi_q(q, t, p)
    phi_t = kernel.phi_t(q, t, p)
    for name, values in (("Phi", phi), ("Phi_t", phi_t)):
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            return f"{name} in row {bad[0]} ({labels[bad[0]]})"
    bad_entries = np.argwhere(~np.isfinite(jacobian))
    if bad_entries.size:
        return f"Phi_q in row {bad_entries[0][0]} ({labels[bad_entries[0][0]]})"
    dq = np.linalg.lstsq(jacobian, -phi_t, rcond=None)[0]
    bad = np.flatnonzero(~np.isfinite(kernel.gamma(q, dq, t, p)))
    if bad.size:
        return f"Gamma in row {bad[0]} ({labels[bad[0]]})"
    return None


def _singular_rows(kernel: KinematicsKernel, last: tuple[float, Array] | None, p: Array,
                   result: Newton, t: float) -> tuple[list[str], float | None]:
    """Dependent equations at the failure, or at the last point solved when Newton failed just
    past it (a mechanism driven through a dead centre has no solution beyond it).

    Returns the row labels and, when they come from the last point solved, its time.
    """
    labels = list(kernel.rows)
    jacobian = kernel.phi_q(result.q, t, p)
    finite = bool(np.all(np.isfinite(jacobian)))
    if result.status == SINGULAR or (finite and np.linalg.cond(jacobian) > ILL_CONDITIONED):
        return _dependent(jacobian, labels), None
    if result.status == NO_CONVERGENCE and last is not None:
        last_t, last_q = last
        jacobian = kernel.phi_q(last_q, last_t, p)
        if np.linalg.cond(jacobian) > NEARLY_SINGULAR:
            return _dependent(jacobian, labels), last_t
    return [], None


def _dependent(jacobian: Array, labels: Sequence[str]) -> list[str]:
    """What is singular, said first, then the dependent rows (a minimal set per lost rank)."""
    rank_loss, groups = dependencies(jacobian, labels)
    said = listed_groups(groups)
    summary = (f"it loses rank {rank_loss}; the equations of {said} are dependent"
               if len(groups) > 1 else f"the equations of {listed(groups[0], '; ')} are dependent")
    return [summary, *dict.fromkeys(row for group in groups for row in group)]


def _worst_rows(phi: Array, labels: Sequence[str], count: int = 3) -> str:
    magnitude = np.where(np.isfinite(phi), np.abs(phi), np.inf)
    order = np.argsort(-magnitude, kind="stable")[:count]
    return "; ".join(f"{labels[k]} ({magnitude[k]:.3g})" for k in order if magnitude[k] > 0)
