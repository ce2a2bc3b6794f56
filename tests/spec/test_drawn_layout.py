"""The drawn layout (``layout: drawn``): global coordinates as drawn, local form derived.

The three newcomer mechanisms (a Watt six-bar, an oscillating cylinder, a 2-DOF five-bar) are
solved from their drawings and compared with references written here from the drawing alone:
circle intersections (the side of each triangle taken from the drawing), the cylinder's angle
and stroke from atan2 and a distance. Velocities and accelerations of the references are
central differences of those positions (step 1e-3, fourth order). Both backends run.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
import yaml
from codegen_support import compiled
from driver_support import BACKENDS

import symkin
from symkin import cli
from symkin.errors import MechanismError
from symkin.spec import expressions
from symkin.symbolic import derivation

ROOT = Path(__file__).resolve().parents[2]
MECHANISMS = Path(__file__).resolve().parents[1] / "mechanisms"
Positions = Callable[[np.ndarray], dict[str, np.ndarray]]  # t -> {"body.point": (T, 2)}


def _solve(name: str, backend: str) -> symkin.runtime.outputs.results.Trajectory:  # type: ignore[name-defined]
    path = MECHANISMS / f"{name}.yaml" if (MECHANISMS / f"{name}.yaml").exists() \
        else ROOT / "examples" / f"{name}.yaml"
    kernel = compiled(path, backend)  # built once per run (the examples from their goldens)
    assert kernel.backend == backend
    return symkin.solve(kernel)


def _differences(positions: Positions, t: np.ndarray, h: float = 1e-3):
    """Positions and their first two t-derivatives by fourth-order central differences."""
    at = {k: positions(t + k * h) for k in (-2, -1, 0, 1, 2)}
    out = {}
    for name in at[0]:
        p = {k: at[k][name] for k in at}
        velocity = (p[-2] - 8 * p[-1] + 8 * p[1] - p[2]) / (12 * h)
        acceleration = (-p[-2] + 16 * p[-1] - 30 * p[0] + 16 * p[1] - p[2]) / (12 * h * h)
        out[name] = (p[0], velocity, acceleration)
    return out


def _compare(trajectory, positions: Positions) -> None:
    for name, exact in _differences(positions, trajectory.t).items():
        body, point = name.split(".")
        for got, want, limit in zip(trajectory.point(body, point), exact, (1e-9, 1e-6, 1e-5)):
            assert np.abs(got - want).max() <= limit, name


def _intersect(p1: np.ndarray, r1: float, p2: np.ndarray, r2: float, side: float) -> np.ndarray:
    """Where the circle (p1, r1) meets (p2, r2), on ``side`` (+1 left) of the line p1 -> p2."""
    chord = p2 - p1
    d = np.linalg.norm(chord, axis=-1, keepdims=True)
    along = (r1**2 - r2**2 + d**2) / (2 * d)
    across = np.sqrt(r1**2 - along**2)
    unit = chord / d
    return p1 + along * unit + side * across * np.stack([-unit[..., 1], unit[..., 0]], -1)


def _side(p1, p2, x) -> float:
    chord, to_x = np.subtract(p2, p1), np.subtract(x, p1)
    return float(np.sign(chord[0] * to_x[1] - chord[1] * to_x[0]))


def _turn(vector: np.ndarray, angle: np.ndarray) -> np.ndarray:
    c, s = np.cos(angle)[:, None], np.sin(angle)[:, None]
    return np.concatenate([c * vector[..., :1] - s * vector[..., 1:],
                           s * vector[..., :1] + c * vector[..., 1:]], -1)


def _crank(pivot, tip, theta: np.ndarray) -> np.ndarray:
    """The crank tip turned by theta about its pivot (from the drawn position)."""
    start = np.broadcast_to(np.subtract(tip, pivot, dtype=float), (theta.size, 2))
    return np.asarray(pivot, float) + _turn(start, theta)


# ----- the Watt six-bar ----------------------------------------------------------------------

def watt_positions(t: np.ndarray) -> dict[str, np.ndarray]:
    O2, O4, O6 = np.array([0, 0.]), np.array([4, 0.]), np.array([9, 0.])
    A0, B0, C0, D0, M0 = (np.array(p, float) for p in ([0, 1], [3, 3], [6, 2], [8, 4],
                                                        [1.5, 2.5]))
    A = _crank(O2, A0, 2 * np.pi * t)
    B = _intersect(A, np.linalg.norm(B0 - A0), O4, np.linalg.norm(B0 - O4), _side(A0, O4, B0))
    rocker_turn = np.arctan2(B[:, 1] - O4[1], B[:, 0] - O4[0]) - np.arctan2(*(B0 - O4)[::-1])
    C = O4 + _turn(np.broadcast_to(C0 - O4, B.shape), rocker_turn)
    D = _intersect(C, np.linalg.norm(D0 - C0), O6, np.linalg.norm(D0 - O6), _side(C0, O6, D0))
    coupler_turn = np.arctan2(*(B - A).T[::-1]) - np.arctan2(*(B0 - A0)[::-1])
    M = A + _turn(np.broadcast_to(M0 - A0, A.shape), coupler_turn)
    return {"crank.A": A, "coupler.B": B, "coupler.M": M, "rocker.C": C, "link.D": D,
            "output.D": D}


@pytest.mark.parametrize("backend", BACKENDS)
def test_watt_six_bar_drawn_matches_circle_intersections(backend: str) -> None:
    _compare(_solve("watt_six_bar", backend), watt_positions)


# ----- the oscillating cylinder --------------------------------------------------------------

def cylinder_positions(t: np.ndarray) -> dict[str, np.ndarray]:
    O3, A0, H0 = np.array([4, 0.]), np.array([0, 1.]), np.array([2, 0.5])
    A = _crank([0, 0], A0, 2 * np.pi * t)
    towards = (O3 - A) / np.linalg.norm(O3 - A, axis=1, keepdims=True)
    H = A + np.linalg.norm(H0 - A0) * towards  # the head stays on the axis, |AH| fixed
    return {"piston.A": A, "piston.H": H}


@pytest.mark.parametrize("backend", BACKENDS)
def test_oscillating_cylinder_drawn_matches_closed_form(backend: str) -> None:
    trajectory = _solve("oscillating_cylinder", backend)
    _compare(trajectory, cylinder_positions)
    # The cylinder (and the rod with it) turns by the change of the angle of O3 -> A.
    A = cylinder_positions(trajectory.t)["piston.A"]
    swing = np.arctan2(A[:, 1], A[:, 0] - 4) - np.arctan2(1, -4)
    phi = trajectory.q[:, trajectory.coordinates.index("cylinder.phi")]
    assert np.abs(np.angle(np.exp(1j * (phi - swing)))).max() < 1e-9
    rod = trajectory.q[:, trajectory.coordinates.index("piston.phi")]
    assert np.abs(rod - phi).max() < 1e-9


# ----- the 2-DOF five-bar --------------------------------------------------------------------

def five_bar_positions(t: np.ndarray) -> dict[str, np.ndarray]:
    A1 = _crank([0, 0], [0, 1], 0.4 * np.sin(2 * np.pi * t))
    A2 = _crank([3, 0], [3, 1], -0.5 * t)
    l3 = l4 = np.hypot(1.5, 2)
    P = _intersect(A1, l3, A2, l4, _side([0, 1], [3, 1], [1.5, 3]))
    return {"left.A1": A1, "right.A2": A2, "arm1.P": P, "arm2.P": P}


@pytest.mark.parametrize("backend", BACKENDS)
def test_five_bar_drawn_matches_circle_intersection(backend: str) -> None:
    _compare(_solve("five_bar", backend), five_bar_positions)


# ----- the derived local form ----------------------------------------------------------------

@pytest.mark.parametrize("name", ["watt_six_bar", "oscillating_cylinder", "five_bar"])
def test_the_drawing_is_an_assembled_configuration(name: str) -> None:
    """Phi(q0, t0) = 0 exactly: the derived local vectors, v, phi0 and q0 reproduce the drawing."""
    system = derivation.derive(symkin.load(MECHANISMS / f"{name}.yaml"))
    values = dict(zip(system.q, system.q0)) | dict(zip(system.p, system.p_values))
    values[system.t] = system.time_grid[0]
    residual = np.array(system.phi.subs(values).evalf(), dtype=float)
    assert np.abs(residual).max() < 1e-12


@pytest.mark.parametrize("backend", BACKENDS)
def test_drawn_crank_slider_reproduces_the_textbook(backend: str) -> None:
    drawn, local = _solve("crank_slider_drawn", backend), _solve("crank_slider", backend)
    names = ("crank.x", "crank.y", "crank.phi", "rod.x", "rod.y", "slider.x", "slider.y")
    for name in names:  # same frames; rod.phi differs by the drawn rod angle, a constant
        k, m = drawn.coordinates.index(name), local.coordinates.index(name)
        for a, b in ((drawn.q, local.q), (drawn.dq, local.dq), (drawn.d2q, local.d2q)):
            assert np.abs(a[:, k] - b[:, m]).max() < 1e-10, name
    for a, b in zip(drawn.point("rod", "B"), local.point("rod", "P")):
        assert np.abs(a - b).max() < 1e-10


def test_derived_local_form_of_the_crank_slider() -> None:
    """What a user would write by hand (examples/crank_slider.yaml), derived from the drawing."""
    mech = symkin.load(ROOT / "examples" / "crank_slider_drawn.yaml")
    a, b, c = sp.symbols("a b c", real=True)
    assert mech.bodies["crank"].points["A"] == ["a", 0]
    assert mech.bodies["crank"].q0 == [0, 0, "pi/2"]
    prismatic = mech.joints[3]
    assert prismatic.v == [0, 1] and prismatic.phi0 == 0  # v: the NORMAL of the x slide
    assert prismatic.sA == "B" and mech.bodies["slider"].points["B"] == [0, 0]
    assert "slider" in mech.bodies and "ground" not in mech.bodies


def _value(raw) -> float:
    k = sp.Symbol("k", real=True)
    return float(expressions.parse(raw, {"k": k}).subs(k, 2.0))


def _drawn(**changes) -> dict:
    data = {
        "name": "slide", "layout": "drawn", "parameters": {"k": 2.0},
        "bodies": {"ground": {"points": {"O": [0, 0]}},
                   "block": {"frame": {"origin": [1, 1], "angle": "pi/6"},
                             "points": {"P": [1, 1], "Q": ["1 + k", 1]}}},
        "joints": [{"type": "prismatic", "i": "ground", "j": "block", "at": "P",
                    "axis": [1, 1]}],
        "drivers": [{"type": "slide", "i": "ground", "j": "block", "sA": "O", "sB": "P",
                     "u": [1, 0], "f": "k*t"}],
        "time": {"t0": 0, "t1": 1, "dt": 0.5}}
    data.update(changes)
    return data


def test_axis_becomes_the_slide_normal_in_the_turned_frame() -> None:
    mech = symkin.from_dict(_drawn())
    joint = mech.joints[0]
    v = np.array([_value(x) for x in joint.v])  # derived text, not user text
    angle = np.pi / 6  # the block's frame is turned: v is the normal of [1, 1], in that frame
    normal_global = np.array([[np.cos(angle), -np.sin(angle)],
                              [np.sin(angle), np.cos(angle)]]) @ v
    assert abs(normal_global @ np.array([1, 1])) < 1e-12 and np.linalg.norm(v) > 0
    assert _value(joint.phi0) == pytest.approx(-np.pi / 6)  # phi_ground - phi_block
    Q = [_value(x) for x in mech.bodies["block"].points["Q"]]
    assert Q == pytest.approx([2 * np.cos(angle), -2 * np.sin(angle)])  # k = 2, turned back


@pytest.mark.parametrize(("changes", "words"), [
    ({"layout": "sketch"}, "unknown layout 'sketch'"),
    ({"bodies": {"block": {"q0": [0, 0, 0], "points": {"P": [0, 0]}}}}, "q0"),
    ({"bodies": {"block": {"points": {}}}}, "no point to place its frame"),
    ({"joints": [{"type": "prismatic", "i": "block", "j": "ground", "at": "P",
                  "v": [0, 1]}]}, "v is not used in the drawn layout"),
    ({"joints": [{"type": "prismatic", "i": "block", "j": "ground", "at": "P"}]},
     "needs axis"),
    ({"joints": [{"type": "revolute", "i": "block", "j": "ground", "at": "R"}]},
     "neither 'block' nor 'ground' has a point named 'R'"),
    ({"joints": [{"type": "prismatic", "i": "block", "j": "ground", "at": "P",
                  "axis": [0, 0]}]}, "the axis is zero"),
])
def test_drawn_mistakes_are_named(changes: dict, words: str) -> None:
    with pytest.raises(MechanismError, match=words.replace("(", r"\(")):
        symkin.from_dict(_drawn(**changes))


def test_a_drawing_that_does_not_close_names_its_joints(tmp_path: Path) -> None:
    text = (MECHANISMS / "watt_six_bar.yaml").read_text()
    text = text.replace("link:    {points: {C: [6, 2]", "link:    {points: {C: [6.01, 2]")
    text = text.replace("output:  {points: {O6: [9, 0], D: [8, 4]}}",
                        "output:  {points: {O6: [9, 0], D: [8, 4.2]}}")
    path = tmp_path / "open.yaml"
    path.write_text(text)
    with pytest.raises(MechanismError) as caught:
        symkin.load(path)
    message = str(caught.value)
    assert "does not close" in message and "joints[4] (revolute rocker–link) is off by 0.01" \
        in message and "joints[5] (revolute link–output) is off by 0.2" in message
    assert "joints[3]" not in message and caught.value.line == 18  # the first open joint
    assert cli.main(["show", str(path)]) == 2


def test_show_local_prints_the_derived_local_form(capsys) -> None:
    assert cli.main(["show", "--local", str(ROOT / "examples" / "crank_slider_drawn.yaml")]) == 0
    out = capsys.readouterr().out
    assert "layout" not in out and "q0: [0, 0, pi/2]" in out
    assert "v: [0, 1]" in out and "phi0: 0" in out
    reread = symkin.from_dict(yaml.safe_load(out))
    assert reread.canonical_json() == symkin.load(
        ROOT / "examples" / "crank_slider_drawn.yaml").canonical_json()


@pytest.mark.parametrize(("value", "field", "words"), [
    ("2.0", "bodies.rod.points.B[0]", "fractional power of a negative number, which is not "
     "real. A link too short (or too long) to close the drawing at these values? Check the "
     "parameters it uses: a, b, c."),
    (".nan", "parameters.b", "nan is not a finite number"),
    ("-.inf", "parameters.b", "-inf is not a finite number"),
])
def test_a_drawing_that_cannot_be_evaluated_names_the_cause(tmp_path: Path, value: str,
                                                            field: str, words: str) -> None:
    """The textbook crank-slider drawn with a rod b too short to reach the slide (c - a = 3), or
    with b not a number: the message names the square root and its parameters, or b itself,
    not a drawn point that uses it."""
    path = tmp_path / "short.yaml"
    path.write_text((ROOT / "examples" / "crank_slider_drawn.yaml").read_text().replace(
        "b: 5.0", f"b: {value}"))
    with pytest.raises(MechanismError) as caught:
        symkin.load(path)
    assert f"at {field}: " in str(caught.value) and words in str(caught.value)
