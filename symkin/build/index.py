"""The kernel index: from a mechanism file straight to its built kernel, without SymPy.

The build cache (symkin.build.cache) is keyed by the generated source, so finding a kernel there
needs the derivation, and with it SymPy, pydantic and jinja2. This index sits in front of it:

    sha256(file bytes, file format, backend, cse, the backend's options, symkin's code and
           templates, interpreter and compiler)
        ->  index/<key>.json  ->  the cache folder of the kernel

Keying on the raw bytes, not on the validated spec, is what lets a warm run skip validation
too: the same bytes read by the same symkin code validate and derive to the same kernel, so
a file that was accepted once needs no second check. Anything else misses: an edited file,
another backend or option, a new symkin version or an edited template.

An entry records the sha256 of every file a warm run loads. An entry that does not parse,
does not match its key, or points at files whose hash changed is deleted (with the kernel
folder it vouched for, so the build cache cannot hand the damaged kernel back) and the run
takes the full pipeline again; it never fails and never loads a kernel that does not match.
Entries are written to a temporary file and renamed, so concurrent runs see whole entries.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import json
import os
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from symkin.build.backend import Backend
from symkin.build.cache import discard, open_cache, sha256_of
from symkin.codegen.target import chosen_options
from symkin.contract.manifest import MANIFEST_SUFFIX
from symkin.runtime.kernel import Kernel, read_manifest

# Bump when the entry layout or the meaning of a key changes.
FORMAT = 1
INDEX_FOLDER = "index"
_PACKAGE = Path(__file__).resolve().parents[1]

Outlines = dict[str, NDArray[np.float64]]


@dataclass(frozen=True)
class Options:
    """What, besides the file, decides the kernel: see ``symkin.build.compile.compile``.

    ``backend`` is the object (``symkin.backends.resolve``); the key and the entry hold its
    name.
    """

    backend: Backend
    cse: bool = True
    # The backend's own options as (name, value) pairs (codegen.target.Option): the ones
    # given; the backend's defaults stand for the rest.
    choices: tuple[tuple[str, str], ...] = ()
    # Parameter values replacing the file's (``--set``), as (name, text) pairs: they change
    # the nominal values (and the first guess q0) recorded with the kernel.
    parameters: tuple[tuple[str, str], ...] = ()


@dataclass
class Prepared:
    """A kernel ready to solve, and where it came from.

    Attributes:
        kernel: the loaded kernel.
        hit: True when it came from the index (no validation, no derivation).
        outlines: per body, the local vectors ``present.plots.animate`` draws, when asked for.
        system: the derived System on a miss, None on a hit.
    """

    kernel: Kernel | Any  # a MotionKernel for a mechanism its forces move (build.motion)
    hit: bool
    outlines: Outlines | None = None
    system: Any = None


def prepare(mechanism: str | Path, options: Options, *, outlines: bool = False,
            cache_dir: str | Path | None = None) -> Prepared:
    """The kernel of a mechanism file: from the index when it can, else the full pipeline.

    Args:
        mechanism: the mechanism file (.yaml or .toml).
        options: backend, CSE and the backend's own options.
        outlines: also return the body outlines for an animation (recorded in the entry, so
            a warm run can draw without SymPy).
        cache_dir: the cache folder; default ``$SYMKIN_CACHE_DIR`` or the user cache.

    Raises:
        MechanismError: the file is invalid (only ever on a miss: a hit was valid before).
        BuildError: generating or compiling failed.
    """
    cache = open_cache(cache_dir)
    key = index_key(Path(mechanism), options)
    if key is not None:
        found = lookup(cache, key, options, need_outlines=outlines)
        if found is not None:
            return found
    prepared = _full_pipeline(Path(mechanism), options, cache, outlines)
    # Not recorded: a request that fell back to another backend (no compiler; the next run
    # must try, and warn, again), a file that changed while it was derived (the kernel may
    # be of other bytes than the key's), and a mechanism its forces move (build.motion: its
    # energy terms need the System).
    if (key is not None and prepared.kernel.backend == options.backend.name
            and not getattr(prepared.kernel, "moves_under_forces", False)
            and index_key(Path(mechanism), options) == key):
        record(cache, key, prepared.kernel, options.backend, prepared.outlines)
    return prepared


def _full_pipeline(mechanism: Path, options: Options, cache: Path,
                   want_outlines: bool) -> Prepared:
    from symkin.build import motion
    from symkin.build.compile import compile as compile_system
    from symkin.spec import validate
    from symkin.symbolic import derivation

    system = derivation.derive(validate.load(mechanism, dict(options.parameters)))
    # Forward dynamics is not recorded in the index (record skips it): its energy terms come
    # from the System (build.motion), so a run derives; the kernel itself is cached.
    build = motion.kernel if motion.moves_under_forces(system) else compile_system
    kernel = build(system, options.backend, dict(options.choices), cse=options.cse,
                   cache_dir=cache)
    return Prepared(kernel, hit=False, outlines=_drawn_outlines(system, want_outlines),
                    system=system)


def _drawn_outlines(system: Any, wanted: bool) -> Outlines | None:
    """The bodies' outlines for an animation, when wanted."""
    from symkin.symbolic import drawing

    # a spatial mechanism is drawn from its points; only its joints' points come from here
    outline = drawing.spatial_outlines if system.mechanism.is_spatial else drawing.outlines
    return outline(system) if wanted else None


# ----- the key -------------------------------------------------------------------------------

def index_key(mechanism: Path, options: Options) -> str | None:
    """The index key of a file and options, or None when the file cannot be read (the full
    pipeline then reports why)."""
    try:
        raw = mechanism.read_bytes()
    except OSError:
        return None
    inputs = {
        "format": FORMAT, "file_sha256": hashlib.sha256(raw).hexdigest(),
        # The loader picks TOML or YAML by suffix: the same bytes may mean different things.
        "file_format": "toml" if mechanism.suffix.lower() == ".toml" else "yaml",
        "options": [options.backend.name, options.cse, _chosen(options),
                    [list(pair) for pair in options.parameters]],
        "code": code_version(), **options.backend.fingerprint(),
    }
    return hashlib.sha256(json.dumps(inputs, sort_keys=True).encode()).hexdigest()


@functools.cache
def code_version() -> str:
    """sha256 over symkin's own Python source and templates (names and contents).

    Any edit to the pipeline or a template changes it, so every entry made by other code
    misses. Hashing the source, not a version number, also covers a working tree.
    """
    digest = hashlib.sha256()
    for root in (_PACKAGE,):  # the backends' templates are inside it
        for path in sorted(root.rglob("*")):
            if path.is_file() and path.suffix != ".pyc" and "__pycache__" not in path.parts:
                digest.update(path.relative_to(root).as_posix().encode() + b"\0")
                digest.update(hashlib.sha256(path.read_bytes()).digest())
    return digest.hexdigest()


# ----- entries -------------------------------------------------------------------------------

def entry_path(cache: Path, key: str) -> Path:
    return cache / INDEX_FOLDER / f"{key}.json"


def lookup(cache: Path, key: str, options: Options, need_outlines: bool = False
           ) -> Prepared | None:
    """The kernel an entry points at, or None on a miss. A damaged entry is removed."""
    path = entry_path(cache, key)
    try:
        entry = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        return None
    except (OSError, ValueError):
        _discard(path, None)
        return None
    folder = _named_folder(cache, entry) if _matches(entry, key, options) else None
    if folder is None:
        _discard(path, None)
        return None
    meta = _intact(folder, entry["files"], options)
    if meta is None:
        _discard(path, folder)  # the folder changed since it was recorded: never reuse it
        return None
    drawn = _outlines(entry.get("outlines"))
    if need_outlines and drawn is None:
        return None  # a valid entry without outlines: the full pipeline adds them
    try:
        loaded = options.backend.load(folder, meta)
    except Exception:
        _discard(path, folder)
        return None
    return Prepared(loaded, hit=True, outlines=drawn)


def _matches(entry: Any, key: str, options: Options) -> bool:
    """A well-formed entry of this format, key and backend."""
    return (isinstance(entry, dict) and entry.get("format") == FORMAT
            and entry.get("key") == key and entry.get("backend") == options.backend.name
            and isinstance(entry.get("files"), dict)
            and any(str(name).endswith(MANIFEST_SUFFIX) for name in entry["files"]))


def _intact(folder: Path, files: dict[Any, Any], options: Options) -> dict[str, Any] | None:
    """The manifest, when every recorded file is still there with the recorded hash and the
    manifest agrees with the options; else None."""
    for name, expected in files.items():
        if not (_plain_name(name) and isinstance(expected, str)
                and sha256_of(folder / name) == expected):
            return None
    return _matching_manifest(folder, options)


def _matching_manifest(folder: Path, options: Options) -> dict[str, Any] | None:
    try:
        meta = read_manifest(folder)
    except (OSError, ValueError):
        return None
    wanted = {"backend": options.backend.name, "cse": options.cse,
              "real": options.backend.precision(_chosen(options))}
    if isinstance(meta, dict) and all(meta.get(k) == v for k, v in wanted.items()):
        return meta
    return None


def _chosen(options: Options) -> dict[str, str]:
    """The backend's options with its defaults filled in: a default given or left out is the
    same kernel, so the same key."""
    return chosen_options(options.backend, dict(options.choices))


def _named_folder(cache: Path, entry: Any) -> Path | None:
    name = entry.get("folder") if isinstance(entry, dict) else None
    if not (isinstance(name, str) and _plain_name(name) and name.startswith("_symkin_")):
        return None
    return cache / name


def _plain_name(name: Any) -> bool:
    """A file name inside one folder: never a path, never hidden (an entry is data, not trust)."""
    return isinstance(name, str) and name not in ("", ".", "..") and Path(name).name == name \
        and not name.startswith(".")


def _outlines(data: Any) -> Outlines | None:
    if not isinstance(data, dict):
        return None
    try:
        drawn = {str(body): _rows(np.array(v, dtype=float)) for body, v in data.items()}
    except (TypeError, ValueError):
        return None
    return drawn


def _rows(array: NDArray[np.float64]) -> NDArray[np.float64]:
    """Rows of 2 components, or of 3 as a spatial joint's point is recorded."""
    return array.reshape(-1, 3 if array.ndim == 2 and array.shape[1] == 3 else 2)


def record(cache: Path, key: str, built: Kernel, backend: Backend,
           outlines: Outlines | None = None) -> None:
    """Write the entry of ``key`` for a kernel the build cache holds (atomic replace).

    Failing to write the index only costs the next run a derivation, so it is not an error.
    """
    folder = built.folder
    if folder is None:
        return
    files = {name: sha256_of(folder / name)
             for name in backend.loaded_files(folder, built.name)}
    if any(digest is None for digest in files.values()):
        return
    entry = {"format": FORMAT, "key": key, "backend": built.backend, "folder": folder.name,
             "files": files}
    if outlines is not None:
        entry["outlines"] = {body: np.asarray(v, dtype=float).tolist()
                             for body, v in outlines.items()}
    with contextlib.suppress(OSError):  # no entry: the next run derives again, that is all
        _write_atomic(entry_path(cache, key), json.dumps(entry, indent=1, sort_keys=True))


def _write_atomic(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    handle, temporary = tempfile.mkstemp(dir=path.parent, prefix=f".{path.stem}.", suffix=".tmp")
    try:
        with os.fdopen(handle, "w", encoding="utf-8") as stream:
            stream.write(text)
        os.replace(temporary, path)
    finally:
        if os.path.exists(temporary):
            os.unlink(temporary)


def _discard(entry: Path, folder: Path | None) -> None:
    """Remove a damaged entry and the kernel folder it vouched for (moved aside first, so a
    concurrent build republishes a whole folder instead of finding a half-deleted one)."""
    entry.unlink(missing_ok=True)
    if folder is not None:
        discard(folder)
