"""Symbolic scenes in named quantities: size, definitions, assumptions, correctness.

Correctness is always checked after substituting numbers, against the independent
mpmath matrix exponential of laplace_springs.bench.reference (never the code's own formulas);
the definitions against quantities computed directly from the matrices (trace and
determinant of A = M⁻¹K) and the textbook damped oscillator.
"""

from __future__ import annotations

import pytest
import sympy as sp

import laplace_springs as ls
from laplace_springs.bench.reference import reference_motion, relative_error
from laplace_springs.exact.named import NamedQuantity, expand_names, named
from laplace_springs.exact.partial_fractions import decompose
from laplace_springs.exact.real_terms import solution_terms, terms_expr
from laplace_springs.model.numbers import to_exact

SEED3 = {"m1": "1", "m2": "2/3", "k1": "0.3", "k2": "0.08", "k3": "0.2",
         "d1": "-0.08", "d2": "0.4", "v1": "0.15", "v2": "-0.3"}
TIMES = ["0", "0.7", "2.9", "11.3"]


def example3(values):
    """The seed's Example 3 with the physics' coupling -k2 x1 (see DESIGN.md)."""
    return ls.Scene.from_components(
        masses={"m1": values["m1"], "m2": values["m2"]},
        springs={"k1": ("wall", "m1", values["k1"]), "k2": ("m1", "m2", values["k2"]),
                 "k3": ("m2", "wall", values["k3"])},
        x0=[values["d1"], values["d2"]], v0=[values["v1"], values["v2"]],
        parameters={name: "real" if name[0] in "dv" else "positive"
                    for name in values.values() if isinstance(name, str) and name.isidentifier()})


def numbers_for(scene, values):
    return {s: to_exact(values[s.name], s.name) for s in scene.free_symbols}


def values_at(exprs, times, dps=30):
    return [[sp.N(e.subs(ls.t, sp.Rational(tv)), dps) for tv in times] for e in exprs]


@pytest.fixture(scope="module")
def example3_solution():
    return ls.solve(example3({k: k for k in SEED3}))


def test_example3_is_small(example3_solution):
    ops = sum(sp.count_ops(e) for e in example3_solution.x)
    assert ops <= 500  # issue 5's target; was 3042 before names
    definitions_ops = sum(sp.count_ops(v) for v in example3_solution.definitions.values())
    assert definitions_ops <= 100


def test_example3_numbers_substituted_match_the_reference(example3_solution):
    scene = example3_solution.scene
    values = numbers_for(scene, SEED3)
    reference = reference_motion(example3(SEED3), TIMES, dps=40)
    named_form = [e.subs(values) for e in example3_solution.x]
    assert relative_error(values_at(named_form, TIMES), reference) < 1e-25
    full = [e.subs(values) for e in example3_solution.substituted()]
    assert not any(e.atoms(NamedQuantity) for e in example3_solution.substituted())
    assert relative_error(values_at(full, TIMES), reference) < 1e-25


def test_example3_frequencies_are_the_modes_of_A(example3_solution):
    definitions = example3_solution.definitions
    names = {q.name: q for q in definitions}
    assert {"omega_1", "omega_2", "S_1", "P_1"} <= set(names)
    scene = example3_solution.scene
    A = scene.M.inv() * scene.K  # independent: trace and determinant of M⁻¹K
    w1, w2 = names["omega_1"], names["omega_2"]
    assert sp.simplify(expand_names(w1**2 + w2**2) - A.trace()) == 0
    values = numbers_for(scene, SEED3)
    product = sp.N(expand_names(w1**2 * w2**2).subs(values), 30)
    assert abs(product - sp.N(A.det().subs(values), 30)) < 1e-25
    assert 0 < sp.N(w1.subs(values)) < sp.N(w2.subs(values))
    assert w1.is_positive and sp.sqrt(w1**2) == w1


def test_example3_verifies(example3_solution):
    assert example3_solution.verify()


def test_named_quantities_are_constants_in_time_and_differentiate_by_definition():
    k, m = sp.symbols("k m", positive=True)
    w = named("omega", 1, sp.sqrt(k / m), positive=True)
    assert sp.diff(sp.cos(w * ls.t), ls.t) == -w * sp.sin(w * ls.t)
    derivative = sp.diff(w, k).subs({k: 3, m: 2})
    assert abs(sp.N(derivative) - sp.N(1 / (2 * sp.sqrt(6)))) < 1e-15
    assert w.subs(k, 4 * m) == 2
    assert named("omega", 1, sp.Integer(3)) == 3  # numbers need no name


SINGLE_MASS = {"m": "positive", "c": "positive", "k": "positive", "x0": "real", "v0": "real"}


def test_damped_single_mass_is_the_textbook_formula():
    scene = ls.Scene.from_matrices(M=[["m"]], C=[["c"]], K=[["k"]], x0=["x0"], v0=["v0"],
                                   parameters=SINGLE_MASS)
    sol = ls.solve(scene)
    names = {q.name: q for q in sol.definitions}
    gamma, omega = names["gamma_1"], names["omega_1"]
    m, c, k = (sp.Symbol(n, positive=True) for n in "mck")
    assert expand_names(gamma) == c / (2 * m)
    assert sp.simplify(expand_names(omega**2) - (k / m - c**2 / (4 * m**2))) == 0
    assert "underdamped assumed" in omega.meaning  # the regime it states
    x0, v0 = sp.symbols("x0 v0", real=True)
    # x = e^{-γt}(x0 cos ωt + (v0 + γ x0) sin(ωt)/ω)  (any ODE textbook)
    textbook = sp.exp(-gamma * ls.t) * (x0 * sp.cos(omega * ls.t)
                                        + (v0 + gamma * x0) * sp.sin(omega * ls.t) / omega)
    assert sp.simplify(sol.x[0] - textbook) == 0
    assert sp.count_ops(sol.x[0]) <= 25


@pytest.mark.parametrize("values", [
    {"m": "2", "c": "1", "k": "3", "x0": "1", "v0": "-2"},  # underdamped
    {"m": "1", "c": "5", "k": "4", "x0": "0.5", "v0": "1"},  # overdamped: cos(iσt) = cosh σt
])
def test_damped_single_mass_numbers_match_the_reference(values):
    symbolic = ls.Scene.from_matrices(M=[["m"]], C=[["c"]], K=[["k"]], x0=["x0"], v0=["v0"],
                                      parameters=SINGLE_MASS)
    numeric = ls.Scene.from_matrices(M=[[values["m"]]], C=[[values["c"]]], K=[[values["k"]]],
                                     x0=[values["x0"]], v0=[values["v0"]])
    x = ls.solve(symbolic).x[0].subs(numbers_for(symbolic, values))
    got = [[sp.re(v) for v in row] for row in values_at([x], TIMES)]
    assert relative_error(got, reference_motion(numeric, TIMES, dps=40)) < 1e-25


def test_symmetric_pair_gets_distinct_names_in_one_scope():
    scene = ls.Scene.from_components(
        masses={"m1": "m", "m2": "m"},
        springs={"k1": ("wall", "m1", "k"), "k2": ("m1", "m2", "K"), "k3": ("m2", "wall", "k")},
        x0=[1, 0], v0=[0, 0], parameters=["m", "k", "K"])
    R = ls.resolvent(scene)
    terms = solution_terms(decompose(list(R.numerators), R.determinant))
    x = [terms_expr(list(row), ls.t) for row in terms]
    names = sorted(q.name for q in set().union(*(e.atoms(NamedQuantity) for e in x)))
    assert names == ["omega_1", "omega_2"]
    values = dict(zip(sorted(scene.free_symbols, key=str), (3, 2, 5)))
    numeric = ls.Scene.from_components(
        masses={"m1": 5, "m2": 5},
        springs={"k1": ("wall", "m1", 2), "k2": ("m1", "m2", 3), "k3": ("m2", "wall", 2)},
        x0=[1, 0], v0=[0, 0])
    assert sorted(s.name for s in values) == ["K", "k", "m"]
    got = values_at([e.subs(values) for e in x], TIMES)
    assert relative_error(got, reference_motion(numeric, TIMES, dps=40)) < 1e-25


def test_numeric_scenes_have_no_definitions():
    sol = ls.solve(ls.load_scene("wall-pair"))
    assert sol.definitions == {}
    assert not any(e.atoms(NamedQuantity) for e in sol.x)  # nothing to define
    assert sol.substituted() == sol.x
