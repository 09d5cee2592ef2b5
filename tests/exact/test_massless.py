"""Massless nodes (zero masses): solved exactly, jumps at t = 0⁺ reported, checked
against an independent route.

The independent route eliminates massless coordinates physically, without any
transform: a node joined only by springs (no dashpot) sits where its springs balance,
x_s = −K_ss⁻¹(K_s· x) (static condensation); a node with dashpots (invertible block
C_dd) obeys the first-order law C_dd x_d' = −(C_d· x' + K_d· x). The state
(massive x, massive v, dashpot-node x) then has an explicit first-order matrix whose
exponential mpmath takes at 40 digits. Its initial state keeps massive positions and
velocities and dashpot-node positions; spring-only nodes start at their balance.
"""

from __future__ import annotations

import mpmath
import numpy as np
import pytest
import sympy as sp
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

import laplace_springs as ls
from laplace_springs.bench.reference import relative_error
from laplace_springs.exact.assembly import ExactMotion
from laplace_springs.exact.jumps import initial_jump, jump_residuals
from laplace_springs.model.errors import SceneError
from laplace_springs.model.scene_files import scene_from_toml_text
from laplace_springs.numeric.mp_expr import numeric_value

TIMES = ["0", "0.25", "1", "3.5", "10"]


# ---------------------------------------------------------------------------
# Independent reference: condensation + first-order matrix exponential
# ---------------------------------------------------------------------------


def _first_order_form(scene):
    """Exact (Z, y0, X, a, r) with y = (x_r, v_a), y' = Z y, y(0⁺) = y0 and x = X y.

    a: massive coordinates; s: massless ones without dashpots (condensed away);
    d: massless ones with dashpots (first-order); r = a + d.
    """
    M, C, K = (sp.Matrix(m) for m in (scene.M, scene.C, scene.K))
    n = scene.n
    a = [i for i in range(n) if M[i, i] != 0]
    b = [i for i in range(n) if M[i, i] == 0]
    s = [i for i in b if all(C[i, j] == 0 and C[j, i] == 0 for j in range(n))]
    d = [i for i in b if i not in s]
    r = a + d

    def sub(A, rows, cols):
        return A.extract(rows, cols) if rows and cols else sp.zeros(len(rows), len(cols))

    condense = -sub(K, s, s).inv() * sub(K, s, r) if s else sp.zeros(0, len(r))
    Kt = sub(K, r, r) + sub(K, r, s) * condense  # Schur complement: springs through s
    na, nd = len(a), len(d)
    # dashpot nodes: C_dd x_d' = -(C_da v_a + K~_d. x_r)
    Cdd_inv = sub(C, d, d).inv() if d else sp.zeros(0, 0)
    Gx, Gv = -Cdd_inv * Kt[na:, :], -Cdd_inv * sub(C, d, a)
    # masses: M_aa v_a' = -(C_aa v_a + C_ad x_d' + K~_a. x_r)
    Minv = sub(M, a, a).inv() if a else sp.zeros(0, 0)
    Hx = -Minv * (Kt[:na, :] + sub(C, a, d) * Gx)
    Hv = -Minv * (sub(C, a, a) + sub(C, a, d) * Gv)
    top = sp.Matrix.hstack(sp.zeros(na, na + nd), sp.eye(na)) if na else sp.zeros(0, na + nd + na)
    Z = sp.Matrix.vstack(top, sp.Matrix.hstack(Gx, Gv), sp.Matrix.hstack(Hx, Hv))
    # rows of Z follow (x_a, x_d, v_a) = (x_r, v_a): top gives x_a', then x_d', then v_a'
    y0 = sp.Matrix([*(scene.x0[i] for i in r), *(scene.v0[i] for i in a)])
    X = sp.zeros(n, len(y0))
    for k, i in enumerate(r):
        X[i, k] = 1
    for k, i in enumerate(s):
        for j in range(len(r)):
            X[i, j] = condense[k, j]
    return Z, y0, X


def condensed_reference(scene, times, dps: int = 40):
    """x(t) of a numeric scene with diagonal M by elimination and an mpmath expm.

    Returns (values, x_plus, v_plus), values of shape (n, len(times)), mpmath numbers.
    """
    Z, y0, X = _first_order_form(scene)

    def to_mp(A):
        return mpmath.matrix([[mpmath.mpf(e.p) / e.q for e in A.row(i)] for i in range(A.rows)])

    with mpmath.workdps(dps):
        values = np.empty((scene.n, len(times)), dtype=object)
        values[:] = mpmath.mpf(0)
        if Z.rows:
            Zm, y0m, Xm = to_mp(Z), to_mp(y0), to_mp(X)
            for col, tv in enumerate(times):
                x = Xm * (mpmath.expm(Zm * mpmath.mpf(tv)) * y0m)
                values[:, col] = [x[i] for i in range(scene.n)]
        x_plus = list(X * y0) if Z.rows else [0] * scene.n
        v_plus = list(X * Z * y0) if Z.rows else [0] * scene.n
        return values, x_plus, v_plus


# ---------------------------------------------------------------------------
# Scenes
# ---------------------------------------------------------------------------


def maxwell_mass(x0=(1, "1/2"), v0=(0, 2)):
    """wall —k— node —c— mass: a mass on a Maxwell element (coordinates: node, mass)."""
    return ls.Scene.from_components(
        masses={"n": 0, "m": 2},
        springs={"k": ("wall", "n", 5)},
        dashpots={"c": ("n", "m", 3)},
        x0=list(x0), v0=list(v0))


def standard_linear_solid(m=1, k1=4, k2=9, c="1/2", x0=(0, 1), v0=(0, 0)):
    """Zener solid: wall —k1— mass, and wall —k2— node —c— mass (coordinates: mass, node)."""
    return ls.Scene.from_components(
        masses={"m": m, "n": 0},
        springs={"k1": ("wall", "m", k1), "k2": ("wall", "n", k2)},
        dashpots={"c": ("n", "m", c)},
        x0=list(x0), v0=list(v0))


def spring_node(x0=(1, 2), v0=(0, 1)):
    """wall —k1 = 3— node —k2 = 2— unit mass: the node is algebraic in the mass."""
    return ls.Scene.from_components(
        masses={"n": 0, "m": 1},
        springs={"k1": ("wall", "n", 3), "k2": ("n", "m", 2)},
        x0=list(x0), v0=list(v0))


def mixed_chain():
    """Two masses, one spring-only node between them, one Maxwell node to the wall."""
    return ls.Scene.from_components(
        masses={"m1": 1, "s": 0, "m2": "3/2", "d": 0},
        springs={"k1": ("wall", "m1", 2), "k2": ("m1", "s", 5), "k3": ("s", "m2", 1),
                 "k4": ("m2", "d", 4), "k5": ("s", "wall", "1/2")},
        dashpots={"c1": ("d", "wall", "3/10"), "c2": ("m1", "wall", "1/10")},
        x0=[1, 7, "-1/2", "1/4"], v0=[0, 3, 1, 5])


def all_massless():
    """Only dashpots and springs (a first-order system), e.g. two Kelvin-Voigt stages."""
    return ls.Scene.from_components(
        masses={"a": 0, "b": 0},
        springs={"k1": ("wall", "a", 2), "k2": ("a", "b", 3)},
        dashpots={"c1": ("wall", "a", 1), "c2": ("a", "b", "1/5")},
        x0=[1, -2], v0=[9, 9])


SCENES = {
    "maxwell-mass": maxwell_mass,
    "standard-linear-solid": standard_linear_solid,
    "spring-node": spring_node,
    "mixed-chain": mixed_chain,
    "all-massless": all_massless,
}


# ---------------------------------------------------------------------------
# Agreement with the independent route
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("name", sorted(SCENES))
def test_motion_matches_condensed_reference(name):
    scene = SCENES[name]()
    sol = ls.solve(scene)
    reference, x_plus, v_plus = condensed_reference(scene, TIMES, dps=40)
    floats = sol.evaluate(TIMES)  # float64 values at the same exact (decimal) times
    assert relative_error(floats, reference) < 1e-13
    assert relative_error(sol.evaluate(TIMES, dps=30), reference) < 1e-28
    jump = sol.initial_jump  # exact on both routes
    assert list(jump.x_plus) == x_plus and list(jump.v_plus) == v_plus
    assert jump.impulses.cols == 0


@pytest.mark.parametrize("name", sorted(SCENES))
def test_verify_passes(name):
    assert ls.solve(SCENES[name]()).verify().ok


def test_verify_rejects_a_wrong_start():
    sol = ls.solve(maxwell_mass())
    # the same closed form claimed for other data of the mass: its position cannot jump
    other = sol.scene.with_initial(x0=[1, 1])
    wrong = ls.ExactSolution(ExactMotion(other, ls.resolvent(other), sol.pieces), reason="wrong on purpose")
    check = wrong.verify()
    assert not check.ok
    assert check.initial_residual > 0.1  # the mass's position is off by 1/2
    assert sol.verify().ok  # while the same closed form is right for its own data


# ---------------------------------------------------------------------------
# Textbook checks
# ---------------------------------------------------------------------------


def test_maxwell_stress_relaxation():
    # Maxwell element held at a fixed total extension: the spring force relaxes as
    # k·u0·e^{-t/τ} with relaxation time τ = c/k (Findley, Lai & Onaran, Creep and
    # Relaxation of Nonlinear Viscoelastic Materials, 1976, §5.2). The node between
    # spring and dashpot obeys k u + c u' = 0.
    scene = ls.Scene.from_components(
        masses={"u": 0}, springs={"k": ("wall", "u", 6)}, dashpots={"c": ("u", "wall", 2)},
        x0=["1/10"], v0=[5])
    sol = ls.solve(scene)
    assert sp.simplify(sol.x[0] - sp.Rational(1, 10) * sp.exp(-3 * ls.t)) == 0
    # the node's velocity is set by the dashpot law, not by v0
    assert sol.initial_jump.v_plus[0] == sp.Rational(-3, 10)
    assert sol.initial_jump.velocity[0] == sp.Rational(-3, 10) - 5


@pytest.mark.parametrize(("k1", "k2", "c", "m"), [(4, 9, "1/2", 1), (0, 5, 3, 2), (1, 1, 10, "1/3")])
def test_standard_linear_solid_characteristic_cubic(k1, k2, c, m):
    # A mass on a standard linear solid (Zener): complex stiffness k1 + k2·cs/(k2 + cs)
    # (R. Lakes, Viscoelastic Materials, 2009, ch. 2), so m s² + k1 + k2 c s/(k2 + c s) = 0,
    # i.e. m c s³ + m k2 s² + c (k1 + k2) s + k1 k2 = 0; k1 = 0 is the mass on a Maxwell
    # element, whose cubic has the root s = 0 (the mass drifts to a new rest position).
    scene = standard_linear_solid(m=m, k1=k1, k2=k2, c=c)
    m, k1, k2, c = (sp.Rational(v) for v in (m, k1, k2, c))
    s = ls.lam
    cubic = sp.Poly(m * c * s**3 + m * k2 * s**2 + c * (k1 + k2) * s + k1 * k2, s)
    assert ls.resolvent(scene).determinant.monic() == cubic.monic()


def test_maxwell_mass_final_rest_position():
    # A mass on a Maxwell element (no spring to ground) creeps to a new rest position.
    # Integrating m x_m'' = -k x_n and k x_n = c (x_m - x_n)' over (0, ∞), with the node
    # continuous (dashpot) and back at 0: m v_m0 = c (x_m(∞) - x_m0 + x_n0), so
    # x_m(∞) = x_m0 - x_n0 + m v_m0 / c = 1/2 - 1 + 2·2/3 = 5/6.
    sol = ls.solve(maxwell_mass(x0=(1, "1/2"), v0=(0, 2)))
    constant = [term for term in sol.terms[1] if term.alpha == 0]
    assert [(term.power, term.a) for term in constant] == [(0, sp.Rational(5, 6))]
    assert not [term for term in sol.terms[0] if term.alpha == 0]  # the node returns to 0


# ---------------------------------------------------------------------------
# Jumps
# ---------------------------------------------------------------------------


def test_spring_node_starts_at_the_balance_of_its_springs():
    # node between wall (k1 = 3) and mass (k2 = 2): 5 x_n = 2 x_m at every t > 0
    sol = ls.solve(spring_node(x0=(1, 2), v0=(0, 1)))
    jump = sol.initial_jump
    assert list(jump.x_plus) == [sp.Rational(4, 5), 2]
    assert list(jump.v_plus) == [sp.Rational(2, 5), 1]
    assert list(jump.position) == [sp.Rational(-1, 5), 0]
    assert not jump.is_continuous
    assert np.allclose(sol.evaluate(0.0)[:, 0], [0.8, 2.0], rtol=0, atol=1e-15)
    assert sp.simplify(5 * sol.x[0] - 2 * sol.x[1]) == 0


def test_maxwell_node_position_is_continuous_and_its_velocity_jumps():
    # node obeys c (x_n' − x_m') = −k x_n: x_n' (0⁺) = v_m0 − k x_n0 / c = 2 − 5/3
    jump = ls.solve(maxwell_mass(x0=(1, "1/2"), v0=(0, 2))).initial_jump
    assert list(jump.position) == [0, 0]
    assert list(jump.velocity) == [sp.Rational(1, 3), 0]


def test_consistent_data_and_positive_masses_do_not_jump():
    assert ls.solve(spring_node(x0=("4/5", 2), v0=("2/5", 1))).initial_jump.is_continuous
    scene = ls.Scene.from_matrices(M=[[1]], C=[[2]], K=[[1]], x0=[1], v0=[3])
    jump = ls.solve(scene).initial_jump
    assert jump.is_continuous and list(jump.x_plus) == [1] and list(jump.v_plus) == [3]


def test_only_springs_and_no_mass_means_rest():
    sol = ls.solve(ls.Scene.from_matrices(M=[[0]], K=[[2]], x0=[1], v0=[3]))
    assert sol.x[0] == 0 and sol.resolvent.determinant.degree() == 0
    assert list(sol.initial_jump.position) == [-1] and sol.verify().ok


def test_impulses_of_an_indefinite_pencil_are_reported():
    # Not a physical scene (C indefinite): x2 = −x1' and x1'' + x2' + x1 = 0 force
    # x1 = x2 = 0 for t > 0, reached through impulses: L[x1] = v1 + x2(0), L[x2] =
    # x1(0) − λ(v1 + x2(0)), i.e. x1 = 5δ, x2 = δ − 5δ'.
    scene = ls.Scene.from_matrices(M=[[1, 0], [0, 0]], C=[[0, 1], [1, 0]], K=[[1, 0], [0, 1]],
                                   x0=[1, 2], v0=[3, 4])
    sol = ls.solve(scene)
    assert sol.initial_jump.impulses == sp.Matrix([[5, 0], [1, -5]])
    assert list(sol.x) == [0, 0]
    assert sol.verify().ok


# ---------------------------------------------------------------------------
# g-basis with deg Δ < 2n
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["maxwell-mass", "spring-node", "standard-linear-solid"])
def test_g_basis_has_degree_delta_functions_and_rebuilds_x(name):
    sol = ls.solve(SCENES[name]())
    D = sol.g_denominator
    d = D.degree()
    assert d < 2 * sol.scene.n and max(sol.g_indices) < d
    # every g_k = L⁻¹[λ^k/D] solves D(d/dt) g = 0 with g^{(j)}(0⁺) = [j = d - 1 - k]/lc(D)
    for k, g in sol.g_basis.items():
        derivatives = [g]
        for _ in range(d):
            derivatives.append(derivatives[-1].diff(ls.t))
        ode = sum(c * derivatives[j] for j, c in enumerate(reversed(D.all_coeffs())))
        assert abs(numeric_value(ode.subs(ls.t, sp.Rational(3, 10)), 40)) < 1e-30
        for j in range(d - k):  # the first d - k derivatives at 0⁺ (λ^k/D ~ λ^{k-d})
            expected = sp.Rational(1, D.LC()) if j == d - 1 - k else 0
            assert abs(numeric_value(derivatives[j].subs(ls.t, 0), 40) - expected) < 1e-30
    # x_i = Σ_k c_ik g_k for t > 0, against the condensed reference (not the code's own x)
    times = ("0.3", "2")
    reference, _, _ = condensed_reference(sol.scene, times, dps=50)
    for i in range(sol.scene.n):
        rebuilt = sum(sol.g_coefficients[i, k] * g for k, g in sol.g_basis.items())
        for col, tv in enumerate(times):
            value = numeric_value(rebuilt.subs(ls.t, sp.Rational(tv)), 40)
            assert abs(value - sp.Float(reference[i, col], 50)) < 1e-30


# ---------------------------------------------------------------------------
# Input: builders, TOML, errors
# ---------------------------------------------------------------------------


def test_toml_accepts_a_massless_node():
    scene = scene_from_toml_text(
        'title = "Maxwell"\n[masses]\nn = 0\nm = 2\n'
        '[springs]\nk = ["wall", "n", 5]\n[dashpots]\nc = ["n", "m", 3]\n'
        '[initial]\nx0 = {n = 1, m = 0.5}\nv0 = {m = 2}\n', source="maxwell.toml")
    assert sp.diag(0, 2) == scene.M
    assert ls.solve(scene).verify().ok


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        ({"masses": {"n": -1, "m": 1}, "springs": {"k": ("n", "m", 1)}},
         r"mass 'n' must be positive, got -1; 0 is allowed for a massless node"),
        ({"masses": {"n": 0, "m": 1}, "springs": {"k": ("m", "wall", 1)}},
         r"pencil .* is singular.*mass 'n' \(coordinate x1\) has zero mass and no spring or dashpot"),
        ({"masses": {"a": 0, "b": 0, "m": 1}, "springs": {"k": ("a", "b", 1), "k2": ("m", "wall", 1)}},
         r"pencil .* is singular.*motion along \[1, 1, 0\]"),
    ],
)
def test_component_errors(arguments, message):
    with pytest.raises(SceneError, match=message):
        ls.Scene.from_components(**arguments)


def test_symbolic_massless_scene():
    scene = ls.Scene.from_components(
        masses={"n": 0, "m": "m"}, springs={"k": ("wall", "n", "k")}, dashpots={"c": ("n", "m", "c")},
        x0=[0, 1], v0=[0, 0], parameters=["m", "k", "c"])
    sol = ls.solve(scene)
    assert sol.resolvent.determinant.degree() == 3
    assert sol.verify().ok


# ---------------------------------------------------------------------------
# Property: random physical scenes with massless nodes
# ---------------------------------------------------------------------------

_values = st.sampled_from([0, 0, "1/2", 1, 2, 3])


@st.composite
def physical_scenes(draw):
    n = draw(st.integers(2, 3))
    masses = {f"m{i}": draw(st.sampled_from([0, 0, 1, "1/2", 2])) for i in range(n)}
    nodes = [*masses, "wall"]
    springs, dashpots = {}, {}
    for i in range(n):
        for j, other in enumerate(nodes[i + 1:]):
            for kind, table in (("k", springs), ("c", dashpots)):
                value = draw(_values)
                if value != 0:
                    table[f"{kind}{i}{j}"] = (f"m{i}", other, value)
    x0 = [draw(st.integers(-3, 3)) for _ in range(n)]
    v0 = [draw(st.integers(-3, 3)) for _ in range(n)]
    try:
        return ls.Scene.from_components(masses=masses, springs=springs, dashpots=dashpots,
                                        x0=x0, v0=v0)
    except SceneError as error:
        assert "singular" in str(error)
        return None


@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(physical_scenes())
def test_random_physical_massless_scenes(scene):
    assume(scene is not None)
    sol = ls.solve(scene, method="exact")
    assert sol.initial_jump.impulses.cols == 0  # no impulses in physical scenes
    assert sol.verify(samples=("1.3",)).ok  # t = 0⁺ and one more time: verify is slow
    n = scene.n
    massless = [i for i in range(n) if scene.M[i, i] == 0]
    dashpot_nodes = [i for i in massless if any(scene.C[i, j] != 0 for j in range(n))]
    if dashpot_nodes and sp.Matrix([[scene.C[i, j] for j in dashpot_nodes]
                                    for i in dashpot_nodes]).det() == 0:
        return  # the reference's first-order form needs an invertible dashpot block
    times = ["0", "0.7", "3"]
    reference, _, _ = condensed_reference(scene, times, dps=40)
    assert relative_error(sol.evaluate(times), reference) < 1e-11


# ---------------------------------------------------------------------------
# Inputs acting from t = 0 (the transform of the delay-0 part given explicitly)
# ---------------------------------------------------------------------------


def _with_input(scene, F, common):
    """Numerators and denominator of X = adj·(r + F)/Δ with F = given/common."""
    R = ls.resolvent(scene)
    lam = ls.lam
    load = sp.Matrix(F)
    numerators = [sp.Poly(sp.expand(N.as_expr() * common + (R.adjugate.row(i) * load)[0]), lam)
                  for i, N in enumerate(R.numerators)]
    return R, numerators, R.determinant * sp.Poly(common, lam)


def test_step_force_moves_a_spring_node_at_once():
    # node between wall spring 3 and spring 2 to a resting unit mass, force 1 on the node
    # from t = 0: at 0⁺ it sits at 1/(3 + 2), the mass has not moved
    R, N, D = _with_input(spring_node(x0=(0, 0), v0=(0, 0)), [1, 0], ls.lam)
    jump = initial_jump(R, N, D)
    assert list(jump.x_plus) == [sp.Rational(1, 5), 0] and list(jump.v_plus) == [0, 0]


def test_impulse_on_a_spring_node_is_an_impulse_in_its_position():
    # force δ(t) on the node: 5 x_n − 2 x_m = δ gives x_n ∋ δ/5 and the mass a kick 2/5
    scene = spring_node(x0=(0, 0), v0=(0, 0))
    R, N, D = _with_input(scene, [1, 0], 1)
    jump = initial_jump(R, N, D)
    assert jump.impulses == sp.Matrix([[sp.Rational(1, 5)], [0]])
    assert list(jump.v_plus) == [sp.Rational(4, 25), sp.Rational(2, 5)]
    residuals = jump_residuals(scene, jump.position, jump.velocity, jump.impulses, load=[[1], [0]])
    assert all(r == 0 for r in residuals)
    assert any(r != 0 for r in jump_residuals(scene, jump.position, jump.velocity, jump.impulses))
