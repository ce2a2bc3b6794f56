"""The backend registry: the one place that knows the concrete backends (``c``, ``numpy``,
``octave``).

Everything that takes a backend by name (the public API, the CLI, a manifest or warm-run entry
naming one) asks here and hands the object down; the stages (codegen, build, runtime) only
see ``symkin.build.backend.Backend`` objects and never name one. A backend is one folder
``symkin/backends/<name>/`` with a ``BACKEND`` object, its templates and an entry in
:data:`_BUILT_IN`; a plug-in (or a test) may :func:`register` its own.
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import TYPE_CHECKING

from symkin.backends import c, numpy, octave
from symkin.build.backend import Backend
from symkin.codegen.target import Option
from symkin.errors import BuildError, SymkinWarning

if TYPE_CHECKING:  # the CLI imports the registry for --backend: no NumPy at start-up
    from symkin.runtime.kernel import Kernel

AUTO = "auto"
"""The first registered backend that can build on this machine (C, else NumPy with a note)."""

# in order of preference ("auto" takes the first that builds here; octave never: NumPy
# always can)
_BUILT_IN: tuple[Backend, ...] = (c.BACKEND, numpy.BACKEND, octave.BACKEND)
_REGISTERED: dict[str, Backend] = {backend.name: backend for backend in _BUILT_IN}


def names() -> tuple[str, ...]:
    """The registered backends' names, in order of preference."""
    return tuple(_REGISTERED)


def choices() -> tuple[str, ...]:
    """What ``backend=`` and ``--backend`` accept: ``"auto"`` and every registered name."""
    return (AUTO, *_REGISTERED)


def declared_options() -> tuple[Option, ...]:
    """Every option some registered backend declares, once by name (for the CLI's flags): the
    choices of all that declare it, the help and default of the first (in order of
    preference). Which backend takes which value is still checked by each backend
    (``codegen.target.chosen_options``)."""
    merged: dict[str, Option] = {}
    for backend in _REGISTERED.values():
        for option in backend.options:
            first = merged.get(option.name, option)
            choices = (*first.choices, *(c for c in option.choices if c not in first.choices))
            merged[option.name] = Option(option.name, choices, first.default, first.help)
    return tuple(merged.values())


def get(name: str) -> Backend:
    """The backend called ``name``.

    Raises:
        BuildError: no backend has that name (the message lists the known ones).
    """
    try:
        return _REGISTERED[name]
    except (KeyError, TypeError):
        raise BuildError(f"unknown backend {name!r}; choose one of "
                         f"{', '.join(choices())}") from None


def resolve(name: str) -> Backend:
    """The backend to build with: ``"auto"`` is the first registered one that can build here
    (with a one-line note when a preferred one cannot); a backend asked for by name that
    cannot build here is an error, never a silent substitute.

    Raises:
        BuildError: an unknown name.
        NoCompilerError: C was asked for by name and there is no C compiler.
    """
    if name != AUTO:
        backend = get(name)
        backend.require()
        return backend
    notes: list[str] = []
    for backend in _REGISTERED.values():
        note = backend.unavailable()
        if note is None:
            if notes:
                warnings.warn(f"{'; '.join(notes)}. Using the {backend.title} backend, which "
                              "gives the same results, more slowly.", SymkinWarning,
                              stacklevel=3)
            return backend
        notes.append(note)
    raise BuildError(f"no backend can build on this machine: {'; '.join(notes)}")


def register(backend: Backend) -> None:
    """Add a backend (a plug-in's or a test's) under ``backend.name``.

    Raises:
        BuildError: the name is taken, or is ``"auto"``.
    """
    if backend.name in _REGISTERED or backend.name == AUTO:
        raise BuildError(f"a backend named {backend.name!r} is already registered")
    _REGISTERED[backend.name] = backend


def unregister(name: str) -> None:
    """Remove a backend added by :func:`register` (the built-in ones stay)."""
    if any(name == backend.name for backend in _BUILT_IN):
        raise BuildError(f"the built-in backend {name!r} cannot be removed")
    _REGISTERED.pop(name, None)


def load(folder: str | Path, name: str | None = None) -> Kernel:
    """Load a built kernel from its folder (a cache entry, or a generated NumPy folder).

    The folder's ``<name>_manifest.json`` says the backend and the mechanism (a folder holding
    several mechanisms needs ``name``); a C folder must also hold the compiled extension.
    Needs only NumPy (and cffi for C), never SymPy.
    """
    from symkin.runtime.kernel import read_manifest

    folder = Path(folder)
    meta = read_manifest(folder, name)
    return get(meta["backend"]).load(folder, meta)


def from_sources(files: dict[str, str], cache_dir: str | Path | None = None) -> Kernel:
    """Build (or find in this machine's cache) and load a kernel from its generated files.

    ``files`` is a generated folder as text, its manifest included (what a sweep sends to the
    processes and cluster workers that solve it); no derivation, so no SymPy. The files are
    keyed and verified exactly as ``compile`` keys and verifies its own.

    Raises:
        BuildError: the files hold no symkin manifest, or the compiler failed.
        NoCompilerError: they are C and this machine has no C compiler.
    """
    from symkin.build.cache import checked_manifest, open_cache

    meta = checked_manifest(files)
    return get(meta["backend"]).build(files, open_cache(cache_dir))
