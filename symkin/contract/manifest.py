"""The manifest every generated folder carries, one per mechanism (so that several mechanisms
can share a folder): its file name and its keys. Written by codegen.render (and build.compile);
read by runtime.kernel, build.cache, build.index, sweeps.parallel and the backends (the registry's
load and from_sources, each backend's build and loader)."""

from __future__ import annotations

from typing import NotRequired, TypedDict

MANIFEST_SUFFIX = "_manifest.json"

GENERATOR = "symkin"
"""The value of ``generator``: a manifest symkin wrote (others are never trusted)."""


def manifest_name(prefix: str) -> str:
    """``crank_slider`` -> ``crank_slider_manifest.json``."""
    return prefix + MANIFEST_SUFFIX


class _Dynamics(TypedDict, total=False):
    """Present only for a mechanism with masses or forces: the labels of the efforts (one
    per driver row) and of the joints' reactions."""

    driver_names: list[str]
    joint_names: list[str]


class Metadata(_Dynamics):
    """What a runtime Kernel needs besides the compiled functions (plain JSON data)."""

    coordinates: list[str]
    parameter_names: list[str]
    p_values: list[float]
    q0: list[float]
    time_grid: list[float]
    rows: list[str]
    pattern_rows: list[int]
    pattern_cols: list[int]
    points: list[list[str]]
    phi_p_rows: list[int]
    phi_p_cols: list[int]
    nq: int
    n_params: int
    nnz: int
    npoints: int
    nshared: int
    nonlinear: NotRequired[list[int]]
    """The coordinates that enter Phi_q or Phi_t (the error model's; absent from kernels
    generated before it: every coordinate then counts)."""
    removed: NotRequired[list[str]]
    """The rows removed as dependent at t0 (only in the manifest of a file that has some)."""
    senses: NotRequired[list[str]]
    """What the rows leave ambiguous, positive at a genuine assembly (the ``senses`` routine's
    outputs; only in the manifest of a file that has some: spatial revolutes, angles)."""
    space: NotRequired[str]
    """``3d`` for a spatial mechanism (points of 3 components, 7 coordinates per body);
    absent for a planar one."""
    input_names: NotRequired[list[str]]
    """The input drivers, in the order of u[] (only a mechanism that has them)."""
    input_lengths: NotRequired[list[str]]
    """Those of the input drivers that are a length, never negative (a distance driver's f;
    only a mechanism that has one)."""
    ranges: NotRequired[list[list[str | float]]]
    """[coordinate, a, b, owner] for each range a file gives a pair's own coordinate (only a
    mechanism that has one), at the nominal parameter values."""


class Manifest(Metadata):
    """The whole manifest: who wrote it, for which backend and real type, the files with their
    sha256 and the op counts, and the :class:`Metadata`."""

    generator: str
    backend: str
    real: str
    cse: bool
    name: str
    spec_sha256: str
    files: dict[str, str]
    ops: dict[str, int]
    ops_before_cse: dict[str, int]


KEYS = frozenset(Manifest.__annotations__)
"""Every key of a manifest (a reader asks for no other)."""

DYNAMICS_KEYS = frozenset(_Dynamics.__annotations__)
"""The keys only a mechanism with masses or forces has."""

OPTIONAL_KEYS = frozenset({"removed", "senses", "space", "input_names",
                           "input_lengths", "ranges"}) | DYNAMICS_KEYS
"""The keys only some manifests have (``removed``: an over-constrained file's; ``senses``: one
with spatial revolutes, cylindricals or angle drivers; ``space``: a
spatial one's; ``input_names``: one with input drivers; the dynamics keys). Written out:
with postponed annotations the TypedDict cannot see NotRequired in Python 3.11."""
