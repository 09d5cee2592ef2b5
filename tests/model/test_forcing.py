"""Driven systems: forcing inputs, exact forced responses, resonance, modes, frequency response.

Independent checks: textbook closed forms (cited per test), mpmath quadrature of the
Laplace integral, and an mpmath matrix exponential of the first-order system augmented
with exosystem states that generate the forcing (laplace_springs.bench.reference).
"""

from __future__ import annotations

import mpmath
import numpy as np
import pytest
import sympy as sp

import laplace_springs as ls
from laplace_springs.bench.reference import (
    first_order_matrix_mp,
    reference_forced_motion,
    reference_motion,
    relative_error,
)
from laplace_springs.model.forcing import input_transform, parse_forcing

t = ls.t
s = sp.Symbol("s")


def _mp(r: sp.Rational) -> mpmath.mpf:
    """A SymPy rational as an mpf at the current precision."""
    return mpmath.mpf(int(r.p)) / int(r.q)


def _harmonic(w: str) -> tuple[list, list]:
    """Exosystem for cos(w t): states (cos, sin)."""
    return [[0, f"-{w}"], [w, 0]], [1, 0]


# ----------------------------------------------------------------------------
# Inputs and their transforms
# ----------------------------------------------------------------------------

def _laplace_by_quadrature(f: sp.Expr, s0: mpmath.mpf, breaks) -> mpmath.mpf:
    x = sp.Symbol("x", positive=True)
    g = f.subs(t, x).replace(sp.Heaviside, lambda a, *r: sp.Piecewise((1, a > 0), (0, True)))
    g = sp.lambdify(x, g, "mpmath")
    return mpmath.quad(lambda v: g(v) * mpmath.exp(-s0 * v), [0, *breaks, mpmath.inf])


@pytest.mark.parametrize("text", [
    "3*sin(2*t + 1/2)", "exp(-t)*t**2", "cos(t)**2", "sin(t)*cos(3*t)", "t**3*exp(-2*t)*sin(5*t)",
    "t*sin(t)*Heaviside(t - 2)", "exp(-t)*Heaviside(t - 1)*cos(t)", "Heaviside(t - 1)*Heaviside(3 - t)*t",
    "cosh(t/2) - 2*sinh(t/3)", "5", "(t - 2)*Heaviside(t - 2)",
])
def test_transform_matches_the_laplace_integral(text):
    f = parse_forcing(text, "f")
    F = input_transform(f, "f", s).as_expr()
    with mpmath.workdps(30):
        s0 = mpmath.mpf(7) / 3
        expected = _laplace_by_quadrature(f, s0, [1, 2, 3])
        got = mpmath.mpf(sp.N(F.subs(s, sp.Rational(7, 3)), 30))
        assert abs(got - expected) < 1e-20 * max(1, abs(expected))


def test_transform_table_entries():
    # Kreyszig, Advanced Engineering Mathematics, Table 6.9: t^n e^{at} -> n!/(s-a)^{n+1},
    # sin ωt -> ω/(s²+ω²), u(t-a) f(t-a) -> e^{-as} F(s), δ(t-a) -> e^{-as}.
    ((tau, F),) = input_transform(t**2 * sp.exp(3 * t), "f", s).parts
    assert tau == 0 and sp.cancel(F - 2 / (s - 3) ** 3) == 0
    assert sp.simplify(input_transform(sp.sin(5 * t), "f", s).parts[0][1] - 5 / (s**2 + 25)) == 0
    delayed = input_transform(parse_forcing("(t - 2)*Heaviside(t - 2)", "f"), "f", s).parts
    assert delayed == ((2, s**-2),)
    assert input_transform(sp.DiracDelta(t - 3), "f", s).parts == ((3, 1),)


@pytest.mark.parametrize("text", ["1/(t + 1)", "cos(t**2)", "sqrt(t)", "Abs(t - 1)", "exp(t**2)",
                                  "DiracDelta(t, 1)", "Heaviside(k*t - 1)", "t**(1/2)",
                                  "__import__('os')", "cos(t) +", "DiracDelta(t-1)*DiracDelta(t-2)"])
def test_unsupported_inputs_raise_scene_error_naming_the_entry(text):
    with pytest.raises(ls.SceneError, match=r"forcing\[1\]"):
        ls.Scene.from_matrices(M=[[1, 0], [0, 1]], x0=[0, 0], v0=[0, 0], forcing=["0", text])


def test_forcing_length_and_time_in_matrices_are_checked():
    with pytest.raises(ls.SceneError, match="forcing has 1 entries, expected 2"):
        ls.Scene.from_matrices(M=[[1, 0], [0, 1]], x0=[0, 0], v0=[0, 0], forcing=["1"])
    with pytest.raises(ls.SceneError, match=r"K\[0,0\].*time t"):
        ls.Scene.from_matrices(M=[[1]], K=[["t"]], x0=[0], v0=[0])


def test_helpers_build_the_expected_inputs():
    assert ls.cosine(10, 20) == 10 * sp.cos(20 * t)
    assert ls.sine(3, 2, "1/2") == 3 * sp.sin(2 * t + sp.Rational(1, 2))
    assert ls.step(2, at=1) == 2 * sp.Heaviside(t - 1)
    assert ls.impulse(4, at="0.5") == 4 * sp.DiracDelta(t - sp.Rational(1, 2))
    assert ls.ramp(3) == 3 * t
    with pytest.raises(ls.SceneError, match="at must be a number >= 0"):
        ls.step(1, at=-1)


def test_forcing_in_toml_and_components(tmp_path):
    path = tmp_path / "driven.toml"
    path.write_text('[masses]\nm1 = "2"\n[springs]\nk1 = ["wall", "m1", "8"]\n'
                    '[initial]\nx0 = ["0"]\nv0 = ["0"]\n[forcing]\nm1 = "4*cos(2*t)"\n')
    scene = ls.load_scene(path)
    assert scene.is_forced and scene.forcing[0] == 4 * sp.cos(2 * t)
    # resonance of m x'' + k x = F0 cos ω_n t: x = F0 t sin(ω_n t)/(2 m ω_n)  (Rao §3.3)
    assert sp.simplify(ls.solve(scene).x[0] - 4 * t * sp.sin(2 * t) / (2 * 2 * 2)) == 0


# ----------------------------------------------------------------------------
# Textbook closed forms
# ----------------------------------------------------------------------------

def test_undamped_beat_closed_form():
    # Rao, Mechanical Vibrations (6th ed.), eq. (3.11) with x0 = v0 = 0:
    # x = F0/(k - mω²) (cos ωt - cos ω_n t)
    m, k, F0, w = 2, 18, 5, sp.Rational(5, 2)
    sol = ls.solve(ls.Scene.from_matrices(M=[[m]], K=[[k]], x0=[0], v0=[0],
                                          forcing=[F0 * sp.cos(w * t)]))
    expected = F0 / (k - m * w**2) * (sp.cos(w * t) - sp.cos(3 * t))
    assert sp.simplify(sol.x[0] - expected) == 0
    assert sp.simplify(sol.steady_state[0] - F0 / (k - m * w**2) * sp.cos(w * t)) == 0
    assert sol.verify()


def test_exact_resonance_gives_secular_term():
    # Rao eq. (3.16): at ω = ω_n, x = x0 cos ω_n t + v0/ω_n sin ω_n t + δ_st ω_n t sin(ω_n t)/2
    sol = ls.solve(ls.Scene.from_matrices(M=[[1]], K=[[9]], x0=[1], v0=[0], forcing=["9*cos(3*t)"]))
    expected = sp.cos(3 * t) + 3 * t * sp.sin(3 * t) / 2
    assert sp.simplify(sol.x[0] - expected) == 0
    assert not sol.x.has(sp.Heaviside)


def test_damped_steady_state_amplitude_and_phase():
    # Rao eqs. (3.28)-(3.29): X = F0/√((k - mω²)² + (cω)²), φ = atan(cω/(k - mω²))
    m, c, k, F0, w = 3, 2, 12, 7, 1
    scene = ls.Scene.from_matrices(M=[[m]], C=[[c]], K=[[k]], x0=[1], v0=[0], forcing=[F0 * sp.cos(w * t)])
    X = F0 / sp.sqrt((k - m * w**2) ** 2 + (c * w) ** 2)
    phi = sp.atan(sp.Rational(c * w, k - m * w**2))
    steady = ls.solve(scene).steady_state[0]
    assert sp.simplify(sp.expand_trig(steady - X * sp.cos(w * t - phi))) == 0
    amplitude, phase = ls.steady_state_amplitude(scene, [F0], w)
    assert sp.simplify(amplitude[0] - X) == 0 and sp.simplify(phase[0] - phi) == 0


def test_constant_force_on_a_free_mass():
    # Newton: x = x0 + v0 t + F t²/(2m)
    sol = ls.solve(ls.Scene.from_matrices(M=[[4]], x0=[1], v0=[2], forcing=["3"]))
    assert sp.expand(sol.x[0] - (1 + 2 * t + 3 * t**2 / 8)) == 0
    assert sol.verify()


def test_step_on_a_damped_oscillator_settles_at_f_over_k():
    # Final-value theorem: x(∞) = F/k; the steady state is exactly F/k·H(t - τ).
    sol = ls.solve(ls.Scene.from_matrices(M=[[1]], C=[[1]], K=[[4]], x0=[0], v0=[0],
                                          forcing=["2*Heaviside(t - 1)"]))
    assert sol.steady_state[0] == sp.Heaviside(t - 1) / 2
    assert sol.evaluate([0.5])[0, 0] == 0.0
    assert abs(sol.evaluate([60.0])[0, 0] - 0.5) < 1e-12
    assert sol.x.has(sp.Heaviside)
    assert sol.verify()


def test_impulse_response():
    # Rao eq. (4.25): impulse F̂ on m, c, k from rest: x = F̂/(m ω_d) e^{-ζω_n t} sin ω_d t
    sol = ls.solve(ls.Scene.from_matrices(M=[[1]], C=[[2]], K=[[10]], x0=[0], v0=[0],
                                          forcing=["6*DiracDelta(t)"]))
    assert sp.simplify(sol.x[0] - 2 * sp.exp(-t) * sp.sin(3 * t)) == 0
    delayed = ls.solve(ls.Scene.from_matrices(M=[[1]], C=[[2]], K=[[10]], x0=[0], v0=[0],
                                              forcing=["6*DiracDelta(t - 2)"]))
    shifted = 2 * sp.exp(-(t - 2)) * sp.sin(3 * (t - 2)) * sp.Heaviside(t - 2)
    assert sp.simplify(delayed.x[0] - shifted) == 0
    assert sol.verify() and delayed.verify()


def test_vibration_absorber_cancels_the_main_mass():
    # Den Hartog, Mechanical Vibrations, §3.2: with ω² = k2/m2 the main mass stands still
    # in steady state and the absorber moves with amplitude F0/k2, in antiphase.
    m1, k1, m2, k2, F0 = 5, 20, 1, 4, 3
    scene = ls.Scene.from_components(masses={"m1": m1, "m2": m2},
                                     springs={"k1": ("wall", "m1", k1), "k2": ("m1", "m2", k2)},
                                     forcing={"m1": f"{F0}*cos(2*t)"})
    steady = ls.solve(scene).steady_state
    assert steady[0] == 0
    assert sp.simplify(steady[1] + sp.Rational(F0, k2) * sp.cos(2 * t)) == 0
    amplitude, _ = ls.steady_state_amplitude(scene, [F0, 0], 2)
    assert list(amplitude) == [0, sp.Rational(F0, k2)]


def test_steady_state_plus_transient_is_the_solution():
    scene = ls.load_scene("three-dashpots").with_forcing(["10*cos(20*t)", "0"])
    sol = ls.solve(scene)
    assert (sol.x - sol.steady_state - sol.transient).applyfunc(sp.expand) == sp.zeros(2, 1)
    assert not sol.steady_state.has(sp.CRootOf)  # the input's poles only: ±20i
    # the steady state is Re(X e^{iωt}) with (K − ω²M + iωC) X = F (any vibrations text)
    with mpmath.workdps(30):
        P = mpmath.matrix([[_mp(scene.K[i, j]) - 400 * _mp(scene.M[i, j]) + 20j * _mp(scene.C[i, j])
                            for j in range(2)] for i in range(2)])
        X = mpmath.lu_solve(P, mpmath.matrix([10, 0]))
        for tv in ("0.3", "1.1"):
            expected = [mpmath.re(X[i] * mpmath.expj(20 * mpmath.mpf(tv))) for i in range(2)]
            got = [sp.N(e.subs(t, sp.Rational(tv)), 30) for e in sol.steady_state]
            assert relative_error(got, expected) < 1e-25


# ----------------------------------------------------------------------------
# Against the exosystem reference (float64 evaluate, 1e-12)
# ----------------------------------------------------------------------------

def _check_against_exosystem(kw, S, w0, G, times, tol=1e-12):
    scene = ls.Scene.from_matrices(**kw)
    sol = ls.solve(scene)
    values, bound = sol.evaluate(times, return_error=True)
    reference = reference_forced_motion(scene, S, w0, G, times, dps=50)  # the same float times
    error = relative_error(values, reference)
    assert error < tol, error
    assert sol.verify()
    return sol, error


@pytest.mark.parametrize("w", ["1.00000001", "0.99999999", "1.0001"])
def test_near_resonance_is_stable_in_float64(w):
    S, w0 = _harmonic(w)
    _check_against_exosystem({"M": [[1]], "K": [[1]], "x0": [0], "v0": [0], "forcing": [f"cos({w}*t)"]},
                             S, w0, [[1, 0]], np.linspace(0, 1e4, 41))


def test_light_damping_at_resonance_over_long_horizon():
    S, w0 = _harmonic("1")
    _check_against_exosystem({"M": [[1]], "C": [["0.000001"]], "K": [[1]], "x0": ["0.5"], "v0": [0],
                              "forcing": ["cos(t)"]},
                             S, w0, [[1, 0]], np.linspace(0, 1e4, 41))


def test_two_masses_driven_at_a_natural_frequency():
    # K = [[2,-1],[-1,2]], M = I: natural frequencies 1 and √3; drive mass 1 at ω = 1.
    S, w0 = _harmonic("1")
    sol, _ = _check_against_exosystem(
        {"M": [[1, 0], [0, 1]], "K": [[2, -1], [-1, 2]], "x0": [0, 0], "v0": [0, 0],
         "forcing": ["cos(t)", "0"]},
        S, w0, [[1, 0], [0, 0]], np.linspace(0, 200, 41))
    assert sol.steady_state.has(t * sp.sin(t))  # the secular term of the resonant mode


def test_seed5_driven_matches_exosystem():
    S, w0 = _harmonic("20")
    _check_against_exosystem(
        {"M": [["1", "0"], ["0", "0.8"]], "C": [["1.9", "-1.4"], ["-1.4", "2.3"]],
         "K": [["779", "-379"], ["-379", "479"]], "x0": ["0.05", "0.07"], "v0": ["3", "2"],
         "forcing": ["10*cos(20*t)", "0"]},
        S, w0, [["10", 0], [0, 0]], np.linspace(0, 4, 41))


def test_delayed_step_by_superposition():
    # x(t) = free motion + step response started at τ = 1 (step response from the
    # exosystem with a constant state, shifted in time).
    kw = {"M": [[1]], "C": [["0.5"]], "K": [[4]], "x0": [1], "v0": [0]}
    sol = ls.solve(ls.Scene.from_matrices(**kw, forcing=["3*Heaviside(t - 1)"]))
    times = np.linspace(0, 10, 21)
    free = reference_motion(ls.Scene.from_matrices(**kw), times, dps=40)
    rest = ls.Scene.from_matrices(M=[[1]], C=[["0.5"]], K=[[4]], x0=[0], v0=[0])
    shifted = [max(float(v) - 1.0, 0.0) for v in times]  # exact: the times are multiples of 1/2
    step = reference_forced_motion(rest, [[0]], [3], [[1]], shifted, dps=40)
    expected = [free[0, k] + (step[0, k] if v >= 1 else 0) for k, v in enumerate(times)]
    assert relative_error(sol.evaluate(times)[0], expected) < 1e-13


def test_evaluate_at_high_precision_with_delays():
    sol = ls.solve(ls.Scene.from_matrices(M=[[1]], K=[[4]], x0=[0], v0=[0], forcing=["Heaviside(t - 1)"]))
    value = sol.evaluate(["2.5"], dps=40)[0, 0]
    with mpmath.workdps(50):
        expected = (1 - mpmath.cos(2 * (mpmath.mpf("2.5") - 1))) / 4
        assert abs(value - expected) < mpmath.mpf(10) ** -38


# ----------------------------------------------------------------------------
# Modes and frequency response
# ----------------------------------------------------------------------------

def test_modes_of_a_symmetric_chain():
    # Three equal masses between walls, equal springs: ω² = (2 - √2, 2, 2 + √2) k/m
    # (Thomson & Dahleh, Theory of Vibration, §6.x: fixed-fixed chain, ω_j = 2 sin(jπ/8)).
    springs = {f"k{i}": (a, b, 1) for i, (a, b) in
               enumerate([("wall", "m1"), ("m1", "m2"), ("m2", "m3"), ("m3", "wall")], 1)}
    scene = ls.Scene.from_components(masses={"m1": 1, "m2": 1, "m3": 1}, springs=springs)
    modes = ls.modes(scene)
    for j, mode in enumerate(modes, 1):
        assert abs(float(mode.natural_frequency) - 2 * np.sin(j * np.pi / 8)) < 1e-14
        assert mode.damping_ratio == 0
    shape = modes[0].shape.real
    assert np.allclose(shape, [np.sin(np.pi / 4), 1, np.sin(np.pi / 4)] / np.float64(1), atol=1e-12)


def test_damping_ratio_of_a_single_mass():
    # ζ = c/(2√(km)), ω_d = ω_n √(1 - ζ²)
    (mode,) = ls.modes(ls.Scene.from_matrices(M=[[2]], C=[[3]], K=[[8]], x0=[0], v0=[0]))
    assert mode.natural_frequency == 2 and mode.damping_ratio == sp.Rational(3, 8)
    assert sp.simplify(mode.damped_frequency - 2 * sp.sqrt(1 - sp.Rational(9, 64))) == 0


def test_frequency_response_exact_and_numeric_agree():
    # H(iω) is the inverse of K − ω²M + iωC: checked for both forms, against a 30-digit
    # mpmath inverse of that matrix (independent of the code under test)
    scene = ls.load_scene("three-dashpots")
    H = ls.frequency_response(scene)
    omegas = [3.0, 15.99, 40.0]
    numeric = ls.frequency_response(scene, omegas)

    for k, w in enumerate(omegas):
        with mpmath.workdps(30):
            wm = mpmath.mpf(w)  # the float's exact value
            P = mpmath.matrix([[_mp(scene.K[i, j]) - _mp(scene.M[i, j]) * wm**2 + 1j * wm * _mp(scene.C[i, j])
                                for j in range(2)] for i in range(2)])
            inverse = np.array(P**-1, dtype=complex).reshape(2, 2)
        exact = np.array(H.subs(ls.omega, sp.Rational(w)).evalf(30).tolist(), dtype=complex)
        assert np.allclose(numeric[k], inverse, rtol=1e-12, atol=0)
        assert np.allclose(exact, inverse, rtol=1e-12, atol=0)


def test_resonance_without_damping_has_no_steady_state():
    with pytest.raises(ls.SceneError, match="resonance"):
        ls.steady_state_amplitude(ls.load_scene("vertical-pair"), [1, 0], 1)


def test_plot_frequency_response_marks_peaks(tmp_path):
    matplotlib = pytest.importorskip("matplotlib")
    matplotlib.use("Agg")
    fig = ls.plot_frequency_response(ls.load_scene("vertical-pair-damped"))
    amp, phase = fig.axes
    assert amp.get_xscale() == "log" and amp.get_yscale() == "log"
    peaks = sorted(line.get_xdata()[0] for line in amp.get_lines() if line.get_linestyle() == "--")
    assert np.allclose(peaks, [np.sqrt(1 - 0.01), 2 * np.sqrt(1 - 0.0025)], rtol=1e-12)
    fig.savefig(tmp_path / "response.png")


def test_irreducible_biquadratic_free_motion():
    # Δ = 5λ⁴ + 44λ² + 80 is irreducible and SymPy rescales its CRootOf (2·CRootOf(...)).
    scene = ls.Scene.from_components(masses={"m1": 5, "m2": 1},
                                     springs={"k1": ("wall", "m1", 20), "k2": ("m1", "m2", 4)},
                                     x0=[1, 0], v0=[0, 1])
    times = np.linspace(0, 20, 11)
    assert relative_error(ls.solve(scene).evaluate(times), reference_motion(scene, times)) < 1e-13


def test_irreducible_biquadratic_prints_real_frequencies():
    # Undamped, irreducible over ℚ but even: ω = √(−μ) with μ a root of the quadratic in λ².
    scene = ls.Scene.from_components(masses={"m1": 5, "m2": 1},
                                     springs={"k1": ("wall", "m1", 20), "k2": ("m1", "m2", 4)},
                                     forcing={"m1": "3*cos(2*t)"})
    x = ls.solve(scene).x
    assert not x.has(sp.cosh, sp.sinh, sp.CRootOf, sp.I)


def test_modes_with_rescaled_algebraic_roots():
    # SymPy returns k*CRootOf(...) for some quartics; the modes must still come out,
    # matching mpmath's eigenvalues of the first-order matrix.
    scene = ls.Scene.from_components(masses={"m0": "3e-3", "m1": 3},
                                     springs={"k1": ("wall", "m0", 2), "k2": ("m0", "m1", 50)},
                                     dashpots={"c": ("m0", "m1", 10)})
    with mpmath.workdps(30):
        eigenvalues = mpmath.eig(first_order_matrix_mp(scene), left=False, right=False)
    expected = sorted({round(float(abs(z)), 9) for z in eigenvalues})
    got = sorted(round(float(mode.natural_frequency), 9) for mode in ls.modes(scene))
    assert got == expected


@pytest.mark.parametrize("force", [ls.square_wave(1, "3/7"), ls.sawtooth(2, "1/2"), "cos(3*t)",
                                   "Heaviside(t - 1)"])
def test_forced_from_rest_starts_at_rest(force):
    # x(0) = x0 and x'(0) = v0 (no impulse): the initial data, whatever the pole sums
    # round to; a scene at rest has no scale for a relative bound to hide behind
    scene = ls.Scene.from_matrices(M=[[1]], C=[["1/5"]], K=[[4]], x0=[0], v0=[0], forcing=[force])
    sol = ls.solve(scene)
    for order in (0, 1):
        values, bounds = sol.evaluate([0.0, 0.5], return_error=True, derivative=order)
        assert values[0, 0] == 0 and bounds[0, 0] <= 1e-300
    assert sol.evaluate([0.0], dps=30)[0, 0] == 0
