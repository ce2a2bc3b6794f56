"""Reading mechanism files: YAML or TOML text -> plain data plus the line of every field.

The YAML reader is deliberately stricter than PyYAML's defaults. It resolves scalars as YAML 1.2
does (``1e-10`` is a number, ``yes``/``on``/``0o17``/``1:20`` are plain text), refuses duplicate
keys, aliases (which can expand into huge structures) and every tag that would build a Python
object, and remembers the line of each field so that errors can point at it.
"""

from __future__ import annotations

import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from symkin.errors import MechanismError

Path_ = tuple[str | int, ...]

_INT = re.compile(r"[-+]?[0-9]+\Z")
_FLOAT = re.compile(r"[-+]?(\.[0-9]+|[0-9]+(\.[0-9]*)?)([eE][-+]?[0-9]+)?\Z")
_SPECIAL_FLOATS = {".inf": float("inf"), "+.inf": float("inf"), "-.inf": float("-inf"),
                   ".nan": float("nan")}
_PLAIN = "tag:symkin,2026:plain"
_ALLOWED_TAGS = {
    _PLAIN, "!",
    "tag:yaml.org,2002:str", "tag:yaml.org,2002:int", "tag:yaml.org,2002:float",
    "tag:yaml.org,2002:bool", "tag:yaml.org,2002:null", "tag:yaml.org,2002:map",
    "tag:yaml.org,2002:seq",
}
MAX_FILE_BYTES = 1_000_000


@dataclass
class Document:
    """A parsed mechanism file: its data and the line where each field path starts."""

    data: Any
    source: str
    lines: dict[Path_, int] = field(default_factory=dict)

    def line_of(self, path: Path_) -> int | None:
        """The line of the deepest known field on ``path``."""
        for end in range(len(path), -1, -1):
            if path[:end] in self.lines:
                return self.lines[path[:end]]
        return None


def read(path: str | Path) -> Document:
    """Read a mechanism file; the format follows the suffix (.toml, else YAML)."""
    path = Path(path)
    source = str(path)
    try:
        raw = path.read_bytes()
    except OSError as error:
        raise MechanismError(f"cannot read the file ({error.strerror})",
                             hint="Check the path.", source=source) from None
    if len(raw) > MAX_FILE_BYTES:
        raise MechanismError(f"the file is larger than {MAX_FILE_BYTES} bytes", source=source)
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as error:
        raise MechanismError(f"the file is not UTF-8 text (byte {error.start})",
                             hint="Save it as UTF-8.", source=source) from None
    if path.suffix.lower() == ".toml":
        return read_toml(text, source)
    return read_yaml(text, source)


def read_toml(text: str, source: str) -> Document:
    """Parse TOML text (line numbers are not tracked for TOML)."""
    try:
        return Document(tomllib.loads(text), source)
    except tomllib.TOMLDecodeError as error:
        raise MechanismError(f"this is not valid TOML: {error}", source=source) from None


def read_yaml(text: str, source: str) -> Document:
    """Parse YAML text into plain data with line numbers, refusing unsafe constructs."""
    try:
        node = yaml.compose(text, Loader=_Loader)
    except yaml.MarkedYAMLError as error:
        line = error.problem_mark.line + 1 if error.problem_mark else None
        raise MechanismError(f"this is not valid YAML: {error.problem}",
                             source=source, line=line) from None
    except yaml.YAMLError as error:
        raise MechanismError(f"this is not valid YAML: {error}", source=source) from None
    document = Document(None, source)
    if node is not None:
        document.data = _convert(node, (), document)
    return document


class _Loader(yaml.SafeLoader):
    """A composer that refuses aliases; plain scalars are resolved later by ``_scalar``."""

    # Replace PyYAML's YAML 1.1 resolution: every plain scalar gets one tag, so an explicit
    # ``!!str`` can still be told apart, and ``_scalar`` applies the YAML 1.2 rules.
    yaml_implicit_resolvers: dict = {}

    def compose_node(self, parent: Any, index: Any) -> Any:
        if self.check_event(yaml.AliasEvent):
            event = self.peek_event()
            raise yaml.composer.ComposerError(
                None, None, "aliases (*name) are not allowed; use parameters to share values",
                event.start_mark)
        return super().compose_node(parent, index)


def _fail(document: Document, node: yaml.Node, path: Path_, message: str,
          hint: str = "") -> MechanismError:
    return MechanismError(message, path, hint, document.source, node.start_mark.line + 1)


def _convert(node: yaml.Node, path: Path_, document: Document) -> Any:
    document.lines[path] = node.start_mark.line + 1
    if node.tag not in _ALLOWED_TAGS:
        raise _fail(document, node, path, f"the YAML tag {node.tag!r} is not allowed",
                    "Remove the tag; mechanism files hold only plain values.")
    if isinstance(node, yaml.MappingNode):
        return _mapping(node, path, document)
    if isinstance(node, yaml.SequenceNode):
        return [_convert(item, path + (k,), document) for k, item in enumerate(node.value)]
    return _scalar(node, path, document)


def _mapping(node: yaml.MappingNode, path: Path_, document: Document) -> dict[str, Any]:
    result: dict[str, Any] = {}
    for key_node, value_node in node.value:
        if isinstance(key_node, yaml.ScalarNode) and key_node.value == "<<":
            raise _fail(document, key_node, path, "merge keys (<<) are not allowed",
                        "Write the keys out.")
        key = _scalar(key_node, path, document) if isinstance(key_node, yaml.ScalarNode) else None
        if not isinstance(key, str):
            shown = key_node.value if isinstance(key_node, yaml.ScalarNode) else "a collection"
            raise _fail(document, key_node, path, f"the key {shown!r} is not a name",
                        "Keys must be plain names.")
        if key in result:
            raise _fail(document, key_node, path + (key,), f"the key {key!r} appears twice",
                        "Remove one of the two.")
        document.lines[path + (key,)] = key_node.start_mark.line + 1
        result[key] = _convert(value_node, path + (key,), document)
        document.lines[path + (key,)] = key_node.start_mark.line + 1
    return result


def _scalar(node: yaml.ScalarNode, path: Path_, document: Document) -> Any:
    """Resolve a scalar the YAML 1.2 core-schema way; quoted scalars stay text."""
    text = node.value
    if node.tag != _PLAIN or node.style is not None:
        return _tagged(node, path, document)
    lowered = text.lower()
    if text in ("", "~") or lowered == "null":
        return None
    if lowered in ("true", "false"):
        return lowered == "true"
    if _INT.match(text):
        return int(text)
    if _FLOAT.match(text):
        return float(text)
    if lowered in _SPECIAL_FLOATS:
        return _SPECIAL_FLOATS[lowered]
    return text


def _tagged(node: yaml.ScalarNode, path: Path_, document: Document) -> Any:
    """A quoted scalar, or one with an explicit core tag (``!!float 1``)."""
    if node.tag in (_PLAIN, "!", "tag:yaml.org,2002:str"):
        return node.value
    value = _scalar(yaml.ScalarNode(_PLAIN, node.value, node.start_mark), path, document)
    wanted = {"tag:yaml.org,2002:int": int, "tag:yaml.org,2002:float": (int, float),
              "tag:yaml.org,2002:bool": bool, "tag:yaml.org,2002:null": type(None)}[node.tag]
    if not isinstance(value, wanted):
        raise _fail(document, node, path, f"{node.value!r} does not match its tag {node.tag!r}")
    return float(value) if node.tag.endswith("float") else value


_Loader.add_implicit_resolver(_PLAIN, re.compile(r".*", re.DOTALL), None)
