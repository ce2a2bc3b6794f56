"""The corpus of bad mechanism files: each is refused with its own message, file and line.

Every file in tests/bad_mechanisms/ is a small variation of one good file (a driven crank).
EXPECTED says, for each, the line the message must point at and a fragment it must contain.
The same files go through the CLI: exit status 2, the message on stderr, no traceback.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from symkin import cli
from symkin.errors import MechanismError
from symkin.spec.validate import load

CORPUS = Path(__file__).resolve().parents[1] / "bad_mechanisms"

# file -> (line, fragment of the message)
EXPECTED: dict[str, tuple[int, str]] = {
    # unknown keys
    "unknown_top_key.yaml": (10, "unknown key 'colour'. Allowed keys here: name, parameters"),
    "unknown_body_key.yaml": (4, "unknown key 'density'. Allowed keys here: q0, points, mass, "
                                 "inertia, com"),
    "unknown_joint_key.yaml": (6, "at joints[0].v: unknown key 'v'. Allowed keys here: name, i, j"),
    "unknown_time_key.yaml": (9, "unknown key 'steps'. Allowed keys here: t0, t1, dt"),
    "poly_coefficient_with_t.yaml": (9, "at drivers[0].theta.poly[1]: in expression 't' at "
                                        "column 1: unknown name 't'"),
    "bad.toml": (11, "at joints[0].colour: unknown key 'colour'"),
    # YAML traps
    "duplicate_key.yaml": (2, "the key 'name' appears twice"),
    "duplicate_body.yaml": (5, "the key 'crank' appears twice"),
    "yes_is_text.yaml": (8, "unknown name 'yes'"),  # YAML 1.1 would have made it True
    "boolean_number.yaml": (9, "at time.dt: expected a number or an expression, got a boolean"),
    "python_tag.yaml": (1, "the YAML tag 'tag:yaml.org,2002:python/object/apply:os.system' "
                           + "is not allowed"),
    "python_name_tag.yaml": (2, "python/name:os.system' is not allowed"),
    "alias.yaml": (2, "aliases (*name) are not allowed"),
    "billion_laughs.yaml": (3, "aliases (*name) are not allowed"),
    "merge_key.yaml": (5, "merge keys (<<) are not allowed"),
    "numeric_key.yaml": (2, "the key '7' is not a name"),
    "invalid_yaml.yaml": (9, "this is not valid YAML"),
    "tab_indent.yaml": (4, "this is not valid YAML: found character '\\t'"),
    "invalid_syntax.toml": (2, "this is not valid TOML: Unclosed inline table"),
    "not_utf8.yaml": (1, "the file is not UTF-8 text"),
    "empty_file.yaml": (1, "the file must be a mapping"),
    "not_a_mapping.yaml": (1, "the file must be a mapping"),
    # references between fields
    "unknown_body.yaml": (6, "at joints[0].j: unknown body 'rod'. Use one of: ground, crank"),
    "unknown_body_in_driver.yaml": (8, "at drivers[0].j: unknown body 'frame'"),
    "unknown_point.yaml": (6, "body 'crank' has no point named 'tail'. Its points are: tip"),
    "point_on_ground.yaml": (6, "body 'ground' has no point named 'tip'"),
    "joint_to_itself.yaml": (6, "a revolute joins body 'crank' to itself"),
    "no_bodies.yaml": (2, "at bodies: needs at least 1 item(s), got 0"),
    "duplicate_constraint_name.yaml": (8, "at drivers[0].name: the name 'pivot' is already "
                                          + "used by joints[0]"),
    "trajectory_of_ground.yaml": (9, "a trajectory needs a moving body j, not the ground"),
    "custom_without_coordinates.yaml": (8, "this equation uses no coordinate"),
    # shapes and numbers
    "vector_too_short.yaml": (6, "at joints[0].sA: expected a vector of 2 numbers, got 1 items"),
    "q0_wrong_length.yaml": (4, "at bodies.crank.q0: expected a vector of 3 numbers, got 2"),
    "vector_not_a_list.yaml": (6, "expected a vector of 2 numbers, got a mapping"),
    "nan_parameter.yaml": (2, "at parameters.a: nan is not a finite number"),
    "infinite_step.yaml": (9, "at time.dt: inf is not a finite number"),
    "division_by_zero.yaml": (2, "the expression is not finite"),
    "complex_parameter.yaml": (2, "at parameters.a: in expression 'asin(2)': asin of 2.0 is not real"),
    "overflow_parameter.yaml": (2, "exp of 22026.5 is larger than the largest double"),
    "complex_point.yaml": (4, "at bodies.crank.points.tip[0]: sqrt(a - 2) has no finite real value at the nominal parameter values: sqrt(a - 2) is a fractional power of a negative number"),
    "zero_direction.yaml": (6, "at joints[0].v: the direction vector is zero"),
    "missing_sB.yaml": (6, "the required key 'sB' is missing"),
    "missing_type.yaml": (6, "the key 'type' is missing. Add type: one of revolute, prismatic"),
    "unknown_type.yaml": (6, "unknown type 'hinge'. Use one of: 'revolute'"),
    # names
    "name_not_ascii.yaml": (4, "'żuraw' is not a plain ASCII identifier"),
    "name_with_dash.yaml": (1, "'my-pendulum' is not a plain ASCII identifier"),
    "name_c_keyword.yaml": (1, "at name: 'int' is a C or Python keyword"),
    "name_python_keyword.yaml": (2, "'lambda' is a Python keyword, which no expression can"),
    "name_libm.yaml": (1, "at name: 'hypot' is the name of a C math library function"),
    "name_t.yaml": (2, "at parameters.t: 't' is the time in expressions"),
    "name_pi.yaml": (4, "at bodies.pi: 'pi' is a constant in expressions"),
    "name_ground.yaml": (5, "'ground' is the fixed frame, present in every mechanism"),
    "name_system_header.yaml": (1, "'string' would generate string.h, the name of a system"),
    "names_clash.yaml": (4, "at bodies.crank: 'crank' is already used at parameters.crank"),
    # every clash in one message, not one per run
    "names_clash_all.yaml": (2, "4 names cannot be used: parameters.t: 't' is the time in "
                                "expressions; parameters.pi: 'pi' is a constant in expressions; "
                                "parameters.sin: 'sin' is a function in expressions"),
    # time grid
    "time_step_zero.yaml": (9, "the time step dt = 0.0 is not positive"),
    "time_backwards.yaml": (9, "the end time t1 = -1.0 is not after t0 = 0.0"),
    "time_grid_huge.yaml": (9, "the grid has more than 10000000 points"),
    "time_missing_t1.yaml": (9, "the required key 't1' is missing"),
    # degrees of freedom
    "dof_too_few_drivers.yaml": (7, "w = 3·1 − 2·1 − 0 = 1 degree(s) of freedom but its "
                                    + "drivers give 0 equation(s), and no body has a mass: "
                                    + "the motion of the 1 free degree(s) needs masses"),
    # expressions
    "bad_expression_syntax.yaml": (8, "in expression 't**': this is not a valid expression"),
    "bad_expression_function.yaml": (8, "unknown function 'system'; allowed functions are Abs"),
    "dunder_attack.yaml": (8, "is not allowed in an expression"),
    "time_in_a_vector.yaml": (6, "at joints[0].sA[0]: in expression 't' at column 1: "
                                 + "unknown name 't'"),
    "empty_poly.yaml": (8, "a polynomial is written {poly: [a0, a1, a2]}"),
    "custom_unknown_coordinate.yaml": (8, "attribute access is not allowed (only body.x"),
    "custom_unknown_body.yaml": (8, "unknown coordinate 'rod.phi'"),
    # inverse dynamics
    "negative_mass.yaml": (4, "at bodies.crank.mass: the mass -2 is negative"),
    "force_unknown_body.yaml": (10, "at forces[0].body: unknown body 'rod'. Use one of: "
                                   "ground, crank"),
    "force_unknown_coordinate.yaml": (11, "at forces[0].m: in expression '-c*rocker.phi_t' at "
                                          "column 4: unknown coordinate 'rocker.phi_t'"),
    "force_unknown_point.yaml": (4, "at bodies.crank.com: body 'crank' has no point named "
                                    "'middle'"),
    # inverse dynamics of a spatial file: masses, inertia tensors, 3-vectors
    "spatial_negative_mass.yaml": (5, "at bodies.crank.mass: the mass -2 is negative"),
    "spatial_inertia_not_symmetric.yaml": (5, "at bodies.crank.inertia: the inertia tensor is "
                                              "not symmetric: [0][2] = 0 but [2][0] = 0.5"),
    "spatial_inertia_negative.yaml": (5, "at bodies.crank.inertia: the inertia tensor has a "
                                         "negative principal moment -2"),
    "spatial_inertia_impossible.yaml": (5, "the principal moments 1, 1, 3 break the triangle "
                                           "inequality"),
    # the closed-form eigenvalues square the entries: at 1e200 they overflowed and passed
    "spatial_inertia_huge_impossible.yaml": (5, "the principal moments 1e+200, 1e+200, 3e+200 "
                                                "break the triangle inequality"),
    "spatial_force_two_components.yaml": (10, "at forces[0].f: expected a vector of 3 numbers, "
                                              "got 2 items"),
    # found by fuzzing the examples' structure: each was a traceback or an unlocated exit 1
    "spatial_parameters_a_list.yaml": (4, "at parameters: expected a mapping of parameter "
                                          "names to values"),
    "spatial_joint_name_a_list.yaml": (9, "at drivers[0].joint: no joint named ['pivot']"),
    "spatial_infinite_point.yaml": (6, "at bodies.crank.points.A[2]: inf is not a finite number"),
    "drawn_body_a_list.yaml": (6, "at joints[0].i: unknown body ['ground']. Use one of: "
                                  "ground, crank."),
    "spatial_body_a_list.yaml": (7, "at joints[0].j: unknown body {'crank': 1}"),
    "spatial_unknown_point.yaml": (6, "no point named 'top'. Its points are: tip; or give a "
                                      "vector [x, y, z]."),
}


def test_the_corpus_is_complete() -> None:
    on_disk = sorted(path.name for path in CORPUS.iterdir())
    assert on_disk == sorted(EXPECTED)
    assert len(on_disk) >= 30


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_bad_file_is_refused_with_its_message(name: str) -> None:
    line, fragment = EXPECTED[name]
    path = CORPUS / name
    with pytest.raises(MechanismError) as caught:
        load(path)
    message = str(caught.value)
    assert message.startswith(f"{path}:{line}: "), message
    assert fragment in message
    assert caught.value.line == line and caught.value.source == str(path)
    assert "Traceback" not in message and "pydantic" not in message.lower()


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_cli_show_exits_2_with_the_message(name: str, capsys: pytest.CaptureFixture) -> None:
    line, fragment = EXPECTED[name]
    path = CORPUS / name
    assert cli.main(["show", str(path)]) == cli.EXIT_BAD_INPUT
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.startswith(f"symkin: error: {path}:{line}: ")
    assert fragment in captured.err
    assert captured.err.count("\n") == 1  # one paragraph


@pytest.mark.parametrize("name", ["python_tag.yaml", "dof_too_few_drivers.yaml"])
def test_python_m_symkin_show_exits_2_without_traceback(name: str) -> None:
    path = CORPUS / name
    result = subprocess.run([sys.executable, "-m", "symkin", "show", str(path)],
                            capture_output=True, text=True, timeout=60, check=False,
                            cwd=Path(__file__).resolve().parents[2])
    assert result.returncode == 2
    assert result.stdout == ""
    assert "Traceback" not in result.stderr
    assert f"{path}:{EXPECTED[name][0]}:" in result.stderr


def test_missing_file_is_a_bad_input(capsys: pytest.CaptureFixture) -> None:
    assert cli.main(["show", str(CORPUS / "no_such_file.yaml")]) == cli.EXIT_BAD_INPUT
    assert "cannot read the file" in capsys.readouterr().err
