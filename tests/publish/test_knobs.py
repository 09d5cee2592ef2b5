"""The knobs of a scene: the knobbed scene at the knobs' own values is the scene itself."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

import laplace_springs as ls
from laplace_springs.publish.knobs import knob_values, knobbed_scene


@pytest.mark.parametrize("name", sorted(ls.bundled_scenes()))
def test_knobbed_scene_at_its_own_values_is_the_scene(name):
    scene = ls.load_scene(name)
    knobbed, knobs = knobbed_scene(scene)
    at_rest = knobbed.subs({k.name: sp.nsimplify(k.value) for k in knobs})  # a free scene: F = 0
    for field in ("M", "C", "K", "x0", "v0"):
        assert sp.Matrix(getattr(at_rest, field)) == sp.Matrix(getattr(scene, field)), field
    times = np.array([0.3, 1.7, 4.2])
    assert np.allclose(ls.solve(at_rest).evaluate(times), ls.solve(scene).evaluate(times),
                       rtol=0, atol=1e-12)


def test_a_stiffer_spring_is_the_scene_rebuilt_with_it():
    # wall-pair with k2 doubled, written out by hand (Example 3's components)
    base = ls.load_scene("wall-pair")
    knobbed, knobs = knobbed_scene(base, knobs=["k2"], initial=False, forcing=False)
    assert [k.name for k in knobs] == ["k2"]
    doubled = ls.Scene.from_components(
        masses={"m1": 1, "m2": "2/3"},
        springs={"k1": ("wall", "m1", "0.3"), "k2": ("m1", "m2", "0.16"), "k3": ("m2", "wall", "0.2")},
        x0=["-0.08", "0.4"], v0=["0.15", "-0.3"])
    assert sp.Matrix(knobbed.subs({"k2": sp.Rational(16, 100)}).K) == sp.Matrix(doubled.K)


def test_a_free_scene_gets_a_drive_and_a_harmonic_one_keeps_its_own():
    free = ls.load_scene("three-dashpots")
    knobbed, knobs = knobbed_scene(free, knobs=[], initial=False)
    names = {k.name: k for k in knobs}
    assert set(names) == {"F", "w"} and names["F"].value == 0
    assert str(knobbed.forcing[0]) == "F*cos(t*w)" and knobbed.forcing[1] == 0
    driven = ls.Scene.from_matrices(M=[[1]], C=[["0.1"]], K=[[4]], x0=[0], v0=[0], forcing=["10*sin(2*t)"])
    _, knobs = knobbed_scene(driven)
    values = knob_values(knobs)
    assert values["F"] == 10 and values["w"] == 2


def test_bad_knobs_are_named():
    with pytest.raises(ls.SceneError, match="'k9' is not a component or mass"):
        knobbed_scene(ls.load_scene("wall-pair"), knobs=["k9"])
    symbolic = ls.Scene.from_matrices(M=[[1]], K=[["k"]], x0=[1], v0=[0], parameters=["k"])
    with pytest.raises(ls.SceneError, match="c is not a parameter"):
        knobbed_scene(symbolic, values={"c": 1})
