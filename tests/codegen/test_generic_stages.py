"""The generic stages name no language: everything of C, NumPy or MATLAB/Octave is in the
backend's own folder and reaches lower, render, compile, the warm-run index, the public entry
points and the Target protocol as the backend object's fields.

The check reads the string literals, comments and docstrings of those modules for the words a
language brings (its name, its real types, its file suffixes, its toolchain) and their
identifiers for a language's name as a part (``_C_OUTPUT``); a short allow-list keeps the two
places that speak of symkin's own implementation.
"""

from __future__ import annotations

import io
import re
import tokenize
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

GENERIC = ["symkin/codegen/lower.py", "symkin/codegen/render.py", "symkin/codegen/target.py",
           "symkin/codegen/printing.py", "symkin/build/compile.py", "symkin/build/index.py",
           "symkin/build/backend.py", "symkin/public.py"]

_WORDS = re.compile(r"\b(?:double|float|numpy|octave|matlab|cffi|python|gcc|clang|libm|"
                    r"restrict|sizeof)\b|\.(?:[ch]|m|py)\b", re.IGNORECASE)
_C = re.compile(r"\bC(?:99)?\b")  # the language C, in capitals (never a variable c)
_IDENTIFIER = re.compile(r"(?:\w*_)?(?:C|PYTHON|NUMPY|OCTAVE|MATLAB)(?:_\w*)?\Z")

# (module, line text) where a word names symkin's own implementation, not a target language.
ALLOWED = {
    ("symkin/build/index.py", "sha256 over symkin's own Python source and templates"),
    ("symkin/build/backend.py", "no NumPy at CLI start-up"),
}


def language_words(source: str) -> list[tuple[int, str, str]]:
    """(line, word, the line's text) for every language word in ``source``'s strings and
    comments, and every identifier with a language's name as a part."""
    lines = source.splitlines()
    found = []
    for token in tokenize.generate_tokens(io.StringIO(source).readline):
        if token.type in (tokenize.STRING, tokenize.COMMENT):
            for match in [*_WORDS.finditer(token.string), *_C.finditer(token.string)]:
                line = token.start[0] + token.string[:match.start()].count("\n")
                found.append((line, match.group(0), lines[line - 1]))
        elif token.type == tokenize.NAME and _IDENTIFIER.match(token.string):
            found.append((token.start[0], token.string, lines[token.start[0] - 1]))
    return found


def test_the_check_finds_a_planted_language_word() -> None:
    planted = ('def f(code):\n'
               '    """Print q[i] as a double."""\n'
               '    x = float(code.real)  # a builtin is not a language word\n'
               '    _C_OUTPUT = {"phi": "out"}  # a C naming table\n'
               '    return f"{x}.h", "kernel.py", c\n')
    words = [(line, word) for line, word, _ in language_words(planted)]
    assert words == [(2, "double"), (4, "_C_OUTPUT"), (4, "C"), (5, ".h"), (5, ".py")]


def test_the_generic_stages_name_no_language() -> None:
    found = []
    for module in GENERIC:
        source = (ROOT / module).read_text(encoding="utf-8")
        for line, word, text in language_words(source):
            if not any(place == module and allowed in text for place, allowed in ALLOWED):
                found.append(f"{module}:{line}: {word!r} in {text.strip()[:80]!r}")
    assert not found, ("language words in a generic stage (move them into the backend's "
                       "folder):\n" + "\n".join(found[:10]) +
                       (f"\n... and {len(found) - 10} more" if len(found) > 10 else ""))


def test_every_allowed_place_is_still_there() -> None:
    """An allow-list entry whose text is gone would excuse a new word unseen."""
    for module, text in ALLOWED:
        assert text in (ROOT / module).read_text(encoding="utf-8"), (module, text)
