"""The file's names checked, each by the rules of its kind; kept apart from validate for size."""

from __future__ import annotations

from typing import Any

from symkin import pairs
from symkin.errors import MechanismError, format_path
from symkin.pairs.fields import GROUND
from symkin.spec.names import name_problem
from symkin.spec.schema import MechanismSpec


def _check_names(mech: MechanismSpec) -> None:
    """Every name by the rules of its kind (spec.names); all clashes reported at once."""
    problem = name_problem(mech.name, "mechanism")
    if problem:
        raise MechanismError(problem, ("name",), "Use a plain identifier such as crank_slider; "
                             "it becomes the C prefix and the file names.")
    problems: list[tuple[tuple[str | int, ...], str]] = []
    seen: dict[str, tuple[str | int, ...]] = {}
    for section, kind in (("parameters", "parameter"), ("bodies", "body")):
        for name in getattr(mech, section):
            path = (section, name)
            problem = name_problem(name, kind)
            if problem is None and name in seen:
                problem = f"{name!r} is already used at {format_path(seen[name])}"
            if problem:
                problems.append((path, problem))
            seen.setdefault(name, path)
    for body, spec in mech.bodies.items():
        for point in spec.points:
            problem = name_problem(point, "point")
            if problem:
                problems.append((("bodies", body, "points", point), problem))
    if problems:
        listed = problems[0][1] if len(problems) == 1 else f"{len(problems)} names cannot be " \
            "used: " + "; ".join(f"{format_path(path)}: {problem}" for path, problem in problems)
        raise MechanismError(listed, problems[0][0],
                             "Rename them. Parameters and bodies may not be t, pi, E, a function "
                             "name, True/False/None or a Python keyword, and must differ from "
                             "each other; point, joint and driver names are free identifiers.")


def _check_coordinate_name(mech: MechanismSpec, constraint: Any,
                           path: tuple[str | int, ...]) -> None:
    """A pair that adds a coordinate NAME.s needs a name that no body has."""
    kind = pairs.of(constraint)
    if kind.coordinate is None:
        return
    if constraint.name is None:
        raise MechanismError(f"a {kind.name} pair needs a name", path + ("name",),
                             f"It adds the coordinate NAME.s (solved and reported like the "
                             f"bodies'); give it one, e.g. name: {kind.name[0]}1.")
    if constraint.name in mech.bodies or constraint.name == GROUND:
        raise MechanismError(f"the name {constraint.name!r} is a body's", path + ("name",),
                             f"Its coordinate {constraint.name}.s would read as a coordinate "
                             "of that body; use another name.")
