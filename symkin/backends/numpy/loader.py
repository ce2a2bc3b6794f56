"""A NumPy kernel: the generated Python module written into the build cache and imported,
behind the runtime's Kernel. Needs only NumPy."""

from __future__ import annotations

import hashlib
from collections.abc import Callable
from pathlib import Path
from types import ModuleType

from symkin.build.cache import build_unless_verified, content_key
from symkin.contract.manifest import manifest_name
from symkin.runtime.kernel import Array, Kernel, import_file


class _ModuleFunctions:
    """Adapter over a generated NumPy module."""

    def __init__(self, module: ModuleType) -> None:
        self.phi = module.phi
        self.phi_q_nz = module.phi_q_nz
        self.phi_t = module.phi_t
        self.gamma = module.gamma
        self.points = module._points
        self.phi_p_nz: Callable[[Array, float, Array], Array] = getattr(
            module, "phi_p_nz", _no_phi_p)
        # Only the module of an over-constrained file has it (Kernel.removed_phi).
        self.removed: Callable[[Array, float, Array], Array] | None = getattr(
            module, "removed", None)
        # Only the module of a file with spatial revolutes or angles has it.
        self.senses: Callable[[Array, float, Array], Array] | None = getattr(
            module, "senses", None)
        # inverse dynamics, generated only for a mechanism with masses or forces
        self.dynamics_rhs: Callable[..., Array] = getattr(module, "dynamics_rhs", _no_dynamics)
        self.loads: Callable[..., Array] = getattr(module, "loads", _no_dynamics)
        # forward dynamics, generated only for a mechanism with masses
        self.mass: Callable[..., Array] | None = getattr(module, "mass", None)
        self.applied: Callable[..., Array] | None = getattr(module, "applied", None)
        # with dynamics and removed rows only (runtime.loads.indeterminate)
        self.removed_q: Callable[..., Array] = getattr(module, "removed_q", _no_dynamics)
        self.loads_full: Callable[..., Array] = getattr(module, "loads_full", _no_dynamics)


def _no_phi_p(q: Array, t: float, p: Array) -> Array:
    raise ValueError("this kernel was generated without Phi_p; rebuild it with symkin.compile")


def _no_dynamics(*arguments: object) -> Array:
    raise ValueError("this mechanism has no masses or forces: no efforts or reactions")


def from_module(module: ModuleType, backend: str, folder: Path | None = None) -> Kernel:
    """A Kernel over a generated NumPy module (its metadata comes from the module)."""
    meta = {
        "name": module.NAME, "coordinates": module.COORDINATES,
        "parameter_names": module.PARAMETER_NAMES, "p_values": module.P_VALUES,
        "q0": module.Q0, "time_grid": module.TIME_GRID, "rows": module.ROWS,
        "pattern_rows": module.PATTERN_ROWS, "pattern_cols": module.PATTERN_COLS,
        "points": module.POINTS, "space": getattr(module, "SPACE", "2d"),
        **({"phi_p_rows": module.PHI_P_ROWS, "phi_p_cols": module.PHI_P_COLS}
           if hasattr(module, "PHI_P_ROWS") else {}),
        **({"removed": module.REMOVED} if hasattr(module, "REMOVED") else {}),
        **({"senses": module.SENSES} if hasattr(module, "SENSES") else {}),
        **({"ranges": module.RANGES} if hasattr(module, "RANGES") else {}),
        **({"driver_names": module.DRIVER_NAMES, "joint_names": module.JOINT_NAMES}
           if hasattr(module, "JOINT_NAMES") else {}),
        "input_names": getattr(module, "INPUT_NAMES", ()),
        "input_lengths": getattr(module, "INPUT_LENGTHS", ()),
        **({"nonlinear": [k for k, entered in enumerate(module.NONLINEAR) if entered]}
           if hasattr(module, "NONLINEAR") else {}),
    }
    return Kernel(backend, meta, _ModuleFunctions(module), folder=folder)


def build(files: dict[str, str], name: str, cache: Path, backend: str) -> Kernel:
    """Write a generated module and its manifest into the cache (unless a verified copy is
    there) and import it; the folder is keyed by the sources."""
    manifest = manifest_name(name)
    key = content_key({"files": {n: text for n, text in files.items() if n != manifest}})
    folder = cache / f"_symkin_{name}_py_{key[:20]}"
    build_unless_verified(cache, folder, files, lambda target: _write_files(target, files))
    module = import_file(folder.name, folder / f"{name}.py", None)
    return from_module(module, backend, folder)


def load(folder: Path, name: str, backend: str) -> Kernel:
    """Import the generated module ``<name>.py`` of ``folder`` (once per process and text)."""
    source = folder / f"{name}.py"
    digest = hashlib.sha256(source.read_bytes()).hexdigest()
    module = import_file(f"_symkin_{name}_py_{digest[:20]}", source, None)
    return from_module(module, backend, folder)


def _write_files(folder: Path, files: dict[str, str]) -> None:
    for name, text in files.items():
        (folder / name).write_text(text, encoding="utf-8", newline="\n")
