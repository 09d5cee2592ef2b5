"""Tests of Scene and its builders.

Expected matrices come from outside the code under test: the seed page's printed
A = [[3, -1], [-2, 2]] (Example 1) and its symbolic A, B (Examples 1, 4), the
equations of motion written out by hand, and the public acceptance scenes
(shared/acceptance/scenes.py), copied here as the decimal strings given there.
"""

from __future__ import annotations

import dataclasses
from fractions import Fraction

import numpy as np
import pytest
import sympy

from laplace_springs import solve
from laplace_springs.model.errors import SceneError
from laplace_springs.model.scene import SUPPORTS, Component, Scene
from laplace_springs.model.symbols import TIME

R = sympy.Rational


def exact(rows):
    """A matrix from decimal strings, converted independently of the code under test."""
    return sympy.Matrix([[R(Fraction(entry)) for entry in row] for row in rows])


# Acceptance scenes (shared/acceptance/scenes.py), as printed there.
SEED2 = {"M": [["1", "0"], ["0", "1/2"]], "C": [["0.2", "0"], ["0", "0.1"]], "K": [["3", "-1"], ["-1", "1"]]}
SEED3 = {"M": [["1", "0"], ["0", "2/3"]], "K": [["0.38", "-0.08"], ["-0.08", "0.28"]]}
SEED5 = {
    "M": [["1", "0"], ["0", "0.8"]],
    "C": [["1.9", "-1.4"], ["-1.4", "2.3"]],
    "K": [["779", "-379"], ["-379", "479"]],
}


def example1(**overrides):
    arguments = {
        "masses": {"m1": 1, "m2": "1/2"},
        "springs": {"k1": ("ceiling", "m1", 2), "k2": ("m1", "m2", 1)},
        "x0": [1, 0],
        "v0": [0, 1],
        "layout": "vertical",
    }
    arguments.update(overrides)
    return Scene.from_components(**arguments)


# --- the seed's examples -----------------------------------------------------------


def test_example1_reproduces_the_seeds_A():
    A, B = example1().normalized()
    assert sympy.Matrix([[3, -1], [-2, 2]]) == A  # seed (1.1), numbers as printed
    assert sympy.zeros(2, 2) == B


def test_example1_symbolic_A_has_minus_k2_over_m2():
    k1, k2, m1, m2 = sympy.symbols("k1 k2 m1 m2", positive=True)
    scene = Scene.from_components(
        masses={"m1": "m1", "m2": "m2"},
        springs={"k1": ("ceiling", "m1", "k1"), "k2": ("m1", "m2", "k2")},
        parameters=["m1", "m2", "k1", "k2"],
    )
    A, _ = scene.normalized()
    # seed (1.1) with its misprint corrected: the (2,1) entry is -k2/m2.
    expected = sympy.Matrix([[(k1 + k2) / m1, -k2 / m1], [-k2 / m2, k2 / m2]])
    assert (A - expected).applyfunc(sympy.simplify) == sympy.zeros(2, 2)


def test_example2_matches_acceptance_matrices():
    scene = example1(dashpots={"delta1": ("air", "m1", 0.2), "delta2": ("air", "m2", 0.1)}, v0=[0, 0])
    for name in ("M", "C", "K"):
        assert getattr(scene, name) == exact(SEED2[name]), name
    A, B = scene.normalized()
    assert sympy.eye(2) / 5 == B  # the seed's B = 0.2 I
    assert sympy.Matrix([[3, -1], [-2, 2]]) == A


def test_example3_matches_acceptance_and_hand_written_physics():
    scene = Scene.from_components(
        masses={"m1": 1, "m2": "2/3"},
        springs={"k1": ("wall", "m1", 0.3), "k2": ("m1", "m2", 0.08), "k3": ("m2", "wall", 0.2)},
        x0=[-0.08, 0.4],
        v0=[0.15, -0.3],
    )
    assert exact(SEED3["M"]) == scene.M
    assert exact(SEED3["K"]) == scene.K
    assert not scene.is_damped
    assert scene.x0 == exact([["-0.08"], ["0.4"]])
    assert scene.v0 == exact([["0.15"], ["-0.3"]])


def test_example3_symbolic_couples_through_k2():
    k1, k2, k3 = sympy.symbols("k1 k2 k3", positive=True)
    scene = Scene.from_components(
        masses={"m1": "m1", "m2": "m2"},
        springs={"k1": ("wall", "m1", "k1"), "k2": ("m1", "m2", "k2"), "k3": ("m2", "wall", "k3")},
        parameters=["m1", "m2", "k1", "k2", "k3"],
    )
    # m1 x1'' + (k1 + k2) x1 - k2 x2 = 0, m2 x2'' + (k2 + k3) x2 - k2 x1 = 0
    assert sympy.Matrix([[k1 + k2, -k2], [-k2, k2 + k3]]) == scene.K


def test_example4_matches_the_seeds_A_and_B():
    k1, k3, b, delta, m1, m2 = sympy.symbols("k1 k3 b delta m1 m2", positive=True)
    scene = Scene.from_components(
        masses=[("m1", "m1"), ("m2", "m2")],
        springs=[("k1", "wall", "m1", "k1"), ("k3", "m2", "wall", "k3")],
        dashpots=[
            ("b", "m1", "m2", "b"),
            ("delta1", "ground", "m1", "delta"),
            ("delta2", "ground", "m2", "delta"),
        ],
        parameters=["m1", "m2", "k1", "k3", "b", "delta"],
    )
    A, B = scene.normalized()
    assert sympy.Matrix([[k1 / m1, 0], [0, k3 / m2]]) == A
    expected_B = sympy.Matrix([[(delta + b) / m1, -b / m1], [-b / m2, (delta + b) / m2]])
    assert (B - expected_B).applyfunc(sympy.simplify) == sympy.zeros(2, 2)


def test_example5_matches_acceptance_matrices():
    scene = Scene.from_components(
        masses={"m1": 1, "m2": 0.8},
        springs={"k1": ("wall", "m1", 400), "k2": ("m1", "m2", 379), "k3": ("m2", "wall", 100)},
        dashpots={"mu1": ("wall", "m1", 0.5), "mu2": ("m1", "m2", 1.4), "mu3": ("m2", "wall", 0.9)},
        x0=[0.05, 0.07],
        v0=[3, 2],
    )
    for name in ("M", "C", "K"):
        assert getattr(scene, name) == exact(SEED5[name]), name
    assert [component.label for component in scene.components] == ["k1", "k2", "k3", "mu1", "mu2", "mu3"]


# --- from_matrices -----------------------------------------------------------------


def test_from_matrices_accepts_the_acceptance_strings():
    scene = Scene.from_matrices(**SEED2, x0=["1", "0"], v0=["0", "0"])
    assert sympy.Matrix([[R(1, 5), 0], [0, R(1, 10)]]) == scene.C
    assert scene.names == ("x1", "x2")
    assert scene.components == () and scene.mass_names == ()
    assert all(isinstance(m, sympy.ImmutableMatrix) for m in (scene.M, scene.C, scene.K, scene.x0, scene.v0))


@pytest.mark.parametrize(
    "convert",
    [
        lambda rows: rows,
        lambda rows: tuple(tuple(row) for row in rows),
        lambda rows: np.array(rows, dtype=float),
        sympy.Matrix,
        sympy.ImmutableMatrix,
    ],
)
def test_from_matrices_accepts_many_matrix_types(convert):
    scene = Scene.from_matrices(
        M=convert([[1, 0], [0, 0.5]]), K=convert([[3, -1], [-1, 1]]), x0=[1, 0], v0=[0, 1]
    )
    assert sympy.diag(1, R(1, 2)) == scene.M
    assert sympy.Matrix([[3, -1], [-1, 1]]) == scene.K


@pytest.mark.parametrize(
    "vector",
    [[1, 0.5], (1, 0.5), [[1], [0.5]], [[1, 0.5]], np.array([1, 0.5]), np.array([[1], [0.5]]),
     sympy.Matrix([1, 0.5]), sympy.Matrix([[1, 0.5]])],
)
def test_vectors_flat_column_or_row(vector):
    scene = Scene.from_matrices(M=[[1, 0], [0, 1]], x0=vector, v0=vector)
    assert scene.x0 == sympy.Matrix([1, R(1, 2)])
    assert scene.x0.shape == (2, 1)


def test_declared_parameters_are_positive_unless_declared_otherwise():
    scene = Scene.from_matrices(M=[["m"]], C=[["c"]], K=[["k"]], x0=["d"], v0=["v"],
                                parameters={"m": "mass", "c": "damping", "k": "positive",
                                            "d": "real", "v": "real"})
    symbols = {symbol.name: symbol for symbol in scene.free_symbols}
    assert set(symbols) == {"m", "c", "k", "d", "v"}
    assert all(symbols[name].is_positive for name in "mck")
    assert symbols["d"].is_real and symbols["d"].is_positive is None
    assert [symbol.name for symbol in scene.parameters] == ["c", "d", "k", "m", "v"]


def test_from_normalized_keeps_a_non_symmetric_A():
    scene = Scene.from_normalized(A=[[3, -1], [-2, 2]], B=[[0.2, 0], [0, 0.2]], x0=[1, 0], v0=[0, 0])
    assert sympy.eye(2) == scene.M
    assert sympy.Matrix([[3, -1], [-2, 2]]) == scene.K
    assert sympy.eye(2) / 5 == scene.C
    A, B = scene.normalized()
    assert sympy.Matrix([[3, -1], [-2, 2]]) == A  # the seed's non-symmetric A, kept as given
    assert sympy.eye(2) / 5 == B


def test_normalized_with_a_full_mass_matrix():
    M = sympy.Matrix([[2, 1], [1, 2]])
    K = sympy.Matrix([[3, -1], [-1, 1]])
    scene = Scene.from_matrices(M=M, K=K, x0=[0, 0], v0=[0, 0])
    A, B = scene.normalized()
    assert M * A == K
    assert sympy.zeros(2, 2) == B


def test_properties_and_repr():
    scene = example1(title="Example 1")
    assert scene.n == 2
    assert not scene.is_damped
    assert scene.free_symbols == frozenset()
    assert repr(scene) == "<Scene 'Example 1': 2 coordinates, undamped>"
    damped = Scene.from_matrices(M=[[1]], C=[["c"]], x0=[1], v0=[0], parameters=["c"])
    assert damped.is_damped
    assert repr(damped) == "<Scene 1 coordinate, damped>"


def test_with_initial_returns_a_new_scene_and_keeps_the_rest():
    scene = example1(title="pair")
    assert scene.with_initial(x0={"m2": 0.5}).x0 == sympy.Matrix([0, R(1, 2)])  # missing masses: 0
    changed = scene.with_initial(x0=[0, 0.5])
    assert changed is not scene
    assert changed.x0 == sympy.Matrix([0, R(1, 2)])
    assert changed.v0 == scene.v0
    assert scene.x0 == sympy.Matrix([1, 0])
    for field in ("M", "C", "K", "names", "title", "layout", "components", "mass_names"):
        assert getattr(changed, field) == getattr(scene, field)
    with pytest.raises(SceneError, match="v0 has 3 entries, expected 2"):
        scene.with_initial(v0=[1, 2, 3])


def test_scene_is_frozen():
    scene = example1()
    with pytest.raises(dataclasses.FrozenInstanceError):
        scene.title = "changed"


def test_custom_names_and_layout():
    scene = Scene.from_matrices(M=[[1, 0], [0, 1]], x0=[0, 0], v0=[0, 0], names=["x", "y"], layout="vertical")
    assert scene.names == ("x", "y")
    assert scene.layout == "vertical"


def test_symbolic_full_mass_matrix_is_accepted_and_normalized():
    # (the numeric SPD full mass matrix is test_normalized_with_a_full_mass_matrix)
    scene = Scene.from_matrices(M=[["m", "mu"], ["mu", "m"]], K=[["k", 0], [0, "k"]], x0=[0, 0], v0=[0, 0],
                                parameters=["m", "mu", "k"])
    m, mu, k = sympy.symbols("m mu k", positive=True)
    assert sympy.Matrix([[m, mu], [mu, m]]) == scene.M
    A, B = scene.normalized()
    # the 2x2 inverse by hand: M⁻¹ = [[m, −mu], [−mu, m]]/(m² − mu²), so A = M⁻¹ k I
    expected = k / (m**2 - mu**2) * sympy.Matrix([[m, -mu], [-mu, m]])
    assert (A - expected).applyfunc(sympy.simplify) == sympy.zeros(2, 2)
    assert sympy.zeros(2, 2) == B


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        ({"M": [[1, 2]]}, r"M must be a non-empty square matrix, got shape 1x2"),
        ({"M": []}, r"non-empty square matrix, got shape 0x0"),
        ({"M": [1, 2]}, r"M: expected a matrix \(a list of rows\), but row 0 is 1"),
        ({"M": "1"}, r"M: expected a matrix"),
        ({"M": [[1, 0], [0, 1, 2]]}, r"M: row 1 has 3 entries but row 0 has 2"),
        ({"M": [[1, 0], [0, 1]], "K": [[1]]}, r"K has shape 1x1 but M has shape 2x2"),
        ({"M": [[1, 0], [0, 1]], "C": [[1, 0, 0]] * 3}, r"C has shape 3x3 but M has shape 2x2"),
        ({"M": [[1, 0], [0, 1]], "x0": [0]}, r"x0 has 1 entries, expected 2"),
        ({"M": [[1, 0], [0, 1]], "v0": [0, 0, 0]}, r"v0 has 3 entries, expected 2"),
        ({"M": [[1, 0], [0, 1]], "x0": [[1, 2], [3, 4]]}, r"x0: expected a vector"),
        ({"M": [[1, 0], [0, 0]]}, r"pencil .* is singular.*coordinate x2 has zero mass and no spring or dashpot"),
        ({"M": [[1, 0], [0, -1]]}, r"mass M\[1,1\] must be positive, got -1"),
        ({"M": [["m", 0], [0, "-m"]], "parameters": ["m"]}, r"mass M\[1,1\] must be positive, got -m"),
        ({"M": [[1, 2], [2, 1]]}, r"M must be symmetric positive semi-definite, but it is indefinite"),
        ({"M": [[1, 2], [2, 4]]}, r"pencil .* is singular.*motion along \[1, -1/2\]"),
        ({"M": [[-1, 1], [1, 2]]}, r"mass M\[0,0\] must be positive, got -1; 0 is allowed"),
        ({"M": [[1, 2], [3, 6]]}, r"M must be symmetric .*M\[0,1\] = 2 but M\[1,0\] = 3"),
        ({"M": [[1, 0], [0, 0]], "C": [[0, 0], [0, 0]], "K": [[0, 0], [0, 0]]},
         r"pencil .* is singular: det\(λ²M \+ λC \+ K\) is identically zero"),
        ({"M": [["m", "m"], ["m", "m"]], "parameters": ["m"]}, r"pencil .* is singular"),
        ({"M": [["m"]]}, r"M\[0,0\]: expected a number, got 'm': unknown name 'm' at column 1 \(to make 'm' a "
                         r"parameter, declare it: parameters=\['m'\]"),
        ({"M": [[1]], "K": [["nan"]]}, r"K\[0,0\]: expected a number, got 'nan': 'nan' is not a finite real"),
        ({"M": [[1]], "K": [["I"]]}, r"K\[0,0\]: expected a number, got 'I': 'I' is not a finite real"),
        ({"M": [[1]], "K": [["1e301"]]}, r"K\[0,0\]: '1e301' has magnitude 1.00e\+301, beyond the limit"),
        ({"M": [[1]], "K": [["exp(10**6)"]]}, r"K\[0,0\]: .*'exp\(10\*\*6\)'.* magnitude .*beyond"),
        ({"M": [[1]], "K": [[10**400]]}, r"K\[0,0\]: .* has magnitude .*beyond the limit"),
        ({"M": [[1]], "K": [[10**6000]]}, r"K\[0,0\]: an integer of 19932 bits has more than 1000 digits"),
        ({"M": [[1]], "K": [["9" * 4001]]}, r"K\[0,0\]: expected a number, got '9999.*number with 4001 digits"),
        ({"M": [[1]], "K": [[1e-310]]}, r"K\[0,0\]: 1e-310 has magnitude .*beyond the limit"),
        ({"M": [[1]], "K": [[float("nan")]]}, r"K\[0,0\]: expected a finite number, got nan"),
        ({"M": [[1]], "C": [[float("inf")]]}, r"C\[0,0\]: expected a finite number"),
        ({"M": [["abc$"]]}, r"M\[0,0\]: expected a number, got 'abc\$'"),
        ({"M": [[1]], "x0": ["1/0"]}, r"x0\[0\]: .*division by zero"),
        ({"M": [[1]], "layout": "diagonal"}, r"layout must be one of horizontal, vertical, got 'diagonal'"),
        ({"M": [[1]], "names": ["a", "b"]}, r"names has 2 entries, expected 1"),
        ({"M": [[1, 0], [0, 1]], "names": ["a", "a"]}, r"names must be distinct"),
        ({"M": [[1, 0], [0, 1]], "names": ["a", ""]}, r"names must be non-empty strings"),
    ],
)
def test_from_matrices_errors(arguments, message):
    n = 2 if isinstance(arguments.get("M"), list) and len(arguments["M"]) == 2 else 1
    arguments = {"x0": [0] * n, "v0": [0] * n, **arguments}
    with pytest.raises(SceneError, match=message):
        Scene.from_matrices(**arguments)


def test_from_normalized_errors_name_A_and_B():
    with pytest.raises(SceneError, match=r"B has shape 1x1 but A has shape 2x2"):
        Scene.from_normalized(A=[[1, 0], [0, 1]], B=[[1]], x0=[0, 0], v0=[0, 0])
    with pytest.raises(SceneError, match=r"A\[0,1\]: expected a number"):
        Scene.from_normalized(A=[[1, "?"], [0, 1]], x0=[0, 0], v0=[0, 0])


def test_constructor_requires_exact_matrices():
    with pytest.raises(SceneError, match="M must be a sympy.ImmutableMatrix"):
        Scene(M=[[1]], C=[[0]], K=[[0]], x0=[0], v0=[0], names=("x1",))
    column = sympy.ImmutableMatrix([0])
    square = sympy.ImmutableMatrix([[1]])
    with pytest.raises(SceneError, match=r"x0 must be a 1x1 column"):
        Scene(M=square, C=square, K=square, x0=sympy.ImmutableMatrix([[0, 0]]), v0=column, names=("x1",))
    with pytest.raises(SceneError, match=r"K\[0,0\] must be a finite number"):
        Scene(M=square, C=square, K=sympy.ImmutableMatrix([[sympy.oo]]), x0=column, v0=column, names=("x1",))


# --- from_components ---------------------------------------------------------------


def test_components_mapping_and_sequence_forms_agree():
    by_mapping = Scene.from_components(
        masses={"m1": 1, "m2": 2},
        springs={"k1": ("wall", "m1", 1), "k2": ("m1", "m2", 3)},
        dashpots={"c": ("m2", "floor", 0.5)},
        x0={"m2": 1},
        v0={"m1": 2},
    )
    by_sequence = Scene.from_components(
        masses=[("m1", 1), ("m2", 2)],
        springs=[("k1", "wall", "m1", 1), ("k2", "m1", "m2", 3)],
        dashpots=[("c", "m2", "floor", 0.5)],
        x0=[0, 1],
        v0=[2, 0],
    )
    for field in ("M", "C", "K", "x0", "v0", "components", "mass_names", "names"):
        assert getattr(by_mapping, field) == getattr(by_sequence, field), field
    assert by_mapping.x0 == sympy.Matrix([0, 1]) and by_mapping.v0 == sympy.Matrix([2, 0])
    assert sympy.Matrix([[4, -3], [-3, 3]]) == by_mapping.K
    assert sympy.Matrix([[0, 0], [0, R(1, 2)]]) == by_mapping.C
    assert by_mapping.mass_names == ("m1", "m2")
    assert by_mapping.components[2] == Component("dashpot", "c", "m2", "floor", R(1, 2))


@pytest.mark.parametrize("support", sorted(SUPPORTS) + ["WALL", "Ceiling"])
def test_every_support_name_is_accepted_case_insensitively(support):
    scene = Scene.from_components(masses={"m": 2}, springs={"k": (support, "m", 5)})
    assert sympy.Matrix([[5]]) == scene.K
    assert scene.components[0].a == support.lower()


def test_initial_data_default_to_zero_and_zero_stiffness_is_allowed():
    scene = Scene.from_components(masses={"m1": 1}, springs={"k": ("wall", "m1", 0)})
    assert scene.x0 == sympy.Matrix([0]) and scene.v0 == sympy.Matrix([0])
    assert sympy.Matrix([[0]]) == scene.K


def test_component_symbols_are_positive():
    scene = Scene.from_components(masses={"m": "m"}, springs={"k": ("wall", "m", "k")}, parameters=["m", "k"])
    assert all(symbol.is_positive for symbol in scene.free_symbols)


@pytest.mark.parametrize(
    ("overrides", "message"),
    [
        ({"springs": {"k": ("m1", "m3", 1)}}, r"spring 'k': unknown node 'm3'; known masses: m1, m2; supports: air, ceiling"),
        ({"dashpots": {"c": ("m1", 7, 1)}}, r"dashpot 'c': unknown node 7"),
        ({"springs": {"k": ("m1", "m1", 1)}}, r"spring 'k' connects 'm1' to itself"),
        ({"springs": {"k": ("wall", "Ground", 1)}}, r"spring 'k' connects two supports \('wall', 'ground'\)"),
        ({"springs": {"k": ("m1", "m2", -1)}}, r"spring 'k': stiffness must be nonnegative, got -1"),
        ({"dashpots": {"c": ("m1", "m2", "-c")}, "parameters": ["c"]}, r"dashpot 'c': damping must be nonnegative, got -c"),
        ({"springs": {"k": ("m1", "m2", 1)}, "dashpots": {"k": ("m1", "m2", 1)}}, r"component label 'k' is used twice"),
        ({"springs": [("k", "m1", "m2", 1), ("k", "m1", "wall", 1)]}, r"component label 'k' is used twice"),
        ({"springs": {"k": ("m1", "m2")}}, r"spring 'k': expected \(node_a, node_b, value\)"),
        ({"springs": [("k", "m1", 1)]}, r"springs: expected rows of 4 items"),
        ({"springs": {"k": ("m1", "m2", "1 +")}}, r"spring 'k': expected a number, got '1 \+'"),
        ({"masses": {"m1": 1, "m2": 0}}, r"pencil .* is singular.*mass 'm2' \(coordinate x2\) has zero mass"),
        ({"masses": {"m1": 1, "m2": -1}}, r"mass 'm2' must be positive, got -1"),
        ({"masses": {"m1": "-m"}, "parameters": ["m"]}, r"mass 'm1' must be positive, got -m"),
        ({"masses": {"Wall": 1}}, r"mass name 'Wall' is reserved for a fixed support"),
        ({"masses": [("m1", 1), ("m1", 2)]}, r"mass 'm1' is given twice"),
        ({"masses": {}}, r"a scene needs at least one mass"),
        ({"masses": {"": 1}}, r"mass names must be non-empty strings"),
        ({"x0": {"m3": 1}}, r"x0: unknown mass or coordinate 'm3'; masses are m1, m2; coordinates are x1, x2"),
        ({"v0": [1]}, r"v0 has 1 entries, expected 2"),
        ({"layout": "sideways"}, r"layout must be one of"),
    ],
)
def test_from_components_errors(overrides, message):
    arguments = {"masses": {"m1": 1, "m2": 2}, **overrides}
    with pytest.raises(SceneError, match=message):
        Scene.from_components(**arguments)


def test_subs_resolves_values_that_name_other_parameters_and_refuses_cycles():
    scene = Scene.from_matrices(M=[[1]], C=[["c"]], K=[["k"]], x0=[1], v0=[0], parameters=["c", "k"])
    critical = scene.subs({"k": 4, "c": "2*sqrt(k)"})
    assert (critical.C[0, 0], critical.K[0, 0], critical.parameters) == (4, 4, ())
    with pytest.raises(SceneError, match="the values of c, k refer to each other in a cycle"):
        scene.subs({"k": "c", "c": "k"})
    with pytest.raises(SceneError, match="parameter 'c' is positive, got -2"):
        scene.subs({"k": 1, "c": "-2*k"})


def test_subs_at_critical_damping_solves_exactly_to_the_textbook_form():
    scene = Scene.from_matrices(M=[[1]], C=[["c"]], K=[[1]], x0=[1], v0=[0], parameters=["c"])
    x = solve(scene.subs({"c": 2})).x[0]  # x'' + 2x' + x = 0, x(0) = 1: (1 + t) e^{-t}
    assert sympy.simplify(x - (1 + TIME) * sympy.exp(-TIME)) == 0


def test_scene_shows_its_equations_in_latex():
    forced = Scene.from_matrices(M=[[1]], C=[["1/5"]], K=[[4]], x0=[1], v0=[0], forcing=["cos(2*t)"])
    text = forced._repr_latex_()
    assert text.startswith("$") and text.endswith("$")
    assert r"\ddot{x}" in text and r"\frac{1}{5}" in text and r"\cos{\left(2 t \right)}" in text
    undamped = Scene.from_matrices(M=[[1]], K=[[4]], x0=[1], v0=[0])._repr_latex_()
    assert r"\dot{x} +" not in undamped and "x = 0" in undamped  # no zero damping term
    big = Scene.from_matrices(M=sympy.eye(13), K=sympy.eye(13), x0=[0] * 13, v0=[0] * 13)
    assert big._repr_latex_() is None
