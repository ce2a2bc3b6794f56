"""Mechanisms that their forces move, shared by the forward-dynamics tests (each derived once
per session: the derivation, not the integration, is the slow part), and the helpers by which
the tests of motion, dynamics, inputs and assemblies share a derivation and a kernel instead of
deriving and generating the same file again in each test (``shared`` and ``kernel``)."""

from __future__ import annotations

import functools
import json
from pathlib import Path
from typing import Any

import pytest
import shared_builds
from codegen_support import compiled

import symkin

PENDULUM = """\
name: pendulum
parameters: {L: 1.3, m: 2.0, g: 9.81}
bodies:
  rod: {q0: [0, 0, PHI0], mass: m, inertia: 0, com: [L, 0], points: {tip: [L, 0]}}
joints:
  - {type: revolute, i: ground, j: rod, sA: [0, 0], sB: [0, 0]}
forces:
  - {type: gravity, g: [0, -g]}
time: {t0: 0, t1: 1, dt: 0.1}
integrator: {rtol: 1e-11, atol: 1e-12}
"""

# The textbook's crank-slider (a = 1, b = 5, c = 4) without its driver: it moves under
# gravity (and a spring from the ground to the slider, SPRING's k), from rest or from
# the crank's given rate.
CRANK_SLIDER = """\
name: free_crank_slider
parameters: {a: 1.0, b: 5.0, c: 4.0, m1: 2.0, m2: 3.0, m3: 1.5, J1: 0.2, J2: 6.5, g: 9.81,
             k: SPRING}
bodies:
  crank:  {q0: [0, 0, 1.8], mass: m1, inertia: J1, com: mid,
           points: {tip: [a, 0], mid: [a/2, 0]}}
  rod:    {q0: [-0.2, 1.0, 0.6], mass: m2, inertia: J2, com: mid,
           points: {P: [b, 0], mid: [b/2, 0]}}
  slider: {q0: [4.3, 4, 0], mass: m3, points: {c: [0, 0]}}
joints:
  - {type: revolute,  i: ground, j: crank,  sA: [0, 0], sB: [0, 0]}
  - {type: revolute,  i: crank,  j: rod,    sA: tip,    sB: [0, 0]}
  - {type: revolute,  i: rod,    j: slider, sA: P,      sB: [0, 0]}
  - {type: prismatic, i: slider, j: ground, sA: [0, 0], sB: [0, c], v: [0, 1], phi0: 0}
forces:
  - {type: gravity, g: [0, -g]}
  - {type: spring, i: ground, A: [1.0, c], j: slider, B: [0, 0], k: k, length0: 2.5}
initial: {velocities: {crank.phi: 2.0}}
integrator: {rtol: 1e-11, atol: 1e-12}
time: {t0: 0, t1: 2, dt: 0.05}
"""


def write(tmp: Path, name: str, text: str) -> Path:
    path = tmp / name
    path.write_text(text, encoding="utf-8")
    return path


def shared(name: str, text: str) -> Path:
    """A mechanism file of ``text`` called ``name``, shared by the run (shared_builds.text_file);
    ``write`` is for a file a test means to have alone (its own folder, messages naming it)."""
    return shared_builds.text_file(name, text)


_SYSTEMS: dict[str, Any] = {}
_KERNELS: dict[tuple[str, str, tuple[tuple[str, str], ...]], Any] = {}


def derived_from(data: dict[str, Any]) -> Any:
    """symkin.derive(from_dict(data)), kept for this process by the data's JSON text (its
    keys in their order: the order of bodies is the order of the coordinates)."""
    from symkin.spec.validate import from_dict

    text = json.dumps(data)
    if text not in _SYSTEMS:
        _SYSTEMS[text] = symkin.derive(from_dict(data))
    return _SYSTEMS[text]


def kernel_from(data: dict[str, Any], backend: str, **options: str) -> Any:
    """symkin.compile(derived_from(data), backend, **options), kept for this process: the
    tests of one file that build the same mechanism (the same dictionary on each backend)
    derive it once and generate each kernel once."""
    key = (json.dumps(data), backend, tuple(sorted(options.items())))
    if key not in _KERNELS:
        _KERNELS[key] = symkin.compile(derived_from(data), backend, **options)
    return _KERNELS[key]


@functools.cache
def kernel(path: Path, backend: str, **options: str) -> Any:
    """codegen_support.compiled(path, backend, **options), kept for this process: a kernel
    is only read by solve, so the tests of one file or of several share it (a file its forces
    move would otherwise generate its code again at each symkin.compile)."""
    return compiled(path, backend, **options)


@pytest.fixture(scope="session")
def crank_slider_system(tmp_path_factory: pytest.TempPathFactory) -> Any:
    """The System of the free crank-slider with a spring of k = 20."""
    path = write(tmp_path_factory.mktemp("motion"), "crank_slider.yaml",
                 CRANK_SLIDER.replace("SPRING", "20.0"))
    return symkin.derive(path)


@pytest.fixture(scope="session")
def crank_slider(crank_slider_system: Any) -> Any:
    """The kernel of the free crank-slider with a spring of k = 20 (generated NumPy)."""
    return symkin.compile(crank_slider_system, backend="numpy")


@pytest.fixture(scope="session")
def crank_slider_c(crank_slider_system: Any) -> Any:
    """The same through the generated C, compiled (skipped without a compiler)."""
    from symkin.errors import NoCompilerError

    try:
        return symkin.compile(crank_slider_system, backend="c")
    except NoCompilerError:
        pytest.skip("no C compiler")
