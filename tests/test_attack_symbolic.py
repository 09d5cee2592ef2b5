"""Symbolic scenes attacked through the public API (helper "attack-sym"), each against an
independent reference: mpmath's matrix exponential of the first-order system at 40 digits."""

from __future__ import annotations

import mpmath
import numpy as np
import pytest
import sympy as sp

import laplace_springs as ls
from laplace_springs.exact.named import named_quantities
from laplace_springs.output.named_terms import NamedTerms

TIMES = [0.0, 0.5, 1.0, 3.0, 10.0]


def _reference(scene: ls.Scene, times: list[float]) -> np.ndarray:
    """x(t) = [I 0] expm(A t) [x0; v0] at 40 digits, A the first-order matrix of a numeric scene."""
    n = scene.n
    with mpmath.workdps(40):
        def number(value: sp.Expr) -> mpmath.mpf:
            return mpmath.mpf(str(sp.N(value, 50)))

        inverse = scene.M.inv()
        stiffness, damping = -inverse * scene.K, -inverse * scene.C
        A = mpmath.zeros(2 * n, 2 * n)
        for i in range(n):
            A[i, n + i] = 1
            for j in range(n):
                A[n + i, j], A[n + i, n + j] = number(stiffness[i, j]), number(damping[i, j])
        y0 = mpmath.matrix([number(v) for v in [*scene.x0, *scene.v0]])
        return np.array([[float((mpmath.expm(A * mpmath.mpf(str(t))) * y0)[i]) for t in times]
                         for i in range(n)])


def _printed_names(solution) -> set[str]:
    return {str(q) for q in named_quantities(list(solution.x))}


@pytest.mark.parametrize("matrices, values", [
    ({"M": [[1]], "K": [[sp.Symbol("omega_1")]]}, {"omega_1": 4}),
    ({"M": [[1]], "C": [[sp.Symbol("gamma_1")]], "K": [[4]]}, {"gamma_1": "0.3"}),
    ({"M": [[1]], "C": [[sp.Symbol("gamma_1")]], "K": [[sp.Symbol("omega_1")]]}, {"gamma_1": 1, "omega_1": 3}),
    ({"M": [[1, 0], [0, 1]], "K": [[sp.Symbol("S_1") + sp.Symbol("P_1"), -sp.Symbol("P_1")],
                                  [-sp.Symbol("P_1"), sp.Symbol("omega_1") + sp.Symbol("P_1")]]},
     {"S_1": 1, "P_1": 2, "omega_1": 3}),
])
def test_named_quantities_avoid_the_names_of_parameters(matrices, values):
    """A parameter called omega_1 (gamma_1, S_1, P_1) was shown next to a different ω₁:
    x = cos(t ω₁) "where ω₁ = √ω₁". The named quantities now skip the scene's names."""
    n = len(matrices["M"])
    scene = ls.Scene.from_matrices(**matrices, x0=[1] + [0] * (n - 1), v0=[0] * (n - 1) + [1])
    solution = ls.solve(scene)
    parameters = {symbol.name for symbol in scene.parameters}
    assert not _printed_names(solution) & parameters
    for name, definition in solution.definitions.items():
        assert str(name) not in {symbol.name for symbol in definition.free_symbols}
    assert solution.verify()
    numeric = solution.subs(values).evaluate(TIMES)
    reference = _reference(scene.subs(values), TIMES)
    assert np.max(np.abs(numeric - reference)) <= 1e-13 * max(1.0, np.max(np.abs(reference)))


def test_named_quantities_avoid_parameter_names_in_forced_scenes():
    """The forced route numbers its names in the same reserved scope."""
    w1, w2, g1 = sp.symbols("omega_1 omega_2 gamma_1")
    scene = ls.Scene.from_matrices(M=[[1]], C=[[g1]], K=[[w1]], x0=[1], v0=[0],
                                   forcing=[sp.cos(w2 * ls.t)])
    solution = ls.solve(scene)
    assert not _printed_names(solution) & {"omega_1", "omega_2", "gamma_1"}
    assert "\\omega_{1} &= " not in solution.latex()


@pytest.mark.parametrize("second, parameters, words", [
    (sp.Symbol("k", positive=True), None, ["Symbol('k')", "Symbol('k', positive=True)"]),
    ("k", ["k"], ["Symbol('k', positive=True) (declared in parameters)", "Symbol('k') (a Symbol",
                  "positive unless"]),
])
def test_two_symbols_of_one_name_are_shown_briefly(second, parameters, words):
    """The error listed both Symbols' 20-key assumptions0 dicts; it now shows each as it was made."""
    with pytest.raises(ls.SceneError) as error:
        ls.Scene.from_matrices(M=[[1, 0], [0, 1]], K=[[sp.Symbol("k"), 0], [0, second]],
                               x0=[1, 0], v0=[0, 0], parameters=parameters)
    message = str(error.value)
    assert "extended_real" not in message and len(message) < 300
    for word in words:
        assert word in message


@pytest.mark.parametrize("values, fragment", [
    ([1, 1j], "sweep: value 1 of parameter 'k': expected a number, got 1j"),
    ([1, "abc"], "sweep: value 1 of parameter 'k': expected a number, got 'abc'"),
    ([1, "2/3", sp.I], "sweep: value 2 of parameter 'k': expected a real number, got I"),
])
def test_sweep_names_the_bad_value(values, fragment):
    """A complex array was reported by its first value ("got (1+0j)"), text by no index."""
    k = sp.Symbol("k")
    scene = ls.Scene.from_matrices(M=[[1]], K=[[k]], x0=[1], v0=[0])
    with pytest.raises(ls.SceneError) as error:
        ls.sweep(scene, {k: values}, [0.0, 1.0])
    assert fragment in str(error.value)


@pytest.mark.parametrize("K, fragment", [
    ([[0, 1], [0, 0]], "the scene is not classical (needs symmetric M, C, K"),
    ([[-1]], "a negative modal stiffness"),
    ([[0]], "a zero frequency (rigid-body motion)"),
])
def test_classical_refusals_say_why(K, fragment):
    """An undamped scene with a nonsymmetric K was refused for "the damping is not
    classical"; x'' − x = 0 for "a zero frequency (rigid-body motion)"."""
    n = len(K)
    scene = ls.Scene.from_matrices(M=np.eye(n, dtype=int).tolist(), K=K, x0=[1] * n, v0=[0] * n)
    with pytest.raises(ls.SceneError) as error:
        ls.solve(scene, method="classical")
    assert fragment in str(error.value)
    reference = _reference(scene, TIMES)   # and the way out the message names serves it
    values = ls.solve(scene).evaluate(TIMES)
    assert np.max(np.abs(values - reference)) <= 1e-13 * np.max(np.abs(reference))


@pytest.mark.parametrize("assumptions", [{}, {"positive": True}])
def test_modes_of_a_symbolic_damped_scene(assumptions):
    """ls.modes of m x'' + c x' + k x gave ω_n through re(), im() and atan2 of the
    parameters (plain Symbols) or cos(atan2(0, c² − 4km)/2) (positive ones), and printing
    the mode raised TypeError. Now √(k/m) and c/(2√(km)) (underdamped assumed), checked
    against numpy's roots of the substituted quadratics."""
    m, c, k = sp.symbols("m c k", **assumptions)
    scene = ls.Scene.from_matrices(M=[[m, 0], [0, m]], C=[[c, 0], [0, c]],
                                   K=[[2 * k, -k], [-k, 2 * k]], x0=[1, 0], v0=[0, 0])
    modes = ls.modes(scene)
    assert "Mode(ω_n=" in repr(modes) and "re(" not in repr(modes)
    values = {m: sp.Rational(3, 2), c: sp.Rational(1, 5), k: 2}
    for mode, mu in zip(modes, (1, 3)):   # K/k has eigenvalues 1 and 3
        root = max(np.roots([1.5, 0.2, 2.0 * mu]), key=lambda z: z.imag)
        assert float(mode.natural_frequency.subs(values)) == pytest.approx(abs(root), rel=1e-14)
        assert float(mode.damping_ratio.subs(values)) == pytest.approx(-root.real / abs(root), rel=1e-14)
        assert float(mode.damped_frequency.subs(values)) == pytest.approx(root.imag, rel=1e-14)
        assert complex(mode.eigenvalue.subs(values)) == pytest.approx(root, rel=1e-14)


def test_poles_of_a_symbolic_solution_name_the_parameters():
    """sol.poles raised mpmath's "cannot create mpf from -gamma_1"; after subs they are
    the roots of m λ² + c λ + k (numpy's, independently)."""
    m, c, k = sp.symbols("m c k")
    solution = ls.solve(ls.Scene.from_matrices(M=[[m]], C=[[c]], K=[[k]], x0=[1], v0=[0]))
    with pytest.raises(ls.SceneError, match="poles need numbers, but the scene has the parameters c, k, m"):
        solution.poles
    poles = solution.subs({m: 2, c: 1, k: 3}).poles
    assert sorted(poles, key=lambda z: z.imag) == pytest.approx(
        sorted(np.roots([2, 1, 3]), key=lambda z: z.imag), rel=1e-15)


@pytest.mark.parametrize("name", ["c_1", "alpha_1", "r_1"])
def test_algebraic_constants_avoid_the_names_of_parameters(name):
    """x0 = [c_1, 0, 0] on a chain whose Δ(λ) has an irreducible sextic: the output named
    its coefficients c_1, c_2, ... too and printed "(c_1 c_1 + c_2) cos(β₁ t)"."""
    p = sp.Symbol(name)
    scene = ls.Scene.from_matrices(M=[[1, 0, 0], [0, 2, 0], [0, 0, 3]],
                                   C=[["1/10", 0, 0], [0, 0, 0], [0, 0, 0]],
                                   K=[[2, -1, 0], [-1, 2, -1], [0, -1, 1]], x0=[p, 0, 0], v0=[0, 0, 1])
    solution = ls.solve(scene)
    terms = NamedTerms()
    terms.prepare(list(solution.x))
    assert name not in {str(symbol) for symbol in terms.constants.values}
    latex = solution.latex()
    assert f"{sp.latex(p)} &=" not in latex and f"{sp.latex(p)} {sp.latex(p)}" not in latex
    values = solution.subs({name: 2}).evaluate(TIMES)
    reference = _reference(scene.subs({name: 2}), TIMES)
    assert np.max(np.abs(values - reference)) <= 1e-13 * np.max(np.abs(reference))


@pytest.mark.parametrize("name, meaning", [
    ("J", "the imaginary unit"), ("sin", "the function sin(...)"), ("pi", "the constant pi"),
    ("inf", "a number that is not finite"),
])
def test_refused_parameter_names_say_what_they_mean(name, meaning):
    """'J' (an impulse, a moment of inertia) was refused as "a function, a constant or a
    number that is not finite and real", without saying which, nor the way out."""
    for parameters, K in (([name], [[name]]), (None, [[sp.Symbol(name)]])):
        with pytest.raises(ls.SceneError) as error:
            ls.Scene.from_matrices(M=[[1]], K=K, x0=[1], v0=[0], parameters=parameters)
        assert f"'{name}' cannot be a parameter name: in text it is {meaning}" in str(error.value)
        assert f"e.g. '{name}_0'" in str(error.value)
    scene = ls.Scene.from_matrices(M=[[1]], K=[[f"{name}_0"]], x0=[1], v0=[0], parameters=[f"{name}_0"])
    assert ls.solve(scene.subs({f"{name}_0": 4})).x[0] == sp.cos(2 * ls.t)


def _unit_step_response(t: float) -> float:
    """x'' + x' + x = θ(t) from rest, written out (ω = √3/2)."""
    if t <= 0:
        return 0.0
    w = mpmath.sqrt(3) / 2
    return float(1 - mpmath.exp(-t / 2) * (mpmath.cos(w * t) + mpmath.sin(w * t) / (2 * w)))


@pytest.mark.parametrize("tau", [sp.Symbol("tau"), sp.Symbol("tau", positive=True)])
def test_helpers_take_a_symbolic_switching_time(tau):
    """ls.step(1, at=tau) was refused ("at must be a number >= 0") while the same input as
    text, "Heaviside(t - tau)" with tau declared, was served."""
    scene = ls.Scene.from_matrices(M=[[1]], C=[[1]], K=[[1]], x0=[0], v0=[0],
                                   forcing=[ls.step(1, at=tau)])
    times = [0.5, 1.5, 3.0]
    for value, values in ((1, ls.solve(scene).subs({tau: 1}).evaluate(times)[0]),
                          (2, ls.sweep(scene, {tau: [2]}, times)[0, 0])):
        assert values == pytest.approx([_unit_step_response(t - value) for t in times], abs=1e-15)
    with pytest.raises(ls.SceneError, match="at must be a number >= 0 or a parameter, got -1"):
        ls.step(1, at=-1)
    with pytest.raises(ls.SceneError, match="at must be a number >= 0 or a parameter"):
        ls.impulse(1, at=sp.Symbol("a", negative=True))
    assert ls.ramp(1, at=tau) == (ls.t - tau) * sp.Heaviside(ls.t - tau)


_R2, _PI = sp.sqrt(2), sp.pi


@pytest.mark.parametrize("matrices", [
    {"M": [[1]], "C": [[2 * _R2]], "K": [[2]]},                       # (λ + √2)²: NotInvertible
    {"M": [[1]], "C": [[2 * sp.sqrt(_PI)]], "K": [[_PI]]},            # (λ + √π)²: x = nan
    {"M": [[1]], "C": [[2 * sp.E]], "K": [[sp.E**2]]},
    {"M": [[1, 0], [0, 1]], "C": [[2 * _R2, 0], [0, 2 * _R2]], "K": [[2, 0], [0, 2]]},   # TypeError
    {"M": [[1, 0], [0, 1]], "C": [[_R2, -_R2], [-_R2, _R2]], "K": [[1, -1], [-1, 1]]},
    {"M": [[1, 0], [0, 1]], "C": [[2 * _R2, 0], [0, 0]], "K": [[2, 0], [0, 0]]},
])
@pytest.mark.parametrize("method", ["auto", "exact", "modal"])
def test_irrational_entries_at_critical_damping(matrices, method):
    """Entries such as √2 or π at a double pole: the exact route raised SymPy's
    NotInvertible (factor_list over EX leaves (λ + √2)² whole), TypeError (adj_det over
    EX, two coordinates) or returned x = nan (ZZ[π, √π] takes √π² for a new unknown);
    the modal route's escalation met the same. Against mpmath's expm at 40 digits."""
    n = len(matrices["M"])
    scene = ls.Scene.from_matrices(**matrices, x0=[1] + [0] * (n - 1), v0=[0] * (n - 1) + [1])
    solution = ls.solve(scene, method=method)
    reference = _reference(scene, TIMES)
    values = solution.evaluate(TIMES)
    assert np.max(np.abs(values - reference)) <= 1e-13 * max(1.0, np.max(np.abs(reference)))
    if method == "exact":
        assert not solution.x.has(sp.nan, sp.zoo) and solution.verify()
