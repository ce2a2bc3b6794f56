"""The cffi declarations of a generated C folder, taken from its own headers.

The headers are the one description of the C interface: cffi reads them after comments,
include guards and ``#include`` lines are removed (cffi's parser takes integer ``#define``s,
typedefs, structs and prototypes as C). So the Python binding can never drift from the header
a C user compiles against, and a template change needs no second edit.
"""

from __future__ import annotations

import re
from collections.abc import Mapping

_COMMENT = re.compile(r"/\*.*?\*/", re.DOTALL)
_INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.MULTILINE)
_GUARD = re.compile(r"^\s*#\s*(ifndef|endif|define\s+\w+_H\s*$)")


def from_headers(files: Mapping[str, str]) -> str:
    """The cdef text: every ``.h`` of ``files``, each after the headers it includes."""
    headers = {name: text for name, text in files.items() if name.endswith(".h")}
    return "\n".join(_declarations(headers[name]) for name in _include_order(headers))


def _include_order(headers: Mapping[str, str]) -> list[str]:
    """Header names so that each comes after the local headers it includes (sorted ties)."""
    ordered: list[str] = []

    def visit(name: str, path: tuple[str, ...]) -> None:
        if name in ordered or name not in headers or name in path:
            return
        for included in sorted(_INCLUDE.findall(headers[name])):
            visit(included, (*path, name))
        ordered.append(name)

    for name in sorted(headers):
        visit(name, ())
    return ordered


def _declarations(header: str) -> str:
    """A header without comments, include guards and includes: plain declarations."""
    kept = [line for line in _COMMENT.sub("", header).splitlines()
            if not (_GUARD.match(line) or _INCLUDE.match(line)) and line.strip()]
    return "\n".join(kept)
