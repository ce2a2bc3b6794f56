"""Pydantic's validation errors said the way a mechanism file's reader thinks: file, line,
field and how to fix it."""

from __future__ import annotations

from typing import Any

from pydantic import BaseModel, ValidationError

from symkin import pairs
from symkin.errors import MechanismError
from symkin.pairs.fields import kind_of
from symkin.spec import loader
from symkin.spec.schema import Body, MechanismSpec, TimeGrid


def translate(error: ValidationError, document: loader.Document) -> MechanismError:
    """Turn pydantic's first error into a MechanismError that names file, line and field."""
    first = error.errors()[0]
    path = tuple(part for part in first["loc"] if part != "[key]")
    path = _data_path(document.data, path)
    kind = first["type"]
    message, hint = first["msg"], ""
    if kind == "extra_forbidden":
        message = f"unknown key {path[-1]!r}"
        hint = f"Allowed keys here: {', '.join(_allowed_keys(path, document.data))}."
    elif kind == "missing":
        message = f"the required key {path[-1]!r} is missing"
    elif kind == "union_tag_invalid":
        tag = first.get("input", {}).get("type") if isinstance(first.get("input"), dict) else None
        message = f"unknown type {tag!r}"
        hint = f"Use one of: {first['ctx']['expected_tags']}."
    elif kind == "union_tag_not_found":
        message = "the key 'type' is missing"
        section = "joints" if path[:1] == ("joints",) else "drivers"
        kinds = ", ".join(kind.name for kind in pairs.in_section(section))
        hint = f"Add type: one of {kinds}."
    elif kind in _PYDANTIC_MESSAGES:
        message = _PYDANTIC_MESSAGES[kind].format(kind=kind_of(first.get("input")),
                                                  **first.get("ctx", {}))
    return MechanismError(message, path, hint, document.source, document.line_of(path))


# pydantic's own wording for shape errors, said the way a mechanism file's reader thinks.
_PYDANTIC_MESSAGES = {
    "string_type": "expected a name (text), got {kind}",
    "dict_type": "expected a mapping of keys to values, got {kind}",
    "model_type": "expected a mapping of keys to values, got {kind}",
    "model_attributes_type": "expected a mapping of keys to values, got {kind}",
    "list_type": "expected a list, got {kind}",
    "too_short": "needs at least {min_length} item(s), got {actual_length}",
    "too_long": "takes at most {max_length} item(s), got {actual_length}",
}


def _data_path(data: Any, loc: tuple[Any, ...]) -> tuple[str | int, ...]:
    """Drop the union-member names pydantic puts into locations; keep real field paths."""
    path: list[str | int] = []
    node = data
    for part in loc:
        in_list = isinstance(node, list) and isinstance(part, int) and part < len(node)
        if (isinstance(node, dict) and part in node) or in_list:
            path.append(part)
            node = node[part]
        elif isinstance(node, dict) and isinstance(part, str) and part in _ALL_FIELDS:
            path.append(part)  # a missing key
            break
    return tuple(path)


def _allowed_keys(path: tuple[str | int, ...], data: Any) -> list[str]:
    section = path[0] if path else ""
    if len(path) <= 1:
        return list(MechanismSpec.model_fields)
    if section == "bodies":
        return list(Body.model_fields)
    if section == "time":
        return list(TimeGrid.model_fields)
    try:
        kind = pairs.named(data[section][path[1]]["type"])
    except (KeyError, IndexError, TypeError):
        kind = None
    if kind is None:
        return ["type, name and the keys of that type"]
    return list(kind.model.model_fields)


_MODELS: tuple[type[BaseModel], ...] = (MechanismSpec, Body, TimeGrid,
                                        *(kind.model for kind in pairs.TYPES))
_ALL_FIELDS = {name for model in _MODELS for name in model.model_fields}
