"""Stage 7 — results, pictures of inverse dynamics: the efforts of the drivers and the
reactions of the joints against time, in one figure beside the kinematics' (``--plot``
writes ``NAME_forces.png`` next to ``NAME.png`` when the file has masses or forces).

Three panels: the efforts (one curve per driver equation), the joints' force magnitudes
|F| = sqrt(Fx² + Fy²), and their moments M (zero for revolutes, so those are left out).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from symkin.present.plots import _pyplot, _save
from symkin.present.series import DEFAULT_UNITS, Units
from symkin.runtime.outputs.results import Trajectory


def forces_path(path: str | Path) -> Path:
    """``run.png`` -> ``run_forces.png``: where the forces' figure goes."""
    path = Path(path)
    return path.with_name(f"{path.stem}_forces{path.suffix}")


def plot_forces(trajectory: Trajectory, path: str | Path, title: str | None = None,
                units: Units = DEFAULT_UNITS) -> Path:
    """Write the efforts and reactions of ``trajectory`` (which has ``forces``) to ``path``,
    their axes in the force and moment units of ``units`` (series.Units.loads)."""
    forces = trajectory.forces
    if forces is None:
        raise ValueError("the trajectory has no efforts or reactions to plot")
    plt = _pyplot()
    figure, axes = plt.subplots(3, 1, figsize=(7.0, 8.8), sharex=True, layout="constrained")
    t = trajectory.t
    for k, name in enumerate(forces.driver_names):
        axes[0].plot(t, forces.effort[:, k], label=name, linewidth=1.4)
    effort_label, force_label, moment_label = units.load_labels(
        spatial=forces.reaction.shape[-1] > 3)
    axes[0].set_ylabel(effort_label)
    # the force's components are Fx, Fy (spatial: Fz too); the moment is M, or Mx, My, Mz
    # of a spatial joint, shown by its magnitude
    n_force = sum(part.startswith("F") for part in forces.parts)
    magnitude = np.linalg.norm(forces.reaction[..., :n_force], axis=-1)
    moment_parts = forces.reaction[..., n_force:]
    spatial = moment_parts.shape[-1] > 1
    moments = np.linalg.norm(moment_parts, axis=-1) if spatial else moment_parts[..., 0]
    for k, name in enumerate(forces.joint_names):
        axes[1].plot(t, magnitude[:, k], label=name, linewidth=1.4)
        if np.nanmax(np.abs(moments[:, k]), initial=0.0) > 1e-9 * max(
                np.nanmax(magnitude, initial=0.0), 1.0):
            axes[2].plot(t, moments[:, k], label=name, linewidth=1.4)
    if not axes[2].get_lines():
        axes[2].text(0.5, 0.5, "no joint carries a moment (revolute pairs only)",
                     transform=axes[2].transAxes, ha="center", va="center")
    axes[1].set_ylabel(force_label)
    axes[2].set_ylabel(moment_label)
    axes[2].set_xlabel(units.time_label())
    for ax in axes:
        ax.grid(True, linewidth=0.4, alpha=0.5)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize="small", frameon=False)
    if title:
        figure.suptitle(f"{title}: efforts and reactions")
    return _save(figure, plt, Path(path))
