"""The mechanism file's joints, drivers and forces, one page each, written from the pair
registry (:mod:`symkin.pairs`) and the pydantic models (:mod:`symkin.spec.schema`,
:mod:`symkin.spec.forces`, :mod:`symkin.spec.forces3d`) when the docs are built: a type
registered there documents itself, and the page cannot drift from the code."""

from __future__ import annotations

import inspect
import re
import typing
from pathlib import Path
from typing import Any

import yaml

from symkin import pairs
from symkin.pairs.kit import PairType
from symkin.spec import forces, forces3d

SPACE_TITLE = {"2d": "planar", "3d": "spatial (`space: 3d`)"}
SPACE_SLUG = {"2d": "planar", "3d": "spatial"}


def _doc(obj: Any) -> str:
    """A docstring as Markdown: Sphinx roles such as :mod:`x` become plain code."""
    text = inspect.cleandoc(obj.__doc__ or "").strip()
    return re.sub(r":[a-z]+:`~?([^`]+)`", r"`\1`", text)


def roles(kind: PairType) -> dict[str, str]:
    """What each key of a type does, as the registry records it."""
    said = {"type": "the pair or driver type", "name": "a label for messages and reports"}
    for n, key in enumerate(kind.bodies):
        said[key] = "the body " + ("it moves along a path" if kind.on_ground else
                                   ("i" if n == 0 else "j")) + " (a name from `bodies`)"
    for key, body in kind.points:
        said[key] = f"a point of body `{body}`: a point name or a local vector"
    for key, body in kind.directions:
        said[key] = f"a direction fixed in body `{body}` (never zero)"
    for key in kind.constants:
        said[key] = "a constant: an expression of the parameters"
    for key in kind.time_functions:
        said[key] = "a function of time `t` (or `input`: a value read at run time)"
    if kind.drawn_model is not None and "at" in kind.drawn_model.model_fields:
        said["at"] = "drawn layout: the point both bodies share, a name or global [x, y]"
    if kind.coordinate:
        said[kind.coordinate] = "first guess of the coordinate the pair adds"
    if kind.coordinate_range:
        said[kind.coordinate_range] = "range [a, b] of that coordinate"
    return said


def _examples(kind: PairType, space: str, examples: Path) -> dict[str, tuple[str, str]]:
    """The shortest entry of this type in the example files of each layout:
    {layout: (file name, its YAML)}."""
    found: dict[str, list[tuple[int, str, str]]] = {}
    for path in sorted(examples.glob("*.yaml")):
        data = yaml.safe_load(path.read_text(encoding="utf-8"))
        if data.get("space", "2d") != space:
            continue
        for section in kind.sections:
            for entry in data.get(section) or []:
                if isinstance(entry, dict) and entry.get("type") == kind.name:
                    text = yaml.safe_dump({section: [_shortened(entry)]},
                                          default_flow_style=None, sort_keys=False, width=96)
                    found.setdefault(data.get("layout", "local"), []).append(
                        (len(text), path.name, text))
    return {layout: min(entries)[1:] for layout, entries in sorted(found.items(), reverse=True)}


def _shortened(value: Any) -> Any:
    """Long expressions (a cam's profile) cut to their start, so the example stays readable."""
    if isinstance(value, dict):
        return {k: _shortened(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_shortened(v) for v in value]
    if isinstance(value, str) and len(value) > 70:
        return value[:50] + " ... (shortened)"
    return value


def _equations(kind: PairType) -> str:
    doc = _doc(kind.equations)
    return doc if doc else "(its module gives no formula)"


def page(kind: PairType, space: str, examples: Path) -> str:
    """The Markdown page of one type in one family."""
    module = inspect.getmodule(kind.equations)
    rows = ", ".join(f"`{r}`" for r in kind.rows) if kind.rows else "one per given equation"
    lines = [f"# `{kind.name}` ({SPACE_TITLE[space]})", "",
             _doc(module) if module else _doc(kind.model), "",
             f"- listed under: {' and '.join(f'`{s}`' for s in kind.sections)}",
             f"- rows of Φ: {rows}",
             f"- in code: `{kind.model.__module__}`", "",
             "## Equations", "", "```text", _equations(kind), "```", "",
             "## Keys (local layout)", "", roles_table(kind, kind.model), ""]
    if kind.drawn_model is not None:
        lines += ["## Keys (drawn layout, `layout: drawn`)", "",
                  _doc(kind.drawn_model) or "Points and directions are global, as drawn.", "",
                  roles_table(kind, kind.drawn_model), ""]
    found = _examples(kind, space, examples)
    lines += ["## Example" + ("s" if len(found) > 1 else ""), ""]
    if not found:
        lines += ["No example file lists this type yet.", ""]
    for layout, (name, text) in found.items():
        lines += [f"From `examples/{name}` ({layout} layout):", "", "```yaml", text.rstrip(),
                  "```", ""]
    return "\n".join(lines)


def roles_table(kind: PairType, model: Any) -> str:
    from symkin_docs.keys import table

    return table(model, roles(kind))


def force_page(space: str) -> str:
    """The ``forces`` section's types of one family."""
    module = forces if space == "2d" else forces3d
    members = typing.get_args(typing.get_args(module.Load)[0])
    lines = [f"# Forces ({SPACE_TITLE[space]})", "", _doc(module), ""]
    for model in members:
        name = model.model_fields["type"].annotation.__args__[0]
        lines += [f"## `{name}`", "", _doc(model), "", _force_table(model), ""]
    return "\n".join(lines)


def _force_table(model: Any) -> str:
    from symkin_docs.keys import table

    return table(model, {"type": "the force type", "name": "a label for reports",
                         "body": "the body it acts on", "i": "the body of point A",
                         "j": "the body of point B", "A": "a point of body i",
                         "B": "a point of body j", "at": "the point of the body it acts at",
                         "g": "the acceleration of gravity, global components",
                         "f": "the force, global components"})


def write_all(out: Path, examples: Path) -> list[str]:
    """Every page under ``out``; returns the names written (without .md)."""
    out.mkdir(parents=True, exist_ok=True)
    names = []
    index = ["# Joint, driver and force types", "",
             "Generated from the pair registry and the file's models when these pages are "
             "built: every type symkin accepts, with its keys.", ""]
    for space in pairs.SPACES:
        family = pairs.in_section("joints", space) + pairs.in_section("drivers", space)
        index += [f"## {SPACE_TITLE[space].capitalize()}", "",
                  "| type | listed under | what it is |", "|---|---|---|"]
        for kind in dict.fromkeys(family):
            name = f"{SPACE_SLUG[space]}-{kind.name}"
            if name in names:  # a joint and a driver of one name (spatial distance)
                name += "-" + kind.sections[-1].rstrip("s")
            _write(out / f"{name}.md", page(kind, space, examples))
            names.append(name)
            module = inspect.getmodule(kind.equations)
            summary = _doc(module).split("\n\n")[0].replace("\n", " ") if module else ""
            index.append(f"| [`{kind.name}`]({name}.md) | {', '.join(kind.sections)} | "
                         f"{summary.replace('|', '/')} |")
        force = f"{SPACE_SLUG[space]}-forces"
        _write(out / f"{force}.md", force_page(space))
        names.append(force)
        index += ["", f"Forces: [{SPACE_TITLE[space]} forces]({force}.md).", ""]
    index += ["```{toctree}", ":hidden:", "", *names, "```", ""]
    _write(out / "index.md", "\n".join(index))
    return names


def _write(path: Path, text: str) -> None:
    # Unchanged pages keep their time stamp, so Sphinx does not read them again.
    if not path.exists() or path.read_text(encoding="utf-8") != text:
        path.write_text(text, encoding="utf-8")
