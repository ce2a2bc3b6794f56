"""The Octave kernel: the generated .m files evaluated in a running Octave (``session``)."""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from symkin.build.cache import build_unless_verified, content_key
from symkin.contract.manifest import MANIFEST_SUFFIX, manifest_name
from symkin.octave_process import Session
from symkin.runtime.kernel import Array, Kernel

_SESSIONS: dict[Path, Session] = {}


class _OctaveFunctions:
    """The Kernel's functions, each a call of the generated <prefix>_<what>.m."""

    # no equations of motion: the backend generates none (build.motion refuses it)
    mass: Callable[[Array, Array], Array] | None = None
    applied: Callable[[Array, Array, float, Array], Array] | None = None

    def __init__(self, session: Session, name: str, meta: Mapping[str, Any]) -> None:
        self._session, self._name = session, name
        self.removed: Callable[[Array, float, Array], Array] | None = (
            (lambda q, t, p: self._call("removed", q, t, p)) if meta.get("removed") else None)
        self.senses: Callable[[Array, float, Array], Array] | None = (
            (lambda q, t, p: self._call("senses", q, t, p)) if meta.get("senses") else None)

    def _call(self, what: str, *arguments: object, output: int = 1) -> Array:
        # a column (MATLAB's shape) read flat; <prefix>_points' rows (a point each) row by row
        return np.asarray(self._session.call(f"{self._name}_{what}", arguments, output)
                          .reshape(-1), dtype=float)

    def phi(self, q: Array, t: float, p: Array) -> Array:
        return self._call("phi", q, t, p)

    def phi_q_nz(self, q: Array, t: float, p: Array) -> Array:
        return self._call("phi_q", q, t, p, output=2)

    def phi_t(self, q: Array, t: float, p: Array) -> Array:
        return self._call("phi_t", q, t, p)

    def gamma(self, q: Array, dq: Array, t: float, p: Array) -> Array:
        return self._call("gamma", q, dq, t, p)

    def points(self, p: Array) -> Array:
        return self._call("points", p)

    def phi_p_nz(self, q: Array, t: float, p: Array) -> Array:
        return self._call("phi_p", q, t, p, output=2)

    def dynamics_rhs(self, q: Array, dq: Array, ddq: Array, t: float, p: Array) -> Array:
        return self._call("dynamics_rhs", q, dq, ddq, t, p)

    def loads(self, q: Array, lam: Array, t: float, p: Array) -> Array:
        return self._call("loads", q, lam, t, p)

    def removed_q(self, q: Array, t: float, p: Array) -> Array:
        return self._call("removed_q", q, t, p)

    def loads_full(self, q: Array, lam: Array, t: float, p: Array) -> Array:
        return self._call("loads_full", q, lam, t, p)


def session(folder: Path) -> Session:
    """The one Octave session of a folder in this process."""
    folder = folder.resolve()
    if folder not in _SESSIONS:
        _SESSIONS[folder] = Session(folder)
    return _SESSIONS[folder]


def _kernel(folder: Path, meta: Mapping[str, Any], backend: str) -> Kernel:
    functions = _OctaveFunctions(session(folder), meta["name"], meta)
    return Kernel(backend, meta, functions, folder=folder)


def build(files: dict[str, str], cache: Path, backend: str) -> Kernel:
    """Write a generated folder into the cache (unless a verified copy is there) and load it."""
    manifest = next(n for n in files if n.endswith(MANIFEST_SUFFIX))
    name = manifest.removesuffix(MANIFEST_SUFFIX)
    key = content_key({"files": {n: text for n, text in files.items() if n != manifest}})
    folder = cache / f"_symkin_{name}_m_{key[:20]}"
    build_unless_verified(cache, folder, files, lambda target: _write_files(target, files))
    return _kernel(folder, json.loads(files[manifest_name(name)]), backend)


def load(folder: Path, meta: Mapping[str, Any], backend: str) -> Kernel:
    """The kernel of a generated or cached Octave folder."""
    return _kernel(folder, meta, backend)


def _write_files(folder: Path, files: dict[str, str]) -> None:
    for name, text in files.items():
        (folder / name).write_text(text, encoding="utf-8", newline="\n")
