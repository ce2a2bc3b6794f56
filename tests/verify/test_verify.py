"""symkin.verify.numeric, numeric route: hand derivations with planted slips are found and located.

The correct hand derivations (examples/textbook_hand_corrected.py and tests/verify_cases/*_hand.py)
are written from the chapter's closed-form formulas, not from symkin's output, so their passing
is also an independent check of the derivation. Each slip is a one-place edit of that source —
a sign, a swapped index, a missing term, a wrong body — and must be reported at exactly the
entries it corrupts, with the owning joint or driver named.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import codegen_support
import numpy as np
import pytest

import symkin
from symkin.verify import hand as verify_hand
from symkin.verify import numeric, sampling

ROOT = Path(__file__).resolve().parents[2]
CASES = Path(__file__).resolve().parents[1] / "verify_cases"
TEXTBOOK = ROOT / "examples" / "crank_slider_general.yaml"
FAITHFUL = ROOT / "examples" / "textbook_hand.py"
CORRECTED = ROOT / "examples" / "textbook_hand_corrected.py"

MECHANISMS = {
    "textbook": (TEXTBOOK, CORRECTED),
    "four_bar": (CASES / "four_bar.yaml", CASES / "four_bar_hand.py"),
    "luffing": (CASES / "luffing.yaml", CASES / "luffing_hand.py"),
}

REV12 = "joints[1] revolute crank-rod"
REV23 = "joints[2] revolute rod-slider"
PRISM = "joints[3] prismatic slider-ground"
CRANK = "drivers[0] angle crank-ground"
ROCKER = "joints[3] revolute rocker-ground"
COUPLER_ROCKER = "joints[2] revolute coupler-rocker"
CRANK_COUPLER = "joints[1] revolute crank-coupler"
CYL = "joints[3] prismatic cylinder-piston"
SLIDE = "drivers[0] slide cylinder-piston"
BOOM = "joints[2] revolute piston-boom"

# (mechanism, kind, source text, replacement, {(function, row, column): owner})
SLIPS = [
    ("textbook", "sign", "Fq[2:4, 2] = OM @ Rot1 @ d.sA1", "Fq[2:4, 2] = -OM @ Rot1 @ d.sA1",
     {("phi_q", 2, 2): REV12, ("phi_q", 3, 2): REV12}),
    ("textbook", "sign", "[-2 * t]", "[2 * t]", {("phi_t", 8, None): CRANK}),
    ("textbook", "swapped index", "Fq[7, 6:8] = -d.v0", "Fq[7, 6:8] = -d.v0[::-1]",
     {("phi_q", 7, 6): PRISM, ("phi_q", 7, 7): PRISM}),
    ("textbook", "missing term",
     "gam[2:4] = Rot1 @ d.sA1 * dfi1**2 - Rot2 @ d.sB2 * dfi2**2",
     "gam[2:4] = Rot1 @ d.sA1 * dfi1**2", {("gamma", 2, None): REV12, ("gamma", 3, None): REV12}),
    ("textbook", "wrong body", "F[4:6] = r2 + Rot2 @ d.sA2 - (r3 + Rot3 @ d.sB3)",
     "F[4:6] = r2 + Rot2 @ d.sA2 - (r3 + Rot2 @ d.sB3)",
     {("phi", 4, None): REV23, ("phi", 5, None): REV23}),
    ("textbook", "wrong body", "Fq[7, 8] = -d.v0 @ OM @ Rot3 @ d.sA3",
     "Fq[7, 8] = -d.v0 @ OM @ Rot1 @ d.sA3", {("phi_q", 7, 8): PRISM}),
    ("four_bar", "sign", 'J[6:8, 8] = OM @ R3 @ s["sA3"]', 'J[6:8, 8] = -OM @ R3 @ s["sA3"]',
     {("phi_q", 6, 8): ROCKER, ("phi_q", 7, 8): ROCKER}),
    ("four_bar", "swapped index", '"sA2": np.array([l2 / 2, h])',
     '"sA2": np.array([h, l2 / 2])',
     {("phi", 4, None): COUPLER_ROCKER, ("phi", 5, None): COUPLER_ROCKER,
      ("phi_q", 4, 5): COUPLER_ROCKER, ("phi_q", 5, 5): COUPLER_ROCKER,
      ("gamma", 4, None): COUPLER_ROCKER, ("gamma", 5, None): COUPLER_ROCKER}),
    ("four_bar", "missing term", 'g[4:6] = R2 @ s["sA2"] * d2**2 - R3 @ s["sB3"] * d3**2',
     'g[4:6] = R2 @ s["sA2"] * d2**2',
     {("gamma", 4, None): COUPLER_ROCKER, ("gamma", 5, None): COUPLER_ROCKER}),
    ("four_bar", "missing term", "out[8] = -(w + t)", "out[8] = -w",
     {("phi_t", 8, None): "drivers[0] angle crank-ground"}),
    ("four_bar", "wrong body", 'J[2:4, 5] = -OM @ R2 @ s["sB2"]',
     'J[2:4, 5] = -OM @ R1 @ s["sB2"]',
     {("phi_q", 2, 5): CRANK_COUPLER, ("phi_q", 3, 5): CRANK_COUPLER}),
    ("luffing", "sign", "J[row, 8] = -a @ OM @ (rp - rc - Rc @ sA)",
     "J[row, 8] = a @ OM @ (rp - rc - Rc @ sA)", {("phi_q", 7, 8): CYL, ("phi_q", 8, 8): SLIDE}),
    ("luffing", "sign", "- Rc @ sA * (dfp - dfc)**2", "+ Rc @ sA * (dfp - dfc)**2",
     {("gamma", 7, None): CYL, ("gamma", 8, None): SLIDE}),
    ("luffing", "swapped index", "J[6, 5] = 1.0\n    J[6, 8] = -1.0",
     "J[6, 8] = 1.0\n    J[6, 5] = -1.0", {("phi_q", 6, 5): CYL, ("phi_q", 6, 8): CYL}),
    ("luffing", "missing term", "g[8] = _sliding_gamma(U, q, dq, p) + 2 * k",
     "g[8] = _sliding_gamma(U, q, dq, p)", {("gamma", 8, None): SLIDE}),
    ("luffing", "wrong body", "J[row, 5] = -a @ OM @ Rc @ sA", "J[row, 5] = -a @ OM @ Rp @ sA",
     {("phi_q", 7, 5): CYL, ("phi_q", 8, 5): SLIDE}),
    ("luffing", "wrong body", "F[4:6] = rp - (rb + Rb @ np.array([bx, by]))",
     "F[4:6] = rp - (rb + Rp @ np.array([bx, by]))", {("phi", 4, None): BOOM,
                                                      ("phi", 5, None): BOOM}),
]


@pytest.fixture(scope="module")
def derived() -> dict[str, numeric.Derived]:
    return {name: numeric.derived_functions(codegen_support.derived(path))  # shared per run
            for name, (path, _) in MECHANISMS.items()}


def _planted(tmp_path: Path, base: Path, old: str, new: str) -> Path:
    source = base.read_text()
    assert source.count(old) == 1, f"the slip's source text must occur once in {base.name}"
    slipped = tmp_path / f"slipped_{base.name}"
    slipped.write_text(source.replace(old, new))
    return slipped


@pytest.mark.parametrize("mechanism, kind, old, new, expected", SLIPS,
                         ids=[f"{s[0]}-{s[1]}-{k}" for k, s in enumerate(SLIPS)])
def test_a_planted_slip_is_found_and_located(derived, tmp_path, mechanism, kind, old, new,
                                             expected) -> None:
    hand = _planted(tmp_path, MECHANISMS[mechanism][1], old, new)
    report = numeric.verify(derived[mechanism], hand)
    found = {(m.function, m.row, m.column): m.owner.rsplit(" (", 1)[0]
             for m in report.mismatches}
    assert found == expected
    assert not report.ok
    text = report.text()
    for m in report.mismatches:
        assert f"{m.entry}: row {m.row} {m.owner}" in text
        if m.column is not None:
            assert f"d/d {derived[mechanism].system.coordinates[m.column]}" in text
        assert m.error > 1e-3 and m.failing > 0


@pytest.mark.parametrize("mechanism", sorted(MECHANISMS))
def test_correct_derivations_pass_over_many_seeds(derived, mechanism) -> None:
    hand = verify_hand.load_hand_module(MECHANISMS[mechanism][1])
    for seed in range(40):
        report = numeric.verify(derived[mechanism], hand, seed=seed)
        assert report.ok, report.text()
        assert [r.name for r in report.results] == ["phi", "phi_q", "phi_t", "gamma"]


def test_the_printed_slip_is_flagged_at_gamma_rows_5_and_6(derived) -> None:
    report = numeric.verify(derived["textbook"], FAITHFUL)
    assert [(m.function, m.row, m.owner) for m in report.mismatches] == [
        ("gamma", 4, f"{REV23} (x)"), ("gamma", 5, f"{REV23} (y)")]
    # gam(5:6) carries the derived term of sB3 and the rate of the slider
    assert all("sB3x" in m.derived and "slider.phi'" in m.derived for m in report.mismatches)
    assert "where:\n  joints[2] revolute rod-slider: gamma[4], gamma[5]" in report.text()


def test_the_printed_slip_hides_at_the_nominal_design(derived) -> None:
    """sB2 = sB3 = 0 in Dane.m: only varying the parameters exposes the slip."""
    assert numeric.verify(derived["textbook"], FAITHFUL, spread=0).ok
    assert numeric.verify(derived["textbook"], CORRECTED).ok


def test_transcription_gives_the_books_example_2_5_values() -> None:
    """Independent check of the transcription: Example 2.5 (j), (k), (l) at its q*, dq*, t*."""
    hand = verify_hand.load_hand_module(FAITHFUL)
    root = math.sqrt(2 * math.pi)
    q = np.array([0, 0, math.pi, -1, 0, math.atan(4 / 3), 2, 4, 0])
    dq = np.array([0, 0, root, 0, -root, root / 3, -4 * root / 3, 0, 0])
    t = math.sqrt(math.pi / 2)
    p = np.array([1, 5, 4, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0], dtype=float)
    np.testing.assert_allclose(hand.phi(q, t, p), np.zeros(9), atol=1e-14)
    np.testing.assert_allclose(hand.phi_t(q, t, p), [0] * 8 + [-root], atol=1e-14)
    np.testing.assert_allclose(hand.gamma(q, dq, t, p), [0, 0, -2 * math.pi, 0, 2 * math.pi / 3,
                                                         8 * math.pi / 9, 0, 0, 2], atol=1e-13)
    assert hand.phi_q(q, t, p)[4, 5] == pytest.approx(-4) and hand.phi_q(q, t, p)[5, 5] == \
        pytest.approx(3)


def test_derived_values_are_the_books_at_example_2_5(derived) -> None:
    """The derived side of the comparison, checked against Example 2.5 (l)."""
    root = math.sqrt(2 * math.pi)
    system = derived["textbook"].system
    state = sampling.State(np.array([0, 0, math.pi, -1, 0, math.atan(4 / 3), 2, 4, 0]),
                         np.array([0, 0, root, 0, -root, root / 3, -4 * root / 3, 0, 0]),
                         math.sqrt(math.pi / 2), np.array(system.p_values))
    np.testing.assert_allclose(derived["textbook"].evaluate("gamma", state),
                               [0, 0, -2 * math.pi, 0, 2 * math.pi / 3, 8 * math.pi / 9, 0, 0, 2],
                               atol=1e-13)
    jacobian = derived["textbook"].evaluate("phi_q", state)
    assert jacobian.shape == (9, 9) and np.count_nonzero(jacobian) <= 25
    assert jacobian[4, 5] == pytest.approx(-4) and jacobian[8, 2] == 1


def test_parameters_vary_around_the_nominal_design() -> None:
    system = codegen_support.derived(TEXTBOOK)  # the run's shared derivation
    states = sampling.sample_states(system, 200, seed=1, spread=0.3)
    p = np.array([s.p for s in states])
    nominal = np.array(system.p_values)
    nonzero = nominal != 0
    assert np.all(np.abs(p[:, nonzero] / nominal[nonzero] - 1) <= 0.3)
    assert np.all(np.abs(p[:, ~nonzero]) <= 0.3 * sampling.length_scale(system))
    assert np.all(np.std(p, axis=0) > 0)  # every parameter, zeros included, is varied
    t0, t1, _ = system.time_grid
    assert all(t0 <= s.t <= t1 for s in states)
    kept = sampling.sample_states(system, 5, seed=1, spread=0)
    assert all(np.array_equal(s.p, nominal) for s in kept)


def test_only_the_defined_functions_are_compared(derived, tmp_path) -> None:
    source = CASES / "four_bar_hand.py"
    partial = tmp_path / "only_gamma.py"
    text = source.read_text()
    partial.write_text(text.replace("def phi(", "def _phi(").replace("def phi_q(", "def _phi_q(")
                       .replace("def phi_t(", "def _phi_t("))
    report = numeric.verify(derived["four_bar"], partial)
    assert [r.name for r in report.results] == ["gamma"]
    assert report.skipped == ("phi", "phi_q", "phi_t") and report.ok
    assert "phi_q  not defined, skipped" in report.text()


def test_a_non_finite_hand_value_is_a_mismatch(derived) -> None:
    import types

    hand = verify_hand.load_hand_module(CASES / "four_bar_hand.py")

    def gamma(q, dq, t, p):
        value = hand.gamma(q, dq, t, p)
        value[8] = np.nan
        return value

    report = numeric.verify(derived["four_bar"], types.SimpleNamespace(gamma=gamma))
    assert [(m.function, m.row) for m in report.mismatches] == [("gamma", 8)]
    assert report.mismatches[0].error == math.inf


def test_loading_by_path_leaves_sys_path_and_modules_alone() -> None:
    path_before, modules_before = list(sys.path), set(sys.modules)
    module = verify_hand.load_hand_module(CASES / "four_bar_hand.py")
    assert callable(module.gamma)
    assert sys.path == path_before
    assert set(sys.modules) - modules_before == set()


@pytest.mark.parametrize("slip", [s for s in SLIPS if s[0] == "textbook"][3:6],
                         ids=lambda s: f"{s[1]}")
def test_slips_behind_zero_dimensions_need_random_parameters(derived, tmp_path, slip) -> None:
    """These slips multiply a local vector that is zero in Dane.m: invisible at the nominal
    design, found once the parameters vary."""
    mechanism, _, old, new, expected = slip
    hand = _planted(tmp_path, MECHANISMS[mechanism][1], old, new)
    assert numeric.verify(derived[mechanism], hand, spread=0).ok
    assert {(m.function, m.row, m.column) for m in numeric.verify(derived[mechanism],
                                                                  hand).mismatches} == set(expected)


def test_a_mechanism_without_parameters() -> None:
    """p is empty; the pendulum's Phi written by hand from (2.18) and (2.27)."""
    import types

    mech = symkin.from_dict({
        "name": "pendulum", "bodies": {"bob": {"q0": [1, 0, 0]}},
        "joints": [{"type": "revolute", "i": "ground", "j": "bob", "sA": [0, 0],
                    "sB": [-1, 0]}],
        "drivers": [{"type": "angle", "i": "bob", "j": "ground", "theta": "sin(t)"}],
        "time": {"t1": 1, "dt": 0.1}})

    def phi(q, t, p):
        x, y, f = q
        assert p.shape == (0,)
        return [-(x - np.cos(f)), -(y - np.sin(f)), f - np.sin(t)]

    def phi_t(q, t, p):
        return [0, 0, np.cos(t)]  # slip: the sign of -theta'

    report = numeric.verify(mech, types.SimpleNamespace(phi=phi, phi_t=phi_t))
    assert [(m.function, m.row, m.owner) for m in report.mismatches] == [
        ("phi_t", 2, "drivers[0] angle bob-ground (angle)")]


def test_rounding_noise_against_an_exact_zero_is_no_mismatch() -> None:
    derived = np.zeros((4, 3))
    noise = np.full((4, 3), 3e-17)
    assert np.all(numeric.relative_errors(derived, noise, least=1e-6) < 1e-10)
    # a real difference on the same floor is one
    assert numeric.relative_errors(derived, noise + 0.1, least=1e-6).min() > 0.9
    # relative to the entry when it is large; the floor keeps tiny entries absolute
    errors = numeric.relative_errors(np.array([[100.0, 1e-9]]), np.array([[100.0 + 1e-6, 2e-9]]))
    assert errors[0, 0] == pytest.approx(1e-8)
    assert errors[0, 1] == pytest.approx(1e-8)  # 1e-9 / (1e-3 * 100), not 0.5


def test_an_input_driven_mechanism_is_refused_with_its_line(tmp_path, capsys) -> None:
    # found by fuzzing: the input's symbol reached lambdify and raised a SyntaxError traceback
    from symkin import cli

    hand = tmp_path / "hand.py"
    hand.write_text("def phi(q, t, p):\n    return [0.0] * 9\n")
    mechanism = ROOT / "examples" / "crank_slider_input.yaml"
    assert cli.main(["verify", str(mechanism), "--against", str(hand)]) == cli.EXIT_BAD_INPUT
    err = capsys.readouterr().err
    line = next(k for k, text in enumerate(mechanism.read_text().splitlines(), start=1)
                if "theta: input" in text)
    assert err.startswith(f"symkin: error: {mechanism}:{line}: at drivers[0].theta: "), err
    assert "write the driver as a function of t" in err
