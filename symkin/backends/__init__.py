"""The backend registry: the one place that knows the concrete backends (``c``, ``numpy``,
``octave``).

Everything that takes a backend by name (the public API, the CLI, a manifest or warm-run entry
naming one) asks here and hands the object down; the stages (codegen, build, runtime) only
see ``symkin.build.backend.Backend`` objects and never name one. A backend is one folder
``symkin/backends/<name>/`` with a ``BACKEND`` object, its templates and an entry in
:data:`_BUILT_IN`; a plug-in (or a test) may :func:`register` its own.
"""

from __future__ import annotations

from symkin.errors import BuildError, SymkinWarning

# Not `typing.TYPE_CHECKING`: importing typing is a tenth of `symkin --help`, which reads the
# names and flags below (mypy takes any constant of this name as true).
TYPE_CHECKING = False
if TYPE_CHECKING:
    from pathlib import Path

    from symkin.build.backend import Backend
    from symkin.codegen.target import Option
    from symkin.runtime.kernel import Kernel

AUTO = "auto"
"""The first registered backend that can build on this machine (C, else NumPy with a note)."""

Flag = tuple[str, tuple[str, ...], str, str]
"""An option as plain data: name, choices, default, help (the fields of ``Option``, which
compares equal to it)."""

# In order of preference ("auto" takes the first that builds here; octave never: NumPy always
# can): each built-in's name, the module whose BACKEND it is, imported only when the backend is
# first asked for, and the options it declares, written here too so that the command line's
# flags cost no import (tests/backends/test_registry_light.py checks they are the backend's own).
_BUILT_IN: tuple[tuple[str, str, tuple[Flag, ...]], ...] = (
    ("c", "symkin.backends.c", (
        ("real", ("double", "float"), "double", "C real type (default double)"),
        ("linalg", ("sparse", "dense"), "sparse",
         "LU behind the C solver: generated sparse LU with run-time pivot checks and a dense "
         "fall-back (default), or dense partial pivoting"))),
    ("numpy", "symkin.backends.numpy", (
        ("real", ("double",), "double", "NumPy computes in double"),)),
    ("octave", "symkin.backends.octave", (
        ("real", ("double",), "double", "MATLAB and Octave compute in double"),)),
)
# name -> the backend; None for a built-in not imported yet
_REGISTERED: dict[str, Backend | None] = {name: None for name, _, _ in _BUILT_IN}


def names() -> tuple[str, ...]:
    """The registered backends' names, in order of preference."""
    return tuple(_REGISTERED)


def choices() -> tuple[str, ...]:
    """What ``backend=`` and ``--backend`` accept: ``"auto"`` and every registered name."""
    return (AUTO, *_REGISTERED)


def declared_flags() -> tuple[Flag, ...]:
    """Every option some registered backend declares, once by name (for the CLI's flags): the
    choices of all that declare it, the help and default of the first (in order of
    preference). Which backend takes which value is still checked by each backend
    (``codegen.target.chosen_options``). Imports no backend that is not loaded yet."""
    merged: dict[str, Flag] = {}
    for options in _declarations():
        for option in options:
            first = merged.get(option[0], option)
            choices = (*first[1], *(c for c in option[1] if c not in first[1]))
            merged[option[0]] = (option[0], choices, first[2], first[3])
    return tuple(merged.values())


def declared_options() -> tuple[Option, ...]:
    """:func:`declared_flags` as ``Option`` values."""
    from symkin.codegen.target import Option

    return tuple(Option(*flag) for flag in declared_flags())


def _declarations() -> list[tuple[Flag, ...]]:
    """Each registered backend's options, in order of preference: a loaded one's own, a
    built-in's not imported yet as :data:`_BUILT_IN` writes them."""
    written = {name: options for name, _, options in _BUILT_IN}
    return [written[name] if backend is None else tuple(backend.options)
            for name, backend in _REGISTERED.items()]


def get(name: str) -> Backend:
    """The backend called ``name`` (a built-in one imported the first time it is asked for).

    Raises:
        BuildError: no backend has that name (the message lists the known ones).
    """
    try:
        backend = _REGISTERED[name]
    except (KeyError, TypeError):
        raise BuildError(f"unknown backend {name!r}; choose one of "
                         f"{', '.join(choices())}") from None
    if backend is None:
        import importlib

        module = next(module for built_in, module, _ in _BUILT_IN if built_in == name)
        backend = _REGISTERED[name] = importlib.import_module(module).BACKEND
    return backend


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
    import warnings

    notes: list[str] = []
    for backend in map(get, names()):
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
    if any(name == built_in for built_in, _, _ in _BUILT_IN):
        raise BuildError(f"the built-in backend {name!r} cannot be removed")
    _REGISTERED.pop(name, None)


def load(folder: str | Path, name: str | None = None) -> Kernel:
    """Load a built kernel from its folder (a cache entry, or a generated NumPy folder).

    The folder's ``<name>_manifest.json`` says the backend and the mechanism (a folder holding
    several mechanisms needs ``name``); a C folder must also hold the compiled extension.
    Needs only NumPy (and cffi for C), never SymPy.
    """
    from pathlib import Path

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
