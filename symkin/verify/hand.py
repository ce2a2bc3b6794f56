"""The hand side: a user's Python module with phi, phi_q, phi_t, gamma, loaded by path.

Loading it runs it, as pytest runs a test file; nothing is added to ``sys.path`` and every
exception it raises becomes a :class:`HandModuleError` naming the function and the line.
"""

from __future__ import annotations

import importlib.util
import sys
import traceback
from collections.abc import Callable, Sequence
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np

from symkin.errors import SymkinError
from symkin.limits import listed
from symkin.verify.sampling import State

FUNCTIONS = ("phi", "phi_q", "phi_t", "gamma")
SIGNATURES = {"phi": "phi(q, t, p)", "phi_q": "phi_q(q, t, p)", "phi_t": "phi_t(q, t, p)",
              "gamma": "gamma(q, dq, t, p)"}


class HandModuleError(SymkinError):
    """A hand-derivation module is missing, cannot be loaded, raises or returns wrong shapes."""




# ----- the hand side --------------------------------------------------------------------------

def load_hand_module(path: str | Path) -> ModuleType:
    """Run a hand-derivation file and return it as a module (loaded by path, not via sys.path)."""
    path = Path(path)
    if not path.is_file():
        what = "is a folder" if path.is_dir() else \
            "is not a regular file" if path.exists() else "does not exist"
        raise HandModuleError(f"{path} {what}; give the Python file that defines "
                              f"{', '.join(SIGNATURES.values())}")
    name = f"_symkin_hand_{abs(hash(str(path.resolve())))}"
    spec = importlib.util.spec_from_file_location(name, path)
    if spec is None or spec.loader is None:
        raise HandModuleError(f"{path} cannot be loaded as a Python module; use a .py file")
    module = importlib.util.module_from_spec(spec)
    # Registered only while it runs: decorators such as @dataclass look their module up.
    sys.modules[name] = module
    try:
        spec.loader.exec_module(module)
    except BaseException as error:  # any failure of the user's file (SystemExit too) is bad input
        if isinstance(error, KeyboardInterrupt):
            raise
        raise HandModuleError(f"{path}: running the file failed: {describe(error, path)}"
                              ) from error
    finally:
        sys.modules.pop(name, None)
    return module


def describe(error: BaseException, path: str | Path | None = None) -> str:
    """``IndexError: index 9 is out of bounds (line 42)`` — the error and where in the file."""
    text = f"{type(error).__name__}: {error}".rstrip(": ")
    if isinstance(error, SyntaxError) and error.lineno:
        return f"{type(error).__name__}: {error.msg} (line {error.lineno})"
    frames: list[traceback.FrameSummary] = list(traceback.extract_tb(error.__traceback__))
    if path is not None:
        target = str(Path(path).resolve())
        frames = [f for f in frames if str(Path(f.filename).resolve()) == target] or frames
    if frames:
        last = frames[-1]
        return f"{text} (line {last.lineno}: {(last.line or '').strip()})"
    return text


def hand_functions(hand: Any, origin: str) -> dict[str, Callable[..., Any]]:
    found = {}
    for name in FUNCTIONS:
        function = getattr(hand, name, None)
        if function is None:
            continue
        if not callable(function):
            raise HandModuleError(f"{origin}: {name} is a {type(function).__name__}, not a "
                                  f"function; define {SIGNATURES[name]}")
        found[name] = function
    if not found:
        raise HandModuleError(f"{origin} defines none of {', '.join(SIGNATURES.values())}; "
                              "define at least one")
    return found


def check_order(hand: Any, origin: str, attribute: str, expected: Sequence[str]) -> None:
    """A hand module may declare COORDINATES or PARAMETERS; then they must be symkin's order."""
    declared = getattr(hand, attribute, None)
    if declared is None:
        return
    if [str(item) for item in declared] != list(expected):
        raise HandModuleError(
            f"{origin}: it declares {attribute} = {listed(map(str, declared))}, but the "
            f"mechanism's {attribute.lower()} are {listed(expected) or 'none'} (in the order "
            f"`symkin show` prints); was it written for another mechanism file?")


def call_hand(name: str, function: Callable[..., Any], state: State, origin: str,
               shape: tuple[int, ...]) -> np.ndarray:
    args: tuple[Any, ...] = (state.q.copy(), state.t, state.p.copy())
    if name == "gamma":
        args = (state.q.copy(), state.dq.copy(), state.t, state.p.copy())
    try:
        value = function(*args)
    except (Exception, SystemExit) as error:  # the user's code: report it, do not crash
        code = getattr(function, "__code__", None)
        where = describe(error, code.co_filename if code else None)
        raise HandModuleError(f"{origin}: {SIGNATURES[name]} raised {where}") from error
    return _as_array(name, value, origin, shape)


def _as_array(name: str, value: Any, origin: str, shape: tuple[int, ...]) -> np.ndarray:
    if hasattr(value, "toarray"):  # a SciPy sparse matrix
        value = value.toarray()
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as error:
        raise HandModuleError(f"{origin}: {SIGNATURES[name]} returned {type(value).__name__}, "
                              f"not numbers ({error})") from None
    if len(shape) == 1 and array.shape in ((shape[0], 1), (1, shape[0])):
        array = array.reshape(shape)
    if array.shape != shape:
        want = " x ".join(map(str, shape))
        raise HandModuleError(f"{origin}: {SIGNATURES[name]} returned shape {array.shape}, "
                              f"expected {want} (rows and coordinates in the order "
                              f"`symkin show` prints)")
    return array
