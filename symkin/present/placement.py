"""Stage 7 — where the pictures put things: a body's local vectors in the global frame at
every time (planar or spatial), and each joint's point on body i, where its reaction arrow
starts (the ``joint:<name>:<body i>`` keys of the drawing data). Shared by the planar GIF and
report and the 3D view, with the arrows' common scale and colour.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from numpy.typing import NDArray

from symkin.runtime.outputs import spatial
from symkin.runtime.outputs.results import Trajectory, rotation

Array = NDArray[np.float64]
Outlines = Mapping[str, Array]

GROUND = "ground"
VECTOR_SHARE = 0.15  # the longest reaction of the run drawn this long, relative to the picture
REACTION = "#c2008f"  # the joint reactions' arrows: a magenta no body is drawn in


def global_vectors(trajectory: Trajectory, body: str, local: Array) -> Array:
    """Local vectors of ``body`` (K, 2) in the global frame at every time: (T, K, 2) (a
    spatial run: (K, 3) and (T, K, 3); the ground's are global already)."""
    if body == GROUND:
        return np.broadcast_to(local, (trajectory.t.size, *local.shape))
    q, dq, d2q = trajectory.body(body)
    if trajectory.spatial:
        r, _, _ = spatial.point_kinematics(q[:, None], dq[:, None], d2q[:, None], local)
        return r
    turned: Array = np.einsum("tij,kj->tki", rotation(q[:, 2]), local)
    return q[:, None, :2] + turned


def joint_points(trajectory: Trajectory, outlines: Outlines) -> dict[str, Array]:
    """Where each joint's reaction acts (its point on body i), (T, 2) in the global frame
    (spatial: (T, 3)), by joint name: the keys ``joint:<name>:<body i>`` (files with masses
    or forces; :func:`symkin.symbolic.drawing.spatial_outlines` for a spatial one)."""
    found = {}
    for key, rows in outlines.items():
        if not key.startswith("joint:"):
            continue
        name, body = key.split(":")[1:3]
        if body == GROUND or body in trajectory.bodies:
            local = np.asarray(rows, dtype=float).reshape(-1, trajectory.point_size)[:1]
            found[name] = global_vectors(trajectory, body, local)[:, 0]
    return found
