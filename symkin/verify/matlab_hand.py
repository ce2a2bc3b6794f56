"""A hand derivation written in MATLAB/Octave: .m functions found by name, run in GNU Octave
and compared entry by entry with what symkin derives, at assembled states along the motion.

The names are the derived ones — ``Phi(q, t)``, ``Phi_q(q, t)``, ``Phi_t(q, t)``,
``Gamma(q, dq, t)`` — and the chapter's own: ``Wiezy(q, t)`` (Phi), ``Jakobian(q)`` or
``Jakobian(q, t)`` (Phi_q), ``Predkosc(q, t)`` (the velocities) and
``Przyspieszenie(dq, q, t)`` (the accelerations). Their files' folder is Octave's path, so
the scripts and helpers they call (the chapter's ``Dane``, ``Rot``) are found. They take no
parameters (the chapter fixes its data in ``Dane.m``), so they are compared at the nominal
design; a function that errors in Octave is reported with Octave's message.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from symkin.errors import BuildError
from symkin.octave_process import OctaveError, Session
from symkin.runtime.arguments import grid
from symkin.verify.hand import HandModuleError
from symkin.verify.numeric import FLOOR_OF_LENGTH, Derived, mismatches, show_expression
from symkin.verify.report import FunctionResult, Report
from symkin.verify.sampling import State, length_scale


@dataclass(frozen=True)
class Function:
    """One name symkin looks for: what it computes and its arguments (the fewest accepted
    first: ``Jakobian(q)`` as in the chapter, or ``Jakobian(q, t)``)."""

    kind: str  # phi, phi_q, phi_t, gamma, dq, ddq
    arguments: tuple[str, ...]
    least: int  # how many of the arguments it must declare


FUNCTIONS: dict[str, Function] = {
    "Phi": Function("phi", ("q", "t"), 2),
    "Wiezy": Function("phi", ("q", "t"), 2),
    "Phi_q": Function("phi_q", ("q", "t"), 2),
    "Jakobian": Function("phi_q", ("q", "t"), 1),
    "Phi_t": Function("phi_t", ("q", "t"), 2),
    "Gamma": Function("gamma", ("q", "dq", "t"), 3),
    "Predkosc": Function("dq", ("q", "t"), 2),
    "Przyspieszenie": Function("ddq", ("dq", "q", "t"), 3),
}
SIGNATURES = {name: f"{name}({', '.join(f.arguments)})" for name, f in FUNCTIONS.items()}
_WHAT = {"dq": "the velocities -Phi_q \\ Phi_t", "ddq": "the accelerations Phi_q \\ Gamma"}


def is_matlab(path: str | Path) -> bool:
    """Whether ``--against`` names MATLAB/Octave hand files: a .m file or a folder."""
    path = Path(path)
    return path.suffix == ".m" or path.is_dir()


def hand_names(path: Path) -> tuple[Path, list[str]]:
    """The folder to put on Octave's path and the functions of FUNCTIONS it holds.

    Raises:
        HandModuleError: no such file or folder, or none of the names.
    """
    known = ", ".join(SIGNATURES.values())
    if path.is_dir():
        names = [name for name in FUNCTIONS if (path / f"{name}.m").is_file()]
        if not names:
            raise HandModuleError(f"{path} is a folder that holds none of {known} (MATLAB/"
                                  "Octave hand files: one function a file, named as the "
                                  "function, e.g. Wiezy.m); a Python hand derivation is one "
                                  ".py file")
        return path, names
    if not path.is_file():
        raise HandModuleError(f"{path} does not exist; give a .m file or the folder of the "
                              f".m files that define {known}")
    if path.stem not in FUNCTIONS:
        raise HandModuleError(f"{path}: symkin compares functions named {known}; rename the "
                              "file and its function, or give the folder that holds them")
    return path.parent, [path.stem]


def verify_matlab(derived: Derived, path: str | Path, *, samples: int, seed: int,
                  tolerance: float) -> Report:
    """Compare the .m functions of ``path`` with the derived ones (see the module docstring).

    Raises:
        HandModuleError: no such functions, Octave is missing, a function errors in Octave
            or returns the wrong shape.
    """
    folder, names = hand_names(Path(path))
    session = Session(folder.resolve())
    try:
        states = assembled_states(derived, samples, seed)
        results = tuple(_compare(derived, session, name, states, str(path), tolerance)
                        for name in names)
    except OctaveError as error:
        raise HandModuleError(f"{path}: {error}; fix the .m file (run it in Octave to see "
                              "where)") from None
    except BuildError as error:  # Octave itself is missing or stopped
        raise HandModuleError(f"{path}: {error}") from None
    finally:
        session.close()
    system = derived.system
    skipped = tuple(n for n in ("Phi", "Phi_q", "Phi_t", "Gamma")
                    if FUNCTIONS[n].kind not in {FUNCTIONS[m].kind for m in names})
    return Report(system.name, str(path), len(states), seed, 0.0, tolerance, results, skipped,
                  length_scale(system),
                  states="assembled states on the motion (.m functions run in Octave)")


def assembled_states(derived: Derived, samples: int, seed: int) -> list[State]:
    """States on the motion at the nominal design: Newton from the file's q0 along its time
    grid (with a predictor), dq = -Phi_q \\ Phi_t; ``samples`` grid points drawn at random."""
    system = derived.system
    p = np.array(system.p_values, dtype=float)
    times = grid(*system.time_grid)
    q = np.array(system.q0, dtype=float)
    dq = np.zeros_like(q)
    states: list[State] = []
    for k, t in enumerate(times):
        if k:
            q = q + dq * (t - times[k - 1])
        zero = np.zeros_like(q)
        for _ in range(50):
            step = np.linalg.lstsq(_phi_q(derived, q, t, p), _value(derived, "phi", q, zero,
                                                                     t, p), rcond=None)[0]
            q = q - step
            if np.max(np.abs(step)) <= 1e-13 * (1 + np.max(np.abs(q))):
                break
        if not np.max(np.abs(_value(derived, "phi", q, zero, t, p))) <= \
                1e-9 * length_scale(system):
            break  # the motion ends here (a limit position): sample what was reached
        dq = -np.linalg.solve(_phi_q(derived, q, t, p), _value(derived, "phi_t", q, zero, t, p))
        states.append(State(q.copy(), dq.copy(), float(t), p))
    if not states:
        raise HandModuleError(f"{system.name} does not assemble at t0 from its q0, so there is "
                              "no state to compare the .m functions at; check the file's q0")
    picked = np.random.default_rng(seed).choice(len(states), min(samples, len(states)),
                                                replace=False)
    return [states[k] for k in sorted(picked)]


def _value(derived: Derived, name: str, q: np.ndarray, dq: np.ndarray, t: float,
           p: np.ndarray) -> np.ndarray:
    return derived.evaluate(name, State(q, dq, float(t), p))


def _phi_q(derived: Derived, q: np.ndarray, t: float, p: np.ndarray) -> np.ndarray:
    return _value(derived, "phi_q", q, np.zeros_like(q), t, p)


def _ours(derived: Derived, kind: str, state: State) -> np.ndarray:
    if kind in ("dq", "ddq"):
        jacobian = _phi_q(derived, state.q, state.t, state.p)
        right = (-_value(derived, "phi_t", state.q, state.dq, state.t, state.p) if kind == "dq"
                 else _value(derived, "gamma", state.q, state.dq, state.t, state.p))
        return np.asarray(np.linalg.solve(jacobian, right), dtype=float)
    return _value(derived, kind, state.q, state.dq, state.t, state.p)


def _call(session: Session, name: str, count: int, state: State, shape: tuple[int, ...],
          origin: str) -> np.ndarray:
    values = {"q": state.q, "dq": state.dq, "t": state.t}
    value = session.call(name, [values[a] for a in FUNCTIONS[name].arguments[:count]])
    if len(shape) == 1 and value.shape in ((shape[0], 1), (1, shape[0])):
        value = value.reshape(shape)
    if value.shape != shape:
        column = " (a column)" if len(shape) == 1 else ""
        raise HandModuleError(
            f"{origin}: {SIGNATURES[name]} returned a {value.shape[0]} x {value.shape[1]} "
            f"array, expected {' x '.join(map(str, shape))}{column} (rows and coordinates in "
            "the order `symkin show` prints)")
    return value


def _compare(derived: Derived, session: Session, name: str, states: list[State],
             origin: str, tolerance: float) -> FunctionResult:
    function = FUNCTIONS[name]
    declared = session.arguments_of(name)
    count = len(function.arguments) if declared < 0 else declared
    if not function.least <= count <= len(function.arguments):
        raise HandModuleError(f"{origin}: {name} declares {count} argument(s); symkin calls "
                              f"{SIGNATURES[name]}")
    system = derived.system
    rows, size = len(system.rows), derived.size
    shape = (rows, size) if function.kind == "phi_q" else (rows,)
    hand = np.array([_call(session, name, count, s, shape, origin) for s in states])
    ours = np.array([_ours(derived, function.kind, s).reshape(shape) for s in states])
    found = mismatches(
        name, ours, hand, states, tolerance, FLOOR_OF_LENGTH * length_scale(system),
        lambda row: _owner(derived, function.kind, row),
        lambda row, column: _expression(derived, function.kind, row, column),
        system.coordinates, base=1)
    return FunctionResult(name, int(np.prod(shape)), found)


def _owner(derived: Derived, kind: str, row: int) -> str:
    system = derived.system
    if kind in _WHAT:  # a velocity or acceleration: its entry is a coordinate
        return f"coordinate {system.coordinates[row]}"
    return str(system.rows[row])


def _expression(derived: Derived, kind: str, row: int, column: int | None) -> str:
    if kind in _WHAT:
        return f"{_WHAT[kind]}, entry {row + 1}"
    return show_expression(derived.system, derived.expression(kind, row, column))
