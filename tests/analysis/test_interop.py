"""Transfer matrix, state space, python-control and SciPy, against independent routes.

- G(s) is checked against the pencil it inverts (G·(s²M + sC + K) = I), against the
  state-space resolvent C(sI − A)⁻¹B of the textbook block matrices built here by hand,
  and at s = iω against python-control's own evaluation of ``to_control(scene)``.
- The python-control and SciPy systems are simulated by their own integrators (matrix
  exponentials on a uniform grid; linear interpolation of the input) and compared with
  ``ls.solve(scene).evaluate``.
- Poles of the StateSpace (float64 eigenvalues of A) against the certified poles; zeros
  against the textbook antiresonance √(k₂/m₂) of a two-mass chain and python-control's
  ``zeros``.
"""

from __future__ import annotations

import sys

import numpy as np
import pytest
import sympy as sp

import laplace_springs as ls
from laplace_springs.analysis.interop import from_state_space, poles_and_zeros, transfer_function
from laplace_springs.model.state_space import initial_state, state_space, to_control, to_scipy

control = pytest.importorskip("control")
signal = pytest.importorskip("scipy.signal")

s = ls.s


def three_mass_chain(**initial):
    """wall - m1 - m2 - m3, springs and dashpots between neighbours (not proportional damping)."""
    return ls.Scene.from_components(
        masses={"m1": 1, "m2": 2, "m3": "3/2"},
        springs={"k1": ("wall", "m1", 10), "k2": ("m1", "m2", 6), "k3": ("m2", "m3", 4)},
        dashpots={"c1": ("wall", "m1", "1/2"), "c3": ("m2", "m3", "3/10")},
        x0=initial.get("x0", [1, "-1/2", "1/4"]), v0=initial.get("v0", [0, 1, "-2"]),
        title="three-mass chain")


def symbolic_pair():
    return ls.Scene.from_matrices(M=[["m", 0], [0, "m"]], C=[["c", 0], [0, 0]],
                                  K=[["2*k", "-k"], ["-k", "k"]], x0=[1, 0], v0=[0, 0],
                                  parameters=["m", "c", "k"])


SCENES = {"three-dashpots": lambda: ls.load_scene("three-dashpots"), "chain3": three_mass_chain}


def textbook_blocks(scene):
    """A = [[0, I], [-M⁻¹K, -M⁻¹C]], B = [[0], [M⁻¹]], built with SymPy's dense inverse."""
    n = scene.n
    Minv = sp.Matrix(scene.M).inv()
    A = sp.Matrix.vstack(sp.Matrix.hstack(sp.zeros(n), sp.eye(n)),
                         sp.Matrix.hstack(-Minv * scene.K, -Minv * scene.C))
    B = sp.Matrix.vstack(sp.zeros(n), Minv)
    C = sp.Matrix.hstack(sp.eye(n), sp.zeros(n))
    return A, B, C


# ----------------------------------------------------------------------------
# The exact transfer matrix
# ----------------------------------------------------------------------------


@pytest.mark.parametrize("name", [*SCENES, "symbolic"])
def test_transfer_function_inverts_the_pencil(name):
    scene = symbolic_pair() if name == "symbolic" else SCENES[name]()
    G = transfer_function(scene)
    assert G.shape == (scene.n, scene.n)
    assert G.free_symbols <= {s, *scene.parameters}
    pencil = s**2 * sp.Matrix(scene.M) + s * sp.Matrix(scene.C) + sp.Matrix(scene.K)
    assert (G * pencil).applyfunc(sp.cancel) == sp.eye(scene.n)
    for entry in G:  # each entry in lowest terms: numerator and denominator coprime
        numerator, denominator = sp.fraction(sp.cancel(entry))
        assert sp.gcd(numerator, denominator).free_symbols.isdisjoint({s})


def test_transfer_function_of_a_symbolic_mass_spring_damper_is_the_textbook_one():
    scene = ls.Scene.from_matrices(M=[["m"]], C=[["c"]], K=[["k"]], x0=[0], v0=[0],
                                   parameters=["m", "c", "k"])
    by_name = {symbol.name: symbol for symbol in scene.parameters}
    m, c, k = by_name["m"], by_name["c"], by_name["k"]
    assert sp.cancel(transfer_function(scene)[0, 0] - 1 / (m * s**2 + c * s + k)) == 0


@pytest.mark.parametrize("name", [*SCENES, "symbolic"])
def test_transfer_function_is_the_state_space_resolvent(name):
    scene = symbolic_pair() if name == "symbolic" else SCENES[name]()
    """C (sI − A)⁻¹ B = G  ⟺  (sI − A) [G; sG] = B (the state is (x, x'))."""
    A, B, _ = textbook_blocks(scene)
    n = scene.n
    G = sp.Matrix(transfer_function(scene))
    state = sp.Matrix.vstack(G, s * G)
    assert ((s * sp.eye(2 * n) - A) * state - B).applyfunc(sp.cancel) == sp.zeros(2 * n, n)


@pytest.mark.parametrize("name", list(SCENES))
def test_G_at_i_omega_matches_frequency_response_and_python_control(name):
    scene = SCENES[name]()
    G = sp.lambdify(s, transfer_function(scene), "numpy")
    system = to_control(scene)
    omegas = [0.3, 1.0, 2.7, 16.0, 33.4, 80.0]
    H = ls.frequency_response(scene, omegas)
    for k, w in enumerate(omegas):
        exact = np.array(G(1j * w), dtype=complex)
        from_control = np.asarray(system(1j * w))  # python-control's evalfr
        scale = np.max(np.abs(exact))
        assert np.max(np.abs(exact - from_control)) <= 1e-10 * scale
        assert np.max(np.abs(exact - H[k])) <= 1e-12 * scale
    response = control.frequency_response(system, omegas)  # an independent second call path
    complex_response = np.asarray(response.complex)  # (outputs, inputs, frequencies)
    for k, w in enumerate(omegas):
        exact = np.array(G(1j * w), dtype=complex)
        assert np.max(np.abs(complex_response[:, :, k] - exact)) <= 1e-10 * np.max(np.abs(exact))


# ----------------------------------------------------------------------------
# The exact state space
# ----------------------------------------------------------------------------


@pytest.mark.parametrize("name", [*SCENES, "symbolic"])
def test_state_space_is_the_textbook_block_form(name):
    scene = symbolic_pair() if name == "symbolic" else SCENES[name]()
    A, B, C, D = state_space(scene)
    A_ref, B_ref, C_ref = textbook_blocks(scene)
    assert (sp.Matrix(A) - A_ref).applyfunc(sp.cancel) == sp.zeros(*A_ref.shape)
    assert (sp.Matrix(B) - B_ref).applyfunc(sp.cancel) == sp.zeros(*B_ref.shape)
    assert sp.Matrix(C) == C_ref
    assert sp.Matrix(D) == sp.zeros(scene.n)
    assert sp.Matrix(initial_state(scene)) == sp.Matrix.vstack(scene.x0, scene.v0)


def test_state_space_of_the_seed_example_5_in_numbers():
    A, B, _, _ = state_space(ls.load_scene("three-dashpots"))
    # M = diag(1, 4/5), K = [[779, -379], [-379, 479]], C = [[1.9, -1.4], [-1.4, 2.3]] (seed)
    assert A[2:, :2].tolist() == [[-779, 379], [sp.Rational(379 * 5, 4), -sp.Rational(479 * 5, 4)]]
    assert A[2:, 2:].tolist() == [[sp.Rational(-19, 10), sp.Rational(7, 5)],
                                  [sp.Rational(7, 4), sp.Rational(-23, 8)]]
    assert B[2:, :].tolist() == [[1, 0], [0, sp.Rational(5, 4)]]


def test_massless_nodes_have_no_state_space():
    scene = ls.Scene.from_components(
        masses={"m1": 1, "n": 0},
        springs={"k1": ("wall", "m1", 4), "k2": ("m1", "n", 2)},
        dashpots={"c": ("n", "wall", 1)}, x0=[1, 0], v0=[0, 0])
    with pytest.raises(ls.SceneError, match=r"mass 'n' \(coordinate x2\) has zero mass.*descriptor form.*not supported"):
        state_space(scene)
    with pytest.raises(ls.SceneError, match="descriptor"):
        to_control(scene)
    # G(s) exists all the same: (s²M + sC + K)⁻¹ of the singular-M pencil
    pencil = s**2 * sp.Matrix(scene.M) + s * sp.Matrix(scene.C) + sp.Matrix(scene.K)
    assert (transfer_function(scene) * pencil).applyfunc(sp.cancel) == sp.eye(2)


def test_symbolic_scenes_cannot_become_float_systems():
    scene = symbolic_pair()
    for convert in (to_control, to_scipy):
        with pytest.raises(ls.SceneError, match=r"parameters c, k, m.*scene\.subs"):
            convert(scene)
    numeric = scene.subs({"m": 1, "c": "1/5", "k": 3})
    assert np.allclose(to_control(numeric).A, [[0, 0, 1, 0], [0, 0, 0, 1], [-6, 3, -0.2, 0], [3, -3, 0, 0]])


def test_symbolic_initial_data_do_not_stop_the_conversion():
    scene = ls.Scene.from_matrices(M=[[1]], K=[[4]], x0=["d"], v0=[0], parameters=["d"])
    assert to_control(scene).A.tolist() == [[0.0, 1.0], [-4.0, 0.0]]


def test_import_errors_name_the_extra(monkeypatch):
    scene = three_mass_chain()
    monkeypatch.setitem(sys.modules, "control", None)
    with pytest.raises(ImportError, match=r"python-control.*pip install 'laplace_springs\[control\]'"):
        to_control(scene)
    monkeypatch.setitem(sys.modules, "scipy.signal", None)
    with pytest.raises(ImportError, match=r"SciPy.*pip install 'laplace_springs\[control\]'"):
        to_scipy(scene)


def test_systems_carry_the_coordinate_names():
    scene = ls.load_scene("three-dashpots")
    system = to_control(scene)
    assert system.input_labels == ["f_x1", "f_x2"]
    assert system.output_labels == ["x1", "x2"]
    assert system.state_labels == ["x1", "x2", "x1_dot", "x2_dot"]
    assert system.isctime()
    assert isinstance(to_scipy(scene), signal.StateSpace)


# ----------------------------------------------------------------------------
# Simulations by python-control and SciPy against the exact motion
# ----------------------------------------------------------------------------


@pytest.mark.parametrize("name", list(SCENES))
def test_initial_response_of_python_control_matches_solve(name):
    scene = SCENES[name]()
    T = np.linspace(0.0, 6.0, 30001)
    X0 = np.array(initial_state(scene), dtype=float).ravel()
    response = control.initial_response(to_control(scene), T, X0=X0)
    exact = ls.solve(scene).evaluate(T)
    scale = np.max(np.abs(exact))
    assert np.max(np.abs(response.outputs - exact)) <= 1e-9 * scale


@pytest.mark.parametrize("name", list(SCENES))
def test_scipy_lsim_matches_solve(name):
    scene = SCENES[name]()
    T = np.linspace(0.0, 6.0, 30001)
    X0 = np.array(initial_state(scene), dtype=float).ravel()
    _, y, _ = signal.lsim(to_scipy(scene), np.zeros((T.size, scene.n)), T, X0=X0)
    exact = ls.solve(scene).evaluate(T)
    assert np.max(np.abs(y.T - exact)) <= 1e-9 * np.max(np.abs(exact))


def test_forced_response_matches_the_exact_forced_motion():
    """The integrators interpolate the sampled input linearly: O(dt²) error, 1e-6 here
    (a smooth input: a step between samples would be a ramp, an O(dt) error)."""
    scene = ls.load_scene("three-dashpots").with_forcing(["10*cos(20*t)", "3*sin(7*t) + 1"])
    T = np.linspace(0.0, 4.0, 40001)
    U = np.vstack([10 * np.cos(20 * T), 3 * np.sin(7 * T) + 1])
    X0 = np.array(initial_state(scene), dtype=float).ravel()
    exact = ls.solve(scene).evaluate(T)
    scale = np.max(np.abs(exact))
    response = control.forced_response(to_control(scene), T, U, X0=X0)
    assert np.max(np.abs(response.outputs - exact)) <= 1e-6 * scale
    _, y, _ = signal.lsim(to_scipy(scene), U.T, T, X0=X0)
    assert np.max(np.abs(y.T - exact)) <= 1e-6 * scale


@pytest.mark.parametrize("name", list(SCENES))
def test_state_space_poles_are_the_certified_poles(name):
    scene = SCENES[name]()  # initial data excite every mode: no pole cancels in X(λ)
    certified = np.sort_complex(ls.solve(scene, method="certified").poles)
    from_control = np.sort_complex(control.poles(to_control(scene)))
    assert certified.size == 2 * scene.n
    assert np.max(np.abs(from_control - certified)) <= 1e-10 * np.max(np.abs(certified))
    ours, _ = poles_and_zeros(scene)
    assert np.max(np.abs(ours - certified)) <= 1e-12 * np.max(np.abs(certified))


# ----------------------------------------------------------------------------
# Zeros
# ----------------------------------------------------------------------------


def test_zeros_of_a_two_mass_chain_are_the_textbook_antiresonance():
    """wall - k1 - m1 - k2 - m2: force on m1, output m1: zeros ±i√(k2/m2) (m2 on its own spring)."""
    scene = ls.Scene.from_components(masses={"m1": 2, "m2": 3},
                                     springs={"k1": ("wall", "m1", 5), "k2": ("m1", "m2", 12)},
                                     x0=[0, 0], v0=[0, 0])
    _, zeros = poles_and_zeros(scene, force=0, output=0)
    assert np.allclose(zeros, [-2j, 2j], atol=1e-14)
    _, zeros = poles_and_zeros(scene, force=0, output=1)  # G21 = k2/Δ: no zeros
    assert zeros.size == 0


@pytest.mark.parametrize(("force", "output"), [(0, 0), (1, 0), (2, 2), (0, 2)])
def test_zeros_match_python_control(force, output):
    scene = three_mass_chain()
    _, ours = poles_and_zeros(scene, force=force, output=output)
    theirs = np.sort_complex(control.zeros(to_control(scene)[output, force]))
    assert ours.shape == theirs.shape
    assert np.max(np.abs(ours - theirs), initial=0.0) <= 1e-8 * max(1.0, np.max(np.abs(ours), initial=0))


def test_poles_and_zeros_refuse_symbols_and_bad_indices():
    with pytest.raises(ls.SceneError, match="parameters c, k, m"):
        poles_and_zeros(symbolic_pair())
    with pytest.raises(ValueError, match="out of range"):
        poles_and_zeros(three_mass_chain(), force=3)


def test_irrational_entries_use_float_roots():
    scene = ls.Scene.from_matrices(M=[[1]], C=[["sqrt(2)"]], K=[[1]], x0=[1], v0=[0])
    poles, zeros = poles_and_zeros(scene)  # s² + √2 s + 1: e^{±3iπ/4}
    assert np.allclose(poles, np.exp([-3j * np.pi / 4, 3j * np.pi / 4]), atol=1e-14)
    assert zeros.size == 0


# ----------------------------------------------------------------------------
# Back from state space
# ----------------------------------------------------------------------------


@pytest.mark.parametrize("name", list(SCENES))
def test_from_state_space_gives_back_the_scene(name):
    scene = SCENES[name]()
    rebuilt = from_state_space(*state_space(scene), x0=scene.x0, v0=scene.v0)
    for field in ("M", "C", "K", "x0", "v0"):
        assert sp.Matrix(getattr(rebuilt, field)) == sp.Matrix(getattr(scene, field)), field


def test_from_state_space_reads_python_control_floats():
    scene = ls.load_scene("three-dashpots")
    system = to_control(scene)
    rebuilt = from_state_space(system.A, system.B, system.C, system.D, x0=scene.x0, v0=scene.v0)
    assert rebuilt.M == scene.M and rebuilt.C == scene.C and rebuilt.K == scene.K
    T = np.linspace(0, 2, 7)
    assert np.allclose(ls.solve(rebuilt).evaluate(T), ls.solve(scene).evaluate(T), rtol=0, atol=1e-13)


def test_from_state_space_without_B_is_the_normalised_form():
    A = [[0, 0, 1, 0], [0, 0, 0, 1], [-3, 1, "-1/5", 0], [2, -2, 0, "-1/5"]]
    scene = from_state_space(A, x0=[1, 0], v0=[0, 0])
    seed = ls.Scene.from_normalized(A=[[3, -1], [-2, 2]], B=[["0.2", 0], [0, "0.2"]],
                                    x0=[1, 0], v0=[0, 0])
    assert (scene.M, scene.C, scene.K) == (seed.M, seed.C, seed.K)


@pytest.mark.parametrize(("args", "message"), [
    (([[1, 1], [0, 0]],), r"A\[0,0\] = 1, expected 0"),
    (([[0, 2], [-1, 0]],), r"A\[0,1\] = 2, expected 1"),
    (([[0, 1, 0], [0, 0, 1], [1, 1, 1]],), "even size"),
    (([[0, 1], [-1, 0]], [[0], [0]]), "singular"),
    (([[0, 1], [-1, 0]], [[0], [1]], [[0, 1]]), r"C\[0,0\] = 0, expected 1"),
    (([[0, 1], [-1, 0]], None, None, [[1]]), "D must be zero"),
])
def test_from_state_space_refuses_other_shapes(args, message):
    with pytest.raises(ls.SceneError, match=message):
        from_state_space(*args)
