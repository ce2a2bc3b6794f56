"""Compiled templates kept beside the templates, as Python keeps its bytecode in __pycache__.

jinja2 compiles every template to Python source and then to a code object at its first use
in a process: for the C backend that is about a quarter of a second, as long as deriving a
small planar mechanism. Kept in a ``__pycache__`` folder of the template root (keyed by
jinja2 on the template's name and the checksum of its source, so an edited template is
compiled afresh), a later process loads the code objects instead. Where the folder cannot be
written (a read-only installation), templates are compiled in memory as before: the cache
only ever saves time, never changes the output.
"""

from __future__ import annotations

import pickle
from pathlib import Path

import jinja2
from jinja2.bccache import Bucket

FOLDER = "__pycache__"
PATTERN = "symkin-%s.jinja"


class TemplateCache(jinja2.FileSystemBytecodeCache):
    """jinja2's file cache in ``<root>/__pycache__``, silent where it cannot read or write."""

    def __init__(self, root: str) -> None:
        super().__init__(str(Path(root) / FOLDER), PATTERN)

    def load_bytecode(self, bucket: Bucket) -> None:
        try:
            super().load_bytecode(bucket)
        except (OSError, EOFError, ValueError, TypeError, pickle.UnpicklingError):
            # unreadable or truncated (another process writing it is atomic: os.replace)
            bucket.reset()

    def dump_bytecode(self, bucket: Bucket) -> None:
        try:
            Path(self.directory).mkdir(exist_ok=True)
            super().dump_bytecode(bucket)
        except OSError:
            pass  # read-only: compiled in memory, as without a cache
