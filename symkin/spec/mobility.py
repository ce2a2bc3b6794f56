"""The degree-of-freedom count (Grübler) and its check, kept apart from validate for size."""

from __future__ import annotations

from typing import Any

from symkin import pairs
from symkin.errors import MechanismError
from symkin.spec.motion import has_masses
from symkin.spec.schema import MechanismSpec, equation_count


def _freedoms_taken(joint: Any) -> int:
    """How many freedoms a joint takes: its rows less the coordinates it adds (a point on a
    curve writes 2 equations and adds s: it takes one freedom, as a pair of class 4)."""
    return equation_count(joint) - len(pairs.of(joint).extra_coordinates(joint))


def degrees_of_freedom(mech: MechanismSpec) -> int:
    """Grübler's count w = 3n - 2 p5 - p4, less the equations of custom joints (in space:
    w = 6n less the joints' equations)."""
    per_body = 6 if mech.is_spatial else 3
    return per_body * len(mech.bodies) - sum(_freedoms_taken(joint) for joint in mech.joints)


def check_degrees_of_freedom(mech: MechanismSpec) -> None:
    """Check that the drivers supply at least as many equations as there are DOF, or that
    the bodies have masses, so that the forces move the mechanism (forward dynamics).

    More equations than coordinates are not refused by the count: joints may repeat each
    other (a parallelogram with an extra parallel bar), which only the rank of Phi_q at the
    assembled t0 can judge (symkin.symbolic.redundancy, when the System is derived).
    """
    dof = degrees_of_freedom(mech)
    driving = sum(equation_count(driver) for driver in mech.drivers)
    if driving >= dof:
        return
    if has_masses(mech):
        return  # the freedoms the drivers leave open move under the forces (spec.motion)
    _needs_masses(mech, dof, driving)


def _needs_masses(mech: MechanismSpec, dof: int, driving: int) -> None:
    """Refuse an under-driven file without masses: its motion is undetermined."""
    if mech.is_spatial:
        _spatial_dof_error(mech, dof, driving)
    # Pairs of class 5 take two freedoms (revolute, prismatic), of class 4 one (pin-in-slot,
    # distance, gear, rack, point on a curve, cam); the equations the file writes itself are
    # counted apart.
    counted = [_freedoms_taken(joint) for joint in mech.joints
               if pairs.of(joint).rows is not None]
    p5, p4 = counted.count(2), counted.count(1)
    formula = f"w = 3·{len(mech.bodies)} − 2·{p5} − {p4}"
    custom = dof - (3 * len(mech.bodies) - 2 * p5 - p4)
    if custom:
        formula += f" − {-custom} (custom joint equations)"
    raise MechanismError(f"the mechanism has {formula} = {dof} degree(s) of freedom but its "
                         f"drivers give {driving} equation(s), and no body has a mass: the "
                         f"motion of the {dof - driving} free degree(s) needs masses",
                         ("drivers",), _MASS_FIX.format(more=dof - driving))


_MASS_FIX = ("Give the bodies a mass (and inertia) so that their motion under the forces is "
             "integrated, or add drivers for {more} more equation(s).")


def _spatial_dof_error(mech: MechanismSpec, dof: int, driving: int) -> None:
    """Refuse an under-driven spatial file without masses (the count in space)."""
    joints = sum(equation_count(joint) for joint in mech.joints)
    raise MechanismError(f"the mechanism has w = 6·{len(mech.bodies)} − {joints} (joint "
                         f"equations) = {dof} degree(s) of freedom but its drivers give "
                         f"{driving} equation(s), and no body has a mass: the motion of the "
                         f"{dof - driving} free degree(s) needs masses", ("drivers",),
                         _MASS_FIX.format(more=dof - driving))
