"""Float64 and mpmath evaluation of exact terms (laplace_springs.numeric.terms, pole_sum).

References: textbook inverse transforms evaluated with 50-digit mpmath, SymPy's adaptive
evalf of the exact closed form, mpmath's expm for divided differences, and the arb
matrix exponential of the first-order system.
"""

from __future__ import annotations

import mpmath
import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st

import laplace_springs as ls
from laplace_springs.bench.reference import reference_motion_arb, relative_error
from laplace_springs.exact.inverse import inverse_laplace_terms
from laplace_springs.exact.real_terms import Term
from laplace_springs.numeric.pole_sum import first_row_exp, two_diff
from laplace_springs.numeric.terms import float_values, mp_values, numeric_terms

s, t = sp.symbols("s t")


def evaluate_float(data, n, times, *, lo=None):
    """The float64 kernel alone (no escalation), as numpy arrays."""
    return float_values(data, n, np.asarray(times, dtype=float), lo)


def evaluate_mp(data, n, times, digits):
    with mpmath.workdps(digits + 30):
        stamps = [mpmath.mpf(v) for v in times]
    values, _, _ = mp_values(data, n, stamps, digits, [0.0] * len(stamps))
    return np.array(values, dtype=object)


def _errors(values, exact) -> tuple[float, float]:
    """max |values - exact| and max |exact| (exact: mpmath numbers)."""
    with mpmath.workdps(60):
        diff = max(float(abs(mpmath.mpf(float(v)) - e)) for v, e in zip(np.ravel(values),
                                                                       np.ravel(exact)))
        scale = max(float(abs(e)) for e in np.ravel(exact))
    return diff, scale


def _beat_terms(omega: sp.Rational, omega_n: sp.Rational) -> list[Term]:
    """(cos ωt − cos ω_n t)/(ω_n² − ω²), built directly as two oscillatory terms."""
    A = 1 / (omega_n**2 - omega**2)
    return [Term("oscillatory", 0, sp.S.Zero, omega, A, sp.S.Zero),
            Term("oscillatory", 0, sp.S.Zero, omega_n, -A, sp.S.Zero)]


@pytest.mark.parametrize("gap", ["1e-4", "1e-8", "1e-12", "1e-15"])
def test_near_resonant_difference_of_cosines(gap):
    # L^{-1}[s/((s²+ω²)(s²+ω_n²))] = (cos ωt − cos ω_n t)/(ω_n² − ω²): coefficients 1/gap.
    omega = sp.Rational(3, 2)
    omega_n = omega + sp.Rational(gap)
    times = np.array([0.0, 1e-9, 1e-3, 0.75, 3.0, 100.0, 2048.5, 1e4])
    x, bound = evaluate_float(numeric_terms([_beat_terms(omega, omega_n)]), 1, times)
    with mpmath.workdps(50):
        w, wn = (mpmath.mpf(v.p) / v.q for v in (omega, omega_n))
        exact = [(mpmath.cos(w * tv) - mpmath.cos(wn * tv)) / (wn**2 - w**2)
                 for tv in map(mpmath.mpf, times)]
    diff, scale = _errors(x[0], exact)
    assert diff <= 1e-15 * scale
    assert np.all(bound[0] >= np.abs(x[0] - np.array([float(e) for e in exact])))


@pytest.mark.parametrize("damping", ["1e-6", "1e-3"])
def test_light_damping_at_resonance(damping):
    # x'' + c x' + x = cos ωt from rest, ω within 1e-8 of 1: 1/((s²+ω²)(s²+cs+1)) · s.
    c, omega = sp.Rational(damping), 1 + sp.Rational(1, 10**8)
    F = s / ((s**2 + omega**2) * (s**2 + c * s + 1))
    terms = inverse_laplace_terms(F, s).terms
    times = np.array([0.0, 0.5, 10.0, 1e3, 4096.25, 1e4])
    x, _ = evaluate_float(numeric_terms([terms]), 1, times)
    expr = ls.inverse_laplace(F, s, t)
    exact = [mpmath.mpf(str(sp.N(expr.subs(t, sp.Rational(tv)), 50))) for tv in times]
    diff, scale = _errors(x[0], exact)
    assert diff <= 1e-14 * scale


def test_critical_and_near_critical_single_mass():
    # Textbook: x'' + 2ζx' + x = 0, x(0)=1, x'(0)=0 at ζ = 1 ± 1e-14 and ζ = 1.
    times = np.array([0.0, 1e-12, 1e-3, 1.0, 7.5, 40.0, 700.0])
    for c in ("2", "1.99999999999998", "2.00000000000002"):
        scene = ls.Scene.from_matrices(M=[[1]], C=[[c]], K=[[1]], x0=[1], v0=[0])
        x = ls.solve(scene).evaluate(times)
        assert relative_error(x, reference_motion_arb(scene, times, digits=40)) <= 1e-15


def test_huge_and_zero_times():
    # c = 1e6, k = 1: roots −1e-6 and −1e6; x(t) at t = 0, 1e-7 and 1e6.
    scene = ls.Scene.from_matrices(M=[[1]], C=[["1000000"]], K=[[1]], x0=[1], v0=[0])
    times = np.array([0.0, 1e-7, 1e-6, 5e5, 1e6])
    x = ls.solve(scene).evaluate(times)
    assert relative_error(x, reference_motion_arb(scene, times, digits=40)) <= 1e-15


def test_empty_times_and_zero_motion():
    scene = ls.Scene.from_matrices(M=[[1]], K=[[1]], x0=[0], v0=[0])
    sol = ls.solve(scene)
    assert evaluate_float(numeric_terms(sol.terms), 1, np.array([]))[0].shape == (1, 0)
    assert np.all(evaluate_float(numeric_terms(sol.terms), 1, np.array([0.0, 5.0]))[0] == 0)
    assert sol.evaluate([]).shape == (1, 0)


def test_return_error_bounds_actual_error():
    scene = ls.Scene.from_components(
        masses={"m1": "1", "m2": "1"},
        springs={"k1": ("wall", "m1", "1"), "k2": ("m1", "m2", "1")},
        dashpots={"c1": ("wall", "m1", "2.0000000002")}, x0=[1, 0], v0=[0, 1])
    sol = ls.solve(scene)
    times = np.linspace(0, 60, 41)
    values, error = sol.evaluate(times, return_error=True)
    assert error.shape == values.shape
    ref = reference_motion_arb(scene, times, digits=40)
    actual = np.array([[abs(float(mpmath.mpf(v) - r)) for v, r in zip(vr, rr)]
                       for vr, rr in zip(values, ref)])
    assert np.all(error >= actual)
    assert error.max() <= 1e-13 * np.abs(values).max()


def test_escalation_to_mpmath():
    # x'' + ω_n² x = cos t, ω_n = 1 + 1e-8, from rest: the beat (cos t − cos ω_n t)/(ω_n² − 1).
    # A target below float64's reach sends every time to the mpmath route (escalation "mp").
    omega_n = 1 + sp.Rational(1, 10**8)
    scene = ls.Scene.from_matrices(M=[[1]], K=[[omega_n**2]], x0=[0], v0=[0], forcing=["cos(t)"])
    sol = ls.solve(scene)
    times = np.array([0.0, 0.25, 1e4])
    x, error = sol.evaluate(times, return_error=True, target=1e-30)
    with mpmath.workdps(50):
        wn = mpmath.mpf(omega_n.p) / omega_n.q
        exact = [(mpmath.cos(tv) - mpmath.cos(wn * tv)) / (wn**2 - 1)
                 for tv in map(mpmath.mpf, times)]
    diff, scale = _errors(x[0], exact)
    assert sol.escalation == "mp"
    assert diff <= 1e-16 * scale
    assert np.all(error <= 1e-14 * scale)  # a float64 bound never claims more than 14 digits
    assert np.all(error >= np.abs(x[0] - np.array([float(e) for e in exact])))


def test_evaluate_mp_raises_its_precision():
    # Data converted at only 20 digits, residues 1e15 that cancel: 50 digits are still
    # delivered (the exact terms are reconverted at the precision the sum needs).
    omega, omega_n = sp.Rational(1), 1 + sp.Rational(1, 10**15)
    data = numeric_terms([_beat_terms(omega, omega_n)], dps=20)
    times = ["0.5", "3", "1000"]
    x = evaluate_mp(data, 1, times, 50)
    with mpmath.workdps(80):
        wn = mpmath.mpf(omega_n.p) / omega_n.q
        for value, tv in zip(x[0], map(mpmath.mpf, times)):
            exact = (mpmath.cos(tv) - mpmath.cos(wn * tv)) / (wn**2 - 1)
            assert abs(value - exact) <= mpmath.mpf(10) ** -48 * abs(exact)


@pytest.mark.parametrize("nodes", [
    [0.1 + 0.2j, 0.1 - 0.2j, -0.3 + 0j],
    [2.0 + 1j, -1.5 + 0.5j, 0.5 - 2j, 3j],       # needs scaling and squaring
    [0.0, 0.0, 0.0, 1e-9],                         # confluent
])
def test_first_row_exp_is_opitz_divided_differences(nodes):
    # Reference: mpmath expm of the bidiagonal matrix at 40 digits.
    x = np.array([nodes], dtype=complex)
    row, _ = first_row_exp(x)
    size = len(nodes)
    with mpmath.workdps(40):
        W = mpmath.matrix(size, size)
        for i, v in enumerate(nodes):
            W[i, i] = mpmath.mpc(v.real, v.imag) if isinstance(v, complex) else v
            if i + 1 < size:
                W[i, i + 1] = 1
        E = mpmath.expm(W)
        exact = [complex(E[0, j]) for j in range(size)]
    assert np.allclose(row[0], exact, rtol=1e-14, atol=1e-16)


@settings(max_examples=25, deadline=None)
@given(exponent=st.integers(2, 15), above=st.booleans(), x0=st.integers(-3, 3),
       v0=st.integers(-3, 3), stop=st.sampled_from([1.0, 50.0, 1e4]))
def test_property_near_critical(exponent, above, x0, v0, stop):
    # x'' + 2(1 ± 10^-e) x' + x = 0 against the certified arb reference.
    if x0 == 0 and v0 == 0:
        x0 = 1
    c = 2 * (1 + (1 if above else -1) * sp.Rational(1, 10**exponent))
    scene = ls.Scene.from_matrices(M=[[1]], C=[[c]], K=[[1]], x0=[x0], v0=[v0])
    times = np.concatenate([[0.0, 0.5, 1.0, 2.0], np.linspace(0.0, stop, 9)])
    x = ls.solve(scene).evaluate(times)
    assert relative_error(x, reference_motion_arb(scene, times, digits=30)) <= 1e-14


@pytest.mark.parametrize("delay", [sp.Rational(1, 3), "0.1", 0.1, sp.sqrt(2)])
def test_delay_is_subtracted_exactly(delay):
    # cos(ω(t − τ)) − cos(ω_n(t − τ)) over (ω_n² − ω²) at t up to 1e4, τ exact.
    omega, omega_n = sp.Rational(1), 1 + sp.Rational(1, 10**8)
    times = np.array([0.5, 1.0, 2.0**-40 + 1, 3333.25, 9999.875])
    data = numeric_terms([_beat_terms(omega, omega_n)])
    with mpmath.workdps(50):
        tau = (mpmath.mpf(delay) if isinstance(delay, (str, float))
               else mpmath.mpf(str(sp.N(delay, 60))))
        tau_hi = float(tau)
        tau_lo = float(tau - tau_hi)
    hi, lo = two_diff(times, tau_hi, tau_lo)
    x, _ = evaluate_float(data, 1, hi, lo=lo)
    with mpmath.workdps(50):
        wn = mpmath.mpf(omega_n.p) / omega_n.q
        exact = [(mpmath.cos(tv - tau) - mpmath.cos(wn * (tv - tau))) / (wn**2 - 1)
                 for tv in map(mpmath.mpf, times)]
    diff, scale = _errors(x[0], exact)
    assert diff <= 1e-15 * scale


def test_evaluate_mp_large_phase():
    # cos(ωt) with ω = 1e4 + 1/3 at t = 1e6: a phase of 1e10 still gives 50 digits.
    omega = 10**4 + sp.Rational(1, 3)
    data = numeric_terms([[Term("oscillatory", 0, sp.S.Zero, omega, sp.S.One, sp.S.Zero)]])
    x = evaluate_mp(data, 1, ["1000000"], 50)
    with mpmath.workdps(100):
        exact = mpmath.cos((mpmath.mpf(10**4) + mpmath.mpf(1) / 3) * 10**6)
        assert abs(x[0, 0] - exact) <= mpmath.mpf(10) ** -49


def test_coefficients_formed_by_cancellation_keep_the_error_of_what_cancelled():
    """K coupled by 1e-15: each mode's pole pair is ±1.7e-16 apart, and x1's coefficients
    (a ± b)/2 with a ≈ −b ≈ 5e15 cancel to 0.33 and then to 1e-16 in the Newton form, whose
    data error was taken relative to the result: x1(100) = 2.1e-36 was off by 2.1e-48 with a
    bound of 4.8e-51 (found by the numeric attack). Reference: arb's matrix exponential."""
    scene = ls.Scene.from_matrices(
        M=[[4, 0], [0, 4]], C=[[16, 0], [0, 4]], K=[[16, "-1e-15"], ["-1e-15", 1]],
        x0=["2857142857142857/20000000000000000", 0], v0=[-2, 1])
    times = [1.0, 10.0, 100.0, 1000.0]
    values, bounds = ls.solve(scene, method="exact").evaluate(times, return_error=True)
    reference = reference_motion_arb(scene, times, digits=40).astype(float)
    assert np.all(np.abs(values - reference) <= bounds)
