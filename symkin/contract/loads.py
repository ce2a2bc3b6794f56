"""The components of a joint's reaction, by space: what the generated ``loads`` routine
writes per joint after the efforts, and the suffixes of the CSV columns ``JOINT.Fx``...

Planar: the force [Fx, Fy] (global) and the moment M; spatial: the force [Fx, Fy, Fz] and the
moment [Mx, My, Mz] (global). Both are what body i exerts on body j, the moment about the
joint's point on body i.
"""

from __future__ import annotations

REACTION_PARTS = {"2d": ("Fx", "Fy", "M"), "3d": ("Fx", "Fy", "Fz", "Mx", "My", "Mz")}


def reaction_parts(space: str) -> tuple[str, ...]:
    """The components of one joint's reaction in a mechanism of ``space`` (2d or 3d)."""
    return REACTION_PARTS[space]


def load_count(n_efforts: int, n_joints: int, space: str) -> int:
    """The outputs of ``loads``: the efforts, then every joint's reaction components."""
    return n_efforts + len(REACTION_PARTS[space]) * n_joints
