"""Attacks on the analysis and sweep APIs, each value checked against an independent route.

References are written here: closed forms worked by hand and evaluated in mpmath at
40 digits, or (K − ω²M + iωC)⁻¹ inverted in mpmath over exact rationals.
"""

from __future__ import annotations

import re
from fractions import Fraction

import mpmath as mp
import numpy as np
import pytest
import sympy as sp

import laplace_springs as ls
from laplace_springs.model.errors import LimitError, SceneError


def _single_mass(c: mp.mpf, k: mp.mpf, t: float) -> tuple[mp.mpf, mp.mpf, mp.mpf]:
    """x, x', x'' of x'' + c x' + k x = 0, x(0) = 1, x'(0) = 0, by hand (m = 1)."""
    t = mp.mpf(t)
    disc = c * c - 4 * k
    if disc == 0:  # critical: x = (1 + at) e^{-at}, a = c/2
        a = c / 2
        x, v = (1 + a * t) * mp.exp(-a * t), -a * a * t * mp.exp(-a * t)
    else:
        s = mp.sqrt(mp.mpc(disc)) / 2
        a = c / 2
        # x = e^{-at}(cosh st + (a/s) sinh st), x' = -(k/s) e^{-at} sinh st
        x = mp.re(mp.exp(-a * t) * (mp.cosh(s * t) + a / s * mp.sinh(s * t)))
        v = mp.re(-k / s * mp.exp(-a * t) * mp.sinh(s * t))
    return x, v, -c * v - k * x


def test_sweep_underflowing_motion_has_a_positive_bound() -> None:
    """A motion that underflows float64 (x = (1 + t)e^{-t} at t = 1e4 is 1e-4339) is 0 in
    float64; its bound must not be 0 (the compiled route gave bound 0 on every set whose
    exponentials underflowed: k = 1, c = 2 at t = 1e4, 1e5; k = 2, c = 2; k = 1e6, c = 2e3
    at t = 7). Every bound is checked against the closed form at 40 digits."""
    mp.mp.dps = 40
    scene = ls.Scene.from_matrices(M=[[1]], C=[["c"]], K=[["k"]], x0=[1], v0=[0],
                                   parameters={"k": "positive", "c": "nonnegative"})
    g = ls.grid(k=[1e-6, 1.0, 2.0, 1e6], c=[0.0, 2e-3, 2.0, 2e3])
    times = np.array([1e5, 7.0, 0.0, 12345.678, 1e4, 0.0, 0.25])
    for order in (0, 1, 2):
        result = ls.sweep(scene, g, times, return_error=True, derivative=order)
        for p in range(len(g["k"])):
            c, k = (mp.mpf(repr(float(g[name][p]))) for name in ("c", "k"))
            for j, t in enumerate(times):
                exact = _single_mass(c, k, float(t))[order]
                value, bound = result.values[p, 0, j], result.error[p, 0, j]
                assert abs(mp.mpf(value) - exact) <= bound, (order, float(c), float(k), t, value, bound)


def _receptance(M: list[list[str]], C: list[list[str]], K: list[list[str]], w: float) -> mp.matrix:
    """(K − ω²M + iωC)⁻¹ in mpmath at 40 digits from the decimal entries read exactly."""
    n = len(M)
    q = mp.mpf(w)
    A = mp.matrix(n, n)
    for i in range(n):
        for j in range(n):
            k, m, c = (mp.mpf(Fraction(x[i][j]).numerator) / Fraction(x[i][j]).denominator
                       for x in (K, M, C))
            A[i, j] = k - q * q * m + 1j * q * c
    return A**-1


def _scene(M: list[list[str]], C: list[list[str]], K: list[list[str]]) -> ls.Scene:
    return ls.Scene.from_matrices(M=M, C=C, K=K, x0=[0] * len(M), v0=[0] * len(M))


@pytest.mark.parametrize(("M", "C", "K", "omegas"), [
    # one mass driven at float64's nearest to √2, undamped: 2 − ω² cancels (error 0.23 before)
    ([["1"]], [["0"]], [["2"]], [float(np.sqrt(2.0))]),
    # ζ = 5e-9 at and near resonance, huge and tiny ω
    ([["1"]], [["1e-8"]], [["1"]], [1.0, 1 + 1e-9, 1e150, 1e-150]),
    # two masses, light damping on each, driven at float64's natural frequencies
    ([["3", "0"], ["0", "1"]], [["1e-9", "0"], ["0", "1e-9"]], [["7.3", "-2.1"], ["-2.1", "2.1"]],
     [1.8682890524164226, 1.0211901634633378, 0.5, 1e-200, 1e100]),
])
def test_frequency_response_near_resonance(M: list[list[str]], C: list[list[str]],
                                           K: list[list[str]], omegas: list[float]) -> None:
    """H(iω) within a few units of float64 rounding of ‖H‖ (normwise), against mpmath."""
    mp.mp.dps = 40
    H = ls.frequency_response(_scene(M, C, K), omegas)
    n = len(M)
    for k, w in enumerate(omegas):
        R = _receptance(M, C, K, w)
        size = max(abs(R[i, j]) for i in range(n) for j in range(n))
        error = max(abs(R[i, j] - complex(H[k, i, j])) for i in range(n) for j in range(n))
        assert error <= 1e-15 * size, (w, float(error / size))


_CHAIN_K = [["0.1", "-0.1", "0"], ["-0.1", "0.8", "-0.7"], ["0", "-0.7", "0.7"]]
_CHAIN_C = [["0.1", "-0.1", "0"], ["-0.1", "0.3", "-0.2"], ["0", "-0.2", "0.2"]]
_EYE3 = [["1", "0", "0"], ["0", "1", "0"], ["0", "0", "1"]]


@pytest.mark.parametrize(("M", "C", "K", "w"), [
    # free-free, damped, at ω = 0 (the message said "an undamped scene")
    ([["1", "0"], ["0", "1"]], [["0.1", "-0.1"], ["-0.1", "0.1"]], [["1", "-1"], ["-1", "1"]], 0.0),
    # free-free chain whose K rounds to a nonsingular float64 matrix (0.1 + 0.7 ≠ 0.8):
    # H(0) came back as about 1e16 (garbage)
    (_EYE3, [["0"] * 3] * 3, _CHAIN_K, 0.0),
    (_EYE3, _CHAIN_C, _CHAIN_K, 0.0),
    ([["sqrt(2)", "0", "0"], ["0", "1", "0"], ["0", "0", "pi"]], _CHAIN_C, _CHAIN_K, 0.0),
    # ω exactly an undamped natural frequency: rational (k/m = 4) and irrational (k = m = √2)
    ([["1"]], [["0"]], [["4"]], 2.0),
    ([["sqrt(2)"]], [["0"]], [["sqrt(2)"]], 1.0),
])
def test_frequency_response_singular_says_so(M: list[list[str]], C: list[list[str]],
                                             K: list[list[str]], w: float) -> None:
    """A pencil that is exactly singular is refused, naming ω and the cause; never a value."""
    cause = "rigid-body mode" if w == 0 else "natural frequency of an undamped mode"
    with pytest.raises(SceneError, match=rf"omega = {w!r}.*singular.*{cause}"):
        ls.frequency_response(_scene(M, C, K), [1.0, w])


def _exact_entry(text: str) -> mp.mpf:
    """An entry of the tests' matrices in mpmath at the working precision."""
    named = {"sqrt(2)": mp.sqrt(2), "pi": mp.pi}
    if text in named:
        return +named[text]
    q = Fraction(text)
    return mp.mpf(q.numerator) / q.denominator


def _receptance_at(M: list[list[str]], C: list[list[str]], K: list[list[str]], w: float) -> mp.matrix:
    """(K − ω²M + iωC)⁻¹ in mpmath, ω the float64 number exactly, at the working precision."""
    n = len(M)
    q = mp.mpf(w)
    return mp.matrix([[_exact_entry(K[i][j]) - q * q * _exact_entry(M[i][j]) + 1j * q * _exact_entry(C[i][j])
                       for j in range(n)] for i in range(n)])**-1


@pytest.mark.parametrize(("M", "C", "K", "omegas", "entrywise"), [
    # free-free chain (K entries 0.1, 0.8, 0.7, no walls), damped and undamped: refused as
    # "singular at float64 precision" below ω ≈ 1e-7 (cond ≈ 1/ω²), though H exists for ω > 0
    (_EYE3, _CHAIN_C, _CHAIN_K, [1e-12, 1e-8, 1e-20, 1e-100, 1e-150, 0.5], True),
    (_EYE3, [["0"] * 3] * 3, _CHAIN_K, [1e-12, 1e-8, 1e-20, 1e-100], True),
    # a chain with irrational masses (certified balls, normwise)
    ([["sqrt(2)", "0", "0"], ["0", "1", "0"], ["0", "0", "pi"]], _CHAIN_C, _CHAIN_K,
     [1e-12, 1e-8, 1e-20, 1e-100], False),
    # two masses, undamped, at float64's nearest to a natural frequency (cond about 1e16):
    # exactly nonsingular, H about 7e14
    ([["3", "0"], ["0", "1"]], [["0", "0"], ["0", "0"]], [["7.3", "-2.1"], ["-2.1", "2.1"]],
     [1.8682890524164226, 1.0211901634633378], True),
])
def test_frequency_response_where_float64_is_singular(M: list[list[str]], C: list[list[str]],
                                                      K: list[list[str]], omegas: list[float],
                                                      entrywise: bool) -> None:
    """H(iω) where the pencil is singular at float64 precision but not exactly: against
    (K − ω²M + iωC)⁻¹ in mpmath at 50 digits plus five per decade of 1/ω (cond ≈ 1/ω², and
    an imaginary part about ω³ times the real one).
    Rational scenes are solved exactly: each real and imaginary part correctly rounded
    (within one ulp here); irrational ones within 2⁻⁵⁰ of max |H|."""
    H = ls.frequency_response(_scene(M, C, K), omegas)
    n = len(M)
    for k, w in enumerate(omegas):
        with mp.workdps(50 + 5 * max(0, int(-mp.log10(w)))):
            R = _receptance_at(M, C, K, w)
            size = max(abs(R[i, j]) for i in range(n) for j in range(n))
            for i in range(n):
                for j in range(n):
                    got = complex(H[k, i, j])
                    for part, ref in ((got.real, mp.re(R[i, j])), (got.imag, mp.im(R[i, j]))):
                        if entrywise:
                            assert abs(part - ref) <= 2.0**-52 * abs(ref), (w, i, j, part, ref)
                        else:
                            assert abs(part - ref) <= 2.0**-50 * size, (w, i, j, part, ref)


def test_frequency_response_beyond_float64_range() -> None:
    """|H| = 1e-600 at ω = 1e300 is no float64 number: a LimitError naming ω; so is
    |H| ≈ 1/(3ω²) ≈ 3e599 at ω = 1e-300 on the free-free chain (found exactly)."""
    with pytest.raises(LimitError, match="omega = 1e\\+300"):
        ls.frequency_response(_scene([["1"]], [["1"]], [["1"]]), [1e300])
    with pytest.raises(LimitError, match=r"omega = 1e-300.*1e\+599"):
        ls.frequency_response(_scene(_EYE3, _CHAIN_C, _CHAIN_K), [1.0, 1e-300])


def test_float_modes_of_an_undamped_scene_have_zero_damping() -> None:
    """M = diag(√2, 1), K = [[1, −1], [−1, 1]], no damping (irrational: the float64 route):
    det(K − μM) = √2μ² − (1 + √2)μ, so ω² = 1 + 1/√2 and a rigid mode; ζ was −2.3e-17 (a
    negative damping ratio on an undamped scene), it is 0."""
    mp.mp.dps = 40
    scene = ls.Scene.from_matrices(M=[["sqrt(2)", 0], [0, 1]], K=[[1, -1], [-1, 1]],
                                   x0=[0, 0], v0=[0, 0])
    rigid, mode = ls.modes(scene)
    assert rigid.kind == "rigid" and mode.kind == "oscillatory"
    assert mode.damping_ratio == 0
    omega = mp.sqrt(1 + 1 / mp.sqrt(2))
    assert abs(mp.mpf(str(mode.natural_frequency)) - omega) <= 1e-14 * omega
    assert abs(mp.mpf(str(mode.damped_frequency)) - omega) <= 1e-14 * omega


def _eigenvalue_count(found: tuple) -> int:
    """Eigenvalues listed, with multiplicity: a complex mode stands for its conjugate too."""
    return sum(m.multiplicity * (2 if m.kind == "oscillatory" else 1) for m in found)


@pytest.mark.parametrize("c", [2 * sp.sqrt(2), "2*sqrt(2)"])
def test_modes_irrational_critical_damping_is_one_double_mode(c: object) -> None:
    """x'' + 2√2 x' + 2x = 0: Δ = (λ + √2)², critical damping (ζ = c/(2√(km)) = 1,
    ω_n = √2 by hand). It was two simple modes at λ = −1.4142135(4 and 9) (float64 split
    the double root by √u); it is one mode λ = −√2 of multiplicity 2, as the rational
    x'' + 2x' + x = 0 gives one mode λ = −1 of multiplicity 2."""
    scene = ls.Scene.from_matrices(M=[[1]], C=[[c]], K=[[2]], x0=[1], v0=[0])
    (mode,) = ls.modes(scene)
    assert mode.multiplicity == 2 and mode.kind == "real"
    assert sp.simplify(mode.eigenvalue + sp.sqrt(2)) == 0
    assert sp.simplify(mode.natural_frequency - sp.sqrt(2)) == 0
    zeta = -sp.re(mode.eigenvalue) / sp.Abs(mode.eigenvalue)  # ζ = −Re λ/|λ|
    assert sp.simplify(zeta - 1) == 0


def test_modes_irrational_two_masses_with_a_double_root() -> None:
    """M = I, K = [[2, −1], [−1, 2]] (ω² = 1, 3), C = (2/√3)K (classical): the ω² = 3 mode
    has λ² + 2√3 λ + 3 = (λ + √3)², critical (by hand); the ω² = 1 mode λ² + (2/√3)λ + 1,
    ζ = 1/√3, ω_d = √(2/3). Before: three modes (the double root split in two)."""
    b = 2 / sp.sqrt(3)
    scene = ls.Scene.from_matrices(M=[[1, 0], [0, 1]], C=[[2 * b, -b], [-b, 2 * b]],
                                   K=[[2, -1], [-1, 2]], x0=[1, 0], v0=[0, 0])
    found = ls.modes(scene)
    assert len(found) == 2 and _eigenvalue_count(found) == 4
    slow, critical = found
    assert critical.multiplicity == 2 and critical.kind == "real"
    assert sp.simplify(critical.eigenvalue + sp.sqrt(3)) == 0
    assert sp.simplify(critical.natural_frequency - sp.sqrt(3)) == 0
    assert np.allclose(critical.shape, [-1, 1]) or np.allclose(critical.shape, [1, -1])
    assert slow.kind == "oscillatory" and slow.multiplicity == 1
    assert abs(float(slow.natural_frequency) - 1) <= 1e-14
    assert abs(float(slow.damping_ratio) - 1 / np.sqrt(3)) <= 1e-14
    assert abs(float(slow.damped_frequency) - np.sqrt(2 / 3)) <= 1e-14


def test_modes_irrational_repeated_roots_other_domains() -> None:
    """Equal frequencies (M = √2 I, K = I: ω = 2^(-1/4) twice, two shapes) and critical
    damping over π (c = 2π, k = π²: λ = −π) and √π (c = 2√π, k = π: λ = −√π), by hand."""
    equal = ls.modes(ls.Scene.from_matrices(M=[["sqrt(2)", 0], [0, "sqrt(2)"]], K=[[1, 0], [0, 1]],
                                            x0=[1, 0], v0=[0, 0]))
    (mode,) = equal
    assert mode.multiplicity == 2 and len(mode.shapes) == 2 and mode.damping_ratio == 0
    assert sp.simplify(mode.natural_frequency - 2 ** sp.Rational(-1, 4)) == 0
    for c, k, root in (("2*pi", "pi**2", sp.pi), ("2*sqrt(pi)", "pi", sp.sqrt(sp.pi))):
        (mode,) = ls.modes(ls.Scene.from_matrices(M=[[1]], C=[[c]], K=[[k]], x0=[1], v0=[0]))
        assert mode.multiplicity == 2 and sp.simplify(mode.eigenvalue + root) == 0, (c, mode)


def test_modes_irrational_near_critical_stays_two_modes() -> None:
    """c = 2√2 + 1e-9, k = 2: two simple real roots (−c ± √(c² − 8))/2, 5e-5 apart, stay
    two modes, each within 1e-9 relative of the roots in mpmath at 40 digits (the float
    route: the simple roots are ill-conditioned, √u·|λ|/gap ≈ 1e-4 of their gap)."""
    found = ls.modes(ls.Scene.from_matrices(M=[[1]], C=[["2*sqrt(2) + 1/10**9"]], K=[[2]],
                                            x0=[1], v0=[0]))
    assert [m.multiplicity for m in found] == [1, 1]
    with mp.workdps(40):
        c = 2 * mp.sqrt(2) + mp.mpf(10) ** -9
        roots = sorted([(-c + mp.sqrt(c * c - 8)) / 2, (-c - mp.sqrt(c * c - 8)) / 2], reverse=True)
        for mode, root in zip(found, roots):
            assert abs(mp.mpf(str(mode.eigenvalue)) - root) <= 1e-9 * abs(root)


@pytest.mark.parametrize("times", [np.array([[0.0, 1.0], [2.0, 3.0]]), [[0.0, 1.0], [2.0, 3.0]],
                                   np.zeros((1, 3)), np.zeros((2, 1, 1))])
def test_sweep_refuses_times_of_more_than_one_axis(times: object) -> None:
    """2-D times were flattened: (2, 2) times gave values of shape (P, n, 4) without a word.
    A number or a 1-D array only (NumPy's rule), the error naming times and the shape."""
    scene = ls.Scene.from_matrices(M=[[1]], C=[["c"]], K=[["k"]], x0=[1], v0=[0], parameters=["c", "k"])
    shape = np.asarray(times).shape
    with pytest.raises(ValueError, match=rf"sweep: times must be a 1-D array .*got shape {re.escape(str(shape))}"):
        ls.sweep(scene, {"k": [1, 2], "c": [0.1, 0.2]}, times)


def test_grid_refuses_values_of_more_than_one_axis() -> None:
    """grid(k=[[1, 2], [3, 4]]) was a grid of four k values (shape (4, 1)); now an error
    naming k and (2, 2). sweep's own values were already refused; settling_time's times too."""
    with pytest.raises(ValueError, match=r"grid: values of 'k' must be a 1-D array .*got shape \(2, 2\)"):
        ls.grid(k=[[1, 2], [3, 4]], c=[0.1])
    with pytest.raises(ValueError, match=r"settling_time: times must be a 1-D array .*got shape \(1, 3\)"):
        ls.sweeps.settling_time(np.zeros((1, 1, 3)), np.zeros((1, 3)), 0.1)


def test_sweep_scalars_are_one_value() -> None:
    """A number is one time, and one value of a parameter: x'' + c x' + k x = 0 from x = 1
    at t = 1.5, (1 + t)e^{-t} (k = 1, c = 2) and (1 + 2t)e^{-2t} (k = 4, c = 4), by hand."""
    scene = ls.Scene.from_matrices(M=[[1]], C=[["c"]], K=[["k"]], x0=[1], v0=[0], parameters=["c", "k"])
    g = ls.grid(k=4.0, c=[2.0, 4.0])
    assert g.shape == (1, 2)
    x = ls.sweep(scene, {"k": [1, 4], "c": [2, 4]}, 1.5)
    assert x.shape == (2, 1, 1)
    t = mp.mpf("1.5")
    for value, exact in ((x[0, 0, 0], (1 + t) * mp.exp(-t)), (x[1, 0, 0], (1 + 2 * t) * mp.exp(-2 * t))):
        assert abs(value - exact) <= 4e-16 * abs(exact)
