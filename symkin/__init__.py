"""symkin: symbolic code generation for the kinematic analysis of planar mechanisms.

The public API (the README's "Python API") is loaded lazily, so that running an
already-compiled kernel does not pay for importing SymPy.
"""

from __future__ import annotations

# Not `typing.TYPE_CHECKING`: every `symkin` command imports this package, `--help` included,
# and typing alone would be a tenth of its cost (mypy takes any constant of this name as true).
TYPE_CHECKING = False
if TYPE_CHECKING:
    from typing import Any

__all__ = [
    "BuildError",
    "MechanismError",
    "SolveError",
    "SymkinError",
    "__version__",
    "compile",
    "derive",
    "from_dict",
    "generate",
    "load",
    "scan",
    "solve",
    "sweep",
    "with_outputs",
]

_EXPORTS = {
    "load": ("symkin.spec.validate", "load"),
    "from_dict": ("symkin.spec.validate", "from_dict"),
    "Mechanism": ("symkin.spec.validate", "Mechanism"),
    "derive": ("symkin.symbolic.derivation", "derive"),
    "System": ("symkin.symbolic.derivation", "System"),
    "generate": ("symkin.public", "generate"),
    "compile": ("symkin.public", "compile"),
    "solve": ("symkin.runtime.driver", "solve"),
    "scan": ("symkin.runtime.scanning.scan", "scan"),
    "sweep": ("symkin.sweeps.api", "sweep"),
    "with_outputs": ("symkin.symbolic.outputs", "with_outputs"),
    "SymkinError": ("symkin.errors", "SymkinError"),
    "MechanismError": ("symkin.errors", "MechanismError"),
    "SolveError": ("symkin.errors", "SolveError"),
    "BuildError": ("symkin.errors", "BuildError"),
}


def _version() -> str:
    """The installed distribution's version when this very file belongs to it; else the
    version in the source tree's pyproject.toml (a checkout on the path); else "unknown"."""
    from importlib import metadata
    from pathlib import Path

    here = Path(__file__).resolve()
    try:
        found = metadata.distribution("symkin")
        if Path(str(found.locate_file("symkin/__init__.py"))).resolve() == here:
            return found.version
    except metadata.PackageNotFoundError:
        pass
    pyproject = here.parent.parent / "pyproject.toml"
    try:
        import tomllib

        project = tomllib.loads(pyproject.read_text(encoding="utf-8")).get("project", {})
        if project.get("name") == "symkin" and isinstance(project.get("version"), str):
            return str(project["version"])
    except (OSError, ValueError):
        pass
    return "unknown"


def __getattr__(name: str) -> Any:
    if name == "__version__":
        return _version()
    if name not in _EXPORTS:
        raise AttributeError(f"module 'symkin' has no attribute {name!r}")
    import importlib

    module, attribute = _EXPORTS[name]
    value = getattr(importlib.import_module(module), attribute)
    globals()[name] = value  # found once: later lookups (symkin.solve in a loop) cost nothing
    return value
