"""Limits that hold at every entry point (the mechanism file, the command line, the API), in
one place so that none of them can be looser than another."""

from collections.abc import Iterable

MAX_GRID_POINTS = 10_000_000
"""Time points of one grid. Its results take (3 N + 1) * 8 bytes a point: 2.2 GB for the
nine-coordinate crank-slider at this limit."""

MAX_FILE_BYTES = 1_000_000
"""Size of a mechanism file; read no further than this."""

MAX_NESTING = 32
"""Depth of nested mappings and lists in a mechanism file (real files use four or five)."""


def grid_points(t0: float, t1: float, dt: float) -> float:
    """How many points the grid t0, t0 + dt, ..., t1 has (a float: it may be astronomically
    large, and is only compared with the limit)."""
    return (t1 - t0) / dt + 1


def result_bytes(points: float, nq: int) -> float:
    """Memory for q, dq, d2q and t over ``points`` time points of ``nq`` coordinates."""
    return points * (3 * nq + 1) * 8


MAX_LISTED = 10
"""Names one message lists (joints, rows, points, files): a mechanism of a thousand bodies must
not print a line of a thousand joints."""


def listed(items: Iterable[str], sep: str = ", ", most: int = MAX_LISTED) -> str:
    """``items`` joined by ``sep``, at most ``most`` of them, then how many more there are."""
    names = list(items)
    shown = sep.join(names[:most])
    rest = len(names) - most
    return f"{shown} and {rest} more" if rest > 0 else shown


def listed_groups(groups: Iterable[Iterable[str]]) -> str:
    """Groups of names (rows that depend on each other) as ``{a, b}; {c}``, each group and
    the list of groups bounded as :func:`listed` bounds one list."""
    return listed(("{" + listed(g) + "}" for g in groups), "; ")
