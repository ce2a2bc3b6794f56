"""A pydantic model's keys as a Markdown table: name, whether it is required (or its default),
what values it takes (read from the model's JSON schema, the same one `symkin schema` prints)
and, where a pair type says so, what role the key plays."""

from __future__ import annotations

import json
from typing import Any

from pydantic import BaseModel


def value_text(prop: dict[str, Any], defs: dict[str, Any]) -> str:
    """A JSON-schema property in a few words: `"revolute"`, `number or expression`, `[x, y]`."""
    if "const" in prop:
        return f'`"{prop["const"]}"`'
    if "$ref" in prop:
        return "a `" + prop["$ref"].rsplit("/", 1)[-1] + "` mapping (below)"
    if "anyOf" in prop:
        if sorted(p.get("type", "") for p in prop["anyOf"]) == ["number", "string"]:
            return "number or expression"
        parts = [value_text(p, defs) for p in prop["anyOf"] if p.get("type") != "null"]
        return " or ".join(dict.fromkeys(parts))
    kind = prop.get("type")
    if kind == "array":
        size = prop.get("minItems")
        items = prop.get("items", {})
        if size is not None and size == prop.get("maxItems") and size <= 9:
            return f"list of {size} " + _plural(value_text(items, defs))
        return "list of " + _plural(value_text(items, defs)) if items else "list"
    if kind == "object":
        extra = prop.get("additionalProperties")
        inner = value_text(extra, defs) if isinstance(extra, dict) else "values"
        return f"mapping of names to {_plural(inner)}"
    if kind == "number" or kind == "integer":
        return "number"
    if kind == "string":
        return "name or text"
    if kind == "boolean":
        return "true or false"
    return "value"


def _plural(text: str) -> str:
    return {"number or expression": "numbers or expressions", "number": "numbers",
            "name or text": "names"}.get(text, text)


def _value(prop: dict[str, Any], defs: dict[str, Any]) -> str:
    text = value_text(prop, defs)
    # a point reference: a point's name or a local vector
    return text.replace("name or text or list of", "point name or list of")


def table(model: type[BaseModel], roles: dict[str, str] | None = None) -> str:
    """The keys of ``model``, one row each, in the model's order."""
    schema = model.model_json_schema()
    defs = schema.get("$defs", {})
    required = set(schema.get("required", []))
    rows = ["| key | required | value | meaning |", "|---|---|---|---|"]
    for key, prop in schema.get("properties", {}).items():
        if key in required:
            need = "yes"
        elif "default" in prop and prop["default"] is not None:
            need = f"no (default `{json.dumps(prop['default'])}`)"
        else:
            need = "no"
        meaning = (roles or {}).get(key, "")
        rows.append(f"| `{key}` | {need} | {_value(prop, defs)} | {meaning} |")
    for name, sub in defs.items():
        if sub.get("type") == "object" and "properties" in sub:
            rows.append("")
            rows.append(f"`{name}`: {sub.get('description', '').strip()}".rstrip(": "))
            rows.append("")
            rows.append("| key | required | value |")
            rows.append("|---|---|---|")
            inner_required = set(sub.get("required", []))
            for key, prop in sub["properties"].items():
                need = "yes" if key in inner_required else "no"
                rows.append(f"| `{key}` | {need} | {_value(prop, defs)} |")
    return "\n".join(rows)
