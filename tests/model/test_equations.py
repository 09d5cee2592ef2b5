"""Scene.from_equations: equations of motion in three notations, checked against the
bundled seed scenes, SymPy's dsolve (an independent route) and hand-written matrices."""

from __future__ import annotations

import subprocess
import sys

import mpmath
import pytest
import sympy as sp

import laplace_springs as ls
from laplace_springs.model.equations import read_equations

t = ls.t

# The seed's five examples written as their equations (shared/seed: the page's displayed
# equations and Mathematica code), with the misprints corrected as DESIGN.md lists and
# each bundled scene file says: Example 2 has delta2 = 0.1 (the normalised damping
# B = 0.2 I on m2 = 1/2; the page writes delta1 twice), Example 3 couples through -k2*x1
# (the page writes -k3*x1), Example 4 names the right spring k3, Example 5 has -mu2 in
# both equations (its Mathematica code writes +mu2*y' and -mu1*x'). Each in a different
# notation: primes, SymPy's Derivative/.diff, Mathematica's brackets and ==.
SEED = {
    "vertical-pair": """
        # Example 1: m1 x1'' = -k1 x1 - k2 (x1 - x2), m2 x2'' = -k2 (x2 - x1)
        m1 = 1; m2 = 1/2; k1 = 2; k2 = 1
        m1*x1'' = -k1*x1 - k2*(x1 - x2)
        m2*x2'' = -k2*(x2 - x1)
        x1(0) = 1; x2(0) = 0; x1'(0) = 0; x2'(0) = 1
    """,
    "vertical-pair-damped": """
        m1 = 1; m2 = 1/2; k1 = 2; k2 = 1; delta1 = 0.2; delta2 = 0.1
        m1*x1'' = -delta1*x1' - k1*x1 - k2*(x1 - x2)
        m2*x2'' = -delta2*x2' - k2*(x2 - x1)
        x1(0) = 1; x2(0) = 0; x1'(0) = 0; x2'(0) = 0
    """,
    "wall-pair": """
        m1 = 1; m2 = 2/3; k1 = 0.3; k2 = 0.08; k3 = 0.2
        d1 = -0.08; d2 = 0.4; v1 = 0.15; v2 = -0.3
        m1*Derivative(x1(t), t, 2) + (k1 + k2)*x1(t) - k2*x2(t) = 0
        m2*x2(t).diff(t, 2) + (k2 + k3)*x2(t) - k2*x1(t) = 0
        x1(0) = d1; x2(0) = d2; x1'(0) = v1; x2'(0) = v2
    """,
    "wall-pair-dashpot": """
        m1 = 1; m2 = 2; k1 = 1; k3 = 2; b = 0.5; delta = 0.1
        m1*x1'' + delta*x1' + k1*x1 + b*(x1' - x2') = 0
        m2*x2'' + delta*x2' + b*(x2' - x1') + k3*x2 = 0
        x1(0) = 0.1; x2(0) = 0.3; x1'(0) = 0.2; x2'(0) = -0.5
    """,
    "three-dashpots": r"""
        (* the seed's Mathematica input, Example 5 *)
        \[Mu]1 = 0.5; \[Mu]2 = 1.4; \[Mu]3 = 0.9; k1 = 400; k2 = 379; k3 = 100; m1 = 1; m2 = 0.8;
        d1 = 0.05; d2 = 0.07; v1 = 3; v2 = 2;
        eqn1 = m1*x''[t] + (\[Mu]1 + \[Mu]2)*x'[t] - \[Mu]2*y'[t] + (k1 + k2)*x[t] - k2*y[t] == 0;
        eqn2 = m2*y''[t] - \[Mu]2*x'[t] + (\[Mu]2 + \[Mu]3)*y'[t] - k2*x[t] + (k2 + k3)*y[t] == 0;
        {x[0] == d1, y[0] == d2, x'[0] == v1, y'[0] == v2}
    """,
}


@pytest.mark.parametrize("name", sorted(SEED))
def test_the_seed_examples_as_equations_are_the_bundled_scenes(name):
    scene = ls.Scene.from_equations(SEED[name])
    bundled = ls.load_scene(name)
    for field in ("M", "C", "K", "x0", "v0"):
        assert getattr(scene, field) == getattr(bundled, field), field
    assert scene.forcing is None and scene.parameters == ()


def test_the_bundled_scenes_are_the_ones_the_cli_lists():
    listed = subprocess.run([sys.executable, "-m", "laplace_springs", "scenes"], capture_output=True,
                            text=True, check=True).stdout
    assert all(name in listed for name in SEED)


def test_example_2_in_the_seeds_normalised_form_gives_the_same_motion():
    # the seed's transformed system: x'' + B x' + A x = 0, B = 0.2 I, A = [[3, -1], [-2, 2]]
    scene = ls.Scene.from_equations("""
        x1'' + 0.2*x1' + 3*x1 - x2 = 0
        x2'' + 0.2*x2' - 2*x1 + 2*x2 = 0
        x1(0) = 1; x2(0) = 0; x1'(0) = 0; x2'(0) = 0""")
    bundled = ls.load_scene("vertical-pair-damped")
    assert scene.normalized() == bundled.normalized()
    times = [0.5, 3, 11]
    assert ls.solve(scene).evaluate(times) == pytest.approx(ls.solve(bundled).evaluate(times), abs=1e-13)


def test_example_2_with_newtons_dots_gives_the_bundled_scene():
    """The seed's ẍ + Bẋ + Ax = 0 as people write it: dots (precomposed ẍ and ẋ, or a letter
    with a combining mark) read as primes, on names with digits too."""
    scene = ls.Scene.from_equations("""
        ẍ1 + 0.2*ẋ1 + 3*x1 - x2 = 0
        x\u0308\u0032 + 0.2*x\u0307\u0032 - 2*x1 + 2*x2 = 0
        x1(0) = 1; x2(0) = 0; ẋ1(0) = 0; ẋ2(0) = 0""")
    assert scene.normalized() == ls.load_scene("vertical-pair-damped").normalized()
    symbolic = ls.Scene.from_equations("ẍ + B*ẋ + A*x = 0", x0=[1], v0=[0],
                                       parameters=["A", "B"])
    A, B = sp.symbols("A B", positive=True)
    assert sp.Matrix([[1]]) == symbolic.M
    assert sp.Matrix([[B]]) == symbolic.C
    assert sp.Matrix([[A]]) == symbolic.K


def test_a_dot_inside_a_name_asks_for_the_product():
    with pytest.raises(ls.SceneError, match=r"a product needs '\*', e.g. B\*ẋ"):
        ls.Scene.from_equations("ẍ + Bẋ + A*x = 0", x0=[1], v0=[0], parameters=["A", "B"])


def test_sympy_objects_with_plain_symbols():
    time = sp.Symbol("t")  # a plain t, as SymPy users write it
    x, y = sp.Function("x"), sp.Function("y")
    m, k = sp.symbols("m k")
    equations = [sp.Eq(m * x(time).diff(time, 2) + 2 * k * x(time) - k * y(time), 0),
                 sp.Eq(sp.Derivative(y(time), (time, 2)) * m - k * x(time) + 2 * k * y(time), sp.cos(time)),
                 sp.Eq(x(0), 1), sp.Eq(y(0), 0), sp.Eq(sp.Subs(sp.Derivative(x(time), time), time, 0), 0),
                 sp.Eq(y(time).diff(time).subs(time, 0), 2)]
    scene = ls.Scene.from_equations(equations)
    assert scene.names == ("x", "y")
    assert sp.Matrix([[m, 0], [0, m]]) == scene.M
    assert sp.Matrix([[2 * k, -k], [-k, 2 * k]]) == scene.K
    assert list(scene.x0) == [1, 0] and list(scene.v0) == [0, 2]
    assert list(scene.forcing) == [0, sp.cos(t)]
    assert set(scene.parameters) == {m, k}


def test_mixed_text_and_sympy_and_separate_initial_data():
    x = sp.Function("x")
    scene = ls.Scene.from_equations(["x'' + 4*x = 0", sp.Eq(x(0), sp.Rational(1, 3))], v0=[5])
    assert scene.x0[0] == sp.Rational(1, 3) and scene.v0[0] == 5


def test_a_driven_mass_against_dsolve():
    """x'' + x'/2 + 4x = 10 cos(3t) + t, x(0) = 1, x'(0) = -1: the scene read from
    the text and solved exactly, against SymPy's dsolve of the same equation (independent)."""
    scene = ls.Scene.from_equations("""
        x'' + x'/2 + 4*x = 10*cos(3*t) + t
        x(0) = 1; x'(0) = -1""")
    assert scene.M[0] == 1 and scene.C[0] == sp.Rational(1, 2) and scene.K[0] == 4
    assert scene.forcing[0] == 10 * sp.cos(3 * t) + t
    s = sp.Symbol("s")
    x = sp.Function("x")
    reference = sp.dsolve(sp.Eq(x(s).diff(s, 2) + x(s).diff(s) / 2 + 4 * x(s), 10 * sp.cos(3 * s) + s), x(s),
                          ics={x(0): 1, x(s).diff(s).subs(s, 0): -1}).rhs
    values = ls.solve(scene).evaluate([0.3, 2, 7.5])[0]
    for time, value in zip([0.3, 2, 7.5], values):
        with mpmath.workdps(30):
            expected = float(sp.N(reference.subs(s, sp.Rational(str(time))), 30))
        assert value == pytest.approx(expected, rel=1e-12, abs=1e-13)


def test_rows_follow_the_coordinates_and_signs_are_normalised():
    scene = ls.Scene.from_equations("""
        -2*x2'' = 3*x2 - x1          # the equation of x2 first, with a negative mass term
        x1'' + 4*x1 - x2 = 0
        x1(0) = 1; x1'(0) = 0; x2(0) = 0; x2'(0) = 0""")
    assert scene.names == ("x2", "x1")
    assert sp.Matrix([[2, 0], [0, 1]]) == scene.M
    assert sp.Matrix([[3, -1], [-1, 4]]) == scene.K
    ordered = ls.Scene.from_equations("""
        -2*x2'' = 3*x2 - x1
        x1'' + 4*x1 - x2 = 0
        x1(0) = 1; x1'(0) = 0; x2(0) = 0; x2'(0) = 0""", coordinates=["x1", "x2"])
    assert ordered.names == ("x1", "x2")
    assert sp.Matrix([[4, -1], [-1, 3]]) == ordered.K


def test_declared_parameters_values_and_the_declaration_line():
    scene = ls.Scene.from_equations("m*x'' + k*x = F0*Heaviside(t - 1); x(0) = 0; x'(0) = 0",
                                    parameters=["m", "k", "F0"])
    assert [p.name for p in scene.parameters] == ["F0", "k", "m"]
    assert all(p.is_positive for p in scene.parameters)
    again = ls.Scene.from_equations("parameters: m, k, F0\nm*x'' + k*x = F0*Heaviside(t - 1)\nx(0) = 0\nx'(0) = 0")
    assert again.M == scene.M and again.forcing == scene.forcing
    valued = ls.Scene.from_equations("k = 4; m = 1/2\nm*x'' + k*x = 0\nx(0) = 1\nx'(0) = 0")
    assert valued.K[0] == 4 and valued.M[0] == sp.Rational(1, 2) and valued.parameters == ()


def test_a_massless_coordinate_needs_no_velocity():
    scene = ls.Scene.from_equations("""
        x1'' + 2*x1 - x2 = 0
        c*x2' + x2 - x1 = 0
        x1(0) = 1; x1'(0) = 0; x2(0) = 0""", parameters=["c"])
    assert sp.Matrix([[1, 0], [0, 0]]) == scene.M
    assert list(scene.v0) == [0, 0]


@pytest.mark.parametrize(("text", "match"), [
    ("x1'' + x1**2 = 0; x1(0) = 1; x1'(0) = 0", r"the term x1\*\*2 is not linear"),
    ("x1'' + sin(x1) = 0; x1(0) = 1; x1'(0) = 0", r"the term sin\(x1\) is not linear"),
    ("x1'' + x1*x2 = 0; x2'' + x2 = 0; x1(0) = 1; x1'(0) = 0; x2(0) = 0; x2'(0) = 0",
     r"the term x1\*x2 is not linear"),
    ("x1'' + t*x1 = 0; x1(0) = 1; x1'(0) = 0", r"the coefficient t of x1 depends on t"),
    ("x1''' + x1 = 0; x1(0) = 1; x1'(0) = 0", r"x1''' is a derivative of order 3"),
    ("Derivative(x1(t), t, 3) + x1 = 0; x1(0) = 1; x1'(0) = 0", r"x1''' is a derivative of order 3"),
    ("x1'' + x1 - x2 = 0; x1(0) = 1; x1'(0) = 0; x2(0) = 0; x2'(0) = 0", r"x2 has no equation"),
    ("x1'' + x1 = 0; x1'' + 2*x1 = 0; x1(0) = 1; x1'(0) = 0", r"2 equations of motion for 1 coordinates"),
    ("x1'' + x1 = 0; x1(0) = 1", r"missing initial condition x1'\(0\)"),
    ("x1'' + x1 = 0; x1'(0) = 1", r"missing initial condition x1\(0\)"),
    ("x1'' + x1 = 0; x1(0) = 1; x1(0) = 2; x1'(0) = 0", r"x1\(0\) is given twice"),
    ("x1'' + x1 = 0; x1(0) = 1; x1'(0) = 0; x1''(0) = 0", r"x1''\(0\) is not an initial condition"),
    ("x1'' + k*x1 = 0; x1(0) = 1; x1'(0) = 0", r"unknown name 'k'"),
    ("x1'' + x1(2*t) = 0; x1(0) = 1; x1'(0) = 0", r"x1\(2\*t\): write the unknown as x1"),
    ("x1'' + x1 = 0 = 1; x1(0) = 1; x1'(0) = 0", r"expected one '=' \(or '=='\), found 2"),
    ("x1'' + x1; x1(0) = 1; x1'(0) = 0", r"expected one '='"),
    ("x1'' + x1 = 0; x1(0) + x1'(0) = 1", r"write it as x1\(0\) = value"),
    ("x1'' + x1 = 1/(t + 1); x1(0) = 1; x1'(0) = 0", r"1/\(t \+ 1\) is not supported"),
    ("x1'' + x1 = 0; x1(0) = __import__('os'); x1'(0) = 0", r"unexpected character '_'"),
    ("x1'' + x1 = 0; x1(0) = 1; x1'(0) = 0; x1(t).foo(t) = 0", r"expected a method after '.'"),
    ("x1'' + x1 = 0; x1(0) = 1; x1'(0) = 0; 2 = 2", r"has no unknown function"),
    ("x1'' + x1 = 0; x1(0) = 1; x1'(0) = 0; x1'' + x1(0) = 0", r"mixes the unknowns and their initial"),
    ("x1'''''''''' = 0", r"a derivative of order 10"),
])
def test_refusals_name_the_statement_and_the_reason(text, match):
    with pytest.raises(ls.SceneError, match=match):
        ls.Scene.from_equations(text)


def test_refusals_of_sympy_input():
    time = sp.Symbol("t")
    x = sp.Function("x")
    with pytest.raises(ls.SceneError, match=r"not linear"):
        ls.Scene.from_equations([sp.Eq(x(time).diff(time, 2) + sp.sin(x(time)), 0), sp.Eq(x(0), 1),
                                 sp.Eq(x(time).diff(time).subs(time, 0), 0)])
    with pytest.raises(ls.SceneError, match=r"x\(t - 1\) is not an unknown function of t"):
        ls.Scene.from_equations([sp.Eq(x(time).diff(time, 2) + x(time - 1), 0)])
    with pytest.raises(ls.SceneError, match=r"expected an Eq"):
        ls.Scene.from_equations([sp.Eq(time, time)])
    with pytest.raises(ls.SceneError, match=r"expected text or SymPy Eq"):
        ls.Scene.from_equations([3.5])


def test_too_many_coordinates_is_a_limit(set_limits):
    set_limits(max_matrix_input_size=2)
    text = "; ".join(f"x{i}'' + x{i} = 0; x{i}(0) = 0; x{i}'(0) = 0" for i in range(3))
    with pytest.raises(ls.LimitError, match="Limits.max_matrix_input_size"):
        ls.Scene.from_equations(text)


def test_read_equations_gives_the_matrices_and_the_forces():
    system = read_equations("x1'' + 2*x1' + 5*x1 - x2 = 3 + exp(-t); x2'' + x2 - x1 = 0;"
                            "x1(0) = 0; x1'(0) = 0; x2(0) = 0; x2'(0) = 0")
    assert system.C == [[2, 0], [0, 0]] and system.K == [[5, -1], [-1, 1]]
    assert system.forcing == [3 + sp.exp(-t), 0]


TOML = """
title = "A driven pair from its equations"
[parameters]
k = "stiffness"
[equations]
motion = [
    "x1'' + 2*k*x1 - k*x2 = cos(t)",
    "x2'' - k*x1 + 2*k*x2 = 0",
    "x1(0) = 0; x2(0) = 0",
]
coordinates = ["x1", "x2"]
[initial]
v0 = ["1/2", 0]
"""


def test_the_equations_form_of_scene_files(tmp_path):
    path = tmp_path / "pair.toml"
    path.write_text(TOML)
    scene = ls.load_scene(path)
    k = sp.Symbol("k", positive=True)
    assert scene.title == "A driven pair from its equations"
    assert sp.Matrix([[2 * k, -k], [-k, 2 * k]]) == scene.K
    assert list(scene.v0) == [sp.Rational(1, 2), 0] and scene.forcing[0] == sp.cos(t)
    with pytest.raises(ls.SceneError, match=r"\[forcing\] does not belong with \[equations\]"):
        ls.model.scene_files.scene_from_toml_text(TOML + "[forcing]\nx1 = 1\n")
    with pytest.raises(ls.SceneError, match=r"unknown key 'motions' in \[equations\]"):
        ls.model.scene_files.scene_from_toml_text('[equations]\nmotions = "x = 0"\n')


def test_the_command_line_reads_equations(tmp_path):
    path = tmp_path / "eqs.txt"
    path.write_text("# one mass at resonance\nx'' + c*x' + k*x = cos(2*t)\nx(0) = 1\nx'(0) = 0\n")
    run = subprocess.run([sys.executable, "-m", "laplace_springs", "solve", "--equations", str(path),
                          "--param", "k=4", "--param", "c=1/2", "--at", "0,1"],
                         capture_output=True, text=True, check=False)
    assert run.returncode == 0, run.stderr
    # x = e^{-t/4}(cos(3√7 t/4) - √7 sin(3√7 t/4)/3) + sin 2t (the steady state at resonance by hand)
    value = mpmath.exp(-0.25) * (mpmath.cos(3 * mpmath.sqrt(7) / 4) - mpmath.sqrt(7) * mpmath.sin(
        3 * mpmath.sqrt(7) / 4) / 3) + mpmath.sin(2)
    assert f"{float(value):.10f}"[:10] in run.stdout
    bad = subprocess.run([sys.executable, "-m", "laplace_springs", "solve", "--equations", str(path)],
                         capture_output=True, text=True, check=False)
    assert bad.returncode == 2 and "unknown name 'c'" in bad.stderr and "parameters: k, c" in bad.stderr


def test_a_plain_symbol_switching_time_in_scene_forcing_states_its_condition():
    time, b = sp.Symbol("t"), sp.Symbol("b")  # b plain: a step at b is a delay where b >= 0
    x = sp.Function("x")
    scene = ls.Scene.from_equations([sp.Eq(x(time).diff(time, 2) + 4 * x(time), sp.Heaviside(time - b)),
                                     sp.Eq(x(0), 0), sp.Eq(x(time).diff(time).subs(time, 0), 0)])
    solution = ls.solve(scene)
    (condition,) = solution.conditions
    assert condition.as_relational() == sp.Ge(b, 0) and r"b \geq 0" in solution.latex()
    # the step response of x'' + 4x: (1 - cos 2(t - b))/4 for t > b (any table)
    value = solution.x[0].subs({b: sp.Rational(1, 2), t: 2})
    assert sp.simplify(value - (1 - sp.cos(3)) / 4) == 0
    declared = ls.solve(ls.Scene.from_equations("x'' + 4*x = Heaviside(t - b); x(0) = 0; x'(0) = 0",
                                                parameters=["b"]))
    assert declared.conditions == ()


SEED_EXAMPLE_5_PROGRAM = (  # the seed page's Mathematica input for Example 5, as printed
    r"ClearAll; (*units of N, N/m, m, kg, m/s*) \[Mu]1 = 0.5; \[Mu]2 = 1.4; \[Mu]3 = 0.9; k1 = 400; "
    r"k2 = 379; k3 = 100; m1 = 1; m2 = 0.8; d1 = 0.05; d2 = 0.07; v1 = 3; v2 = 2; eqn1 = "
    r"m1*x''[t] + (\[Mu]1 + \[Mu]2)*x'[t] + \[Mu]2*y'[t] + (k1 + k2)* x[t] - k2*y[t] == 0; eqn2 = "
    r"m2*y''[t] - \[Mu]1*x'[t] + (\[Mu]2 + \[Mu]3)*y'[t] - k2*x[t] + (k2 + k3)*y[t] == 0; eqns = "
    r"{eqn1, eqn2, x[0] == d1, y[0] == d2, x'[0] == v1, y'[0] == v2}; sol = DSolve[eqns, {x[t], y[t]}, t];")


def test_the_seeds_mathematica_program_reads_as_printed():
    # as printed (its two sign misprints: +mu2*y' and -mu1*x'), the damping is not the physics'
    printed = ls.Scene.from_equations(SEED_EXAMPLE_5_PROGRAM)
    misprinted = sp.Matrix([[sp.Rational(19, 10), sp.Rational(7, 5)], [-sp.Rational(1, 2), sp.Rational(23, 10)]])
    assert misprinted == printed.C
    corrected = SEED_EXAMPLE_5_PROGRAM.replace(r"+ \[Mu]2*y'[t]", r"- \[Mu]2*y'[t]").replace(
        r"- \[Mu]1*x'[t]", r"- \[Mu]2*x'[t]")
    scene, bundled = ls.Scene.from_equations(corrected), ls.load_scene("three-dashpots")
    for field in ("M", "C", "K", "x0", "v0"):
        assert getattr(scene, field) == getattr(bundled, field), field
