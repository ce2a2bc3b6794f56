"""The file's names checked, each by the rules of its kind; kept apart from validate for size."""

from __future__ import annotations

from typing import Any

from symkin import pairs
from symkin.contract.columns import RATE_SUFFIXES
from symkin.errors import MechanismError, format_path
from symkin.pairs.fields import GROUND, is_input
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


def input_places(mech: MechanismSpec) -> list[tuple[str, int, str, int | None]]:
    """Every driver function written ``input``, drivers in file order, components in order:
    (its name, the driver's index, the key, the component or None). The name is the driver's
    (``drivers[k]`` when unnamed), with ``_x``, ``_y``, ``_z`` per component of a vector."""
    found = []
    for index, driver in enumerate(mech.drivers):
        base = driver.name or f"drivers[{index}]"
        for key in pairs.of(driver).time_functions:
            value = getattr(driver, key)
            components = enumerate(value) if isinstance(value, list) else ((None, value),)
            for component, raw in components:
                if is_input(raw):
                    name = base if component is None else f"{base}_{'xyz'[component]}"
                    found.append((name, index, key, component))
    return found


def length_inputs(mech: MechanismSpec) -> tuple[str, ...]:
    """The inputs that are a length (PairType.lengths: a distance driver's f), by name."""
    return tuple(name for name, index, key, _ in input_places(mech)
                 if key in pairs.of(mech.drivers[index]).lengths)


def _check_input_names(mech: MechanismSpec) -> None:
    """Each input's value, rate and acceleration need a name of their own (a column of an
    inputs table, a key of inputs=): two inputs of one name, or one named as another's rate
    (v and v_t), would read one another's values."""
    seen: dict[str, tuple[str, tuple[str | int, ...]]] = {}
    for name, index, key, component in input_places(mech):
        path: tuple[str | int, ...] = ("drivers", index, key) + (
            () if component is None else (component,))
        for suffix, what in zip(("", *RATE_SUFFIXES), ("the input", "the rate of the input",
                                                       "the acceleration of the input")):
            column, this = name + suffix, f"{what} {name!r}"
            if column in seen:
                other, where = seen[column]
                raise MechanismError(
                    f"{this} and {other} at {format_path(where)} share the name {column!r}",
                    path,
                    "Inputs are given by name (a column of the inputs table, with NAME_t and "
                    "NAME_tt for rates and accelerations): name the drivers so that no input "
                    "is called as another or as another's rate (v and v_t).")
            seen[column] = (this, path)
