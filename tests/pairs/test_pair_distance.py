"""The distance constraint |r_B - r_A| = length (symkin/pairs/planar/distance.py) against an
independent closed form: a crank-rocker four-bar whose coupler is a rod with no body, solved
by circle intersection here and differentiated exactly with SymPy; both backends. Then its
meaning (the default length is the drawn distance, the row's first-order size is the length
error), the local layout, its label and drawing, its limit position, and bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp
from codegen_support import compiled, derived
from driver_support import BACKENDS, MECHANISMS, kernel_for

import symkin
from symkin.errors import MechanismError, SolveError
from symkin.symbolic import drawing

A_, C_, D_, PSI0, W = 1.0, 2.5, 3.0, 2 * math.pi / 5, 2 * math.pi
B_DRAWN = (D_ + C_ * math.cos(PSI0), C_ * math.sin(PSI0))
LENGTH = math.hypot(B_DRAWN[0], B_DRAWN[1] - A_)
T = sp.Symbol("t", real=True)


def _rocker_angle() -> sp.Expr:
    """The rocker's angle psi(t) by circle intersection: B is |B - D| = c from the pivot D and
    |B - A| = LENGTH from the crank pin A, on the side of line AD where it was drawn."""
    theta = sp.pi / 2 + sp.Float(W) * T
    ax, ay = A_ * sp.cos(theta), A_ * sp.sin(theta)
    ex, ey = D_ - ax, -ay
    span = sp.sqrt(ex**2 + ey**2)
    along = (span**2 + LENGTH**2 - C_**2) / (2 * span)
    height = sp.sqrt(LENGTH**2 - along**2)
    # as drawn (t = 0): A = (0, a), D = (d, 0); B lies to the left of A -> D
    side = 1.0 if (D_ - 0) * (B_DRAWN[1] - A_) - (0 - A_) * (B_DRAWN[0] - 0) > 0 else -1.0
    bx = ax + along * ex / span - side * height * ey / span
    by = ay + along * ey / span + side * height * ex / span
    return sp.atan2(by, bx - D_)


def _wrapped(angle: np.ndarray) -> np.ndarray:
    return np.angle(np.exp(1j * angle))


@pytest.fixture(scope="module")
def system():
    return derived(MECHANISMS / "four_bar_rod.yaml")  # shared with the other tests of the file


@pytest.fixture(scope="module")
def rocker_angle():
    """psi(t) and its first two derivatives as NumPy functions of t (SymPy's second derivative
    of the closed form takes a second: both backends compare with the one reference)."""
    psi = _rocker_angle()
    return [sp.lambdify(T, sp.diff(psi, T, k), "numpy") for k in range(3)]


@pytest.mark.parametrize("backend", BACKENDS)
def test_rod_four_bar_follows_the_circle_intersection(system, rocker_angle, backend: str) -> None:
    kernel = compiled(MECHANISMS / "four_bar_rod.yaml", backend)
    assert kernel.backend == backend
    run = symkin.solve(kernel)
    exact = [derivative(run.t) for derivative in rocker_angle]
    column = system.coordinates.index("rocker.phi")
    assert np.abs(_wrapped(run.q[:, column] + PSI0 - exact[0])).max() < 1e-9
    assert np.abs(run.dq[:, column] - exact[1]).max() < 1e-8
    assert np.abs(run.d2q[:, column] - exact[2]).max() < 1e-7 * np.abs(exact[2]).max()
    assert not run.flagged.any()
    # the rod keeps its length at every point: the rocker's B against the crank's A
    crank, rocker = (system.coordinates.index(f"{b}.phi") for b in ("crank", "rocker"))
    pin = A_ * np.stack([-np.sin(run.q[:, crank]), np.cos(run.q[:, crank])], 1)
    end = np.array([D_, 0]) + C_ * np.stack([np.cos(run.q[:, rocker] + PSI0),
                                             np.sin(run.q[:, rocker] + PSI0)], 1)
    assert np.abs(np.linalg.norm(end - pin, axis=1) - LENGTH).max() < 1e-12


def test_default_length_is_the_drawn_distance_and_the_row_measures_its_error(system) -> None:
    row = next(k for k, r in enumerate(system.rows) if r.type == "distance")
    values = dict(zip(system.p, system.p_values))
    q0 = dict(zip(system.q, system.q0))
    assert abs(float(system.phi[row].subs(values).subs(q0))) < 1e-15
    # move the rocker's pivot frame by delta along the rod: the row reads delta, to first order
    delta = 1e-6
    direction = (np.array(B_DRAWN) - np.array([0, A_])) / LENGTH
    moved = {**q0, system.q[system.coordinates.index("rocker.x")]: D_ + delta * direction[0],
             system.q[system.coordinates.index("rocker.y")]: delta * direction[1]}
    assert float(system.phi[row].subs(values).subs(moved)) == pytest.approx(delta, rel=1e-5)


def test_local_layout_with_a_length_gives_the_same_motion(system) -> None:
    local = symkin.from_dict({
        "name": "four_bar_rod_local",
        "parameters": {"a": A_, "c": C_, "d": D_, "L": LENGTH, "w": W},
        "bodies": {"crank": {"q0": [0, 0, 0], "points": {"A": [0, "a"]}},
                   "rocker": {"q0": ["d", 0, PSI0], "points": {"B": ["c", 0]}}},
        "joints": [{"type": "revolute", "i": "ground", "j": "crank", "sA": [0, 0], "sB": [0, 0]},
                   {"type": "revolute", "i": "rocker", "j": "ground", "sA": [0, 0],
                    "sB": ["d", 0]},
                   {"type": "distance", "i": "crank", "j": "rocker", "A": "A", "B": "B",
                    "length": "L"}],
        "drivers": [{"type": "angle", "i": "crank", "j": "ground", "theta": "w*t"}],
        "time": {"t0": 0, "t1": 1, "dt": 0.01}})
    drawn = symkin.solve(kernel_for(system, "numpy"))
    run = symkin.solve(kernel_for(symkin.derive(local), "numpy"))
    rocker = system.coordinates.index("rocker.phi")
    assert np.abs(_wrapped(run.q[:, rocker] - PSI0 - drawn.q[:, rocker])).max() < 1e-12


def test_row_label_and_drawing(system) -> None:
    assert str(system.rows[-2]) == "joints[2] coupler distance crank-rocker (length)"
    outlines = drawing.outlines(system)
    rod = outlines["rod:crank:rocker"]
    # A in the crank's frame (at O), B in the rocker's (at D), as drawn
    assert np.allclose(rod, [[0, A_], [B_DRAWN[0] - D_, B_DRAWN[1]]], atol=1e-15)


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_rod_too_short_for_the_whole_turn_is_a_limit_position(backend: str) -> None:
    """Rocker c = 2, ground d = 3, crank a = 2 driven by theta = t, rod b = 2 (the
    non-Grashof four-bar of tests/mechanisms/non_grashof.yaml with its coupler a rod): rod
    and rocker align at cos(theta) = -1/4."""
    mech = symkin.from_dict({
        "name": "non_grashof_rod",
        "parameters": {"a": 2.0, "b": 2.0, "c": 2.0, "d": 3.0},
        "bodies": {"crank": {"q0": [0, 0, 0], "points": {"A": ["a", 0]}},
                   "rocker": {"q0": [3, 0, 1.8], "points": {"B": ["c", 0]}}},
        "joints": [{"type": "revolute", "i": "ground", "j": "crank", "sA": [0, 0], "sB": [0, 0]},
                   {"type": "distance", "name": "rod", "i": "crank", "j": "rocker", "A": "A",
                    "B": "B", "length": "b"},
                   {"type": "revolute", "i": "rocker", "j": "ground", "sA": [0, 0],
                    "sB": ["d", 0]}],
        "drivers": [{"type": "angle", "name": "input", "i": "crank", "j": "ground",
                     "theta": "t"}],
        "time": {"t0": 0, "t1": 2.5, "dt": 0.05}})
    with pytest.raises(SolveError) as caught:
        symkin.solve(kernel_for(symkin.derive(mech), backend))
    message = str(caught.value)
    assert "limit position near t = 1.82347658" in message
    assert "rod distance crank-rocker" in message


GOOD = {"type": "distance", "name": "coupler", "i": "crank", "j": "rocker", "A": "A", "B": "B"}


@pytest.mark.parametrize(("change", "field", "said"), [
    ({"length": 0}, "joints[2].length", "the length 0 is not positive"),
    ({"length": "-c"}, "joints[2].length", "the length -2.5 is not positive"),
    ({"length": "t"}, "joints[2].length", "unknown name 't'"),
    ({"length": float("nan")}, "joints[2].length", "not a finite number"),
    ({"A": "Z"}, "joints[2].A", "body 'crank' has no point named 'Z'"),
    ({"j": "crank", "B": "A"}, "joints[2].j", "a distance joins body 'crank' to itself"),
    ({"j": "wheel"}, "joints[2].j", "unknown body 'wheel'"),
    ({"B": [0, 1]}, "joints[2]", "A and B coincide where they start"),
    ({"sA": "A"}, "joints[2].sA", "unknown key 'sA'"),
])
def test_bad_distance_is_refused_with_its_field(tmp_path, change, field, said) -> None:
    import yaml

    data = yaml.safe_load((MECHANISMS / "four_bar_rod.yaml").read_text())
    data["joints"][2] = {**GOOD, **change}
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    with pytest.raises(MechanismError) as caught:
        symkin.load(path)
    text = str(caught.value)
    assert f"at {field}:" in text and said in text, text
    assert f"{path}:" in text  # located in the file


def test_missing_point_is_refused() -> None:
    with pytest.raises(MechanismError, match="'B' is missing"):
        symkin.from_dict({"name": "m", "bodies": {"crank": {}, "rocker": {}},
                          "joints": [{"type": "distance", "i": "crank", "j": "rocker",
                                      "A": [0, 0]}],
                          "time": {"t1": 1, "dt": 0.1}})


def test_the_animation_draws_the_rod_at_its_length(system) -> None:
    from symkin.present.animation import rods

    run = symkin.solve(kernel_for(system, "numpy"))
    (start, end), = rods(run, drawing.outlines(system))
    assert start.shape == end.shape == (run.t.size, 2)
    assert np.abs(np.linalg.norm(end - start, axis=1) - LENGTH).max() < 1e-12
