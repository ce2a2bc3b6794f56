"""Reading mechanism files: YAML or TOML text -> plain data plus the line of every field.

The YAML reader is deliberately stricter than PyYAML's defaults. It resolves scalars as YAML 1.2
does (``1e-10`` is a number, ``yes``/``on``/``0o17``/``1:20`` are plain text), refuses duplicate
keys, aliases (which can expand into huge structures) and every tag that would build a Python
object, and remembers the line of each field so that errors can point at it.
"""

from __future__ import annotations

import re
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar, cast

import numpy as np
import yaml

from symkin.errors import MechanismError
from symkin.limits import MAX_FILE_BYTES, MAX_NESTING

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
        with path.open("rb") as stream:  # never more than the limit, even from /dev/zero
            raw = stream.read(MAX_FILE_BYTES + 1)
    except OSError as error:
        raise MechanismError(f"cannot read the file ({error.strerror})",
                             hint="Check the path.", source=source) from None
    if len(raw) > MAX_FILE_BYTES:
        raise MechanismError(f"the file is larger than {MAX_FILE_BYTES} bytes",
                             hint="A mechanism file is a few kilobytes; check the path.",
                             source=source)
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as error:
        raise MechanismError(f"the file is not UTF-8 text (byte {error.start})",
                             hint="Save it as UTF-8.", source=source,
                             line=raw[:error.start].count(b"\n") + 1) from None
    if path.suffix.lower() == ".toml":
        return read_toml(text, source)
    return read_yaml(text, source)


def read_toml(text: str, source: str) -> Document:
    """Parse TOML text; field lines are found by a light scan of keys and table headers."""
    try:
        data = tomllib.loads(text)
    except RecursionError:
        raise _too_deep(source) from None
    except tomllib.TOMLDecodeError as error:
        # tomllib puts the place into its message: "... (at line 2, column 23)".
        found = _TOML_PLACE.search(str(error))
        message = _TOML_PLACE.sub("", str(error)).strip()
        raise MechanismError(f"this is not valid TOML: {message}", source=source,
                             line=int(found.group(1)) if found else None) from None
    if _depth(data) > MAX_NESTING:
        raise _too_deep(source)
    return Document(data, source, _toml_lines(text))


def from_python(data: Any, source: str) -> Document:
    """Data built in Python (``symkin.from_dict``) as a file would give it: numpy scalars and
    arrays become Python numbers and lists, tuples lists, mappings dicts; as deep as a file may
    nest (a mapping that contains itself is refused, not followed)."""
    return Document(_plain(data, source, 0), source)


def _plain(node: Any, source: str, depth: int) -> Any:
    if depth > MAX_NESTING:
        raise _too_deep(source)
    if isinstance(node, Mapping):
        return {_plain_key(key): _plain(value, source, depth + 1) for key, value in node.items()}
    if isinstance(node, (list, tuple, np.ndarray)):
        return [_plain(value, source, depth + 1) for value in node]
    if isinstance(node, np.generic):
        return node.item()  # np.float64(1.5) -> 1.5, np.bool_(True) -> True
    return node


def _plain_key(key: Any) -> Any:
    """A key stays hashable (a tuple key stays a tuple, for the schema to refuse)."""
    return key.item() if isinstance(key, np.generic) else key


def _depth(data: Any) -> int:
    """How deeply lists and mappings nest in plain data (iterative: no recursion limit)."""
    deepest, stack = 0, [(data, 0)]
    while stack:
        node, depth = stack.pop()
        deepest = max(deepest, depth)
        if isinstance(node, dict):
            stack.extend((value, depth + 1) for value in node.values())
        elif isinstance(node, list):
            stack.extend((value, depth + 1) for value in node)
    return deepest


_TOML_PLACE = re.compile(r"\(at line (\d+), column \d+\)")
_TOML_HEADER = re.compile(r"\s*(\[\[?)\s*([A-Za-z0-9_.\s-]+?)\s*\]\]?\s*(#.*)?\Z")
_TOML_KEY = re.compile(r"\s*([A-Za-z0-9_-]+(?:\s*\.\s*[A-Za-z0-9_-]+)*)\s*=(?!=)")


def _toml_lines(text: str) -> dict[Path_, int]:
    """The line of each table header and bare key (dotted keys and arrays of tables too).

    Only line numbers for messages come from this scan; the data comes from tomllib.
    """
    lines: dict[Path_, int] = {}
    arrays: dict[Path_, int] = {}  # array-of-tables path -> index of its last element
    table: Path_ = ()
    in_string = False
    for number, line in enumerate(text.splitlines(), start=1):
        opens_or_closes = bool(line.count('"""') % 2 or line.count("'''") % 2)
        if not in_string:
            header = _TOML_HEADER.match(line)
            key = _TOML_KEY.match(line)
            if header:
                table = _toml_table(header.group(2).split("."), header.group(1) == "[[", arrays)
                lines.setdefault(table, number)
            elif key:
                path = table + tuple(k.strip() for k in key.group(1).split("."))
                lines.setdefault(path, number)
        in_string ^= opens_or_closes  # inside a multi-line string nothing is a key
    return lines


def _toml_table(parts: list[str], is_array: bool, arrays: dict[Path_, int]) -> Path_:
    """Resolve a table header to a field path; array elements get their index."""
    path: Path_ = ()
    for part in parts:
        path += (part.strip(),)
        if path in arrays and (path != tuple(p.strip() for p in parts) or not is_array):
            path += (arrays[path],)
    if is_array:
        arrays[path] = arrays.get(path, -1) + 1
        path += (arrays[path],)
    return path


def read_yaml(text: str, source: str) -> Document:
    """Parse YAML text into plain data with line numbers, refusing unsafe constructs."""
    try:
        node = yaml.compose(text, Loader=_Loader)
    except RecursionError:
        raise _too_deep(source) from None
    except yaml.MarkedYAMLError as error:
        # A problem at the end of the stream is reported on the last line, not past it.
        last = max(1, len(text.splitlines()))
        line = min(error.problem_mark.line + 1, last) if error.problem_mark else None
        raise MechanismError(f"this is not valid YAML: {error.problem}",
                             source=source, line=line) from None
    except yaml.reader.ReaderError as error:
        # A character YAML does not allow: its reader counts characters, so say the line
        # and column (a control character is invisible in most editors).
        line = text.count("\n", 0, error.position) + 1
        column = error.position - (text.rfind("\n", 0, error.position) + 1) + 1
        what = (f"U+{error.character:04X}" if isinstance(error.character, int)
                else repr(error.character))
        raise MechanismError(f"this is not valid YAML: the character {what} at column "
                             f"{column} is not allowed (a control character?)",
                             source=source, line=line,
                             hint="Delete it, or write it as an escape in a quoted "
                                  "string.") from None
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
    yaml_implicit_resolvers: ClassVar[dict[str, Any]] = {}

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


def _too_deep(source: str, line: int | None = None) -> MechanismError:
    return MechanismError(f"lists and mappings are nested more than {MAX_NESTING} deep",
                          hint="A mechanism file nests a few levels; check the brackets.",
                          source=source, line=line)


def _convert(node: yaml.Node, path: Path_, document: Document) -> Any:
    document.lines[path] = node.start_mark.line + 1
    if len(path) > MAX_NESTING:
        raise _too_deep(document.source, node.start_mark.line + 1)
    _check_tag(node, path, document)
    if isinstance(node, yaml.MappingNode):
        return _mapping(node, path, document)
    if isinstance(node, yaml.SequenceNode):
        return [_convert(item, path + (k,), document) for k, item in enumerate(node.value)]
    return _scalar(node, path, document)


def _check_tag(node: yaml.Node, path: Path_, document: Document) -> None:
    """Values and keys alike carry no tag but the core schema's."""
    if node.tag not in _ALLOWED_TAGS:
        raise _fail(document, node, path, f"the YAML tag {node.tag!r} is not allowed",
                    "Remove the tag; mechanism files hold only plain values.")


def _mapping(node: yaml.MappingNode, path: Path_, document: Document) -> dict[str, Any]:
    result: dict[str, Any] = {}
    for key_node, value_node in node.value:
        if isinstance(key_node, yaml.ScalarNode) and key_node.value == "<<":
            raise _fail(document, key_node, path, "merge keys (<<) are not allowed",
                        "Write the keys out.")
        _check_tag(key_node, path, document)
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
    wanted = _TAG_TYPES[node.tag]
    # bool is an int to Python, not to YAML: `!!float true` is refused.
    if not isinstance(value, wanted) or (isinstance(value, bool) and wanted is not bool):
        raise _fail(document, node, path, f"{node.value!r} does not match its tag {node.tag!r}")
    return float(cast(float, value)) if node.tag.endswith("float") else value


# What an explicit core tag accepts (``!!float 1`` is fine, ``!!int 1.5`` is not).
_TAG_TYPES: dict[str, type | tuple[type, ...]] = {
    "tag:yaml.org,2002:int": int, "tag:yaml.org,2002:float": (int, float),
    "tag:yaml.org,2002:bool": bool, "tag:yaml.org,2002:null": type(None)}

_Loader.add_implicit_resolver(_PLAIN, re.compile(r".*", re.DOTALL), None)
